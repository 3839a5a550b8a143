"""`--autopilot px4` writes PX4's Gazebo Sim contract, checked against PX4's own files.

The expected values are written here from PX4's files (facts, not reedtool's output):
PX4-gazebo-models models/x500_base/model.sdf (the four sensors, their rates and noise),
models/x500/model.sdf (the motor systems), models/x500/model.config, worlds/default.sdf
(spherical coordinates); PX4-Autopilot ROMFS/px4fmu_common/init.d-posix/airframes/
4001_gz_x500 (the airframe), src/modules/simulation/gz_bridge/GZBridge.cpp (the topics the
bridge subscribes to) and px4-rc.simulator (models/NAME, worlds/NAME.sdf). The port is read
back with lxml and with libsdformat (tests/sdformat_oracle.py), not with reedtool's writer.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from cli_helpers import run_cli
from lxml import etree
from rotors_builder import multirotor_urdf

from reedtool.io.fileio import reset_inputs

FIXTURES = Path(__file__).parent / "fixtures"
X500 = FIXTURES / "px4_x500_ref" / "models" / "x500"
SEED_MODEL = FIXTURES / "seed000" / "reed_gazebo" / "urdf" / "mav_generic_odometry_sensor.gazebo"
SEED_ARGS = ("mav_name:=reed_quad_x", "namespace:=reed_quad_x", "enable_mavlink_interface:=true",
             "enable_ground_truth:=true", "enable_logging:=false", "log_file:=reed_quad_x",
             "wait_to_record_bag:=false")
MOTOR = "gz-sim-multicopter-motor-model-system"

# PX4-gazebo-models models/x500_base/model.sdf: sensor name -> (type, update_rate), all on
# base_link, where GZBridge.cpp subscribes (/world/W/model/M/link/base_link/sensor/NAME/...).
PX4_SENSORS = {"imu_sensor": ("imu", "250"), "air_pressure_sensor": ("air_pressure", "50"),
               "magnetometer_sensor": ("magnetometer", "100"), "navsat_sensor": ("navsat", "30")}
# ... and their noise stddev (x500_base: IIM42653, BMP390, IIS2MDC).
PX4_NOISE = {
    "imu_sensor": {"imu/angular_velocity/x": "0.0008726646",
                   "imu/angular_velocity/y": "0.0008726646",
                   "imu/angular_velocity/z": "0.0008726646",
                   "imu/linear_acceleration/x": "0.00637", "imu/linear_acceleration/y": "0.00637",
                   "imu/linear_acceleration/z": "0.00686"},
    "air_pressure_sensor": {"air_pressure/pressure": "3"},
    "magnetometer_sensor": {"magnetometer/x": "0.0001", "magnetometer/y": "0.0001",
                            "magnetometer/z": "0.0001"},
}
# PX4-gazebo-models models/x500/model.sdf: per motor (jointName, linkName, turningDirection,
# motorNumber), and the constants every motor shares.
PX4_MOTORS = [("rotor_0_joint", "rotor_0", "ccw", "0"), ("rotor_1_joint", "rotor_1", "ccw", "1"),
              ("rotor_2_joint", "rotor_2", "cw", "2"), ("rotor_3_joint", "rotor_3", "cw", "3")]
PX4_MOTOR_CONSTANTS = {"maxRotVelocity": 1000.0, "motorConstant": 8.54858e-06,
                       "momentConstant": 0.016, "timeConstantUp": 0.0125,
                       "timeConstantDown": 0.025, "rotorVelocitySlowdownSim": 10.0}
# PX4-gazebo-models worlds/default.sdf <spherical_coordinates>.
PX4_SPHERICAL = {"surface_model": "EARTH_WGS84", "world_frame_orientation": "ENU",
                 "latitude_deg": 47.397971057728974, "longitude_deg": 8.546163739800146,
                 "elevation": 488.0}
# The gz-sim systems that run those four sensors (gz-sim's system names).
SENSOR_SYSTEMS = {"gz::sim::systems::Imu", "gz::sim::systems::AirPressure",
                  "gz::sim::systems::Magnetometer", "gz::sim::systems::NavSat"}
# PX4-Autopilot airframes/4001_gz_x500, as written there.
AIRFRAME_4001 = """PX4_SIMULATOR=${PX4_SIMULATOR:=gz}
PX4_GZ_WORLD=${PX4_GZ_WORLD:=default}
PX4_SIM_MODEL=${PX4_SIM_MODEL:=x500}
param set-default SIM_GZ_EN 1
param set-default CA_AIRFRAME 0
param set-default CA_ROTOR_COUNT 4
param set-default CA_ROTOR0_PX 0.13
param set-default CA_ROTOR0_PY 0.22
param set-default CA_ROTOR0_KM  0.05
param set-default CA_ROTOR1_PX -0.13
param set-default CA_ROTOR1_PY -0.20
param set-default CA_ROTOR1_KM  0.05
param set-default CA_ROTOR2_PX 0.13
param set-default CA_ROTOR2_PY -0.22
param set-default CA_ROTOR2_KM -0.05
param set-default CA_ROTOR3_PX -0.13
param set-default CA_ROTOR3_PY 0.20
param set-default CA_ROTOR3_KM -0.05
param set-default SIM_GZ_EC_FUNC1 101
param set-default SIM_GZ_EC_FUNC2 102
param set-default SIM_GZ_EC_FUNC3 103
param set-default SIM_GZ_EC_FUNC4 104
param set-default SIM_GZ_EC_MIN1 150
param set-default SIM_GZ_EC_MIN2 150
param set-default SIM_GZ_EC_MIN3 150
param set-default SIM_GZ_EC_MIN4 150
param set-default SIM_GZ_EC_MAX1 1000
param set-default SIM_GZ_EC_MAX2 1000
param set-default SIM_GZ_EC_MAX3 1000
param set-default SIM_GZ_EC_MAX4 1000
param set-default MPC_THR_HOVER 0.60
"""


def migrate_px4(tmp_path: Path, model: Path, args=()) -> tuple[dict, Path]:
    reset_inputs()
    code, text = run_cli("migrate", model, *args, "--to", "gz", "-o", tmp_path / "out",
                         "--format", "json", "--autopilot", "px4")
    assert code == 0, text
    document = json.loads(text)
    return document, Path(document["target"])


def root_link(model: etree._Element) -> etree._Element:
    children = {joint.findtext("child") for joint in model.iter("joint")}
    roots = [link for link in model.findall("link") if link.get("name") not in children]
    assert len(roots) == 1
    return roots[0]


def check_contract(target: Path, name: str) -> etree._Element:
    """What every --autopilot px4 output must meet; returns the model element."""
    import sdformat_oracle

    files = {p.relative_to(target).as_posix() for p in target.rglob("*") if p.is_file()}
    assert {f"models/{name}/model.sdf", f"models/{name}/model.config", f"worlds/{name}.sdf",
            f"airframes/4900_gz_{name}"} <= files
    model_dir = target / "models" / name
    model = etree.parse(str(model_dir / "model.sdf")).getroot().find("model")
    base = root_link(model)
    assert base.get("name") == "base_link"
    sensors = {s.get("name"): s for s in base.findall("sensor")}
    for sensor_name, (kind, _rate) in PX4_SENSORS.items():
        assert sensors[sensor_name].get("type") == kind
        # gz's default topic, the one GZBridge.cpp subscribes to.
        assert sensors[sensor_name].find("topic") is None
    motors = model.findall(f"plugin[@filename='{MOTOR}']")
    assert motors
    for motor in motors:
        assert motor.findtext("commandSubTopic") == "command/motor_speed"
        assert motor.find("robotNamespace") is None
        # gz-sim >= 8 reads actuator_number, gz-sim 7 motorNumber (MulticopterMotorModel.cc).
        assert motor.findtext("actuator_number") == motor.findtext("motorNumber") is not None
    config = etree.parse(str(model_dir / "model.config")).getroot()
    assert config.findtext("name") == name
    assert (config.find("sdf").get("version"), config.findtext("sdf")) == ("1.9", "model.sdf")
    world = etree.parse(str(target / "worlds" / f"{name}.sdf")).getroot().find("world")
    assert world.get("name") == name             # PX4_GZ_WORLD is the file's stem
    assert SENSOR_SYSTEMS <= {p.get("name") for p in world.iter("plugin")}
    spherical = world.find("spherical_coordinates")
    for tag, value in PX4_SPHERICAL.items():
        text = spherical.findtext(tag).strip()
        assert (float(text) == value) if isinstance(value, float) else text == value
    assert world.find("include") is None         # PX4 spawns the vehicle itself
    assert sdformat_oracle.libsdformat_error(model_dir / "model.sdf", [target / "models"]) is None
    assert sdformat_oracle.libsdformat_error(target / "worlds" / f"{name}.sdf",
                                             [target / "models"]) is None
    return model


def test_x500_port_agrees_with_px4_x500_element_by_element(tmp_path):
    from reedtool.checks.runner import run_checks
    from reedtool.flightstack.px4 import load_px4_params, parse_px4_params
    from reedtool.io.loader import load_robot

    document, target = migrate_px4(tmp_path, X500)
    assert not document["proof"]["differences"], document["proof"]["differences"]
    model = check_contract(target, "x500")
    base = root_link(model)
    for sensor in base.findall("sensor"):
        name = sensor.get("name")
        assert sensor.findtext("update_rate").strip() == PX4_SENSORS[name][1]
        for path, stddev in PX4_NOISE.get(name, {}).items():
            assert float(sensor.find(path).findtext("noise/stddev")) == float(stddev), path
    motors = {m.findtext("jointName"): m for m in model.findall(f"plugin[@filename='{MOTOR}']")}
    assert sorted(motors) == [joint for joint, *_ in PX4_MOTORS]
    for joint, link, spin, number in PX4_MOTORS:
        motor = motors[joint]
        assert (motor.findtext("linkName"), motor.findtext("turningDirection"),
                motor.findtext("motorNumber")) == (link, spin, number)
        for tag, value in PX4_MOTOR_CONSTANTS.items():
            assert float(motor.findtext(tag)) == value, tag
    # The airframe, against 4001_gz_x500 where the vehicles are the same: the model's
    # rotor table (positions from the model, 0.174 m; 4001 describes the real frame's
    # 0.13 x 0.22) with 4001's signs, outputs, idle and top speed.
    ours = load_px4_params(target / "airframes" / "4900_gz_x500")
    px4 = parse_px4_params(AIRFRAME_4001, "4001_gz_x500")
    for key in ["SIM_GZ_EN", "CA_AIRFRAME", "CA_ROTOR_COUNT",
                *(f"SIM_GZ_EC_{p}{k}" for p in ("FUNC", "MIN", "MAX") for k in range(1, 5))]:
        assert ours.get(key).value == px4.get(key).value, key
    for i in range(4):
        for suffix in ("PX", "PY", "KM"):
            mine, theirs = ours.get(f"CA_ROTOR{i}_{suffix}").value, px4.get(f"CA_ROTOR{i}_{suffix}").value
            assert mine * theirs > 0, f"CA_ROTOR{i}_{suffix}: {mine} vs 4001's {theirs}"
    text = (target / "airframes" / "4900_gz_x500").read_text()
    assert "PX4_SIM_MODEL=${PX4_SIM_MODEL:=x500}" in text
    assert "PX4_SIMULATOR=${PX4_SIMULATOR:=gz}" in text
    # PX4's own airframe flies PX4's x500: on the port it finds no flight-stack error.
    port = load_robot(target / "models" / "x500" / "model.sdf", {}, [target / "models"])
    errors = [f for f in run_checks(port, flight_params=[px4]) if f.severity == "error"
              and f.code.startswith("C")]
    assert errors == []
    mine = [f for f in run_checks(port, flight_params=[ours])
            if f.code.startswith("C") and f.severity != "info"]
    assert mine == []


def test_seed_quad_port_takes_px4_names_and_places(tmp_path):
    """The bundled seed: root 'reed_quad_x/base_link' becomes base_link, the RotorS IMU on
    its own link moves to base_link with PX4's name, baro/mag/navsat are added; the proof
    still reads the port back as the original (the rename is followed)."""
    document, target = migrate_px4(tmp_path, SEED_MODEL, SEED_ARGS)
    assert not document["proof"]["differences"], document["proof"]["differences"]
    model = check_contract(target, "reed_quad_x")
    assert model.find("link[@name='reed_quad_x/base_link']") is None
    imu_rows = [r for r in document["elements"] if 'name="imu_sensor"' in r["output"]]
    assert len(imu_rows) == 1 and "moved from link 'reed_quad_x/imu_link'" in imu_rows[0]["why"]
    assert "rotors_gazebo_imu_plugin" in imu_rows[0]["element"]     # the row of its source
    added = {r["output"].split('name="')[1].rstrip('">') for r in document["elements"]
             if r["element"].startswith("(no ")}
    assert added == {"air_pressure_sensor", "magnetometer_sensor", "navsat_sensor"}


@pytest.mark.parametrize("max_rad_s", [1100, 1500])
def test_px4_takes_its_own_vehicles_top_speeds(tmp_path, max_rad_s):
    """PX4's Classic iris (1100 rad/s) and typhoon_h480 (1500), px4vision's SIM_GZ_EC_MAX
    1100: the 0..1000 of gz_bridge module.yaml is QGroundControl's range, not PX4's."""
    from reedtool.workflows.new_package import new_package
    from reedtool.flightstack.px4 import load_px4_params
    from reedtool.generate.package_spec import build_spec

    spec = build_spec("fast", frame="quad-x", ros=2, flags={"max_rot_velocity": str(max_rad_s)},
                      sim="gz")
    result = new_package(spec, tmp_path, autopilot="px4")
    airframe = next(f for f in result.files if f.parts[0] == "px4" and "airframe" in f.as_posix())
    params = load_px4_params(result.target / airframe)
    assert [params.get(f"SIM_GZ_EC_MAX{k}").value for k in range(1, 5)] == [max_rad_s] * 4


def test_px4_refuses_a_speed_no_output_can_carry(tmp_path):
    from reedtool.workflows.new_package import new_package
    from reedtool.errors import ReedtoolError
    from reedtool.generate.package_spec import build_spec

    spec = build_spec("rads", frame="quad-x", ros=2, flags={"max_rot_velocity": "70000"},
                      sim="gz")
    with pytest.raises(ReedtoolError, match="16-bit"):
        new_package(spec, tmp_path, autopilot="px4")


@pytest.mark.parametrize("frame", ["quad-x", "hex-x"])
def test_new_package_gz_px4_writes_the_contract(tmp_path, frame):
    """new-package --sim gz --autopilot px4: the ROS 2 package's model talks to PX4's
    bridge (motors on command/motor_speed, no namespace, both numbers; PX4's sensors on
    base_link, no velocity controller), and px4/ holds the same model in PX4's layout with
    its airframe; PX4's airframe and the model agree (no flight-stack warning)."""
    from reedtool.checks.runner import run_checks
    from reedtool.workflows.new_package import new_package
    from reedtool.flightstack.px4 import load_px4_params
    from reedtool.io.loader import load_robot
    from reedtool.generate.package_spec import build_spec

    name = f"px4_{frame.replace('-', '_')}"
    spec = build_spec(name, frame=frame, ros=2, flags={}, sim="gz")
    result = new_package(spec, tmp_path, autopilot="px4")
    px4_dir = result.target / "px4"
    model = check_contract(px4_dir, name)
    import sdformat_oracle

    # The ROS package's own world: PX4's sensor systems and spherical coordinates too.
    world_file = result.target / "worlds" / f"{name}.sdf"
    assert sdformat_oracle.libsdformat_error(world_file) is None
    world = etree.parse(str(world_file)).getroot().find("world")
    assert SENSOR_SYSTEMS <= {p.get("name") for p in world.iter("plugin")}
    assert float(world.findtext("spherical_coordinates/latitude_deg")) == PX4_SPHERICAL["latitude_deg"]
    assert len(model.findall(f"plugin[@filename='{MOTOR}']")) == spec.frame.rotor_count
    xacro = (result.target / "urdf" / f"{name}.urdf.xacro").read_text()
    assert "MulticopterVelocityControl" not in xacro
    bridge = (result.target / "config" / f"{name}_bridge.yaml").read_text()
    assert "cmd_vel" not in bridge
    assert f"/world/{name}_world/model/{name}/link/base_link/sensor/imu_sensor/imu" in bridge
    package_model = load_robot(result.target / "urdf" / f"{name}.urdf.xacro")
    port = load_robot(px4_dir / "models" / name / "model.sdf", {}, [px4_dir / "models"])
    airframe = load_px4_params(px4_dir / "airframes" / f"4900_gz_{name}")
    for robot in (package_model, port):
        found = [f for f in run_checks(robot, flight_params=[airframe])
                 if f.code.startswith("C") and f.severity != "info"]
        assert found == []


@pytest.mark.parametrize("edits, reasons", [
    ({}, []),                                                        # PX4's x500: reachable
    ({"x500_base": ("base_link", "body")}, ["base_link"]),           # no link base_link
    ({"x500": ("<commandSubTopic>command/motor_speed", "<commandSubTopic>gazebo/command/motor_speed")},
     ["motor"]),                                                     # RotorS' topic
])
def test_validate_says_when_px4s_bridge_cannot_reach_the_model(tmp_path, edits, reasons):
    """C439 with a gz airframe (4001_gz_x500): GZBridge.cpp reads the sensors of the link
    named base_link, GZMixingInterfaceESC.cpp publishes /<model>/command/motor_speed."""
    import shutil

    from reedtool.checks.runner import run_checks
    from reedtool.flightstack.px4 import parse_px4_params
    from reedtool.io.loader import load_robot

    models = tmp_path / "models"
    shutil.copytree(X500.parent, models)
    for name, (old, new) in edits.items():
        path = models / name / "model.sdf"
        text = path.read_text()
        assert old in text
        path.write_text(text.replace(old, new))
    robot = load_robot(models / "x500" / "model.sdf", {}, [models])
    found = [f for f in run_checks(robot, flight_params=[parse_px4_params(AIRFRAME_4001, "4001")])
             if f.code == "C439"]
    assert len(found) == len(reasons)
    for finding, reason in zip(sorted(found, key=lambda f: f.message), sorted(reasons)):
        assert finding.severity == "error" and reason in finding.message


def test_tilted_rotors_get_their_thrust_axes(tmp_path):
    """A tilted rotor's CA_ROTORi_AX/AY/AZ is its thrust axis in FRD (PX4's default is
    straight up, (0, 0, -1)): the airframe of a tilted hexacopter port validates clean
    against the port (C418/C426 compare the axes) and each axis is a unit vector."""
    from reedtool.checks.runner import run_checks
    from reedtool.flightstack.px4 import load_px4_params
    from reedtool.io.loader import load_robot

    document, target = migrate_px4(tmp_path, FIXTURES / "rotors_neo" / "neo_balanced_tilt.sdf")
    name = target.name
    params = load_px4_params(target / "airframes" / f"4900_gz_{name}")
    tilted = [i for i in range(params.rotor_count) if params.has(f"CA_ROTOR{i}_AX")]
    assert tilted
    for i in tilted:
        axis = [params.get(f"CA_ROTOR{i}_A{c}").value for c in "XYZ"]
        assert sum(v * v for v in axis) == pytest.approx(1.0, abs=3e-6)   # 6 printed digits
    port = load_robot(target / "models" / name / "model.sdf", {}, [])
    found = [f for f in run_checks(port, flight_params=[params])
             if f.code.startswith("C") and f.severity != "info"]
    assert found == []


def _quad_urdf(imu_xyz: str, imu_rpy: str, sensor_pose: str) -> str:
    """A small URDF quad (gz motor systems) with an IMU sensor on its own link."""
    return multirotor_urdf(
        4, name="imuquad", positions=[(0.2, -0.2, 0.05), (-0.2, 0.2, 0.05), (0.2, 0.2, 0.05),
                                      (-0.2, -0.2, 0.05)], spins=["ccw", "ccw", "cw", "cw"],
        body_inertia=(0.03, 0.03, 0.05),
        body_xml='<collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>',
        rotor_kg=0.01, rotor_inertia=(1e-5, 1e-5, 2e-5),
        rotor_xml='<collision><geometry><cylinder radius="0.1" length="0.005"/></geometry>'
                  '</collision>',
        plugin="gz", motor={"maxRotVelocity": 1000, "rotorDragCoefficient": None,
                            "rollingMomentCoefficient": None, "rotorVelocitySlowdownSim": None,
                            "commandSubTopic": "command/motor_speed", "motorType": "velocity"},
        imu_kg=0.015, imu_origin=f'xyz="{imu_xyz}" rpy="{imu_rpy}"',
        extra=f"""<gazebo reference="imu_link"><sensor name="my_imu" type="imu">
    <pose>{sensor_pose}</pose><always_on>1</always_on><update_rate>200</update_rate>
    <topic>/imuquad/imu</topic></sensor></gazebo>""")


def test_an_imu_on_another_link_moves_to_base_link_where_it_was(tmp_path):
    """The IMU keeps its place: imu_link at (0.1, 0, 0.05) yawed 90°, the sensor 0.02 m
    along imu_link's x, so in base_link it sits at (0.1, 0.02, 0.05), yawed 90°
    (hand-composed); its rate (200 Hz) is the model's, its name and topic PX4's."""
    import math

    source = tmp_path / "imuquad.urdf"
    source.write_text(_quad_urdf("0.1 0 0.05", "0 0 1.5707963267948966", "0.02 0 0 0 0 0"))
    _document, target = migrate_px4(tmp_path, source)
    model = check_contract(target, "imuquad")
    imu = root_link(model).find("sensor[@name='imu_sensor']")
    values = [float(v) for v in imu.findtext("pose").split()]
    # Composition of two poses written with repr() floats: round-off ~1e-16.
    assert values == pytest.approx([0.1, 0.02, 0.05, 0.0, 0.0, math.pi / 2], abs=1e-12)
    assert imu.findtext("update_rate").strip() == "200"
    assert model.find("link[@name='imu_link']/sensor") is None
