"""RotorS' Lee position controller's parameters, read from the YAML files its node loads.

`lee_position_controller_node` (rotors_control) reads, from its private namespace,
`position_gain/{x,y,z}`, `velocity_gain/...`, `attitude_gain/...` and
`angular_rate_gain/...` (the `lee_controller_<mav>.yaml` a launch file loads), then the
vehicle parameters `mass`, `inertia/{xx..zz}` and `rotor_configuration/<i>/...` (the
`<mav>.yaml` loaded beside it; read by flightstack.controller_tables). A parameter that is
not set keeps RotorS' compiled-in default (the AscTec Firefly's: lee_position_controller.h
and parameters.h) with only a ROS warning, so the defaults are kept here too, and listed.

Several files are merged the way `rosparam load` fills one namespace: a later file's key
replaces an earlier one's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.flightstack.controller_tables import (
    ControllerTable,
    compose_yaml,
    find_vehicle_mapping,
    parse_controller_yaml,
)
from reedtool.model import SourceLoc

GAIN_KEYS = ("position_gain", "velocity_gain", "attitude_gain", "angular_rate_gain")
# rotors_control lee_position_controller.h kDefault*Gain (the Firefly's tuning): what the
# node flies with when the YAML does not set a gain.
ROTORS_DEFAULT_GAINS = {"position_gain": (6.0, 6.0, 6.0), "velocity_gain": (4.7, 4.7, 4.7),
                        "attitude_gain": (3.0, 3.0, 0.035),
                        "angular_rate_gain": (0.52, 0.52, 0.025)}
# rotors_control parameters.h: kDefaultMass, kDefaultInertia{Xx,Yy,Zz} (the Firefly's).
ROTORS_DEFAULT_MASS_KG = 1.56779
ROTORS_DEFAULT_INERTIA_KG_M2 = (0.0347563, 0.0458929, 0.0977)
# rotors_control parameters.h kDefaultGravity: the controller's own g, whatever the world's.
ROTORS_GRAVITY_M_S2 = 9.81


@dataclass
class LeeGainsTable:
    """The four gain vectors as the node reads them, with where each was written."""

    position_gain: np.ndarray            # (3,) [N/m]: RotorS divides by the YAML mass
    velocity_gain: np.ndarray            # (3,) [N/(m/s)]
    attitude_gain: np.ndarray            # (3,) [N*m/rad] for a diagonal YAML inertia
    angular_rate_gain: np.ndarray        # (3,) [N*m/(rad/s)]
    locs: dict[str, SourceLoc] = field(default_factory=dict)   # "attitude_gain/x" -> loc
    defaulted: list[str] = field(default_factory=list)         # keys RotorS' default fills
    problems: list[tuple[str, SourceLoc]] = field(default_factory=list)

    def gain(self, key: str) -> np.ndarray:
        return getattr(self, key)

    def loc_of(self, key: str, axis: str | None = None) -> SourceLoc | None:
        return self.locs.get(f"{key}/{axis}" if axis else key) or self.locs.get(key)


@dataclass
class LeeParameters:
    """Everything the Lee node reads: gains and the vehicle table (mass, inertia, rotors)."""

    gains: LeeGainsTable
    vehicle: ControllerTable
    files: list[str]
    notes: list[str] = field(default_factory=list)   # what was assumed, one line each


def load_lee_parameters(paths) -> LeeParameters:
    """The Lee node's parameters from the YAML files it would load (gains, vehicle).

    With only a `lee_controller_<mav>.yaml`, the `<mav>.yaml` beside it is the vehicle
    file (the pair RotorS' and new-package's launch files load together).
    """
    from reedtool.io.fileio import read_text_file

    paths = [Path(p) for p in paths]
    texts = [(path, _read_controller_file(path)) for path in paths]
    notes = []
    if not any(_has_key(text, path, "rotor_configuration") for path, text in texts):
        sibling = _vehicle_beside(paths)
        if sibling is None:
            first = paths[0]
            raise ReedtoolError(
                "no rotor_configuration in the controller files: the Lee controller's "
                "allocation needs the vehicle parameter file too", file=first,
                hint="add --controller config/<mav>.yaml (mass, inertia, rotor_configuration)")
        notes.append(f"vehicle parameters from {sibling} (beside {paths[0].name}, loaded "
                     "with it by the package's launch file)")
        paths.append(sibling)
        texts.append((sibling, read_text_file(sibling, what="controller file")))
    vehicle = None
    for path, text in texts:
        if _has_key(text, path, "rotor_configuration"):
            vehicle = parse_controller_yaml(text, path)       # the last one wins
    gains = parse_gains([(path, text) for path, text in texts])
    if vehicle.mass_kg is None:
        vehicle.mass_kg = ROTORS_DEFAULT_MASS_KG
        notes.append(f"mass not set: RotorS uses its default {ROTORS_DEFAULT_MASS_KG} kg "
                     "(the Firefly's)")
    if vehicle.inertia_kg_m2 is None and not any("inertia" in m for m, _ in vehicle.problems):
        vehicle.inertia_kg_m2 = np.diag(ROTORS_DEFAULT_INERTIA_KG_M2)
        notes.append("inertia not set: RotorS uses its default "
                     f"{ROTORS_DEFAULT_INERTIA_KG_M2} kg*m^2 (the Firefly's)")
    if gains.defaulted:
        notes.append(f"not set, RotorS' default (the Firefly's) used: {', '.join(gains.defaulted)}")
    vehicle.lee_gains = gains
    return LeeParameters(gains, vehicle, [str(p) for p in paths], notes)


def _read_controller_file(path: Path) -> str:
    """The text of a --controller file; a missing one is one error naming it."""
    from reedtool.io.fileio import read_text_file

    if not path.exists() and not path.is_symlink():
        raise ReedtoolError("controller file not found", file=path,
                            hint="check the --controller path")
    return read_text_file(path, what="controller file")


def _has_key(text: str, path: Path, key: str) -> bool:
    root = compose_yaml(text, path)
    if key == "rotor_configuration":
        return find_vehicle_mapping(root) is not None
    return _find_mapping_with(root, key) is not None


def _vehicle_beside(paths: list[Path]) -> Path | None:
    for path in paths:
        name = path.name
        if name.startswith("lee_controller_"):
            candidate = path.with_name(name[len("lee_controller_"):])
            if candidate.is_file():
                return candidate
    return None


def _find_mapping_with(node, key: str, depth: int = 0):
    """The mapping holding `key`: top level or under a node namespace (ROS 2 files)."""
    import yaml

    if not isinstance(node, yaml.MappingNode) or depth > 3:
        return None
    if any(isinstance(k, yaml.ScalarNode) and k.value == key for k, _ in node.value):
        return node
    for _k, value in node.value:
        found = _find_mapping_with(value, key, depth + 1)
        if found is not None:
            return found
    return None


def parse_gains(texts: list[tuple[Path, str]]) -> LeeGainsTable:
    """The four gain vectors from the files in load order (later keys win)."""
    import yaml

    values = {key: list(ROTORS_DEFAULT_GAINS[key]) for key in GAIN_KEYS}
    set_keys: set[str] = set()
    locs: dict[str, SourceLoc] = {}
    problems: list[tuple[str, SourceLoc]] = []
    for path, text in texts:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
        for key in GAIN_KEYS:
            holder = _find_mapping_with(root, key)
            if holder is None:
                continue
            key_node, node = next((k, v) for k, v in holder.value
                                  if isinstance(k, yaml.ScalarNode) and k.value == key)
            locs[key] = SourceLoc(str(path), key_node.start_mark.line + 1)
            if not isinstance(node, yaml.MappingNode):
                problems.append((f"{key} must be a mapping {{x: .., y: .., z: ..}}", locs[key]))
                continue
            entries = {k.value: v for k, v in node.value if isinstance(k, yaml.ScalarNode)}
            for i, axis in enumerate("xyz"):
                if axis not in entries:
                    continue
                loc = SourceLoc(str(path), entries[axis].start_mark.line + 1)
                locs[f"{key}/{axis}"] = loc
                try:
                    value = float(entries[axis].value)
                except (TypeError, ValueError):
                    value = math.nan
                if not math.isfinite(value):
                    problems.append((f"{key}/{axis} is not a finite number", loc))
                    continue
                values[key][i] = value
                set_keys.add(f"{key}/{axis}")
    defaulted = [f"{key}/{axis}" for key in GAIN_KEYS for axis in "xyz"
                 if f"{key}/{axis}" not in set_keys]
    return LeeGainsTable(*(np.array(values[key], dtype=float) for key in GAIN_KEYS),
                         locs=locs, defaulted=defaulted, problems=problems)


# ------------------------------------------------------------ the loops the gains make

# The Firefly's gains (rotors_gazebo lee_controller_firefly.yaml) and the vehicle they were
# tuned on (firefly.yaml): what "N times the usual gain" is measured against.
FIREFLY_GAINS = {"position_gain": (6.0, 6.0, 6.0), "velocity_gain": (4.7, 4.7, 4.7),
                 "attitude_gain": (3.0, 3.0, 0.15), "angular_rate_gain": (0.52, 0.52, 0.18)}
FIREFLY_MASS_KG = ROTORS_DEFAULT_MASS_KG
FIREFLY_INERTIA_KG_M2 = ROTORS_DEFAULT_INERTIA_KG_M2


def _expm(M: np.ndarray) -> np.ndarray:
    """exp(M) of a small matrix: scaling and squaring with an 18-term Taylor series (the
    norm is scaled below 0.5 first, so the truncation error is below 0.5^19 / 19!)."""
    norm = float(np.max(np.sum(np.abs(M), axis=1)))
    s = max(0, int(math.ceil(math.log2(norm / 0.5)))) if norm > 0.5 else 0
    A = M / (2.0 ** s)
    out, term = np.eye(len(M)), np.eye(len(M))
    for k in range(1, 19):
        term = term @ A / k
        out = out + term
    for _ in range(s):
        out = out @ out
    return out


def loop_spectral_radius(stiffness: float, damping: float, inertia: float, lag_s: float,
                         period_s: float) -> float:
    """The spectral radius of one axis' sampled closed loop: inertia * x'' = f, the force
    (or torque) f following the command u through a first-order lag `lag_s` (the motors;
    0: none), u = -stiffness x_k - damping x'_k computed every `period_s` and held (zero-
    order hold, as RotorS' node holds its command between odometry messages). < 1: stable.

    The exact discretisation: x_{k+1} = Phi x_k + Gamma u_k from the matrix exponential of
    [[A, B], [0, 0]] * period, closed with u_k = -K x_k.
    """
    if lag_s > 0:
        A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0 / inertia], [0.0, 0.0, -1.0 / lag_s]])
        B = np.array([0.0, 0.0, 1.0 / lag_s])
        K = np.array([stiffness, damping, 0.0])
    else:
        A = np.array([[0.0, 1.0], [0.0, 0.0]])
        B = np.array([0.0, 1.0 / inertia])
        K = np.array([stiffness, damping])
    n = len(A)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B
    E = _expm(M * period_s)
    closed = E[:n, :n] - np.outer(E[:n, n], K)
    return float(np.max(np.abs(np.linalg.eigvals(closed))))


def largest_stable_scale(stiffness: float, damping: float, inertia: float, lag_s: float,
                         period_s: float) -> float:
    """The largest s for which s * (stiffness, damping) keeps the sampled loop stable
    (bisection on log s over 1e-6 .. 1e6, to 1 %); inf if stable throughout."""
    def stable(s: float) -> bool:
        return loop_spectral_radius(s * stiffness, s * damping, inertia, lag_s, period_s) < 1.0

    lo, hi = 1e-6, 1e6
    if stable(hi):
        return math.inf
    if not stable(lo):
        return 0.0
    while hi / lo > 1.01:
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def firefly_scaled(key: str, axis: int, mass_kg: float, inertia_kg_m2) -> float:
    """The Firefly's gain for `key`/axis scaled to a vehicle: by mass for the position and
    velocity gains (forces per metre), by the principal moment for the attitude and rate
    gains (torques per radian): the same closed-loop frequencies and damping as the
    Firefly's (sim.lee_rotors.loops)."""
    base = FIREFLY_GAINS[key][axis]
    if key in ("position_gain", "velocity_gain"):
        return base * mass_kg / FIREFLY_MASS_KG
    return base * float(np.asarray(inertia_kg_m2)[axis, axis]) / FIREFLY_INERTIA_KG_M2[axis]


def load_controller_files(paths) -> list[ControllerTable]:
    """validate --controller's files: each vehicle YAML (rotor_configuration) is a table;
    Lee gain files (lee_controller_<mav>.yaml) are read with the vehicle file given
    beside them on the command line (the last one) or found beside them, and their gains
    ride on that table (checked by C450-C451)."""
    from reedtool.flightstack.controller_tables import load_controller_yaml

    paths = [Path(p) for p in paths]
    vehicle_files, gain_files = [], []
    for path in paths:
        text = _read_controller_file(path)
        has_gains = any(_has_key(text, path, key) for key in GAIN_KEYS)
        if has_gains and not _has_key(text, path, "rotor_configuration"):
            gain_files.append(path)
        else:
            vehicle_files.append(path)
    tables = [load_controller_yaml(path) for path in vehicle_files]
    if gain_files:
        lee = load_lee_parameters(gain_files + vehicle_files[-1:])
        same = [t for t in tables if t.file == lee.vehicle.file]
        if same:
            same[-1].lee_gains = lee.gains
        else:
            tables.append(lee.vehicle)
    return tables
