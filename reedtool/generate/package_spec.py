"""What `new-package` builds: parameters from flags or a YAML spec, checked, in SI units.

Every parameter is declared once in PARAMS (YAML key, unit dimension, default, which
vehicle kinds use it, one line of documentation). YAML keys are the RotorS xacro property
names a RotorS user already knows (`mass`, `arm_length`, `motor_constant`, ...); values are
plain numbers in SI units or strings with a unit ("187.38 mm", "1500 g", "8000 rpm").
Flags override the spec file; the spec file overrides the defaults.

`mass` is the BODY mass (as RotorS' multirotor_base_macro takes it), not the total: rotors
and sensors add to it, and the hover check below counts them.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

from reedtool.errors import PLAUSIBLE, ReedtoolError, check_plausible
from reedtool.io.xml_numbers import short_text
from reedtool.model import inertia_values
from reedtool.physics.propulsion import FIREFLY
from reedtool.generate.airframes import Airframe, GroundLayout, get_frame

# Unit factors to SI, per dimension. A dimension with no units takes plain numbers only.
UNITS: dict[str, dict[str, float]] = {
    "mass": {"kg": 1.0, "g": 1e-3, "lb": 0.45359237},
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "in": 0.0254},
    "time": {"s": 1.0, "ms": 1e-3},
    "angular_velocity": {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0},
    "number": {},
}

# The sensors the generated multirotor mounts, as RotorS' macros declare them: default_imu
# (ADIS16448, 0.015 kg), plus the ground-truth IMU, ground-truth odometry and the generic
# odometry sensor at 1e-5 kg each. Only used for the hover margin estimate printed at
# generation time; validate and hover-test read the real expanded model.
SENSOR_MASS_KG = 0.015 + 3 * 0.00001

# Simulators a multirotor package can target. "classic": Gazebo classic with RotorS' plugins
# (ROS 1 and 2). "gz": Gazebo Sim (Harmonic and later) with its MulticopterMotorModel and
# MulticopterVelocityControl systems, ROS 2 only (ros_gz has no ROS 1 release for it).
SIMULATORS = ("gz", "classic")

STANDARD_GRAVITY_M_S2 = 9.80665
# Below this max-thrust / weight ratio the vehicle hovers at > 80 % throttle and has no
# authority left to correct attitude; new-package refuses such a spec.
MIN_THRUST_TO_WEIGHT = 1.25

MULTIROTOR = frozenset({"multirotor"})
GROUND = frozenset({"ground"})
BOTH = MULTIROTOR | GROUND


@dataclass(frozen=True)
class Param:
    key: str                     # YAML key and xacro property name
    dimension: str               # a key of UNITS
    default: float | Callable[[Airframe | GroundLayout], float]
    kinds: frozenset
    doc: str
    allow_zero: bool = False

    @property
    def unit(self) -> str:
        units = UNITS[self.dimension]
        return next(iter(units)) if units else "-"


def _by_kind(multirotor: float, ground: float):
    return lambda frame: multirotor if frame.kind == "multirotor" else ground


def _arm_length_default(frame) -> float:
    # quad-x: the seed's 0.18738 m x/y offset. Others: 0.265 m from the centre (the same
    # motor distance); the octo needs 0.30 m so 0.1 m propellers do not overlap.
    return {"quad-x": 0.18738, "octo-x": 0.30}.get(frame.name, 0.265)


PARAMS: tuple[Param, ...] = (
    Param("mass", "mass", _by_kind(1.5, 2.0), BOTH,
          "body (chassis) mass; rotors, wheels and sensors come on top"),
    # multirotor
    Param("arm_length", "length", _arm_length_default, MULTIROTOR,
          "centre to rotor axis (quad-x: the rotor's x and y offset)"),
    Param("body_width", "length", _by_kind(0.2, 0.3), BOTH,
          "body box width (multirotor: x and y edge; ground: y edge)"),
    Param("body_height", "length", _by_kind(0.06, 0.1), BOTH, "body box height"),
    Param("rotor_offset_top", "length",
          lambda frame: 0.05 if frame.name == "y6" else 0.026, MULTIROTOR,
          "rotor height above the body centre (y6: lower rotors at minus this)"),
    Param("mass_rotor", "mass", 0.005, MULTIROTOR, "mass of one rotor (propeller)"),
    Param("radius_rotor", "length", 0.1, MULTIROTOR, "propeller radius"),
    # the motor model's defaults: RotorS firefly's (physics.propulsion.FIREFLY, which the
    # summary names when no --motor/--prop/--battery derive them)
    Param("motor_constant", "number", FIREFLY["motor_constant"], MULTIROTOR,
          "thrust per squared rotor speed [N/(rad/s)^2]"),
    Param("moment_constant", "number", FIREFLY["moment_constant"], MULTIROTOR,
          "drag torque per thrust [m]"),
    Param("max_rot_velocity", "angular_velocity", FIREFLY["max_rot_velocity"], MULTIROTOR,
          "maximum rotor speed"),
    Param("time_constant_up", "time", FIREFLY["time_constant_up"], MULTIROTOR,
          "motor spin-up time constant"),
    Param("time_constant_down", "time", FIREFLY["time_constant_down"], MULTIROTOR,
          "motor spin-down time constant"),
    Param("rotor_drag_coefficient", "number", 8.06428e-05, MULTIROTOR,
          "RotorS rotor drag coefficient [N/(m/s)/(rad/s)]", allow_zero=True),
    Param("rolling_moment_coefficient", "number", 1e-06, MULTIROTOR,
          "RotorS rolling moment coefficient [N*m/(m/s)/(rad/s)]", allow_zero=True),
    Param("rotor_velocity_slowdown_sim", "number", 10.0, MULTIROTOR,
          "RotorS visual slowdown factor; also scales rotor inertia (RotorS convention)"),
    # ground
    Param("body_length", "length", 0.4, GROUND, "body box length (x)"),
    Param("wheel_radius", "length", 0.05, GROUND, "wheel radius"),
    Param("wheel_width", "length", 0.04, GROUND, "wheel width"),
    Param("wheel_mass", "mass", 0.2, GROUND, "mass of one wheel"),
    Param("wheelbase", "length", 0.25, GROUND, "front to rear axle distance (car-4w)"),
    Param("track_width", "length", 0.36, GROUND,
          "distance between left and right wheel centres"),
    Param("ground_clearance", "length", 0.04, GROUND, "gap under the body"),
    Param("caster_mass", "mass", 0.05, GROUND, "caster ball mass (diff-drive)"),
)
PARAM_MAP = {p.key: p for p in PARAMS}

# Non-numeric spec keys.
TEXT_KEYS = ("name", "frame", "ros", "sim", "mesh", "description", "maintainer",
             "maintainer_email", "license", "version", "motor", "prop", "battery")
# What --motor, --prop and --battery (spec keys motor, prop, battery) derive together
# (reedtool.physics.propulsion); given with them, these would contradict them.
PROPULSION_KEYS = ("motor_constant", "moment_constant", "max_rot_velocity", "radius_rotor")


@dataclass
class CadPlacement:
    """Where a CAD body mesh puts things, in its own frame (base_link = the CAD origin,
    FLU, metres): set by generate.cad_body when --mesh is given."""

    centre_m: tuple[float, float, float]            # rotors are placed about it
    body_com_m: tuple[float, float, float]          # the body's COM (its <inertial><origin>)
    body_bottom_z_m: float                          # lowest point of the mesh
    rotor_positions_m: tuple | None = None          # (n, 3) on the motor mounts, else None


@dataclass
class PackageSpec:
    name: str
    frame: Airframe | GroundLayout
    ros: int                                   # 1 (catkin) or 2 (ament_cmake)
    values: dict[str, float]                   # SI values of the PARAMS of this kind
    mesh: Path | None = None                   # body mesh, when given
    description: str = ""
    maintainer: str = "TODO Maintainer"
    maintainer_email: str = "maintainer@example.com"
    license: str = "BSD-3-Clause"
    version: str = "0.1.0"
    origin: dict[str, str] = field(default_factory=dict)  # key -> "default"|"spec"|"--flag"
    sim: str = "classic"                       # a SIMULATORS entry
    cad: CadPlacement | None = None            # a CAD body's frame, COM and mounts
    # reedtool.physics.propulsion.Propulsion when --motor/--prop/--battery derived the
    # motor constants; None: the constants are the defaults (RotorS firefly) or given.
    propulsion: object | None = None

    @property
    def kind(self) -> str:
        return self.frame.kind

    def __getitem__(self, key: str) -> float:
        return self.values[key]


# ------------------------------------------------------------------ quantities

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z/]*)\s*$")


def parse_quantity(value, param: Param, source: str) -> float:
    """A number in SI, or a string with one of the dimension's units, to SI."""
    if isinstance(value, bool):
        raise ReedtoolError(f"{param.key}: expected a number, got {value!r}", file=source)
    if isinstance(value, (int, float)):
        si = float(value)
    elif isinstance(value, str):
        match = _QUANTITY.match(value)
        units = UNITS[param.dimension]
        if not match:
            raise ReedtoolError(f"{param.key}: cannot read '{value}' as a number",
                                file=source, hint=_unit_hint(param))
        number, unit = float(match.group(1)), match.group(2)
        if unit and unit not in units:
            raise ReedtoolError(f"{param.key}: unknown unit '{unit}'", file=source,
                                hint=_unit_hint(param))
        si = number * (units[unit] if unit else 1.0)
    else:
        raise ReedtoolError(f"{param.key}: expected a number, got {type(value).__name__}",
                            file=source, hint=_unit_hint(param))
    if not math.isfinite(si):
        raise ReedtoolError(f"{param.key}: value must be finite, got {value!r}", file=source)
    if si < 0.0 or (si == 0.0 and not param.allow_zero):
        need = "zero or positive" if param.allow_zero else "positive"
        raise ReedtoolError(f"{param.key}: must be {need}, got {value!r}", file=source)
    if param.dimension in PLAUSIBLE and not (si == 0.0 and param.allow_zero):
        check_plausible(param.dimension, si, param.key, file=source)
    return si


def _unit_hint(param: Param) -> str:
    units = list(UNITS[param.dimension])
    if not units:
        return "give a plain number"
    return f"give a number in {units[0]} or a string with one of: {', '.join(units)}"


# ------------------------------------------------------------------ names

_REP144 = re.compile(r"^[a-z][a-z0-9_]*$")


def check_package_name(name: str) -> None:
    """REP 144: lowercase letters, digits and single underscores, starting with a letter."""
    problem = None
    if not name:
        problem = "is empty"
    elif not _REP144.match(name):
        problem = ("must start with a lowercase letter and contain only lowercase letters, "
                   "digits and underscores")
    elif "__" in name:
        problem = "must not contain consecutive underscores"
    elif name.endswith("_"):
        problem = "must not end with an underscore"
    if problem:
        suggestion = re.sub(r"_+", "_", re.sub(r"[^a-z0-9_]", "_", name.lower())).strip("_")
        if suggestion and not suggestion[0].isalpha():
            suggestion = "pkg_" + suggestion
        hint = f"try '{suggestion}'; see ROS REP 144" if suggestion else "see ROS REP 144"
        raise ReedtoolError(f"invalid ROS package name '{name}': it {problem}", hint=hint)


def _check_not_bundled(name: str) -> None:
    """A package named like one reedtool bundles would shadow it: its own model, which
    includes the bundled macros of that name, could then not be expanded."""
    from reedtool.resolve.packages import bundled_package_names

    if name in bundled_package_names():
        raise ReedtoolError(f"package name '{name}' is the name of a package reedtool "
                            "bundles (and the generated model uses)",
                            hint=f"choose another name, e.g. '{name}_custom'")


# ------------------------------------------------------------------ loading

def read_spec_file(path: Path) -> dict:
    import yaml

    from reedtool.io.fileio import read_text_file

    text = read_text_file(Path(path), what="spec file")
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise ReedtoolError(f"invalid YAML: {getattr(exc, 'problem', None) or exc}", file=path,
                            line=mark.line + 1 if mark else None) from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ReedtoolError("a spec file must be a mapping of parameter: value", file=path)
    return data


def build_spec(name: str, *, frame: str | None = None, ros: int | None = None,
               spec_file: Path | None = None, flags: Mapping[str, object] | None = None,
               mesh: Path | None = None, sim: str | None = None,
               drive: Mapping[str, str | None] | None = None) -> PackageSpec:
    """Merge defaults < spec file < flags, convert to SI and check the result.

    `drive`: the --motor, --prop and --battery texts (None where not given); with the
    spec file's `motor`, `prop` and `battery` they derive the motor constants."""
    data = read_spec_file(spec_file) if spec_file else {}
    src = str(spec_file) if spec_file else "<spec>"
    unknown = [k for k in data if k not in PARAM_MAP and k not in TEXT_KEYS]
    if unknown:
        key = unknown[0]
        close = difflib.get_close_matches(key, [*PARAM_MAP, *TEXT_KEYS], n=1)
        hint = f"did you mean '{close[0]}'?" if close else "docs/new-package.md lists the keys"
        raise ReedtoolError(f"unknown spec key '{key}'", file=spec_file, hint=hint)
    if "name" in data and str(data["name"]) != name:
        raise ReedtoolError(f"spec names package '{data['name']}' but the command line says "
                            f"'{name}'", file=spec_file, hint="drop `name` from the spec or "
                            "use the same name")
    check_package_name(name)
    _check_not_bundled(name)
    _check_text_keys(data, spec_file)

    try:
        frame_obj = get_frame(frame or str(data.get("frame", "quad-x")))
    except ReedtoolError as exc:
        if frame is not None or exc.file is not None:
            raise
        raise ReedtoolError(f"frame: {exc.message}", file=spec_file, hint=exc.hint) from None
    ros_value = ros if ros is not None else data.get("ros", 1)
    if str(ros_value) not in ("1", "2"):
        raise ReedtoolError(f"ros: must be 1 or 2, got {ros_value!r}", file=spec_file)
    sim_value = _choose_simulator(sim, data.get("sim"), frame_obj, int(ros_value), spec_file)

    values: dict[str, float] = {}
    origin: dict[str, str] = {}
    for param in PARAMS:
        if frame_obj.kind not in param.kinds:
            if param.key in data:
                raise ReedtoolError(f"{param.key}: not used by a {frame_obj.kind} frame "
                                    f"('{frame_obj.name}')", file=spec_file,
                                    hint="remove it or pick another --frame")
            continue
        default = param.default(frame_obj) if callable(param.default) else param.default
        values[param.key], origin[param.key] = float(default), "default"
        if param.key in data:
            values[param.key] = parse_quantity(data[param.key], param, src)
            origin[param.key] = "spec"
    for key, value in (flags or {}).items():
        if value is None:
            continue
        flag = "--" + key.replace("_", "-")
        param = PARAM_MAP[key]
        if frame_obj.kind not in param.kinds:
            raise ReedtoolError(f"{flag} does not apply to a {frame_obj.kind} frame "
                                f"('{frame_obj.name}')")
        values[key] = parse_quantity(value, param, flag)
        origin[key] = flag

    mesh_value = mesh if mesh is not None else data.get("mesh")
    if mesh_value is not None:
        mesh_path = Path(str(mesh_value)).expanduser()
        if not mesh_path.is_absolute() and mesh is None and spec_file is not None:
            mesh_path = Path(spec_file).parent / mesh_path   # relative to the spec file
        if not mesh_path.is_file():
            raise ReedtoolError("mesh file not found", file=mesh_path)
        mesh_value = mesh_path

    spec = PackageSpec(
        name=name, frame=frame_obj, ros=int(ros_value), values=values, mesh=mesh_value,
        description=str(data.get("description") or
                        f"{frame_obj.title} model '{name}' generated by reedtool"),
        maintainer=str(data.get("maintainer", PackageSpec.maintainer)),
        maintainer_email=str(data.get("maintainer_email", PackageSpec.maintainer_email)),
        license=str(data.get("license", PackageSpec.license)),
        version=str(data.get("version", PackageSpec.version)),
        origin=origin, sim=sim_value,
    )
    spec.propulsion = _derive_propulsion(spec, data, drive or {}, spec_file)
    check_geometry(spec)
    return spec


def _derive_propulsion(spec: PackageSpec, data: Mapping[str, object],
                       drive: Mapping[str, str | None], spec_file: Path | None):
    """Motor constants from --motor/--prop/--battery (flags over the spec's keys): all
    three or none, and not beside the constants they derive."""
    given = {key: (f"--{key}", drive[key]) if drive.get(key) is not None else
             (f"{key} in the spec", data[key]) for key in ("motor", "prop", "battery")
             if drive.get(key) is not None or data.get(key) is not None}
    if not given:
        return None
    if spec.kind != "multirotor":
        raise ReedtoolError(f"{next(iter(given.values()))[0]} applies to multirotor frames "
                            f"only, not '{spec.frame.name}'")
    missing = [f"--{key}" for key in ("motor", "prop", "battery") if key not in given]
    if missing:
        raise ReedtoolError(f"{', '.join(label for label, _ in given.values())} needs "
                            f"{' and '.join(missing)} too: the maximum rotor speed is KV x "
                            "battery voltage, and the thrust at it is the propeller's",
                            hint="e.g. --motor 920 --prop 10x4.7 --battery 3S")
    clash = [key for key in PROPULSION_KEYS if spec.origin.get(key) not in (None, "default")]
    if clash:
        raise ReedtoolError(f"{clash[0]} ({spec.origin[clash[0]]}) and --motor/--prop/--battery "
                            "both set it", file=spec_file,
                            hint="give either the constants or the motor, propeller and "
                                 "battery they are derived from")
    from reedtool.physics.propulsion import derive, parse_battery, parse_motor, parse_propeller

    try:
        motor = parse_motor(given["motor"][1])
        diameter_in, pitch_in = parse_propeller(given["prop"][1])
        cells = parse_battery(given["battery"][1])
    except ReedtoolError as exc:
        from_spec = any(label.endswith("spec") for label, _ in given.values())
        raise ReedtoolError(exc.message, file=spec_file if from_spec else None,
                            hint=exc.hint) from None
    result = derive(motor, diameter_in, pitch_in, cells)
    label = (f"{given['motor'][0]} {given['motor'][1]}, {given['prop'][0]} "
             f"{given['prop'][1]}, {given['battery'][0]} {given['battery'][1]}")
    for key, derived in result.constants.items():
        if key in PROPULSION_KEYS or spec.origin.get(key) == "default":
            spec.values[key], spec.origin[key] = float(derived.value), label
    spec.values["radius_rotor"], spec.origin["radius_rotor"] = result.radius_m, given["prop"][0]
    return result


# catkin and ament both require a version of three dot-separated integers (REP 149).
_VERSION = re.compile(r"^\d+\.\d+\.\d+$")


def _check_text_keys(data: Mapping[str, object], spec_file: Path | None) -> None:
    """Text keys are single strings; `version` is X.Y.Z. A list or a map here would be
    printed into package.xml as Python's repr."""
    for key in TEXT_KEYS:
        value = data.get(key)
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise ReedtoolError(f"{key}: expected a single value, got {type(value).__name__}",
                                file=spec_file, hint=f"write {key}: on one line")
    version = data.get("version")
    if version is not None and not _VERSION.match(str(version)):
        raise ReedtoolError(f"version: '{version}' is not MAJOR.MINOR.PATCH", file=spec_file,
                            hint="write it quoted with three numbers, e.g. version: \"0.1.0\"")


def _choose_simulator(flag: str | None, from_spec, frame_obj, ros: int,
                      spec_file: Path | None) -> str:
    """--sim, else the spec's `sim`, else gz for ROS 2 multirotors and classic otherwise."""
    if flag is None and from_spec is None:
        return "gz" if ros == 2 and frame_obj.kind == "multirotor" else "classic"
    chosen = str(flag if flag is not None else from_spec)
    label, where = (f"--sim {chosen}", {}) if flag is not None else \
        (f"sim: {chosen}", {"file": spec_file})
    if chosen not in SIMULATORS:
        raise ReedtoolError(f"sim: must be one of {', '.join(SIMULATORS)}, got {chosen!r}",
                            **where)
    if chosen == "gz" and ros != 2:
        raise ReedtoolError(f"{label} needs ROS 2: Gazebo Sim (Harmonic+) has ROS 2 "
                            "integration (ros_gz) only", **where,
                            hint="use --ros 2, or --sim classic for a ROS 1 package")
    if chosen == "gz" and frame_obj.kind != "multirotor":
        raise ReedtoolError(f"{label} is available for multirotor frames only, not "
                            f"'{frame_obj.name}'", **where,
                            hint="use --sim classic for a ground robot")
    return chosen


# ------------------------------------------------------------------ checks

def rotor_positions_m(spec: PackageSpec):
    """(n, 3) rotor hub positions in the body frame, ordered by motor number: on a CAD
    body's motor mounts, else the frame's pattern for arm_length about the rotor centre."""
    import numpy as np

    if spec.cad is not None and spec.cad.rotor_positions_m is not None:
        return np.array(spec.cad.rotor_positions_m, dtype=float)
    pattern = spec.frame.rotor_positions_m(spec["arm_length"], spec["rotor_offset_top"])
    return pattern + np.array(rotor_centre_m(spec))


def rotor_centre_m(spec: PackageSpec) -> tuple[float, float, float]:
    return spec.cad.centre_m if spec.cad is not None else (0.0, 0.0, 0.0)


def body_com_m(spec: PackageSpec) -> tuple[float, float, float]:
    return spec.cad.body_com_m if spec.cad is not None else (0.0, 0.0, 0.0)


def total_mass_estimate_kg(spec: PackageSpec) -> float:
    """Body + rotors + sensors (multirotor) or body + wheels + caster (ground)."""
    if spec.kind == "multirotor":
        return spec["mass"] + spec.frame.rotor_count * spec["mass_rotor"] + sensor_mass_kg(spec)
    caster = spec["caster_mass"] if spec.frame.caster else 0.0
    return spec["mass"] + len(spec.frame.wheels) * spec["wheel_mass"] + caster


def sensor_mass_kg(spec: PackageSpec) -> float:
    """RotorS' sensor macros carry mass; the gz-sim model's IMU is a sensor on base_link."""
    return SENSOR_MASS_KG if spec.sim == "classic" else 0.0


def thrust_to_weight(spec: PackageSpec) -> float:
    max_thrust_N = (spec.frame.rotor_count * spec["motor_constant"]
                    * spec["max_rot_velocity"] ** 2)
    return max_thrust_N / (total_mass_estimate_kg(spec) * STANDARD_GRAVITY_M_S2)


def _where(spec: PackageSpec, *keys: str) -> str:
    return ", ".join(f"{k} from {spec.origin.get(k, 'default')}" for k in keys)


def check_geometry(spec: PackageSpec) -> None:
    """Refuse specs that cannot make a working vehicle; each message says what to change."""
    if spec.kind == "multirotor":
        tw = thrust_to_weight(spec)
        if tw < MIN_THRUST_TO_WEIGHT:
            raise ReedtoolError(
                f"the rotors cannot lift this vehicle with a control margin: max thrust / "
                f"weight = {tw:.2f} (total mass {total_mass_estimate_kg(spec):.3f} kg), "
                f"need >= {MIN_THRUST_TO_WEIGHT}",
                hint="lower --mass or raise motor_constant / max_rot_velocity")
        _check_propeller_clearance(spec)
    else:
        r, w = spec["wheel_radius"], spec["wheel_width"]
        if spec["track_width"] <= w:
            raise ReedtoolError(f"track_width {spec['track_width']} m must exceed wheel_width "
                                f"{w} m ({_where(spec, 'track_width', 'wheel_width')})")
        if spec.frame.name == "car-4w" and spec["wheelbase"] <= 2 * r:
            raise ReedtoolError(f"wheelbase {spec['wheelbase']} m is too short: front and rear "
                                f"wheels (radius {r} m) overlap",
                                hint="raise wheelbase above 2 * wheel_radius")
        if spec["ground_clearance"] >= 2 * r:
            raise ReedtoolError(f"ground_clearance {spec['ground_clearance']} m puts the body "
                                f"above the tops of its wheels (radius {r} m)",
                                hint="keep ground_clearance below 2 * wheel_radius")


def _check_propeller_clearance(spec: PackageSpec) -> None:
    import numpy as np

    positions = rotor_positions_m(spec)
    slots = spec.frame.rotors
    radius = spec["radius_rotor"]
    for i in range(len(slots)):
        for j in range(i + 1, len(slots)):
            if slots[i].level != slots[j].level:
                continue  # coaxial pairs sit on different planes
            gap_m = float(np.linalg.norm(positions[i, :2] - positions[j, :2]))
            if gap_m < 2 * radius:
                raise ReedtoolError(
                    f"propellers overlap: rotors {slots[i].motor_number} ({slots[i].suffix}) "
                    f"and {slots[j].motor_number} ({slots[j].suffix}) are {gap_m:.3f} m apart, "
                    f"less than 2 * radius_rotor = {2 * radius:.3f} m "
                    f"({_where(spec, 'arm_length', 'radius_rotor')})",
                    hint="raise arm_length or lower radius_rotor")


# ------------------------------------------------------------------ what templates get

# RotorS' firefly, which the Lee controller gains in rotors_gazebo were tuned for.
_FIREFLY_MASS_KG = 1.56779
_FIREFLY_INERTIA_KG_M2 = (0.0347563, 0.0458929, 0.0977)
# rotors_gazebo/resource/lee_controller_firefly.yaml, the file RotorS' firefly launch
# files load. Yaw: 0.15 and 0.18, not lee_position_controller.h's compiled-in 0.035 and
# 0.025. RotorS' normalisation makes the yaw loop J_z psi'' = -k_R psi - k_w psi' (see
# sim/lee_rotors.py), so on the Firefly (J_z 0.0977) the compiled-in pair gives
# w_n = sqrt(0.035 / 0.0977) = 0.60 rad/s at damping 0.025 / (2 sqrt(0.035 * 0.0977))
# = 0.21 (a 0.3 rad yaw error takes ~8 s to settle within 2 deg), the YAML's 1.24 rad/s
# at 0.74. Scaling by J_z keeps both numbers on any vehicle (hover-test --controller
# flies them: tests/test_lee_controller.py).
_FIREFLY_LEE_GAINS = {
    "position_gain": (6.0, 6.0, 6.0), "velocity_gain": (4.7, 4.7, 4.7),
    "attitude_gain": (3.0, 3.0, 0.15), "angular_rate_gain": (0.52, 0.52, 0.18)}

# The seed's rotor inertia convention (RotorS' own): a 3 mm x 15 mm blade box as long as
# the rotor radius, with the rotor mass multiplied by rotor_velocity_slowdown_sim because
# the simulated rotor turns that many times slower than the real one.
ROTOR_BLADE_WIDTH_M = 0.015
ROTOR_BLADE_THICKNESS_M = 0.003
ROTOR_DISC_THICKNESS_M = 0.005   # the rotor's visual and collision disc


def _py_coeff(coefficient: float, prop: str) -> str:
    """coefficient * prop as a xacro (Python) expression, e.g. `-arm_length`."""
    if coefficient == 0.0:
        return "0"
    if coefficient == 1.0:
        return prop
    if coefficient == -1.0:
        return f"-{prop}"
    return f"{prop}*{coefficient!r}"


def _xacro_coeff(coefficient: float, prop: str) -> str:
    return _as_xacro(_py_coeff(coefficient, prop))


def _as_xacro(expr: str) -> str:
    """A Python expression as a xacro attribute value: plain numbers stay plain."""
    try:
        float(expr)
        return expr
    except ValueError:
        return f"${{{expr}}}"


def _centred(centre_m: float, expr: str) -> str:
    """`expr` moved by a rotor-centre coordinate, e.g. `0.0152 + arm_length`."""
    if centre_m == 0.0:
        return expr
    if expr == "0":
        return short_text(centre_m)
    return f"{short_text(centre_m)} + {expr}"


def com_text(com_m) -> str:
    """A COM as an xyz attribute; below a nanometre is the mesh integral's round-off: 0."""
    return " ".join(short_text(0.0 if abs(v) < 1e-9 else float(v)) for v in com_m)


def _body_depth_m(spec: PackageSpec) -> float:
    """How far the body reaches below base_link: the mesh's lowest point, else half the box."""
    if spec.cad is not None:
        return max(-spec.cad.body_bottom_z_m, 0.0)
    return spec["body_height"] / 2.0


def _inertia_attrs(I) -> dict[str, str]:
    return {key: short_text(value) for key, value in inertia_values(I).items()}


def template_context(spec: PackageSpec, body_props=None) -> dict:
    """Everything the templates may use, with numbers already formatted.

    `body_props` (reedtool.physics.inertia.MassProperties in the body frame: COM and the
    tensor about it) replaces the body box when a mesh was imported; its COM is written
    into the body's <inertial><origin>.
    """
    ctx: dict = {
        "name": spec.name, "ros": spec.ros, "kind": spec.kind, "sim": spec.sim,
        "frame": {"name": spec.frame.name, "title": spec.frame.title},
        "description": spec.description, "version": spec.version, "license": spec.license,
        "maintainer": spec.maintainer, "maintainer_email": spec.maintainer_email,
        "p": {key: short_text(value) for key, value in spec.values.items()},
        "mesh_file": "body.stl" if spec.mesh is not None else None,
        "command_line": "",
    }
    if spec.kind == "multirotor":
        ctx.update(_multirotor_context(spec, body_props))
    else:
        ctx.update(_ground_context(spec, body_props))
    return ctx


def scaled_lee_gains(mass_kg: float, inertia_kg_m2) -> dict[str, list[str]]:
    """RotorS' firefly Lee gains scaled by this vehicle's mass (position, velocity) and
    principal inertia diagonal (attitude, angular rate), 4 significant digits: the gains
    the generated controllers (Lee YAML, gz MulticopterVelocityControl) carry."""
    mass_ratio = mass_kg / _FIREFLY_MASS_KG
    inertia_ratio = [inertia_kg_m2[i][i] / _FIREFLY_INERTIA_KG_M2[i] for i in range(3)]
    gains = {}
    for key, values in _FIREFLY_LEE_GAINS.items():
        ratio = [mass_ratio] * 3 if key in ("position_gain", "velocity_gain") else inertia_ratio
        gains[key] = [short_text(float(f"{v * r:.4g}")) for v, r in zip(values, ratio)]
    return gains


def _multirotor_context(spec: PackageSpec, body_props) -> dict:
    import numpy as np

    from reedtool.physics.inertia import (
        MassProperties,
        box_inertia,
        combine,
        sphere_inertia,
    )

    frame: Airframe = spec.frame
    mass_kg = spec["mass"]
    if body_props is None:
        size = (spec["body_width"], spec["body_width"], spec["body_height"])
        body_props = MassProperties(mass_kg, np.zeros(3), box_inertia(mass_kg, size))
        body_source = (f"a solid box {short_text(size[0])} x {short_text(size[1])} x "
                       f"{short_text(size[2])} m of {short_text(mass_kg)} kg")
    else:
        body_source = f"the body mesh (meshes/body.stl) filled uniformly, {short_text(mass_kg)} kg"
    blade = (spec["radius_rotor"], ROTOR_BLADE_WIDTH_M, ROTOR_BLADE_THICKNESS_M)
    rotor_I = box_inertia(spec["mass_rotor"] * spec["rotor_velocity_slowdown_sim"], blade)

    positions = rotor_positions_m(spec)
    centre = rotor_centre_m(spec)
    on_mounts = spec.cad is not None and spec.cad.rotor_positions_m is not None
    rotors = []
    parts = [body_props]
    if sensor_mass_kg(spec) > 0.0:
        parts.append(MassProperties(sensor_mass_kg(spec), np.zeros(3),
                                    sphere_inertia(sensor_mass_kg(spec), 0.01)))
    for slot, position in zip(frame.rotors, positions):
        ux, uy = frame.unit_xy(slot)
        if on_mounts:
            # On the CAD body's motor mounts: where the mesh has them, not a pattern.
            xyz_expr = [short_text(float(v)) for v in position]
        else:
            xyz_expr = [_centred(c, expr) for c, expr in zip(centre, (
                _py_coeff(ux, "arm_length"), _py_coeff(uy, "arm_length"),
                "rotor_offset_top" if slot.level > 0 else "-rotor_offset_top"))]
        rotors.append({
            "suffix": slot.suffix, "motor_number": slot.motor_number,
            "direction": slot.direction, "direction_sign": 1 if slot.direction == "ccw" else -1,
            "color": "Red" if position[0] < -1e-9 else "Blue",
            "xyz": " ".join(_as_xacro(expr) for expr in xyz_expr),
            "xyz_expr": xyz_expr,
            "position_m": [short_text(v) for v in position],
        })
        parts.append(MassProperties(spec["mass_rotor"], np.asarray(position),
                                    box_inertia(spec["mass_rotor"], blade)))
    total = combine(parts)
    I_total = total.inertia_kg_m2
    body_com = body_props.com_m
    # The controller's rotor angles and arms are measured from the centre of mass: RotorS'
    # allocation gives torques about the point they are measured from, and the body turns
    # about its COM (checks/controller_rules.py, C405/C406).
    for rotor, position in zip(rotors, positions):
        dx, dy = position[0] - total.com_m[0], position[1] - total.com_m[1]
        rotor["angle_rad"] = short_text(float(np.arctan2(dy, dx)))
        rotor["radial_m"] = short_text(float(np.hypot(dx, dy)))
    gains = scaled_lee_gains(total.mass_kg, I_total)
    return {
        "rotor_count": frame.rotor_count,
        "rotors": rotors,
        "frame_reference": frame.reference,
        "body_inertia": _inertia_attrs(body_props.inertia_kg_m2),
        "body_inertia_source": body_source,
        "body_com_xyz": com_text(body_com),
        "rotor_inertia": _inertia_attrs(rotor_I),
        "total_mass_kg": short_text(total.mass_kg),
        "total_inertia": _inertia_attrs(I_total),
        "lee_gains": gains,
        "thrust_to_weight": f"{thrust_to_weight(spec):.2f}",
        "rotor_disc_thickness_m": short_text(ROTOR_DISC_THICKNESS_M),
        # Spawn 5 cm above the ground: below the body (box or mesh) or the lower rotor discs.
        "spawn_z_m": short_text(round(0.05 + max(_body_depth_m(spec), max(
            -p[2] for p in positions) + ROTOR_DISC_THICKNESS_M / 2.0), 3)),
    }


def _ground_context(spec: PackageSpec, body_props) -> dict:
    import numpy as np

    from reedtool.physics.inertia import (
        MassProperties,
        box_inertia,
        cylinder_inertia,
        sphere_inertia,
    )

    layout: GroundLayout = spec.frame
    mass_kg = spec["mass"]
    size = (spec["body_length"], spec["body_width"], spec["body_height"])
    if body_props is None:
        body_props = MassProperties(mass_kg, np.zeros(3), box_inertia(mass_kg, size))
        body_source = (f"a solid box {' x '.join(short_text(s) for s in size)} m of "
                       f"{short_text(mass_kg)} kg")
    else:
        body_source = f"the body mesh (meshes/body.stl) filled uniformly, {short_text(mass_kg)} kg"
    r, h = spec["wheel_radius"], spec["body_height"]
    base_height_m = spec["ground_clearance"] + h / 2.0      # base_link above the ground
    wheel_z_m = r - base_height_m
    wheels = [{
        "name": w.name,
        "x": short_text(w.x_per_wheelbase * spec["wheelbase"]) if layout.name == "car-4w" else "0",
        "y": short_text(w.side * spec["track_width"] / 2.0),
        "side": "left" if w.side > 0 else "right",
    } for w in layout.wheels]
    caster_radius_m = spec["ground_clearance"] / 2.0
    ctx = {
        "wheels": wheels,
        "drive": layout.drive,
        "body_inertia": _inertia_attrs(body_props.inertia_kg_m2),
        "body_inertia_source": body_source,
        "body_com_xyz": com_text(body_props.com_m),
        "wheel_inertia": _inertia_attrs(cylinder_inertia(spec["wheel_mass"], r,
                                                         spec["wheel_width"], axis="y")),
        "base_height": short_text(base_height_m),
        "wheel_z": short_text(wheel_z_m),
        "wheel_diameter": short_text(2 * r),
        "caster": layout.caster,
        "caster_radius": short_text(caster_radius_m),
        "caster_x": short_text(-(spec["body_length"] / 2.0 - caster_radius_m)),
        "caster_z": short_text(caster_radius_m - base_height_m),
        "caster_inertia": _inertia_attrs(sphere_inertia(spec["caster_mass"], caster_radius_m)),
        "total_mass_kg": short_text(total_mass_estimate_kg(spec)),
    }
    return ctx


# RotorS xacro/SDF names of the motor constants, as the summary prints them.
_ROTORS_NAMES = {"motor_constant": "motorConstant", "moment_constant": "momentConstant",
                 "max_rot_velocity": "maxRotVelocity", "time_constant_up": "timeConstantUp",
                 "time_constant_down": "timeConstantDown"}
_UNITS = {"motor_constant": "N/(rad/s)^2", "moment_constant": "m", "max_rot_velocity": "rad/s",
          "time_constant_up": "s", "time_constant_down": "s"}


def propulsion_lines(spec: PackageSpec) -> list[str]:
    """What new-package says about the motor constants: each derived one with its source,
    or that they are RotorS firefly's defaults and what thrust-to-weight they give."""
    if spec.kind != "multirotor":
        return []
    n = spec.frame.rotor_count
    per_rotor_N = spec["motor_constant"] * spec["max_rot_velocity"] ** 2
    thrust = (f"{n} x {per_rotor_N:.4g} N = {n * per_rotor_N:.4g} N at full speed, "
              f"thrust-to-weight {thrust_to_weight(spec):.2f} for the "
              f"{total_mass_estimate_kg(spec):.3g} kg vehicle")
    result = spec.propulsion
    if result is not None:
        lines = [f"motor constants from {result.motor.name}, {result.diameter_in:g}x"
                 f"{result.pitch_in:g} propeller, {result.cells}S LiPo ({result.voltage_V:.3g} V):"]
        for key, derived in result.constants.items():
            value = spec[key]
            source = derived.source if spec.origin.get(key, "").startswith(("--motor", "motor")) \
                else f"as given ({spec.origin[key]})"
            lines.append(f"  {_ROTORS_NAMES[key]} {value:.6g} {derived.unit}: {source}")
        lines.append(f"  propeller data: {result.propeller.name}, {result.match}")
        lines.append(f"  {thrust}")
        return lines
    keys = list(_ROTORS_NAMES)
    given = [k for k in keys if spec.origin.get(k) != "default"]
    values = ", ".join(f"{_ROTORS_NAMES[k]} {spec[k]:g} {_UNITS[k]}" for k in keys)
    if not given:
        return [f"motor constants: RotorS firefly defaults ({values}), not your motor's: "
                f"{thrust}; --motor, --prop and --battery derive them"]
    return [f"motor constants: {values} ({', '.join(_ROTORS_NAMES[k] for k in given)} as "
            f"given, the rest RotorS firefly defaults): {thrust}"]
