"""The port of a Gazebo Classic model to Gazebo Sim: one mapping table, one plan.

`PLUGIN_FAMILIES` is the one place that says what becomes of every Classic plugin
family reedtool knows: its gz-sim counterpart, or why it is dropped. `plan_port` reads a
`Robot` (URDF, xacro or SDF, as the loader built it) and returns a `GzPort`: the links
and joints to write, the gz elements (plugins, sensors) built from the table, the world
systems they need, and one `PortRow` per source element saying what happened to it.
`port.sdf_writer` turns the plan into files; nothing here writes.

What is carried and how:
- Links and joints one to one, poses as written (each link relative to its parent link,
  the joint frame at the child link, as URDF has it). A fixed joint whose child or parent
  has no `<inertial>` is folded into the parent the way Gazebo folds URDF fixed joints,
  because SDF gives a link without `<inertial>` 1 kg (a massless URDF link has none);
  the folded link's name stays available as a `<frame>`.
- Plugin constants as text, unchanged (`motorConstant 8.54858e-06` stays that string),
  so they are exact by construction. `rotorVelocitySlowdownSim` is carried with the
  rotor link inertia unchanged: gz's MulticopterMotorModel reads it the way RotorS does
  (joint speed = rotor speed / slowdown, inertia scaled by it in the source), so scaling
  the inertia again would apply the factor twice.
- `motorNumber` becomes `actuator_number` with the same value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from reedtool.io.sdf_write import pose_text
from reedtool.io.xml_numbers import float_text
from reedtool.model import (
    MOTOR_PLUGINS,
    Collision,
    Inertial,
    Plugin,
    Robot,
    SourceLoc,
    Visual,
    XmlNode,
    inertia_values,
)
from reedtool.port.gz_sensors import SENSOR_KINDS, sensor_kind, sensor_plugin_why, split_name

# ------------------------------------------------------------- mapping table

MOTOR_SYSTEM = ("gz-sim-multicopter-motor-model-system", "gz::sim::systems::MulticopterMotorModel")
# The Classic motor models the port turns into MOTOR_SYSTEM: model.MOTOR_PLUGINS, the table
# rotor discovery reads, less the gz systems themselves.
CLASSIC_MOTOR_LIBRARIES = tuple(library for library, family in MOTOR_PLUGINS.items()
                                if family != "gz")
JOINT_POSITION_SYSTEM = ("gz-sim-joint-position-controller-system",
                         "gz::sim::systems::JointPositionController")
JOINT_STATE_SYSTEM = ("gz-sim-joint-state-publisher-system", "gz::sim::systems::JointStatePublisher")
ODOMETRY_SYSTEM = ("gz-sim-odometry-publisher-system", "gz::sim::systems::OdometryPublisher")
VELOCITY_CONTROL_SYSTEM = ("gz-sim-multicopter-control-system",
                           "gz::sim::systems::MulticopterVelocityControl")
LIFT_DRAG_SYSTEM = ("gz-sim-lift-drag-system", "gz::sim::systems::LiftDrag")
ARDUPILOT_SYSTEM = ("ArduPilotPlugin", "ArduPilotPlugin")

# World systems, by what needs them.
WORLD_PHYSICS = ("gz-sim-physics-system", "gz::sim::systems::Physics")
WORLD_USER_COMMANDS = ("gz-sim-user-commands-system", "gz::sim::systems::UserCommands")
WORLD_SCENE = ("gz-sim-scene-broadcaster-system", "gz::sim::systems::SceneBroadcaster")
# The gz-sim system each gz sensor type needs (port.gz_sensors holds the full table).
SENSOR_SYSTEMS = {kind.gz: kind.system for kind in SENSOR_KINDS if kind.gz is not None}
# Where PX4's gz bridge sends motor speeds, below the model instance's name, as PX4's own
# gz models subscribe.
PX4_MOTOR_TOPIC = "command/motor_speed"
# Where a navsat sensor is on Earth when the source names no home: PX4 Classic's default
# home (common.h kDefaultHomeLatitude/Longitude/Altitude), where its GPS plugin put it.
# gz-sim's NavSat system publishes nothing without the world's <spherical_coordinates>.
DEFAULT_HOME = (47.397742, 8.545594, 488.0)    # latitude deg, longitude deg, elevation m
# The IMU update rate the port writes: RotorS' noise densities become per-sample
# standard deviations at this rate (sigma = density * sqrt(rate)).
IMU_RATE_HZ = 250.0


@dataclass(frozen=True)
class Family:
    """A Classic plugin family and what the port makes of it."""

    key: str
    libraries: tuple[str, ...]     # Plugin.library spellings (no lib prefix, no .so)
    action: str                    # how plan_port handles it (see _HANDLERS)
    gz: str                        # what it becomes, for the report ("" when dropped)
    why: str                       # the reason, for the report
    sensor: str | None = None      # the gz sensor type it simulates, if any
    # its noise parameters (as the plugin names them) the port does not carry, and why
    noise_not_carried: tuple[tuple[str, ...], str] = ((), "")


PLUGIN_FAMILIES: tuple[Family, ...] = (
    Family("motor-model", CLASSIC_MOTOR_LIBRARIES, "motor",
           "gz-sim-multicopter-motor-model-system (velocity) or "
           "gz-sim-joint-position-controller-system (position servo)",
           "the same motor model in gz-sim; motorNumber becomes actuator_number, every "
           "constant carried as written"),
    Family("multirotor-base", ("rotors_gazebo_multirotor_base_plugin",
                               "gazebo_multirotor_base_plugin"), "joint_states",
           "gz-sim-joint-state-publisher-system",
           "RotorS' (and PX4 Classic's) base plugin publishes joint states; gz's "
           "JointStatePublisher does"),
    Family("imu", ("rotors_gazebo_imu_plugin", "gazebo_imu_plugin", "gazebo_ros_imu_sensor",
                   "gazebo_ros_imu"), "imu",
           "<sensor type=\"imu\"> on the link + gz-sim-imu-system in the world",
           "gz simulates IMUs as sensors; noise densities become per-sample deviations "
           f"at {IMU_RATE_HZ:g} Hz", sensor="imu"),
    Family("odometry", ("rotors_gazebo_odometry_plugin", "gazebo_odometry_plugin",
                        "gazebo_groundtruth_plugin", "gazebo_ros_p3d"), "odometry",
           "gz-sim-odometry-publisher-system",
           "ground-truth odometry of the model in gz"),
    Family("gps", ("gazebo_gps_plugin",), "sensor:navsat",
           "<sensor type=\"navsat\"> + gz-sim-navsat-system", "gz's GNSS sensor",
           sensor="navsat", noise_not_carried=(
               ("gpsXYRandomWalk", "gpsZRandomWalk", "gpsXYNoiseDensity", "gpsZNoiseDensity",
                "gpsVXYNoiseDensity", "gpsVZNoiseDensity"),
               "PX4 Classic's random-walk GNSS model has no navsat counterpart")),
    Family("magnetometer", ("gazebo_magnetometer_plugin",), "sensor:magnetometer",
           "<sensor type=\"magnetometer\"> + gz-sim-magnetometer-system", "gz's magnetometer",
           sensor="magnetometer", noise_not_carried=(
               ("noiseDensity", "randomWalk", "biasCorrelationTime"),
               "PX4 Classic's magnetometer noise is in gauss with its own bias model; gz's "
               "is per axis in tesla: set <magnetometer><x><noise> by hand")),
    Family("barometer", ("gazebo_barometer_plugin",), "sensor:air_pressure",
           "<sensor type=\"air_pressure\"> + gz-sim-air-pressure-system", "gz's barometer",
           sensor="air_pressure", noise_not_carried=(
               ("baroDriftPaPerSec",),
               "PX4 Classic's barometer drift has no air_pressure counterpart")),
    Family("mavlink", ("rotors_gazebo_mavlink_interface", "gazebo_mavlink_interface"), "drop",
           "", "PX4's gz bridge (and ArduPilot's plugin) replace the MAVLink interface in "
               "gz-sim; --autopilot px4 writes the airframe it reads"),
    Family("controller-interface", ("rotors_gazebo_controller_interface",), "controller",
           "gz-sim-multicopter-control-system with --velocity-control",
           "gz's MulticopterVelocityControl flies the rotors from twist commands; without "
           "--velocity-control speed commands go to the motor models' commandSubTopic"),
    Family("gimbal-controller", ("gazebo_gimbal_controller_plugin",), "drop", "",
           "PX4 Classic's gimbal controller (MAVLink gimbal commands to joint PIDs): with "
           "gz, PX4 drives a gimbal's joints through gz-sim-joint-position-controller-system "
           "topics (as PX4-gazebo-models' gimbal does); add those by hand"),
    Family("bag", ("rotors_gazebo_bag_plugin",), "drop", "",
           "records ROS 1 bags; with ROS 2 record the ros_gz_bridge topics with ros2 bag"),
    Family("ros-control", ("gazebo_ros_control",), "drop", "",
           "Classic ros_control; gz_ros2_control is its gz-sim counterpart, configured by hand"),
    Family("lift-drag", ("LiftDragPlugin",), "lift_drag", "gz-sim-lift-drag-system",
           "the same aerodynamic model in gz-sim, parameters carried"),
    Family("ardupilot", ("ArduPilotPlugin",), "ardupilot", "ArduPilotPlugin (ardupilot_gazebo)",
           "ardupilot_gazebo's plugin exists for gz-sim with the same <control> blocks"),
)

_BY_LIBRARY = {library: family for family in PLUGIN_FAMILIES for library in family.libraries}

# Parameters gz-sim's MulticopterMotorModel reads (gz-sim MulticopterMotorModel.cc).
GZ_MOTOR_PARAMS = ("robotNamespace", "jointName", "linkName", "turningDirection",
                   "timeConstantUp", "timeConstantDown", "maxRotVelocity", "motorConstant",
                   "momentConstant", "commandSubTopic", "actuator_number",
                   "rotorDragCoefficient", "rollingMomentCoefficient", "motorSpeedPubTopic",
                   "rotorVelocitySlowdownSim", "motorType", "reversible")
# <gazebo> elements that only steer Classic's URDF conversion.
URDF_HINTS = {"preserveFixedJoint", "disableFixedJointLumping"}


def family_of(plugin: Plugin) -> Family | None:
    return _BY_LIBRARY.get(plugin.library)


def is_gz_plugin(plugin: Plugin) -> bool:
    """Already a gz-sim system (filename gz-sim-* / ignition-gazebo-*, or a gz:: class)."""
    filename = (plugin.filename or "").rsplit("/", 1)[-1]
    name = plugin.name or ""
    return (filename.startswith(("gz-sim", "libgz-sim", "ignition-gazebo", "libignition-gazebo"))
            or name.startswith(("gz::sim::", "ignition::gazebo::")))


# ---------------------------------------------------------------- the plan

@dataclass
class Element:
    """A small XML element to write: tag, attributes, text, children (in order)."""

    tag: str
    attrib: dict[str, str] = field(default_factory=dict)
    text: str | None = None
    children: list["Element"] = field(default_factory=list)

    def add(self, tag: str, text: object | None = None, **attrib: str) -> "Element":
        child = Element(tag, dict(attrib), None if text is None else str(text))
        self.children.append(child)
        return child

    def find(self, tag: str) -> "Element | None":
        return next((c for c in self.children if c.tag == tag), None)


@dataclass
class PortRow:
    """What happened to one source element: mapped, folded, dropped or kept out."""

    source: SourceLoc
    element: str                   # e.g. "plugin front_right_motor_model (rotors_gazebo_motor_model)"
    action: str                    # 'mapped' | 'folded' | 'dropped' | 'unknown'
    output: str                    # the element written, "" when none
    why: str
    carried: dict[str, str] = field(default_factory=dict)   # number name -> text as written
    target: Element | None = None  # the output element, for its line in model.sdf
    covers: tuple[SourceLoc, ...] = ()  # every source location inside the element
    target_key: tuple[str, str] | None = None   # ('link' | 'joint', name) written in model.sdf

    def to_dict(self) -> dict:
        return {"source": str(self.source), "element": self.element, "action": self.action,
                "output": self.output, "why": self.why, "carried": dict(self.carried)}


@dataclass
class PortLink:
    name: str
    parent: str | None             # the parent link in the port, None for the root
    T_parent_link: np.ndarray      # pose in the parent link (identity for the root)
    inertials: list[tuple[np.ndarray, Inertial]]     # (T_link_part, inertial) folded in
    visuals: list[tuple[np.ndarray, Visual]]
    collisions: list[tuple[np.ndarray, Collision]]
    loc: SourceLoc
    sensors: list[Element] = field(default_factory=list)


@dataclass
class PortJoint:
    name: str
    type: str                      # as reedtool reads it: continuous, revolute, ...
    parent: str
    child: str
    axis: np.ndarray
    limit: tuple[float | None, float | None, float | None, float | None] | None
    loc: SourceLoc
    T_child_jointframe: np.ndarray | None = None   # SDF: the joint frame in the child link


@dataclass
class PortFrame:
    name: str                      # a folded link's name
    attached_to: str
    T_link_frame: np.ndarray


@dataclass
class GzPort:
    name: str
    links: list[PortLink]
    joints: list[PortJoint]
    frames: list[PortFrame]
    plugins: list[Element]         # model-level <plugin> elements
    world_systems: list[tuple[str, str]]
    rows: list[PortRow]
    meshes: dict[str, object] = field(default_factory=dict)   # uri -> model.Mesh
    namespace: str = ""
    options: "PortOptions" = None
    # --autopilot ardupilot: the velocity motor plugins ArduPilotPlugin drives, with their rows
    ardupilot_rotors: list[tuple[Plugin, PortRow]] = field(default_factory=list)
    # Sensors the port adds that the source has not (an autopilot needs them): (link,
    # sensor name, why). The proof notes them instead of calling them a difference.
    added_sensors: list[tuple[str, str, str]] = field(default_factory=list)
    # Sensors a port renames and moves on purpose: original name -> (name, link) in the
    # port (PX4's contract: its four on base_link, posed where they were).
    moved_sensors: dict[str, tuple[str, str]] = field(default_factory=dict)
    # Mesh URIs whose file lies outside the model's packages -> why (resolve.references.outside_reason);
    # they are referenced where they are, not copied, unless copy_outside_files.
    outside_files: dict[str, str] = field(default_factory=dict)
    copy_outside_files: bool = False
    target_dir: object = None      # the model directory being written (pathlib.Path)
    # (latitude deg, longitude deg, elevation m) of the world's <spherical_coordinates>,
    # from the source's GPS plugin (homeLatitude, ...) when it names one
    home: tuple[float, float, float] | None = None

    def add_sensor(self, link: "PortLink", sensor: Element, why: str) -> None:
        link.sensors.append(sensor)
        self.added_sensors.append((link.name, sensor.attrib.get("name", ""), why))
        system = SENSOR_SYSTEMS.get(sensor.attrib.get("type", ""))
        if system is not None and system not in self.world_systems:
            self.world_systems.append(system)
        self.rows.append(PortRow(link.loc, f"(none: added) sensor {sensor.attrib.get('name')}",
                                 "mapped", f"link {link.name}: <sensor type=\""
                                 f"{sensor.attrib.get('type')}\">", why, target=sensor))


@dataclass(frozen=True)
class PortOptions:
    velocity_control: bool = False
    autopilot: str | None = None   # 'px4' | 'ardupilot' | None


def plan_port(robot: Robot, name: str, options: PortOptions = PortOptions()) -> GzPort:
    """The gz-sim form of `robot` and a row for every element (see the module docstring)."""
    links, joints, frames, rows, fold = _structure(robot)
    port = GzPort(name=name, links=links, joints=joints, frames=frames, plugins=[],
                  world_systems=[WORLD_PHYSICS, WORLD_USER_COMMANDS, WORLD_SCENE], rows=rows,
                  namespace=_namespace(robot) or name, options=options)
    by_name = {link.name: link for link in links}
    for link in links:
        for _T, shape in [*link.visuals, *link.collisions]:
            geometry = shape.geometry
            if geometry is not None and hasattr(geometry, "uri"):
                port.meshes.setdefault(geometry.uri, geometry)
    for block in robot.gazebo:
        for element in block.elements:
            _gazebo_element(port, block.reference, element, fold, by_name)
    for _block, plugin in robot.plugins():
        family = family_of(plugin)
        if family is None:
            if is_gz_plugin(plugin):
                port.plugins.append(_copy(plugin.node))
                rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                                    f"plugin {plugin.filename}", "already a gz-sim system: "
                                    "kept as written", target=port.plugins[-1]))
            else:
                rows.append(PortRow(plugin.loc, _plugin_label(plugin), "unknown", "",
                                    "no gz-sim counterpart reedtool knows: kept out of the "
                                    "port; port it by hand if the model needs it",
                                    covers=_covers(plugin)))
            continue
        _HANDLERS[family.action.split(":")[0]](port, robot, plugin, family, fold, by_name)
    return port


# ---------------------------------------------------------------- structure

def _has_mass(inertials) -> bool:
    return any(inertial.mass_kg > 0 for _T, inertial in inertials)


def _structure(robot: Robot):
    """Links and joints of the port; fixed joints to or from a massless link folded.

    Returns (links, joints, frames, rows, fold) where fold maps every source link name to
    (port link name, T_portlink_link).
    """
    rows: list[PortRow] = []
    root = robot.base_link
    children: dict[str, list] = {}
    for joint in robot.joints:
        children.setdefault(joint.parent, []).append(joint)
    fold: dict[str, tuple[str, np.ndarray]] = {root: (root, np.eye(4))}
    links: dict[str, PortLink] = {}
    joints: list[PortJoint] = []
    frames: list[PortFrame] = []

    def port_link(link, parent, T_parent_link) -> PortLink:
        return PortLink(link.name, parent, T_parent_link,
                        [(np.eye(4), link.inertial)] if link.inertial is not None else [],
                        [(v.T_link_geom, v) for v in link.visuals],
                        [(c.T_link_geom, c) for c in link.collisions], link.loc)

    def link_row(link, parent) -> None:
        carried = {}
        if link.inertial is not None:
            carried["mass"] = float_text(link.inertial.mass_kg)
            carried.update({key: float_text(value) for key, value in
                            inertia_values(link.inertial.inertia_kg_m2).items()})
        rows.append(PortRow(link.loc, f"link {link.name}", "mapped", f"link {link.name}",
                            "posed relative to its parent link" if parent else "the root link",
                            carried, target_key=("link", link.name)))

    links[root] = port_link(robot.link_map[root], None, np.eye(4))
    link_row(robot.link_map[root], None)
    queue = [root]
    while queue:
        parent_name = queue.pop(0)
        for joint in children.get(parent_name, []):
            child = robot.link_map.get(joint.child)
            if child is None or joint.child in fold:
                continue
            survivor, T_survivor_parent = fold[parent_name]
            T_survivor_child = T_survivor_parent @ joint.T_parent_joint
            target = links[survivor]
            if joint.type == "fixed" and (child.inertial is None or not _has_mass(target.inertials)):
                fold[child.name] = (survivor, T_survivor_child)
                if child.inertial is not None:
                    target.inertials.append((T_survivor_child, child.inertial))
                target.visuals += [(T_survivor_child @ v.T_link_geom, v) for v in child.visuals]
                target.collisions += [(T_survivor_child @ c.T_link_geom, c)
                                      for c in child.collisions]
                frames.append(PortFrame(child.name, survivor, T_survivor_child))
                why = ("has no <inertial>: SDF would give it 1 kg" if child.inertial is None
                       else f"its parent '{parent_name}' has no <inertial>")
                rows.append(PortRow(joint.loc, f"fixed joint {joint.name} -> link {child.name}",
                                    "folded", f"link {survivor} (frame {child.name})",
                                    f"the link {why}; folded into '{survivor}' as Gazebo folds "
                                    "URDF fixed joints, its name kept as a <frame>"))
            else:
                fold[child.name] = (child.name, np.eye(4))
                links[child.name] = port_link(child, survivor, T_survivor_child)
                link_row(child, survivor)
                sdf_type = "revolute (unbounded)" if joint.type == "continuous" else joint.type
                rows.append(PortRow(joint.loc, f"joint {joint.name} ({joint.type})", "mapped",
                                    f"joint {joint.name} ({sdf_type})",
                                    f"{survivor} -> {child.name}; the joint frame at the child "
                                    "link, as URDF has it",
                                    {"pose": pose_text(T_survivor_child),
                                     "axis": " ".join(float_text(v) for v in joint.axis)},
                                    target_key=("joint", joint.name)))
                limit = joint.limit
                joints.append(PortJoint(
                    joint.name, joint.type, survivor, child.name,
                    np.asarray(joint.axis, dtype=float),
                    None if limit is None else (limit.lower, limit.upper, limit.effort,
                                                limit.velocity), joint.loc,
                    joint.T_child_jointframe))
            queue.append(child.name)
    for link in robot.links:
        if link.name not in fold:
            rows.append(PortRow(link.loc, f"link {link.name}", "dropped", "",
                                "not connected to the root link"))
    return list(links.values()), joints, frames, rows, fold


def _namespace(robot: Robot) -> str | None:
    for _block, plugin in robot.plugins():
        text = plugin.param("robotNamespace")
        if text:
            return text
    return None


# ---------------------------------------------------------------- elements

def _copy(node: XmlNode, skip: set[str] = frozenset()) -> Element:
    out = Element(node.tag, dict(node.attrib), node.text.strip() if node.text and node.text.strip()
                  else None)
    out.children = [_copy(child) for child in node.children if child.tag not in skip]
    return out


def _plugin_label(plugin: Plugin) -> str:
    return f"plugin {plugin.name or '?'} ({plugin.filename or '?'})"


def _carried(node: XmlNode, tags) -> dict[str, str]:
    out = {}
    for tag in tags:
        text = node.findtext(tag)
        if text is not None:
            out[tag] = text
    return out


def _resolve_link(name: str | None, fold, by_name) -> tuple[str | None, np.ndarray]:
    """(port link, T_portlink_link) of a source link name, scoped names tolerated."""
    from reedtool.physics.rotors import resolve_name

    key = resolve_name(name, fold) if name else None
    if key is None:
        return None, np.eye(4)
    return fold[key]


def _gazebo_element(port: GzPort, reference: str | None, node: XmlNode, fold, by_name) -> None:
    label = f"<gazebo{' reference=' + repr(reference) if reference else ''}> <{node.tag}>"
    if node.tag in URDF_HINTS:
        port.rows.append(PortRow(node.loc, label, "dropped", "",
                                 "steers Classic's URDF conversion only; the port keeps every "
                                 "fixed joint whose links carry mass"))
        return
    if node.tag == "sensor":
        _classic_sensor(port, reference, node, fold, by_name, label)
        return
    port.rows.append(PortRow(node.loc, label, "dropped", "",
                             "a Classic-only setting (OGRE material scripts, ODE contact "
                             "parameters): gz-sim does not read it; set its gz form by hand"))


def _classic_sensor(port: GzPort, reference: str | None, node: XmlNode, fold, by_name,
                    label: str) -> None:
    """A <sensor> of a link: its gz form from port.gz_sensors' table (type and child
    names as gz spells them, posed on the link it survives in), or a row saying why not;
    then one row for each Classic plugin inside it."""
    sensor_type = node.attrib.get("type", "")
    label = f"sensor {node.attrib.get('name', '?')} ({sensor_type or '?'}) on link {reference}"
    kind = sensor_kind(sensor_type)
    link, T = _resolve_link(reference, fold, by_name)
    if link is None:
        port.rows.append(PortRow(node.loc, label, "dropped", "",
                                 f"its link '{reference}' is not a link of the model",
                                 covers=tuple(n.loc for n in node.iter())))
        return
    if kind is None or kind.gz is None:
        action = "unknown" if kind is None else "dropped"
        why = kind.why if kind is not None else \
            f"a sensor type ('{sensor_type}') reedtool knows no gz-sim counterpart for: kept " \
            "out of the port; port it by hand if the model needs it"
        port.rows.append(PortRow(node.loc, label, action, "", why,
                                 covers=tuple(n.loc for n in node.iter())))
        _sensor_plugins(port, node)
        return
    if kind.system not in port.world_systems:
        port.world_systems.append(kind.system)
    renamed = "" if sensor_type == kind.gz else f" (Classic '{sensor_type}')"
    if kind.split:
        _split_sensor(port, node, kind, link, T, label)
        _sensor_plugins(port, node)
        return
    sensor = _copy(node, skip={"plugin"})
    sensor.attrib["type"] = kind.gz
    for child in sensor.children:
        child.tag = kind.renames.get(child.tag, child.tag)
    _place_sensor(sensor, T)
    by_name[link].sensors.append(sensor)
    port.rows.append(PortRow(node.loc, label, "mapped",
                             f"link {link}: <sensor type=\"{kind.gz}\"{renamed}>",
                             f"{kind.why}; pose, rate and noise as written",
                             _carried_sensor(node), target=sensor))
    _sensor_plugins(port, node)


def _split_sensor(port: GzPort, node: XmlNode, kind, link: str, T: np.ndarray,
                  label: str) -> None:
    """A Classic multicamera: one gz camera sensor per <camera>, each posed at the
    sensor's pose composed with its camera's <pose>."""
    from reedtool.frames import make_T, rpy_to_matrix

    def T_of(element) -> np.ndarray:
        pose = element.find("pose")
        values = ([float(v) for v in (pose.text or "").split()] if pose is not None else [])
        values = (values + [0.0] * 6)[:6]
        return make_T(rpy_to_matrix(values[3:]), values[:3])

    T_link_sensor = T_of(node)
    port_link = next(candidate for candidate in port.links if candidate.name == link)
    for index, camera in enumerate(node.findall("camera")):
        name = split_name(node.attrib.get("name", "camera"), camera.attrib.get("name"), index)
        sensor = _copy(node, skip={"plugin", "camera", "pose"})
        sensor.attrib.update({"name": name, "type": kind.gz})
        own = _copy(camera, skip={"pose"})
        own.attrib.pop("name", None)
        sensor.children.append(own)
        sensor.children.insert(0, Element("pose", {}, pose_text(T_link_sensor @ T_of(camera))))
        _place_sensor(sensor, T)
        port_link.sensors.append(sensor)
        port.rows.append(PortRow(camera.loc, f"{label} <camera name="
                                 f"{camera.attrib.get('name', index)!r}>", "mapped",
                                 f"link {link}: <sensor type=\"{kind.gz}\" name=\"{name}\">",
                                 kind.why, _carried_sensor(node), target=sensor))


def _note_home(port: GzPort, plugin_node: XmlNode) -> None:
    """A Classic GPS plugin's home (degrees, metres) for the world's spherical coordinates."""
    values = [plugin_node.findtext(tag) for tag in ("homeLatitude", "homeLongitude",
                                                     "homeAltitude")]
    if port.home is None and any(v is not None for v in values) \
            and all(v is None or _is_number(v) for v in values):
        port.home = tuple(float(v) if v is not None else default
                          for v, default in zip(values, DEFAULT_HOME))


def _sensor_plugins(port: GzPort, node: XmlNode) -> None:
    """One row for each Classic plugin inside a <sensor>: why it is not carried."""
    for inner in node.findall("plugin"):
        _note_home(port, inner)
        library = Plugin(inner.attrib.get("name"), inner.attrib.get("filename"), inner,
                         inner.loc).library
        why = sensor_plugin_why(library)
        plugin_label = f"plugin {inner.attrib.get('name') or '?'} " \
                       f"({inner.attrib.get('filename') or '?'}) in sensor " \
                       f"{node.attrib.get('name', '?')}"
        numbers = {child.tag: (child.text or "").strip() for child in inner.children
                   if _is_number((child.text or "").strip())}
        if why is None:
            port.rows.append(PortRow(inner.loc, plugin_label, "unknown", "",
                                     "a Classic sensor plugin reedtool knows no gz-sim "
                                     "counterpart for: kept out of the port; the sensor "
                                     "itself is carried",
                                     covers=tuple(n.loc for n in inner.iter())))
        else:
            port.rows.append(PortRow(inner.loc, plugin_label, "dropped", "",
                                     why + ("; left with it: " + ", ".join(
                                         f"{k} {v}" for k, v in numbers.items())
                                         if numbers else ""),
                                     covers=tuple(n.loc for n in inner.iter())))


def _carried_sensor(node: XmlNode) -> dict[str, str]:
    out = {}
    for key in ("update_rate", "pose"):
        text = node.findtext(key)
        if text is not None:
            out[key] = " ".join(text.split())
    return out


def _place_sensor(sensor: Element, T_link_sensor: np.ndarray) -> None:
    """Pose the sensor in the port link: `T_link_sensor` (where its source link sits in
    the port link, when folded) composed with its own <pose>."""
    from reedtool.frames import make_T, rpy_to_matrix

    if np.allclose(T_link_sensor, np.eye(4), rtol=0, atol=0):
        return
    pose = sensor.find("pose")
    T = T_link_sensor
    if pose is not None:
        values = [float(v) for v in (pose.text or "").split()] or [0.0] * 6
        values = (values + [0.0] * 6)[:6]
        T = T_link_sensor @ make_T(rpy_to_matrix(values[3:]), values[:3])
        sensor.children.remove(pose)
    sensor.children.insert(0, Element("pose", {}, pose_text(T)))


def _gz_plugin(system: tuple[str, str], name: str | None = None) -> Element:
    return Element("plugin", {"filename": system[0], "name": system[1]})


def _motor(port: GzPort, robot, plugin: Plugin, family: Family, fold, by_name) -> None:
    node = plugin.node
    from reedtool.physics.rotors import motor_type as motor_type_of

    motor_type = motor_type_of(plugin)     # as the motor plugin reads it (exact words)
    if motor_type == "position":
        out = _gz_plugin(JOINT_POSITION_SYSTEM)
        out.add("joint_name", plugin.param("jointName"))
        topic = plugin.param("commandSubTopic")
        if topic:
            out.add("topic", f"/{port.namespace}/{topic.lstrip('/')}")
        pid = node.find("joint_control_pid")
        carried = {}
        if pid is not None:
            for src, dst in (("p", "p_gain"), ("i", "i_gain"), ("d", "d_gain")):
                text = pid.findtext(src)
                if text is not None:
                    out.add(dst, text)
                    carried[f"joint_control_pid/{src}"] = text
        port.plugins.append(out)
        port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                                 f"plugin {JOINT_POSITION_SYSTEM[0]} "
                                 f"(joint {plugin.param('jointName')})",
                                 "a position servo (motorType position): gz's joint position "
                                 "controller, PID gains carried", carried, target=out))
        return
    if motor_type != "velocity":
        port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "dropped", "",
                                 f"motorType '{motor_type}': gz-sim's motor model spins "
                                 "velocity motors only; port this actuator by hand"))
        return
    if port.options is not None and port.options.autopilot == "ardupilot":
        # ArduPilot SITL drives joints through its own plugin; the blades make the thrust.
        # The whole-vehicle parts (channels from the frame match, PID gains from the rotor
        # inertia) are built by workflows.migration, which fills in this row's target.
        row = PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                      f"plugin ArduPilotPlugin <control channel=\"{plugin.param('motorNumber')}\"> "
                      "+ 2 gz-sim-lift-drag-system blades",
                      "ArduPilot SITL spins the rotor (VELOCITY control, joint PID) and two "
                      "LiftDrag blades give its thrust and drag torque, sized so thrust = "
                      "motorConstant w^2 and drag torque = momentConstant x thrust exactly",
                      _carried(node, ("motorNumber", "turningDirection", "motorConstant",
                                      "momentConstant", "maxRotVelocity", "timeConstantUp")))
        port.rows.append(row)
        port.ardupilot_rotors.append((plugin, row))
        return
    out = _gz_plugin(MOTOR_SYSTEM)
    carried: dict[str, str] = {}
    dropped: list[str] = []
    for child in node.children:
        tag = child.tag
        text = (child.text or "").strip()
        if tag == "motorNumber":
            if node.find("actuator_number") is not None:
                continue  # gz reads actuator_number; the alias adds nothing
            tag = "actuator_number"
        if tag not in GZ_MOTOR_PARAMS:
            dropped.append(tag)
            continue
        if tag == "motorType":
            text = motor_type    # what the source's plugin ran as (PX4 classic's ignores it)
        out.add(tag, text)
        carried[child.tag if child.tag != tag else tag] = text
    if out.find("motorType") is None:
        out.add("motorType", "velocity")
    if out.find("robotNamespace") is None:
        out.children.insert(0, Element("robotNamespace", {}, port.namespace))
    why = family.why + (f"; not read by gz-sim, dropped: {', '.join(dropped)}" if dropped else "")
    if port.options is not None and port.options.autopilot == "px4":
        # PX4's gz bridge publishes on /<model instance>/command/motor_speed (x500_0, ...);
        # without <robotNamespace> the motor model takes the instance name, as PX4's own
        # gz models leave it.
        topic = out.find("commandSubTopic") or out.add("commandSubTopic")
        changed = [f"commandSubTopic '{topic.text or ''}' -> '{PX4_MOTOR_TOPIC}'"] \
            if topic.text != PX4_MOTOR_TOPIC else []
        topic.text = PX4_MOTOR_TOPIC
        namespace = out.find("robotNamespace")
        out.children.remove(namespace)
        changed.append(f"robotNamespace '{namespace.text or ''}' left out (gz uses the "
                       "model instance's name)")
        why += f"; for PX4's gz bridge: {', '.join(changed)}"
    number = out.find("actuator_number")
    port.plugins.append(out)
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"plugin {MOTOR_SYSTEM[0]} (actuator_number "
                             f"{number.text if number is not None else '?'})", why, carried,
                             target=out))


def _joint_states(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    if any(p.attrib.get("filename") == JOINT_STATE_SYSTEM[0] for p in port.plugins):
        port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                                 f"plugin {JOINT_STATE_SYSTEM[0]} (shared)", family.why))
        return
    out = _gz_plugin(JOINT_STATE_SYSTEM)
    out.add("topic", f"/{port.namespace}/joint_states")
    port.plugins.append(out)
    carried = _carried(plugin.node, ("rotorVelocitySlowdownSim",))
    why = family.why
    if carried:
        why += ("; its rotorVelocitySlowdownSim is the motor models' own (each keeps it, "
                "and the rotor inertia is carried unscaled)")
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"plugin {JOINT_STATE_SYSTEM[0]}", why, carried, target=out))


_IMU_NOISE = (("gyroscope", "angular_velocity"), ("accelerometer", "linear_acceleration"))


def _imu(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    link_name = plugin.param("linkName") or plugin.param("bodyName") or plugin.param("frameName")
    link, T = _resolve_link(link_name, fold, by_name)
    if link is None:
        link, T = fold[robot.base_link]
    sensor = Element("sensor", {"name": plugin.name or "imu", "type": "imu"})
    _place_sensor(sensor, T)
    sensor.add("always_on", "true")
    sensor.add("update_rate", float_text(IMU_RATE_HZ))
    topic = plugin.param("imuTopic") or plugin.param("topicName") or "imu"
    sensor.add("topic", f"/{port.namespace}/{topic.lstrip('/')}")
    carried = {}
    imu = Element("imu")
    for prefix, gz_tag in _IMU_NOISE:
        density = plugin.param(f"{prefix}NoiseDensity")
        if density is None:
            continue
        numbers = {key: plugin.param(f"{prefix}{key}") for key in
                   ("NoiseDensity", "RandomWalk", "BiasCorrelationTime", "TurnOnBiasSigma")}
        carried.update({f"{prefix}{k}": v for k, v in numbers.items() if v is not None})
        group = imu.add(gz_tag)
        for axis in "xyz":
            noise = group.add(axis).add("noise", type="gaussian")
            # RotorS' discrete white noise: sigma = density / sqrt(dt).
            noise.add("stddev", float_text(float(numbers["NoiseDensity"]) * math.sqrt(IMU_RATE_HZ)))
            if numbers["TurnOnBiasSigma"] is not None:
                noise.add("bias_stddev", numbers["TurnOnBiasSigma"])
            if numbers["RandomWalk"] is not None:
                noise.add("dynamic_bias_stddev", numbers["RandomWalk"])
            if numbers["BiasCorrelationTime"] is not None:
                noise.add("dynamic_bias_correlation_time", numbers["BiasCorrelationTime"])
    if imu.children:
        sensor.children.append(imu)
    by_name[link].sensors.append(sensor)
    if SENSOR_SYSTEMS["imu"] not in port.world_systems:
        port.world_systems.append(SENSOR_SYSTEMS["imu"])
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"link {link}: <sensor type=\"imu\" name=\"{sensor.attrib['name']}\">",
                             family.why + ("; noise stddev = density x sqrt(rate), bias and "
                                           "random walk as gz's bias_stddev and dynamic bias"
                                           if carried else "; the plugin names no noise: "
                                           "the Classic plugin's built-in default noise is "
                                           "not carried, the port's IMU is noiseless"),
                             carried, target=sensor))


def _odometry(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    out = _gz_plugin(ODOMETRY_SYSTEM)
    out.add("odom_frame", plugin.param("parentFrameId") or "odom")
    out.add("robot_base_frame", plugin.param("childFrameId") or plugin.param("linkName")
            or robot.base_link)
    topic = plugin.param("odometryTopic") or plugin.param("topicName") or "odometry"
    out.add("odom_topic", f"/{port.namespace}/{topic.lstrip('/')}")
    out.add("dimensions", "3")
    port.plugins.append(out)
    noise = [tag for tag in ("noiseNormalPosition", "noiseNormalQuaternion",
                             "noiseNormalLinearVelocity", "noiseNormalAngularVelocity",
                             "noiseUniformPosition", "noiseUniformQuaternion",
                             "noiseUniformLinearVelocity", "noiseUniformAngularVelocity")
             if any(float(v) != 0 for v in (plugin.param(tag) or "0").split()
                    if _is_number(v))]
    why = family.why + ("; it reports the model's pose (the sensor link's offset is not "
                        "applied)")
    if noise:
        why += f"; not carried (OdometryPublisher adds no such noise): {', '.join(noise)}"
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"plugin {ODOMETRY_SYSTEM[0]} ({topic})", why, target=out))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _sensor(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    """A model-level Classic sensor plugin (PX4's magnetometer, barometer, GPS): a gz
    sensor on the link the plugin names, else the root link."""
    kind = family.action.split(":")[1]
    link_name = plugin.param("linkName") or plugin.param("bodyName")
    link, T = _resolve_link(link_name, fold, by_name)
    if link is None:
        link, T = fold[robot.base_link]
    sensor = Element("sensor", {"name": plugin.name or kind, "type": kind})
    _place_sensor(sensor, T)
    sensor.add("always_on", "true")
    rate = next((plugin.param(tag) for tag in ("pubRate", "updateRate", "update_rate")
                 if plugin.param(tag)), None)
    sensor.add("update_rate", rate or "50")
    by_name[link].sensors.append(sensor)
    _note_home(port, plugin.node)
    if SENSOR_SYSTEMS[kind] not in port.world_systems:
        port.world_systems.append(SENSOR_SYSTEMS[kind])
    names, reason = family.noise_not_carried
    lost = {tag: plugin.param(tag) for tag in names if plugin.param(tag) is not None}
    why = family.why + ("" if rate else "; no rate in the plugin: 50 Hz")
    if lost:
        why += f"; noise not carried ({reason}): " + ", ".join(f"{k} {v}" for k, v in lost.items())
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"link {link}: <sensor type=\"{kind}\">", why,
                             {"update_rate": rate} if rate else {}, target=sensor))


def _covers(plugin: Plugin) -> tuple[SourceLoc, ...]:
    return tuple(node.loc for node in plugin.node.iter())


def _drop(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "dropped", "", family.why,
                             covers=_covers(plugin)))


def _controller(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    """Dropped; MulticopterVelocityControl is written by the writer with --velocity-control
    (its gains need the whole model's mass and inertia)."""
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "dropped", "", family.why,
                             covers=_covers(plugin)))


def _lift_drag(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    out = _gz_plugin(LIFT_DRAG_SYSTEM)
    out.children = [_copy(child) for child in plugin.node.children]
    port.plugins.append(out)
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             f"plugin {LIFT_DRAG_SYSTEM[0]}", family.why,
                             _carried(plugin.node, ("a0", "cla", "cda", "area", "cp", "forward",
                                                    "upward", "air_density")), target=out))


def _ardupilot(port: GzPort, robot, plugin, family, fold, by_name) -> None:
    out = _gz_plugin(ARDUPILOT_SYSTEM)
    out.children = [_copy(child) for child in plugin.node.children]
    port.plugins.append(out)
    port.rows.append(PortRow(plugin.loc, _plugin_label(plugin), "mapped",
                             "plugin ArduPilotPlugin", family.why, target=out))


_HANDLERS = {"motor": _motor, "joint_states": _joint_states, "imu": _imu,
             "odometry": _odometry, "sensor": _sensor, "drop": _drop,
             "controller": _controller, "lift_drag": _lift_drag, "ardupilot": _ardupilot}
