"""Controller-side rotor tables: the geometry a multirotor controller is told, read with lines.

Two formats, both from the Lee et al. geometric controller family:

* gz-sim `MulticopterVelocityControl` (a `<plugin>` in the model, SDF or URDF `<gazebo>`):
  `<comLinkName>` and `<rotorConfiguration><rotor><jointName/><forceConstant/>
  <momentConstant/><direction/></rotor>...`. gz-sim computes each rotor's angle and arm
  length itself from the named joint's pose in the comLinkName link frame, and the
  vehicle's mass and inertia from the links, so those are not in the table.
* A RotorS vehicle parameter YAML (`rotors_gazebo/resource/<mav>.yaml`, read by
  rotors_control's GetVehicleParameters): `mass`, `inertia: {xx, xy, xz, yy, yz, zz}` and
  `rotor_configuration: {'0': {angle, arm_length, rotor_force_constant,
  rotor_moment_constant, direction}, '1': ...}`. RotorS reads the entries '0', '1', ...
  in order and stops at the first missing index.

Conventions, the same in both (RotorS common.h and gz-sim Common.cc build the same
allocation matrix): angle [rad] is measured in the body xy-plane from +x towards +y
(counter-clockwise seen from above, z up); arm length [m] is the distance from the body
frame origin in that plane; direction +1 is a counter-clockwise rotor seen from above
(turningDirection "ccw"), -1 clockwise; the controller's entry i commands the motor whose
`motorNumber` is i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.model import Plugin, Robot, SourceLoc

VELOCITY_CONTROL_NAMES = {"gz::sim::systems::MulticopterVelocityControl",
                          "ignition::gazebo::systems::MulticopterVelocityControl"}
VELOCITY_CONTROL_LIBRARIES = {"gz-sim-multicopter-control-system",
                              "ignition-gazebo-multicopter-control-system"}
YAML_ROTOR_FIELDS = ("angle", "arm_length", "rotor_force_constant", "rotor_moment_constant",
                     "direction")
INERTIA_KEYS = ("xx", "xy", "xz", "yy", "yz", "zz")


@dataclass
class ControllerRotor:
    index: int                          # the actuator index this entry commands
    loc: SourceLoc                      # the entry (<rotor> element or the YAML key)
    joint_name: str | None = None       # velocity-control names the rotor's joint
    angle_rad: float | None = None      # YAML only: from body +x towards +y
    arm_length_m: float | None = None   # YAML only: in the body xy-plane
    force_constant: float = math.nan    # thrust = force_constant * omega^2 [N/(rad/s)^2]
    moment_constant: float = math.nan   # yaw drag torque = moment_constant * thrust [m]
    direction: float = math.nan         # +1 ccw, -1 cw, as written
    field_locs: dict[str, SourceLoc] = field(default_factory=dict)

    def loc_of(self, name: str) -> SourceLoc:
        return self.field_locs.get(name, self.loc)


@dataclass
class ControllerTable:
    source: str                          # 'velocity-control' | 'yaml'
    file: str
    loc: SourceLoc                       # <rotorConfiguration> or the rotor_configuration key
    rotors: list[ControllerRotor] = field(default_factory=list)
    mass_kg: float | None = None
    inertia_kg_m2: np.ndarray | None = None   # about the COM, body axes
    locs: dict[str, SourceLoc] = field(default_factory=dict)  # 'mass', 'inertia', 'comLinkName'
    com_link: str | None = None          # velocity-control: the frame arms are measured in
    plugin: Plugin | None = None
    problems: list[tuple[str, SourceLoc]] = field(default_factory=list)  # unreadable entries
    # RotorS Lee gains loaded with this table (flightstack.rotors_lee.LeeGainsTable), if any
    lee_gains: object | None = None

    @property
    def label(self) -> str:
        if self.source == "yaml":
            return f"controller {Path(self.file).name}"
        return "MulticopterVelocityControl"

    def loc_of(self, name: str) -> SourceLoc:
        return self.locs.get(name, self.loc)


# ------------------------------------------------------------ velocity control

def is_velocity_control(plugin: Plugin) -> bool:
    return (plugin.name or "") in VELOCITY_CONTROL_NAMES \
        or plugin.library in VELOCITY_CONTROL_LIBRARIES


def velocity_control_tables(robot: Robot) -> list[ControllerTable]:
    """Every MulticopterVelocityControl <rotorConfiguration> in the model."""
    tables = []
    for _block, plugin in robot.plugins():
        if not is_velocity_control(plugin):
            continue
        config = plugin.node.find("rotorConfiguration")
        table = ControllerTable(source="velocity-control", file=plugin.loc.file,
                                loc=config.loc if config is not None else plugin.loc,
                                com_link=plugin.param("comLinkName"), plugin=plugin)
        table.locs["comLinkName"] = plugin.param_loc("comLinkName")
        if config is None:
            table.problems.append(("has no <rotorConfiguration>; gz-sim's controller will not "
                                   "start", plugin.loc))
        for index, rotor_node in enumerate(config.findall("rotor") if config is not None else []):
            entry = ControllerRotor(index=index, loc=rotor_node.loc,
                                    joint_name=rotor_node.findtext("jointName"))
            for tag, attr in (("forceConstant", "force_constant"),
                              ("momentConstant", "moment_constant"),
                              ("direction", "direction")):
                node = rotor_node.find(tag)
                if node is None or not (node.text or "").strip():
                    table.problems.append((f"rotor {index} has no <{tag}>; gz-sim skips this "
                                           "rotor", rotor_node.loc))
                    continue
                entry.field_locs[attr] = node.loc
                try:
                    setattr(entry, attr, float(node.text.strip()))
                except ValueError:
                    table.problems.append((f"rotor {index} <{tag}>{node.text.strip()}</{tag}> "
                                           "is not a number", node.loc))
            jn = rotor_node.find("jointName")
            if jn is not None:
                entry.field_locs["joint_name"] = jn.loc
            if entry.joint_name is None:
                table.problems.append((f"rotor {index} has no <jointName>; gz-sim skips this "
                                       "rotor", rotor_node.loc))
            table.rotors.append(entry)
        tables.append(table)
    return tables


# ------------------------------------------------------------ RotorS YAML

def load_controller_yaml(path: Path | str) -> ControllerTable:
    from reedtool.io.fileio import read_text_file

    path = Path(path)
    if not path.exists() and not path.is_symlink():
        raise ReedtoolError("controller file not found", file=path,
                            hint="check the --controller path")
    return parse_controller_yaml(read_text_file(path, what="controller file"), path)


def find_vehicle_mapping(node, depth: int = 0):
    """The mapping holding `rotor_configuration`: top level, or under a node namespace
    (`node: {ros__parameters: {...}}` in ROS 2 parameter files)."""
    import yaml

    if not isinstance(node, yaml.MappingNode) or depth > 3:
        return None
    keys = {k.value for k, _ in node.value if isinstance(k, yaml.ScalarNode)}
    if "rotor_configuration" in keys:
        return node
    for _key, value in node.value:
        found = find_vehicle_mapping(value, depth + 1)
        if found is not None:
            return found
    return None


def compose_yaml(text: str, file: Path | str):
    """The YAML node tree of `text` (nodes keep their lines); malformed YAML is one error
    naming the file and the position."""
    import yaml

    try:
        return yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise ReedtoolError(f"malformed YAML: {getattr(exc, 'problem', None) or exc}", file=file,
                            line=mark.line + 1 if mark else None,
                            hint="fix the YAML syntax at that position") from exc


def parse_controller_yaml(text: str, file: Path | str) -> ControllerTable:
    """A RotorS vehicle parameter YAML as a ControllerTable with a line for every value."""
    import yaml

    file = str(file)

    def loc(node) -> SourceLoc:
        return SourceLoc(file, node.start_mark.line + 1)

    root = compose_yaml(text, file)
    vehicle = find_vehicle_mapping(root)
    if vehicle is None:
        raise ReedtoolError("no rotor_configuration found; expected a RotorS vehicle parameter "
                            "file (mass, inertia, rotor_configuration)", file=file,
                            hint="see docs/controller-crosscheck.md for the format")
    items = {k.value: (k, v) for k, v in vehicle.value if isinstance(k, yaml.ScalarNode)}
    config_key, config = items["rotor_configuration"]
    table = ControllerTable(source="yaml", file=file, loc=loc(config_key))

    def number(node, what: str) -> float:
        if isinstance(node, yaml.ScalarNode):
            try:
                value = float(node.value)
                if math.isfinite(value):
                    return value
            except ValueError:
                pass
        table.problems.append((f"{what} is not a finite number", loc(node)))
        return math.nan

    if "mass" in items:
        key, value = items["mass"]
        table.mass_kg = number(value, "mass")
        table.locs["mass"] = loc(key)
    if "inertia" in items:
        key, value = items["inertia"]
        table.locs["inertia"] = loc(key)
        entries = {k.value: v for k, v in value.value} \
            if isinstance(value, yaml.MappingNode) else {}
        if set(INERTIA_KEYS) - set(entries):
            table.problems.append((f"inertia needs the keys {', '.join(INERTIA_KEYS)}", loc(key)))
        else:
            v = {k: number(entries[k], f"inertia/{k}") for k in INERTIA_KEYS}
            table.inertia_kg_m2 = np.array([[v["xx"], v["xy"], v["xz"]],
                                            [v["xy"], v["yy"], v["yz"]],
                                            [v["xz"], v["yz"], v["zz"]]])

    if not isinstance(config, yaml.MappingNode):
        table.problems.append(("rotor_configuration must map '0', '1', ... to rotor entries",
                               loc(config)))
        return table
    by_key = {str(k.value): (k, v) for k, v in config.value}
    index = 0
    while str(index) in by_key:
        key, entry_node = by_key.pop(str(index))
        entry = ControllerRotor(index=index, loc=loc(key))
        fields = {k.value: v for k, v in entry_node.value} \
            if isinstance(entry_node, yaml.MappingNode) else {}
        for name in YAML_ROTOR_FIELDS:
            if name not in fields:
                table.problems.append((f"rotor_configuration/{index} has no {name}", loc(key)))
                continue
            value = number(fields[name], f"rotor_configuration/{index}/{name}")
            entry.field_locs[name] = loc(fields[name])
            attr = {"angle": "angle_rad", "arm_length": "arm_length_m",
                    "rotor_force_constant": "force_constant",
                    "rotor_moment_constant": "moment_constant"}.get(name, name)
            setattr(entry, attr, value)
        entry.field_locs["angle_rad"] = entry.field_locs.pop("angle", entry.loc)
        entry.field_locs["arm_length_m"] = entry.field_locs.pop("arm_length", entry.loc)
        entry.field_locs["force_constant"] = entry.field_locs.pop("rotor_force_constant", entry.loc)
        entry.field_locs["moment_constant"] = entry.field_locs.pop("rotor_moment_constant",
                                                                   entry.loc)
        table.rotors.append(entry)
        index += 1
    for key, _value in by_key.values():
        table.problems.append((f"rotor_configuration key '{key.value}' is never read: RotorS "
                               f"reads '0', '1', ... and stops at the first missing index "
                               f"('{index}')", loc(key)))
    return table
