"""The proof of a port: read it back and compare it with the original, side by side.

Compared (numbers to `REL_TOL` relative, each against the size of its own kind so a zero
is compared against the vehicle's scale, not against itself):
- links: every port link's mass, COM and inertia against the original link plus the
  links folded into it (combined with physics.inertia.combine, the one audited place);
  every link's pose in the base frame;
- the joint tree: type, parent (after folding), child, axis, the joint frame in the child
  link (where the axis line passes), limits (position, effort,
  velocity; "no limit" equal to "no limit" whatever its spelling);
- the whole robot: Pinocchio's mass, COM and inertia of each model;
- rotors, matched by joint: position, thrust axis, spin, number, constants, time
  constants, drag coefficients, role;
- the hover trim (thrusts and speeds) and the hover-test verdict, both flown with the
  same settings;
- validate's findings: an error or warning code on one side only is a difference;
- sensors (`compare_sensors`): each sensor of the original (a link's <sensor>, or a
  Classic plugin simulating one) present in the port with the same type, on the link it
  was folded into, at the same pose in that link, with the same update rate and noise
  (a Classic IMU plugin's noise density against the port's stddev / sqrt(rate)). A sensor
  the port drops with a reason, one it adds with a reason (an autopilot's IMU), and plugin
  noise the port declares not carried, are notes;
  a sensor that vanished, moved or changed is a difference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from reedtool.model import Robot

# Every compared number is written as the shortest text that reads back exactly, and the
# folded inertials are one parallel-axis sum (a few ulps): 1e-9 leaves six orders of
# magnitude for round-off and still catches any real change (a digit, a unit, a sign).
REL_TOL = 1e-9


@dataclass
class Difference:
    section: str                   # 'links' | 'joints' | 'mass' | 'rotors' | 'trim' | 'hover' | 'findings'
    subject: str
    quantity: str
    original: object
    port: object

    def to_dict(self) -> dict:
        return {"section": self.section, "subject": self.subject, "quantity": self.quantity,
                "original": _jsonable(self.original), "port": _jsonable(self.port)}

    def __str__(self) -> str:
        return (f"{self.section}: {self.subject} {self.quantity}: original "
                f"{_show(self.original)}, port {_show(self.port)}")


@dataclass
class Proof:
    differences: list[Difference] = field(default_factory=list)
    compared: dict[str, int] = field(default_factory=dict)     # section -> numbers compared
    side_by_side: dict[str, dict] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    @property
    def equal(self) -> bool:
        return not self.differences

    def to_dict(self) -> dict:
        return {"equal": self.equal, "rel_tol": REL_TOL, "compared": dict(self.compared),
                "differences": [d.to_dict() for d in self.differences],
                "side_by_side": _jsonable(self.side_by_side), "notes": list(self.notes)}


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _show(value) -> str:
    if isinstance(value, (np.ndarray, list, tuple)):
        return "[" + ", ".join(_show(v) for v in np.asarray(value, dtype=object).ravel()) + "]"
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.12g}"
    return str(value)


class _Comparer:
    def __init__(self, proof: Proof):
        self.proof = proof

    def numbers(self, section: str, subject: str, quantity: str, original, port,
                scale: float) -> None:
        a = np.asarray(original, dtype=float)
        b = np.asarray(port, dtype=float)
        self.proof.compared[section] = self.proof.compared.get(section, 0) + a.size
        if a.shape != b.shape:
            self.differ(section, subject, quantity, original, port)
            return
        both_nan = np.isnan(a) & np.isnan(b)
        size = max(scale, float(np.max(np.abs(np.nan_to_num(a)), initial=0.0)),
                   float(np.max(np.abs(np.nan_to_num(b)), initial=0.0)))
        close = both_nan | (np.abs(a - b) <= REL_TOL * size)
        if not np.all(close):
            self.differ(section, subject, quantity, original, port)

    def same(self, section: str, subject: str, quantity: str, original, port) -> None:
        self.proof.compared[section] = self.proof.compared.get(section, 0) + 1
        if original != port:
            self.differ(section, subject, quantity, original, port)

    def differ(self, section, subject, quantity, original, port) -> None:
        self.proof.differences.append(Difference(section, subject, quantity, original, port))


# ------------------------------------------------------------------ structure

def compare_structure(original: Robot, port: Robot, fold: dict, proof: Proof) -> None:
    """Links, poses and joints; `fold` maps every original link to (port link, T)."""
    from reedtool.io.limits import is_no_limit
    from reedtool.physics.inertia import combine_inertials
    from reedtool.physics.kinematics import link_poses

    check = _Comparer(proof)
    size_m = _size_m(original)
    poses_original, poses_port = link_poses(original), link_poses(port)
    expected: dict[str, list] = {}
    for link in original.links:
        survivor, T = fold.get(link.name, (None, None))
        if survivor is not None and link.inertial is not None:
            expected.setdefault(survivor, []).append((T, link.inertial))
    port_names = {link.name for link in port.links}
    for name in sorted(set(expected) | {s for s, _ in fold.values()} | port_names):
        link = port.link_map.get(name)
        if link is None:
            check.differ("links", name, "present", True, False)
            continue
        if name not in {s for s, _ in fold.values()}:
            check.differ("links", name, "present", False, True)
            continue
        want = combine_inertials(expected.get(name, []))
        got = combine_inertials([(np.eye(4), link.inertial)]
                                if link.inertial is not None else [])
        mass_scale = max(want.mass_kg, 1e-12)
        check.numbers("links", name, "mass_kg", want.mass_kg, got.mass_kg, mass_scale)
        check.numbers("links", name, "com_m", want.com_m, got.com_m, size_m)
        inertia_scale = float(np.max(np.abs(want.inertia_kg_m2), initial=0.0)) or 1e-30
        check.numbers("links", name, "inertia_kg_m2", want.inertia_kg_m2, got.inertia_kg_m2,
                      inertia_scale)
        if name in poses_original and name in poses_port:
            check.numbers("links", name, "T_base_link", poses_original[name], poses_port[name],
                          max(size_m, 1.0))
    joints_port = port.joint_map
    for joint in original.joints:
        survivor_child = fold.get(joint.child, (None,))[0]
        if survivor_child != joint.child:
            continue  # folded: its child link is part of its parent in the port
        other = joints_port.get(joint.name)
        if other is None:
            check.differ("joints", joint.name, "present", True, False)
            continue
        check.same("joints", joint.name, "type", joint.type, other.type)
        check.same("joints", joint.name, "parent", fold.get(joint.parent, (joint.parent,))[0],
                   other.parent)
        check.same("joints", joint.name, "child", joint.child, other.child)
        if joint.type != "fixed":
            check.numbers("joints", joint.name, "axis", _unit(joint.axis), _unit(other.axis), 1.0)
            # Where the axis line passes: the joint frame in the child link (SDF joints
            # posed away from their child's origin).
            check.numbers("joints", joint.name, "T_child_jointframe",
                          _or_eye(joint.T_child_jointframe), _or_eye(other.T_child_jointframe),
                          max(size_m, 1.0))
        if joint.type in ("revolute", "prismatic") and joint.limit and other.limit:
            check.numbers("joints", joint.name, "limits",
                          [joint.limit.lower or 0, joint.limit.upper or 0],
                          [other.limit.lower or 0, other.limit.upper or 0], 1.0)
        if joint.type in ("revolute", "prismatic", "continuous"):
            for tag in ("effort", "velocity"):
                # "No limit" is one notion whatever its spelling (-1 in SDF, DBL_MAX in
                # URDF, absent): io.limits.is_no_limit.
                a, b = (math.inf if limit is None or is_no_limit(getattr(limit, tag))
                        or getattr(limit, tag) < 0 else getattr(limit, tag)
                        for limit in (joint.limit, other.limit))
                if math.isinf(a) or math.isinf(b):
                    check.same("joints", joint.name, f"{tag} limit", a, b)
                else:
                    check.numbers("joints", joint.name, f"{tag} limit", a, b, abs(a))
    known = {j.name for j in original.joints}
    for joint in port.joints:
        if joint.name not in known:
            check.differ("joints", joint.name, "present", False, True)


def _or_eye(T) -> np.ndarray:
    return np.eye(4) if T is None else np.asarray(T, dtype=float)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


def _size_m(robot: Robot) -> float:
    """The vehicle's size: the largest link distance from the base (at least 1 cm)."""
    from reedtool.physics.kinematics import link_poses

    distances = [float(np.linalg.norm(T[:3, 3])) for T in link_poses(robot).values()]
    return max([0.01, *[d for d in distances if math.isfinite(d)]])


# ------------------------------------------------------------------ vehicle

ROTOR_NUMBERS = ("motor_constant", "moment_constant", "max_rot_velocity_rad_s",
                 "time_constant_up_s", "time_constant_down_s", "rotor_drag_coefficient",
                 "rolling_moment_coefficient")


def compare_vehicle(original: Robot, port: Robot, proof: Proof, config, fly: bool = True) -> None:
    """Whole-robot mass properties, rotors, trim and the hover verdict, each side assembled
    as hover-test assembles it (workflows.vehicle, workflows.flight)."""
    from reedtool.workflows.vehicle import Vehicle

    check = _Comparer(proof)
    size_m = _size_m(original)
    vehicles = {"original": Vehicle.of(original), "port": Vehicle.of(port)}
    props = {side: v.props for side, v in vehicles.items()}
    a, b = props["original"], props["port"]
    check.numbers("mass", "robot", "mass_kg", a.mass_kg, b.mass_kg, a.mass_kg)
    check.numbers("mass", "robot", "com_m", a.com_m, b.com_m, size_m)
    check.numbers("mass", "robot", "inertia_kg_m2", a.inertia_kg_m2, b.inertia_kg_m2,
                  float(np.max(np.abs(a.inertia_kg_m2))))
    proof.side_by_side["mass"] = {side: {"mass_kg": p.mass_kg, "com_m": p.com_m,
                                         "inertia_kg_m2": p.inertia_kg_m2}
                                  for side, p in props.items()}

    rotors = {side: v.every_rotor for side, v in vehicles.items()}
    by_joint = {r.joint: r for r in rotors["port"]}
    rows = []
    for rotor in rotors["original"]:
        other = by_joint.get(rotor.joint)
        if other is None:
            check.differ("rotors", rotor.name, "present", True, False)
            continue
        check.numbers("rotors", rotor.name, "position_m", rotor.position_m, other.position_m,
                      size_m)
        check.numbers("rotors", rotor.name, "axis", rotor.axis, other.axis, 1.0)
        check.same("rotors", rotor.name, "direction", rotor.direction, other.direction)
        check.same("rotors", rotor.name, "turning_sign", rotor.turning_sign, other.turning_sign)
        check.same("rotors", rotor.name, "number", rotor.motor_number, other.motor_number)
        check.same("rotors", rotor.name, "role", rotor.role, other.role)
        check.same("rotors", rotor.name, "reversible", rotor.reversible, other.reversible)
        values = {key: getattr(other, key) for key in ROTOR_NUMBERS}
        if other.kind == "ardupilot" and rotor.kind != "ardupilot":
            values.update(_ardupilot_values(port, other, rotor, proof))
        for key in ROTOR_NUMBERS:
            x, y = getattr(rotor, key), values[key]
            if key in ARDUPILOT_APPROXIMATED and other.kind == "ardupilot" \
                    and rotor.kind != "ardupilot":
                continue  # declared in the notes by _ardupilot_values
            check.numbers("rotors", rotor.name, key, x, y, abs(x) if math.isfinite(x) else 0.0)
        rows.append({"rotor": rotor.name, "joint": rotor.joint,
                     "number": [rotor.motor_number, other.motor_number],
                     "number_from": [rotor.number_tag, other.number_tag],
                     "direction": [rotor.direction, other.direction],
                     "position_m": [rotor.position_m, other.position_m],
                     **{key: [getattr(rotor, key), getattr(other, key)] for key in ROTOR_NUMBERS}})
    for rotor in rotors["port"]:
        if rotor.joint not in {r.joint for r in rotors["original"]}:
            check.differ("rotors", rotor.name, "present", False, True)
    proof.side_by_side["rotors"] = rows

    trims = {side: v.trim for side, v in vehicles.items()}
    t0, t1 = trims["original"], trims["port"]
    check.same("trim", "robot", "feasible", t0.feasible, t1.feasible)
    if len(t0.thrust_N) == len(t1.thrust_N):
        weight = a.mass_kg * 9.80665
        check.numbers("trim", "robot", "thrust_N", t0.thrust_N, t1.thrust_N, weight)
        check.numbers("trim", "robot", "omega_rad_s", t0.omega_rad_s, t1.omega_rad_s,
                      float(np.max(np.abs(np.nan_to_num(t0.omega_rad_s)), initial=0.0)))
    proof.side_by_side["trim"] = {side: {"feasible": t.feasible, "message": t.message,
                                         "thrust_N": t.thrust_N, "omega_rad_s": t.omega_rad_s}
                                  for side, t in trims.items()}
    if fly:
        flights = {side: _fly(v, config) for side, v in vehicles.items()}
        check.same("hover", "robot", "verdict", flights["original"]["status"],
                   flights["port"]["status"])
        proof.side_by_side["hover"] = flights


# What ArduPilot's plugin cannot carry from a motor model: its joint PID has one time
# constant (the port sets it to timeConstantUp), and LiftDrag blades have no rotor drag or
# rolling moment coefficient.
ARDUPILOT_APPROXIMATED = ("time_constant_down_s", "rotor_drag_coefficient",
                          "rolling_moment_coefficient")


def _ardupilot_values(port: Robot, rotor, original, proof: Proof) -> dict:
    """A port rotor driven by ArduPilotPlugin: its time constant as hover-test derives it
    from the joint PID, and a note for each number the plugin cannot carry."""
    from reedtool.physics.rotors import ardupilot_time_constant

    tau = ardupilot_time_constant(port, rotor).time_constant_s
    proof.notes.append(
        f"{original.name}: not carried by ArduPilotPlugin: time_constant_down_s "
        f"{original.time_constant_down_s:g} (its joint PID has one time constant, set from "
        f"timeConstantUp), rotor_drag_coefficient {original.rotor_drag_coefficient:g} and "
        f"rolling_moment_coefficient {original.rolling_moment_coefficient:g} (LiftDrag "
        "blades model neither)")
    return {"time_constant_up_s": tau, "time_constant_down_s": tau}


def _fly(vehicle, config) -> dict:
    """hover-test's verdict on one vehicle (workflows.flight.hover_test), or why it cannot
    fly (the same refusal hover-test makes, as a status)."""
    from reedtool.workflows.flight import hover_test
    from reedtool.errors import ReedtoolError

    try:
        report = hover_test(vehicle.robot, config, vehicle=vehicle)
    except ReedtoolError as exc:
        return {"status": "not flown", "message": exc.message, "passed": False}
    sim = report.get("sim") or {}
    return {"status": report.get("status"), "message": report.get("message"),
            "passed": report["passed"],
            **{key: sim[key] for key in ("settle_time_s", "max_position_error_m",
                                         "final_position_error_m", "max_throttle") if key in sim}}


# ------------------------------------------------------------------ findings

def compare_findings(original: list, port: list, proof: Proof, dropped=(),
                     resolved: dict | None = None) -> None:
    """Error and warning counts per code of validate on each side.

    `dropped`: (file, line, macro) of source elements the port leaves out. A finding on one of
    them (R312: the MAVLink interface's rotor count) goes with its element: it is listed
    in the notes, not counted as hidden. `resolved`: code -> why, for the original's
    findings the port settles because the user asked it to (S169, a file named by its
    absolute path, with --copy-outside-files): listed in the notes.
    """
    dropped = set(dropped)
    resolved = resolved or {}

    def keys(findings, side):
        out: dict[tuple[str, str], list] = {}
        for f in findings:
            if f.severity not in ("error", "warning"):
                continue
            if side == "original" and (f.file, f.line, f.macro) in dropped:
                proof.notes.append(f"{f.code} ({f.severity}) on the original is about an "
                                   f"element the port leaves out ({f.file}:{f.line}): "
                                   f"{f.message}")
                continue
            if side == "original" and f.code in resolved:
                proof.notes.append(f"{f.code} ({f.severity}) on the original is settled by "
                                   f"the port ({resolved[f.code]}): {f.message}")
                continue
            out.setdefault((f.code, f.severity), []).append(f)
        return out

    a, b = keys(original, "original"), keys(port, "port")
    for key in sorted(set(a) | set(b)):
        n, m = len(a.get(key, [])), len(b.get(key, []))
        proof.compared["findings"] = proof.compared.get("findings", 0) + 1
        if n != m:
            proof.differences.append(Difference("findings", key[0], key[1], n, m))
    proof.side_by_side["findings"] = {
        "original": [f"{f.code} {f.severity}: {f.message}" for f in original
                     if f.severity in ("error", "warning")],
        "port": [f"{f.code} {f.severity}: {f.message}" for f in port
                 if f.severity in ("error", "warning")]}


# ------------------------------------------------------------------ sensors

@dataclass
class SensorRecord:
    """One sensor as its model states it: a <sensor> of a link, or a model-level Classic
    plugin that simulates one (noise then in the plugin's own terms)."""

    name: str
    type: str                      # gz spelling (port.gz_sensors)
    link: str
    T_link_sensor: np.ndarray
    rate_hz: float | None
    noise: dict[str, float]
    plugin: object = None          # the Family of a plugin sensor, else None


def _floats(text: str | None) -> list[float] | None:
    try:
        return [float(v) for v in (text or "").split()]
    except ValueError:
        return None


def _noise_of(node, renames: dict[str, str]) -> dict[str, float]:
    """Every number inside a <noise> of the sensor, keyed by its path with the type
    container spelled as gz spells it (`gps/...` -> `navsat/...`)."""
    out: dict[str, float] = {}

    def walk(element, path: tuple[str, ...]) -> None:
        for child in element.children:
            tag = renames.get(child.tag, child.tag) if not path else child.tag
            here = (*path, tag)
            if child.children:
                walk(child, here)
            elif "noise" in here:
                values = _floats(child.text)
                if values is not None and len(values) == 1:
                    out["/".join(here)] = values[0]
    walk(node, ())
    return out


def sensor_inventory(robot: Robot) -> tuple[list[SensorRecord], list[str]]:
    """(the sensors the model simulates, those a gz port drops and why)."""
    from reedtool.frames import make_T, rpy_to_matrix
    from reedtool.physics.rotors import resolve_name
    from reedtool.port.gz_port import family_of
    from reedtool.port.gz_sensors import sensor_kind, split_name

    records: list[SensorRecord] = []
    dropped: list[str] = []
    for block in robot.gazebo:
        for node in block.elements:
            if node.tag != "sensor" or block.reference is None:
                continue
            name, sensor_type = node.attrib.get("name", "?"), node.attrib.get("type", "")
            kind = sensor_kind(sensor_type)
            if kind is None or kind.gz is None:
                dropped.append(f"{name} ({sensor_type}) on {block.reference}: "
                               f"{kind.why if kind else 'no gz-sim counterpart known'}")
                continue
            pose = (_floats(node.findtext("pose")) or []) + [0.0] * 6
            rate = _floats(node.findtext("update_rate"))
            link = resolve_name(block.reference, robot.link_map) or block.reference
            T = make_T(rpy_to_matrix(pose[3:6]), pose[:3])
            if kind.split:
                # A Classic multicamera is one camera per <camera>, each at its own pose.
                for index, camera in enumerate(node.findall("camera")):
                    own = (_floats(camera.findtext("pose")) or []) + [0.0] * 6
                    wrapper = type(node)("sensor", {}, None, [camera], node.loc)
                    records.append(SensorRecord(
                        split_name(name, camera.attrib.get("name"), index), kind.gz, link,
                        T @ make_T(rpy_to_matrix(own[3:6]), own[:3]),
                        rate[0] if rate else None, _noise_of(wrapper, {})))
                continue
            records.append(SensorRecord(name, kind.gz, link, T, rate[0] if rate else None,
                                        _noise_of(node, kind.renames)))
    for _block, plugin in robot.plugins():
        family = family_of(plugin)
        if family is None or family.sensor is None:
            continue
        link_name = plugin.param("linkName") or plugin.param("bodyName")
        link = resolve_name(link_name, robot.link_map) if link_name else None
        rate = next((_floats(plugin.param(tag)) for tag in ("pubRate", "updateRate",
                                                            "update_rate")
                     if plugin.param(tag)), None)
        noise = {child.tag: _floats(child.text)[0] for child in plugin.node.children
                 if any(key in child.tag for key in ("Noise", "noise", "RandomWalk",
                                                     "randomWalk", "BiasCorrelationTime",
                                                     "biasCorrelationTime", "TurnOnBiasSigma",
                                                     "Drift"))
                 and _floats(child.text) and len(_floats(child.text)) == 1}
        records.append(SensorRecord(plugin.name or family.key, family.sensor,
                                    link or robot.base_link, np.eye(4),
                                    rate[0] if rate else None, noise, family))
    return records, dropped


# A Classic IMU plugin's terms from a gz IMU sensor: RotorS' and PX4's discrete noise is
# sigma = density * sqrt(rate); the bias terms are gz's bias and dynamic bias.
_IMU_TERMS = (("gyroscope", "angular_velocity"), ("accelerometer", "linear_acceleration"))


def _classic_imu_terms(sensor: SensorRecord) -> dict[str, float]:
    out: dict[str, float] = {}
    for prefix, group in _IMU_TERMS:
        for suffix, key in (("NoiseDensity", "stddev"), ("TurnOnBiasSigma", "bias_stddev"),
                            ("RandomWalk", "dynamic_bias_stddev"),
                            ("BiasCorrelationTime", "dynamic_bias_correlation_time")):
            values = {sensor.noise.get(f"imu/{group}/{axis}/noise/{key}") for axis in "xyz"}
            if None in values or len(values) != 1:
                continue     # absent, or the axes differ: no single Classic number
            value = values.pop()
            if suffix == "NoiseDensity":
                if not sensor.rate_hz:
                    continue
                value = value / math.sqrt(sensor.rate_hz)
            out[prefix + suffix] = value
    return out


def compare_sensors(original: Robot, port: Robot, fold: dict, proof: Proof,
                    added=(), moved=None) -> None:
    """Every sensor of the original against the port's: present, type, link (after
    folding), pose in that link, update rate, noise. A sensor the port drops by the table
    (port.gz_sensors) is a note, as the report lists it; one that vanishes or moves is
    a difference. `moved`: original name -> (port name, port link) of the sensors a port
    renames and moves on purpose (PX4's contract puts its four on base_link): those are
    held to the same place in the robot's base frame instead of in their link."""
    from reedtool.physics.kinematics import link_poses

    check = _Comparer(proof)
    size_m = max(_size_m(original), 1.0)
    mine, dropped = sensor_inventory(original)
    theirs, _ = sensor_inventory(port)
    moved = moved or {}
    poses_original = link_poses(original) if moved else {}
    poses_port = link_poses(port) if moved else {}
    proof.notes += [f"sensor {text}: dropped by the port (see the report)" for text in dropped]
    unmatched = list(theirs)
    rows = []
    for sensor in mine:
        survivor, T_fold = fold.get(sensor.link, (sensor.link, np.eye(4)))
        subject = f"{sensor.name} ({sensor.type})"
        candidates = [s for s in unmatched if s.type == sensor.type]
        if sensor.name in moved:
            new_name, survivor = moved[sensor.name]
            match = next((s for s in candidates if s.name == new_name), None)
        else:
            match = next((s for s in candidates if s.name == sensor.name), None) or \
                next((s for s in candidates if s.link == survivor), None)
        proof.compared["sensors"] = proof.compared.get("sensors", 0) + 1
        if match is None:
            check.differ("sensors", subject, "present", True, False)
            continue
        unmatched.remove(match)
        check.same("sensors", subject, "link", survivor, match.link)
        if sensor.name in moved:
            check.numbers("sensors", subject, "T_base_sensor",
                          poses_original.get(sensor.link, np.full((4, 4), np.nan))
                          @ sensor.T_link_sensor,
                          poses_port.get(match.link, np.full((4, 4), np.nan))
                          @ match.T_link_sensor, size_m)
        else:
            check.numbers("sensors", subject, "T_link_sensor", T_fold @ sensor.T_link_sensor,
                          match.T_link_sensor, size_m)
        if sensor.rate_hz is not None:
            check.numbers("sensors", subject, "update_rate_hz", sensor.rate_hz,
                          match.rate_hz if match.rate_hz is not None else math.nan,
                          sensor.rate_hz)
        if sensor.plugin is not None:
            declared, reason = sensor.plugin.noise_not_carried
            got = _classic_imu_terms(match) if sensor.type == "imu" else {}
            lost = [f"{key} {value:g}" for key, value in sensor.noise.items() if key in declared]
            if lost:
                proof.notes.append(f"sensor {subject}: not carried ({reason}): "
                                   + ", ".join(lost))
            for key, value in sensor.noise.items():
                if key in declared:
                    continue
                elif key in got:
                    check.numbers("sensors", subject, key, value, got[key], abs(value))
                else:
                    check.differ("sensors", subject, key, value, None)
        else:
            for key in sorted(set(sensor.noise) | set(match.noise)):
                a, b = sensor.noise.get(key), match.noise.get(key)
                if a is None or b is None:
                    check.differ("sensors", subject, key, a, b)
                else:
                    check.numbers("sensors", subject, key, a, b, abs(a))
        rows.append({"sensor": sensor.name, "type": sensor.type,
                     "link": [sensor.link, match.link], "port_name": match.name,
                     "rate_hz": [sensor.rate_hz, match.rate_hz]})
    added = {(link, name): why for link, name, why in added}
    for sensor in unmatched:
        why = added.get((sensor.link, sensor.name))
        if why is not None:
            proof.notes.append(f"sensor {sensor.name} ({sensor.type}) on {sensor.link}: added "
                               f"by the port: {why}")
        else:
            check.differ("sensors", f"{sensor.name} ({sensor.type})", "present", False, True)
    proof.side_by_side["sensors"] = rows
