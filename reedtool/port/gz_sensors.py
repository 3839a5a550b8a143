"""What every Classic `<sensor>` and sensor plugin becomes in Gazebo Sim: one table, as data.

`SENSOR_KINDS` maps a sensor `type=` (Classic and gz spellings) to the gz-sim sensor type,
the gz-sim system the world must load for it, the child elements gz spells differently,
or the reason it is dropped. `SENSOR_PLUGINS` says why each Classic plugin that lives
inside a `<sensor>` is not carried (in gz the sensor itself publishes on a gz topic). A
model-level Classic plugin that simulates a sensor (RotorS' and PX4's IMU, PX4's
magnetometer, barometer and GPS plugins) is in `port.gz_port.PLUGIN_FAMILIES`, whose
`sensor` names the gz type it becomes.

Another module may rename what it takes from here (PX4's gz bridge wants the sensors named
imu_sensor, air_pressure_sensor, ...): the table is the facts, a port decides the names.

Sources of the facts: gz-sim's src/systems (one system per sensor kind; the rendering
sensors all run in gz-sim-sensors-system, whose Sensors.cc creates camera, depth,
gpu_lidar, rgbd, thermal, segmentation, bounding-box and wide-angle cameras), sdformat's
sensor.sdf types, and Gazebo Classic's sensor list.
"""

from __future__ import annotations

from dataclasses import dataclass, field

SENSORS_SYSTEM = ("gz-sim-sensors-system", "gz::sim::systems::Sensors")


@dataclass(frozen=True)
class SensorKind:
    types: tuple[str, ...]          # `type=` spellings this row covers (Classic and gz)
    gz: str | None                  # the gz-sim sensor type; None: dropped
    system: tuple[str, str] | None  # (filename, name) of the world system it needs
    why: str                        # for the report
    renames: dict[str, str] = field(default_factory=dict)  # child tag -> gz child tag
    # Classic's multicamera: one gz sensor per <camera> child, named SENSOR_CAMERA and posed
    # at the sensor's pose composed with the camera's.
    split: bool = False


SENSOR_KINDS: tuple[SensorKind, ...] = (
    SensorKind(("imu",), "imu", ("gz-sim-imu-system", "gz::sim::systems::Imu"),
               "gz's IMU sensor, run by the Imu system"),
    SensorKind(("gps", "navsat"), "navsat", ("gz-sim-navsat-system", "gz::sim::systems::NavSat"),
               "gz's GNSS sensor (Classic's gps), run by the NavSat system; the world needs "
               "<spherical_coordinates>", {"gps": "navsat"}),
    SensorKind(("magnetometer",), "magnetometer",
               ("gz-sim-magnetometer-system", "gz::sim::systems::Magnetometer"),
               "gz's magnetometer, run by the Magnetometer system"),
    SensorKind(("air_pressure",), "air_pressure",
               ("gz-sim-air-pressure-system", "gz::sim::systems::AirPressure"),
               "gz's barometer, run by the AirPressure system"),
    SensorKind(("air_speed",), "air_speed",
               ("gz-sim-air-speed-system", "gz::sim::systems::AirSpeed"),
               "gz's airspeed sensor, run by the AirSpeed system"),
    SensorKind(("altimeter",), "altimeter",
               ("gz-sim-altimeter-system", "gz::sim::systems::Altimeter"),
               "gz's altimeter, run by the Altimeter system"),
    SensorKind(("camera",), "camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("depth", "depth_camera"), "depth_camera", SENSORS_SYSTEM,
               "gz's depth camera (Classic's depth), a rendering sensor"),
    SensorKind(("rgbd_camera", "rgbd"), "rgbd_camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("thermal_camera", "thermal"), "thermal_camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("wideanglecamera", "wide_angle_camera"), "wide_angle_camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("segmentation_camera", "segmentation"), "segmentation_camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("boundingbox_camera", "boundingbox"), "boundingbox_camera", SENSORS_SYSTEM,
               "a rendering sensor: gz-sim-sensors-system runs it"),
    SensorKind(("ray", "gpu_ray", "lidar", "gpu_lidar"), "gpu_lidar", SENSORS_SYSTEM,
               "gz's lidar (Classic's ray / gpu_ray) is the GPU lidar, a rendering sensor; "
               "<ray> is written <lidar>", {"ray": "lidar"}),
    SensorKind(("contact",), "contact", ("gz-sim-contact-system", "gz::sim::systems::Contact"),
               "gz's contact sensor, run by the Contact system; its <collision> must name a "
               "collision of the link as the port writes it"),
    SensorKind(("force_torque",), "force_torque",
               ("gz-sim-forcetorque-system", "gz::sim::systems::ForceTorque"),
               "gz's force-torque sensor, run by the ForceTorque system"),
    SensorKind(("logical_camera",), "logical_camera",
               ("gz-sim-logical-camera-system", "gz::sim::systems::LogicalCamera"),
               "gz's logical camera, run by the LogicalCamera system"),
    SensorKind(("multicamera",), "camera", SENSORS_SYSTEM,
               "gz-sim has no multicamera: each <camera> becomes a camera sensor "
               "SENSOR_CAMERA, posed at the sensor's pose composed with the camera's",
               split=True),
    SensorKind(("sonar",), None, None,
               "gz-sim has no sonar sensor: a gpu_lidar with a few narrow rays is its usual "
               "stand-in; add one by hand"),
    SensorKind(("rfid", "rfidtag"), None, None, "gz-sim has no RFID sensor"),
    SensorKind(("wireless_receiver", "wireless_transmitter", "transceiver"), None, None,
               "gz-sim has no wireless sensor (gz-sim's comms systems model radio links)"),
)

_BY_TYPE = {t: kind for kind in SENSOR_KINDS for t in kind.types}


def sensor_kind(sensor_type: str | None) -> SensorKind | None:
    """The row for a `type=` spelling; None when reedtool knows no such sensor."""
    return _BY_TYPE.get((sensor_type or "").strip())


_ROS_BRIDGE = ("a ROS publisher for the Classic sensor: in gz the sensor publishes on its "
               "own gz topic; bridge it to ROS with ros_gz_bridge")
_PX4_BRIDGE = ("PX4 Classic's bridge of this sensor to PX4 (MAVLink/UDP): with gz, PX4's gz "
               "bridge reads the gz sensor's topic")

# Plugins found inside a Classic <sensor>, by library (no lib prefix, no .so).
SENSOR_PLUGINS: dict[str, str] = {
    **{name: _ROS_BRIDGE for name in (
        "gazebo_ros_camera", "gazebo_ros_multicamera", "gazebo_ros_depth_camera",
        "gazebo_ros_openni_kinect", "gazebo_ros_laser", "gazebo_ros_gpu_laser",
        "gazebo_ros_block_laser", "gazebo_ros_ray_sensor", "gazebo_ros_range",
        "gazebo_ros_imu_sensor", "gazebo_ros_gps_sensor", "gazebo_ros_bumper",
        "gazebo_ros_ft_sensor", "gazebo_ros_magnetometer_sensor",
        "gazebo_ros_camera_utils", "hector_gazebo_ros_sonar")},
    **{name: _PX4_BRIDGE for name in (
        "gazebo_lidar_plugin", "gazebo_sonar_plugin", "gazebo_opticalflow_plugin",
        "gazebo_airspeed_plugin", "gazebo_irlock_plugin")},
    "gazebo_gps_plugin": "PX4 Classic's GNSS model (random walk and white noise in its own "
                         "parameters): gz's navsat sensor replaces it; its noise "
                         "parameters have no navsat counterpart and are not carried",
    "gazebo_gst_camera_plugin": "PX4 Classic's GStreamer video stream of the camera: with gz "
                                "PX4 streams gz camera topics (its GZBridge camera support)",
    "gazebo_camera_manager_plugin": "PX4 Classic's MAVLink camera protocol for the camera: no "
                                    "gz-sim counterpart; the camera itself is carried",
    "gazebo_geotagged_images_plugin": "PX4 Classic's geotagging of camera images: no gz-sim "
                                      "counterpart",
    "gazebo_aruco_plugin": "PX4 Classic's ArUco marker detector: no gz-sim counterpart",
    "RayPlugin": "Gazebo Classic's example ray plugin (it only reads the ranges): the gz "
                 "lidar publishes them on its topic",
}


def sensor_plugin_why(library: str) -> str | None:
    return SENSOR_PLUGINS.get(library)


def split_name(sensor_name: str, camera_name: str | None, index: int) -> str:
    """The gz camera sensor one <camera> of a Classic multicamera becomes."""
    return f"{sensor_name}_{camera_name or index}"
