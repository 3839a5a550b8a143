"""PX4's Gazebo Sim contract: what a model must look like for PX4's gz bridge to fly it.

The facts, from PX4's own files (PX4-Autopilot src/modules/simulation/gz_bridge:
GZBridge.cpp, GZMixingInterfaceESC.cpp; ROMFS/px4fmu_common/init.d-posix/px4-rc.simulator;
PX4-gazebo-models models/x500, models/x500_base, worlds/default.sdf):

- The bridge subscribes to /world/W/model/M/link/base_link/sensor/S/T for the IMU
  (imu_sensor/imu), barometer (air_pressure_sensor/air_pressure), magnetometer
  (magnetometer_sensor/magnetometer) and GNSS (navsat_sensor/navsat): four sensors on a
  link named base_link, publishing on gz-sim's default topics (no <topic>).
- It publishes motor speeds in rad/s on /M/command/motor_speed, M the model instance
  (x500_0): each MulticopterMotorModel has commandSubTopic command/motor_speed and no
  robotNamespace (gz then takes the instance's name). The motor reads velocity[n] of that
  message: n is <actuator_number> for gz-sim 8 and later, <motorNumber> (deprecated
  there) for gz-sim 7 and earlier (gz-sim MulticopterMotorModel.cc), so both are written.
- px4-rc.simulator spawns ${PX4_GZ_MODELS}/<model> into ${PX4_GZ_WORLDS}/<world>.sdf,
  whose <world name> is the <world> of every topic: the layout models/NAME/model.sdf (with
  model.config) and worlds/NAME.sdf, a world named NAME with <spherical_coordinates> (the
  navsat and magnetometer need them) and the sensor systems, without the vehicle (PX4
  spawns it).

`apply_px4_contract` rewrites a port plan (port.gz_port) to that shape and says what
it changed, row by row; `px4_world_sdf` writes the world; `px4_layout` the file paths.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import PurePosixPath

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.port.gz_port import (
    MOTOR_SYSTEM,
    SENSOR_SYSTEMS,
    WORLD_PHYSICS,
    WORLD_SCENE,
    WORLD_USER_COMMANDS,
    Element,
    GzPort,
    PortRow,
    pose_text,
)

ROOT_LINK = "base_link"
MOTOR_TOPIC = "command/motor_speed"
# An autostart number for the airframe file (NNNN_gz_NAME). PX4's gz airframes are 4001..
# 40xx; 4900 is free in PX4-Autopilot's tree. Rename the file if yours uses it.
AIRFRAME_AUTOSTART = 4900
# PX4-gazebo-models worlds/default.sdf: PX4's home (Zurich) and the field there.
SPHERICAL_COORDINATES = (("surface_model", "EARTH_WGS84"), ("world_frame_orientation", "ENU"),
                         ("latitude_deg", "47.397971057728974"),
                         ("longitude_deg", "8.546163739800146"), ("elevation", "488"))
MAGNETIC_FIELD_T = "6e-06 2.3e-05 -4.2e-05"


@dataclass(frozen=True)
class Px4Sensor:
    """A sensor PX4's gz bridge reads: its name, gz type, rate and noise as x500_base has
    them (noise: (element path, stddev) per axis group)."""

    name: str
    type: str
    update_rate_hz: str
    noise: tuple[tuple[str, str], ...] = ()


PX4_SENSORS = (
    # IIM42653 noise, as x500_base writes it: gyro 0.05 deg/s, accel 0.65 / 0.70 mg rms.
    Px4Sensor("imu_sensor", "imu", "250", (
        ("imu/angular_velocity/x", "0.0008726646"), ("imu/angular_velocity/y", "0.0008726646"),
        ("imu/angular_velocity/z", "0.0008726646"), ("imu/linear_acceleration/x", "0.00637"),
        ("imu/linear_acceleration/y", "0.00637"), ("imu/linear_acceleration/z", "0.00686"))),
    Px4Sensor("air_pressure_sensor", "air_pressure", "50",          # BMP390: 3 Pa
              (("air_pressure/pressure", "3"),)),
    Px4Sensor("magnetometer_sensor", "magnetometer", "100", (       # IIS2MDC
        ("magnetometer/x", "0.0001"), ("magnetometer/y", "0.0001"), ("magnetometer/z", "0.0001"))),
    Px4Sensor("navsat_sensor", "navsat", "30"),
)
WORLD_SYSTEMS = (WORLD_PHYSICS, WORLD_USER_COMMANDS, WORLD_SCENE,
                 *(SENSOR_SYSTEMS[s.type] for s in PX4_SENSORS))
_SOURCE = "PX4-gazebo-models models/x500_base"


@dataclass
class Px4Contract:
    """What apply_px4_contract did: the root's old name (None: it was base_link already)
    and the rows it added."""

    renamed_root: str | None = None
    rows: list[PortRow] = field(default_factory=list)

    def link_name(self, name: str) -> str:
        return ROOT_LINK if name == self.renamed_root else name


# ----------------------------------------------------------------- the model

def _T_root(port: GzPort) -> dict[str, np.ndarray]:
    """T_root_link of every port link at zero joint positions."""
    by_name = {link.name: link for link in port.links}
    out: dict[str, np.ndarray] = {}

    def resolve(name: str) -> np.ndarray:
        if name not in out:
            link = by_name[name]
            out[name] = np.eye(4) if link.parent is None else \
                resolve(link.parent) @ link.T_parent_link
        return out[name]

    for link in port.links:
        resolve(link.name)
    return out


def _pose_of(sensor: Element) -> np.ndarray:
    from reedtool.frames import make_T, rpy_to_matrix

    pose = sensor.find("pose")
    if pose is None or not (pose.text or "").split():
        return np.eye(4)
    values = [float(v) for v in pose.text.split()]
    return make_T(rpy_to_matrix(values[3:6]), values[:3])


def _replace_text(element: Element, old: str, new: str) -> None:
    """Every child text naming link `old` (linkName, comLinkName, robot_base_frame, ...)."""
    for child in element.children:
        if child.text is not None and child.text.strip() == old:
            child.text = new
        _replace_text(child, old, new)


def _rename_root(port: GzPort, contract: Px4Contract) -> None:
    root = port.links[0]
    old = root.name
    if old == ROOT_LINK:
        return
    if any(link.name == ROOT_LINK for link in port.links) or \
            any(frame.name == ROOT_LINK for frame in port.frames):
        raise ReedtoolError(
            f"--autopilot px4: PX4's gz bridge reads the sensors of the link named "
            f"'{ROOT_LINK}', which must be the root; here the root is '{old}' and "
            f"'{ROOT_LINK}' is another link or frame", file=str(root.loc.file),
            hint=f"rename the other '{ROOT_LINK}' in the source model")
    root.name = ROOT_LINK
    for link in port.links:
        if link.parent == old:
            link.parent = ROOT_LINK
    for joint in port.joints:
        joint.parent = ROOT_LINK if joint.parent == old else joint.parent
        joint.child = ROOT_LINK if joint.child == old else joint.child
    for frame in port.frames:
        if frame.attached_to == old:
            frame.attached_to = ROOT_LINK
    for element in [*port.plugins, *(s for link in port.links for s in link.sensors)]:
        _replace_text(element, old, ROOT_LINK)
    for row in port.rows:
        if row.target_key is not None and row.target_key[0] == "joint":
            row.why = row.why.replace(f"{old} -> ", f"{ROOT_LINK} -> ", 1)
        if row.target_key == ("link", old):
            row.target_key = ("link", ROOT_LINK)
            row.output = f"link {ROOT_LINK}"
            row.why += f"; renamed from '{old}' (PX4's gz bridge reads link {ROOT_LINK})"
    contract.renamed_root = old


def px4_sensor_element(spec: Px4Sensor) -> Element:
    """The SDF `<sensor>` a PX4 gz sensor spec asks for (type, rate, noise per axis)."""
    sensor = Element("sensor", {"name": spec.name, "type": spec.type})
    sensor.add("always_on", "1")
    sensor.add("update_rate", spec.update_rate_hz)
    for path, stddev in spec.noise:
        node = sensor
        for tag in path.split("/"):
            node = node.find(tag) or node.add(tag)
        noise = node.add("noise", type="gaussian")
        noise.add("mean", "0")
        noise.add("stddev", stddev)
    return sensor


def _place_sensors(port: GzPort, contract: Px4Contract) -> None:
    T_root = _T_root(port)
    root = port.links[0]
    root_loc = root.loc
    for spec in PX4_SENSORS:
        found = [(link, s) for link in port.links for s in link.sensors
                 if s.attrib.get("type") == spec.type]
        if not found:
            sensor = px4_sensor_element(spec)
            root.sensors.append(sensor)
            contract.rows.append(PortRow(
                root_loc, f"(no {spec.type} sensor in the source)", "mapped",
                f"link {ROOT_LINK}: <sensor type=\"{spec.type}\" name=\"{spec.name}\">",
                f"added for PX4's gz bridge, which needs it on {ROOT_LINK}; rate and noise "
                f"as {_source_note(spec)}", target=sensor))
            port.added_sensors.append((root.name, spec.name, "PX4's gz bridge needs it"))
        else:
            link, sensor = found[0]
            old_name = sensor.attrib.get("name", "")
            # A pose is in its link's frame, or in the link its relative_to names.
            pose_el = sensor.find("pose")
            frame = pose_el.attrib.get("relative_to", link.name) if pose_el is not None \
                else link.name
            T_root_sensor = T_root.get(frame, T_root[link.name]) @ _pose_of(sensor)
            if link is not root:
                link.sensors.remove(sensor)
                root.sensors.append(sensor)
            if pose_el is not None:
                sensor.children.remove(pose_el)
            if not np.allclose(T_root_sensor, np.eye(4), rtol=0, atol=0):
                sensor.children.insert(0, Element("pose", {}, pose_text(T_root_sensor)))
            sensor.attrib["name"] = spec.name
            port.moved_sensors[old_name] = (spec.name, root.name)
            topic = sensor.find("topic")
            if topic is not None:
                sensor.children.remove(topic)
            changes = []
            if old_name != spec.name:
                changes.append(f"renamed '{old_name}' -> '{spec.name}'")
            if link is not root:
                changes.append(f"moved from link '{link.name}' to {ROOT_LINK}, posed where it "
                               "was (zero joint positions)")
            if topic is not None:
                changes.append(f"<topic> {topic.text} left out (PX4 reads gz's default topic)")
            output = f"link {ROOT_LINK}: <sensor type=\"{spec.type}\" name=\"{spec.name}\">"
            _amend(port, contract, sensor, output, "for PX4's gz bridge: " + "; ".join(changes)
                   if changes else "", root_loc, f"sensor {old_name} ({spec.type})")
            for _other_link, other in found[1:]:
                name = other.attrib.get("name", "?")
                _amend(port, contract, other, None,
                       f"a second {spec.type}: PX4's gz bridge reads {spec.name} only",
                       root_loc, f"sensor {name} ({spec.type})")
        if SENSOR_SYSTEMS[spec.type] not in port.world_systems:
            port.world_systems.append(SENSOR_SYSTEMS[spec.type])


def _amend(port: GzPort, contract: Px4Contract, sensor: Element, output: str | None,
           why: str, loc, label: str) -> None:
    """Say what the contract did to a sensor on the row that wrote it (a row of its own
    when no row did)."""
    if not why:
        return
    rows = [row for row in port.rows if row.target is sensor]
    for row in rows:
        if output is not None:
            row.output = output
        row.why += f"; {why}"
    if not rows:
        contract.rows.append(PortRow(loc, label, "mapped", output or "", why, target=sensor))


def _source_note(spec: Px4Sensor) -> str:
    return f"{_SOURCE} ({spec.update_rate_hz} Hz)"


def _motors(port: GzPort, contract: Px4Contract) -> None:
    for plugin in port.plugins:
        if plugin.attrib.get("filename") != MOTOR_SYSTEM[0]:
            continue
        namespace = plugin.find("robotNamespace")
        if namespace is not None:
            plugin.children.remove(namespace)
        topic = plugin.find("commandSubTopic") or plugin.add("commandSubTopic")
        topic.text = MOTOR_TOPIC
        number = plugin.find("actuator_number") or plugin.find("motorNumber")
        if number is None:
            continue
        for tag in ("actuator_number", "motorNumber"):
            if plugin.find(tag) is None:
                index = plugin.children.index(number) + 1
                plugin.children.insert(index, Element(tag, {}, number.text))


def apply_px4_contract(port: GzPort) -> Px4Contract:
    """Rewrite the port to PX4's gz contract (the module docstring): the root link named
    base_link, PX4's four sensors on it (the model's own, renamed and moved there, else
    x500_base's), every velocity motor on command/motor_speed without a namespace and
    numbered by both actuator_number and motorNumber, the sensor systems in the world."""
    contract = Px4Contract()
    _rename_root(port, contract)
    _place_sensors(port, contract)
    _motors(port, contract)
    port.rows.extend(contract.rows)
    return contract


# ----------------------------------------------------------------- the files

def px4_layout(name: str, path: PurePosixPath) -> PurePosixPath:
    """Where a file of the flat port goes in PX4-gazebo-models' layout."""
    if path.parts[0] == "worlds":
        return path
    return PurePosixPath("models", name, *path.parts)


def airframe_path(name: str) -> PurePosixPath:
    return PurePosixPath("airframes", f"{AIRFRAME_AUTOSTART}_gz_{name}")


def px4_world_sdf(world_name: str) -> bytes:
    """worlds/<world_name>.sdf as PX4 starts it: named as the file, gz-sim's sensor systems
    in it (the world names its systems, so gz does not add its server.config defaults),
    spherical coordinates and the magnetic field of PX4's default world, no vehicle."""
    from lxml import etree

    from reedtool.io.sdf_write import (
        SDF_VERSION,
        ground_plane_element,
        physics_element,
        sdf_bytes,
        sub,
        sun_element,
    )

    root = etree.Element("sdf", version=SDF_VERSION)
    root.append(etree.Comment(
        f" {world_name}: a world for PX4 SITL, written by reedtool. PX4 spawns the vehicle "
        f"(PX4_SIM_MODEL) into it; PX4_GZ_WORLD={world_name}. "))
    world = sub(root, "world", name=world_name)
    physics_element(world)      # PX4's default world steps 4 ms (its IMU, lockstep: 250 Hz)
    sub(world, "gravity", "0 0 -9.8")
    sub(world, "magnetic_field", MAGNETIC_FIELD_T)
    sub(world, "atmosphere", type="adiabatic")
    for filename, name in WORLD_SYSTEMS:
        sub(world, "plugin", filename=filename, name=name)
    sun_element(world)
    ground_plane_element(world)
    spherical = sub(world, "spherical_coordinates")
    for tag, text in SPHERICAL_COORDINATES:
        sub(spherical, tag, text)
    return sdf_bytes(root)


def readme_text(name: str, tool: str) -> str:
    """How to fly the model with PX4 SITL, for the output's README.md."""
    airframe = airframe_path(name)
    return f"""# {name} for PX4 SITL on Gazebo Sim

Written by `reedtool {tool} --autopilot px4` in PX4-gazebo-models' layout:

    models/{name}/model.sdf     the vehicle: link base_link with imu_sensor,
                                air_pressure_sensor, magnetometer_sensor, navsat_sensor;
                                motors on command/motor_speed (PX4's gz bridge)
    models/{name}/model.config
    worlds/{name}.sdf          a world named {name}: sensor systems, spherical coordinates
    {airframe}      the airframe: PX4_SIM_MODEL={name}, PX4_GZ_WORLD={name},
                                SIM_GZ_EN 1, CA_ROTOR*, SIM_GZ_EC_FUNC/MIN/MAX/DIS

## Fly it

In a PX4-Autopilot tree (PX4 v1.14 or later):

    cp -r models/{name} PX4-Autopilot/Tools/simulation/gz/models/
    cp worlds/{name}.sdf PX4-Autopilot/Tools/simulation/gz/worlds/
    cp {airframe} PX4-Autopilot/ROMFS/px4fmu_common/init.d-posix/airframes/
    # add {airframe.name} to ROMFS/px4fmu_common/init.d-posix/airframes/CMakeLists.txt
    cd PX4-Autopilot && make px4_sitl gz_{name}

Or with Gazebo started by hand (PX4_GZ_STANDALONE):

    export GZ_SIM_RESOURCE_PATH=$PWD/models:$GZ_SIM_RESOURCE_PATH
    gz sim -r worlds/{name}.sdf &
    PX4_GZ_STANDALONE=1 PX4_GZ_MODELS=$PWD/models PX4_GZ_WORLD={name} \\
      PX4_SYS_AUTOSTART={AIRFRAME_AUTOSTART} PX4_SIM_MODEL=gz_{name} \\
      PX4-Autopilot/build/px4_sitl_default/bin/px4

{AIRFRAME_AUTOSTART} is an autostart number PX4's own tree does not use; rename the airframe
file if yours does. Check the pair before flying:

    reedtool validate models/{name}/model.sdf --airframe {airframe}
"""


def package_px4_files(name: str, rendered) -> list[tuple[PurePosixPath, bytes]]:
    """new-package --sim gz --autopilot px4: the package's model (urdf/NAME.urdf.xacro, as
    rendered) ported to PX4's layout: models/NAME (model.sdf, model.config, meshes),
    worlds/NAME.sdf, README.md. The package is written to a scratch directory so the
    xacro expands as it will in the package (package:// meshes)."""
    import tempfile
    from pathlib import Path

    from reedtool.io.loader import load_robot
    from reedtool.port.gz_port import PortOptions, plan_port
    from reedtool.port.sdf_writer import port_files

    with tempfile.TemporaryDirectory(prefix="reedtool-px4-") as scratch:
        root = Path(scratch) / name
        for file in rendered:
            path = root.joinpath(*file.path.parts)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(file.data)
        model = root / "urdf" / f"{name}.urdf.xacro"
        robot = load_robot(model, {}, [Path(scratch)])
        port = plan_port(robot, name, PortOptions(autopilot="px4"))
        apply_px4_contract(port)
        source = f"package {name}, urdf/{name}.urdf.xacro"
        written, _rows = port_files(port, source)
    out = []
    for file in written.files:
        if file.path == PurePosixPath("worlds", f"{name}.sdf"):
            out.append((file.path, px4_world_sdf(name)))
        else:
            out.append((px4_layout(name, file.path), file.data))
    out.append((PurePosixPath("README.md"), readme_text(name, "new-package").encode("utf-8")))
    return out
