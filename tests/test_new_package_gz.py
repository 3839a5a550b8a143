"""`reedtool new-package --ros 2` for Gazebo Sim (issue 7): every multirotor frame, judged by
oracles nobody here wrote (check_urdf, catkin_pkg, lxml, Python's parser, pip's xacro,
Pinocchio), by gz-sim's own rules for MulticopterVelocityControl (its Common.cc allocation
matrix, rebuilt here from the expanded URDF) and by the other reedtool subcommands."""

from __future__ import annotations

import ast
import json
import math
import runpy
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli
from lxml import etree
from oracles import CHECK_URDF

from reedtool.cli import SUBCOMMANDS

ARM_LENGTH_M = 0.3      # every frame is generated with this --arm-length

# PX4's airframe reference, transcribed independently of reedtool/airframes.py: per motor
# (index - 1), the bearing in degrees clockwise from the nose seen from above and the spin
# ("ccw" pushes the body cw). quad-x places rotors at (+-L, +-L): radius L*sqrt(2).
PX4 = {
    "quad-x": ([45, -135, -45, 135], ["ccw", "ccw", "cw", "cw"], math.sqrt(2)),
    "quad-plus": ([90, -90, 0, 180], ["ccw", "ccw", "cw", "cw"], 1.0),
    "hex-x": ([90, -90, -30, 150, 30, -150], ["cw", "ccw", "cw", "ccw", "ccw", "cw"], 1.0),
    "hex-plus": ([0, 180, -120, 60, -60, 120], ["cw", "ccw", "cw", "ccw", "ccw", "cw"], 1.0),
    "octo-x": ([22.5, -157.5, 67.5, 157.5, -22.5, -112.5, -67.5, 112.5],
               ["ccw", "ccw", "cw", "cw", "cw", "cw", "ccw", "ccw"], 1.0),
    "y6": ([60, 60, 180, 180, -60, -60], ["cw", "ccw", "cw", "ccw", "cw", "ccw"], 1.0),
}
FRAMES = list(PX4)
VELOCITY_CONTROL = "gz::sim::systems::MulticopterVelocityControl"
MOTOR_MODEL = "gz::sim::systems::MulticopterMotorModel"


def pkg_name(frame: str) -> str:
    return f"g_{frame.replace('-', '_')}"


def model_file(pkg: Path) -> Path:
    return pkg / "urdf" / f"{pkg.name}.urdf.xacro"


@pytest.fixture(scope="module")
def packages(tmp_path_factory) -> dict[str, Path]:
    """One package per frame with `--ros 2` and no --sim: gz-sim is the ROS 2 default."""
    out = tmp_path_factory.mktemp("gz")
    made = {}
    for frame in FRAMES:
        code, output = run_cli("new-package", pkg_name(frame), "--frame", frame, "--ros", "2",
                               "--arm-length", ARM_LENGTH_M, "-o", out)
        assert code == 0, output
        assert "gz-sim" in output.splitlines()[0]
        made[frame] = out / pkg_name(frame)
    return made


@pytest.fixture(scope="module")
def expanded(packages, tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("gz_urdf")
    urdfs = {}
    for frame, pkg in packages.items():
        urdf = out / f"{pkg.name}.urdf"
        code, output = run_cli("expand", model_file(pkg), "-o", urdf)
        assert code == 0, output
        urdfs[frame] = urdf
    return urdfs


def plugins(root, name: str):
    return [p for p in root.iter("plugin") if p.get("name") == name]


def text(element, tag: str) -> str:
    node = element.find(tag)
    assert node is not None, f"<{tag}> missing in <{element.tag} name={element.get('name')}>"
    return node.text.strip()


# ------------------------------------------------------------------ package and files

@pytest.mark.parametrize("frame", FRAMES)
def test_layout_is_gz_sim_and_free_of_rotors(packages, frame):
    pkg = packages[frame]
    n = pkg.name
    files = {p.relative_to(pkg).as_posix() for p in pkg.rglob("*") if p.is_file()}
    assert files == {"package.xml", "CMakeLists.txt", "README.md", "meshes/README.md",
                     f"urdf/{n}.urdf.xacro", f"worlds/{n}.sdf", f"launch/{n}.launch.py",
                     f"config/{n}_bridge.yaml"}
    for f in files:
        body = (pkg / f).read_text()
        assert "rotors_" not in body and "gazebo_ros" not in body, f   # no RotorS / classic


@pytest.mark.parametrize("frame", FRAMES)
def test_package_xml_parses_with_ros_gz_exec_depends(packages, frame):
    from catkin_pkg.package import parse_package

    pkg = packages[frame]
    manifest = parse_package(str(pkg / "package.xml"))
    manifest.validate()
    assert manifest.name == pkg.name
    assert manifest.package_format == 3
    assert manifest.get_build_type() == "ament_cmake"
    exec_deps = {d.name for d in manifest.exec_depends}
    assert {"ros_gz_sim", "ros_gz_bridge", "xacro", "robot_state_publisher",
            "launch", "launch_ros", "ament_index_python"} <= exec_deps


def test_cmake_installs_every_package_directory(packages):
    for pkg in packages.values():
        cmake = (pkg / "CMakeLists.txt").read_text()
        installed = cmake.split("install(DIRECTORY", 1)[1].split("DESTINATION")[0].split()
        assert sorted(installed) == ["config", "launch", "meshes", "urdf", "worlds"]
        assert all((pkg / d).is_dir() for d in installed)


@pytest.mark.parametrize("frame", FRAMES)
def test_xml_files_are_well_formed(packages, frame):
    pkg = packages[frame]
    for path in [pkg / "package.xml", model_file(pkg), *pkg.glob("worlds/*.sdf")]:
        etree.parse(str(path))      # raises on malformed XML


@pytest.mark.parametrize("frame", FRAMES)
def test_world_has_what_gz_sim_needs(packages, frame):
    pkg = packages[frame]
    root = etree.parse(str(pkg / "worlds" / f"{pkg.name}.sdf")).getroot()
    assert root.tag == "sdf" and root.get("version")
    worlds = root.findall("world")
    assert len(worlds) == 1
    world = worlds[0]
    assert float(text(world.find("physics"), "max_step_size")) > 0
    systems = {p.get("name"): p.get("filename") for p in world.findall("plugin")}
    assert systems == {
        "gz::sim::systems::Physics": "gz-sim-physics-system",
        "gz::sim::systems::UserCommands": "gz-sim-user-commands-system",
        "gz::sim::systems::SceneBroadcaster": "gz-sim-scene-broadcaster-system",
        "gz::sim::systems::Imu": "gz-sim-imu-system",   # the model carries an IMU sensor
    }
    sun = world.find("light[@name='sun']")
    assert sun is not None and sun.get("type") == "directional"
    assert len(text(sun, "direction").split()) == 3
    ground = world.find("model[@name='ground_plane']")
    assert text(ground, "static") == "true"
    assert text(ground.find("link/collision/geometry/plane"), "normal").split() == ["0", "0", "1"]


# ------------------------------------------------------------------ launch and bridge

# Names the real `launch`, `launch_ros` and `ament_index_python` APIs define; the stubs
# below provide only these, so a misspelt import fails.
LAUNCH_API = {
    "launch": ["LaunchDescription"],
    "launch.actions": ["AppendEnvironmentVariable", "DeclareLaunchArgument",
                       "IncludeLaunchDescription", "SetEnvironmentVariable", "GroupAction",
                       "OpaqueFunction"],
    "launch.launch_description_sources": ["PythonLaunchDescriptionSource"],
    "launch.substitutions": ["LaunchConfiguration", "PathJoinSubstitution"],
    "launch_ros.actions": ["Node"],
}


class Recorded:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


def run_launch_file(path: Path, shares: dict[str, Path], monkeypatch) -> Recorded:
    """Execute generate_launch_description() with launch/launch_ros stubbed (they need ROS)
    and the real pip `xacro`; returns the recorded LaunchDescription."""
    for module_name in ["launch", "launch.actions", "launch.launch_description_sources",
                        "launch.substitutions", "launch_ros", "launch_ros.actions",
                        "ament_index_python", "ament_index_python.packages"]:
        module = types.ModuleType(module_name)
        for cls in LAUNCH_API.get(module_name, []):
            setattr(module, cls, type(cls, (Recorded,), {}))
        monkeypatch.setitem(sys.modules, module_name, module)

    def get_package_share_directory(package: str) -> str:
        return str(shares[package])       # KeyError: the launch file needs another package

    sys.modules["ament_index_python.packages"].get_package_share_directory = \
        get_package_share_directory
    namespace = runpy.run_path(str(path))
    return namespace["generate_launch_description"]()


@pytest.mark.parametrize("frame", ["quad-x", "y6"])
def test_launch_file_runs_and_wires_gz_sim(packages, frame, tmp_path, monkeypatch):
    pkg = packages[frame]
    launch = pkg / "launch" / f"{pkg.name}.launch.py"
    ast.parse(launch.read_text(), str(launch))
    # The source tree is laid out as CMake installs it, so it serves as the share dir.
    ros_gz_sim = tmp_path / "ros_gz_sim"
    description = run_launch_file(launch, {pkg.name: pkg, "ros_gz_sim": ros_gz_sim}, monkeypatch)
    actions = description.args[0]
    kinds = [type(a).__name__ for a in actions]
    assert kinds.count("IncludeLaunchDescription") == 1
    include = next(a for a in actions if type(a).__name__ == "IncludeLaunchDescription")
    assert include.args[0].args[0] == str(ros_gz_sim / "launch" / "gz_sim.launch.py")
    gz_args = "".join(dict(include.kwargs["launch_arguments"])["gz_args"])
    world = Path(gz_args.split()[-1])
    assert world == pkg / "worlds" / f"{pkg.name}.sdf" and world.is_file()
    assert "-r" in gz_args.split()           # start the simulation running

    nodes = {(a.kwargs["package"], a.kwargs["executable"]): a
             for a in actions if type(a).__name__ == "Node"}
    assert set(nodes) == {("robot_state_publisher", "robot_state_publisher"),
                          ("ros_gz_sim", "create"), ("ros_gz_bridge", "parameter_bridge")}
    rsp = nodes[("robot_state_publisher", "robot_state_publisher")].kwargs["parameters"][0]
    robot = etree.fromstring(rsp["robot_description"].encode())   # xacro ran on the model
    assert robot.get("name") == pkg.name and len(plugins(robot, VELOCITY_CONTROL)) == 1
    assert rsp["use_sim_time"] is True
    create = nodes[("ros_gz_sim", "create")].kwargs["arguments"]
    assert create[create.index("-topic") + 1] == "robot_description"
    assert create[create.index("-name") + 1] == pkg.name
    bridge = nodes[("ros_gz_bridge", "parameter_bridge")].kwargs["parameters"][0]
    assert Path(bridge["config_file"]) == pkg / "config" / f"{pkg.name}_bridge.yaml"


def test_bridge_topics_are_the_models_topics(packages, expanded):
    """Every gz topic the bridge names is one the model's systems use, in the right direction."""
    import yaml

    pkg = packages["hex-x"]
    root = etree.parse(str(expanded["hex-x"])).getroot()
    control = plugins(root, VELOCITY_CONTROL)[0]
    ns = text(control, "robotNamespace")
    odometry = plugins(root, "gz::sim::systems::OdometryPublisher")[0]
    joint_states = plugins(root, "gz::sim::systems::JointStatePublisher")[0]
    imu = next(s for s in root.iter("sensor") if s.get("type") == "imu")
    expected = {   # gz topic -> (ROS type, gz type, direction)
        "/clock": ("rosgraph_msgs/msg/Clock", "gz.msgs.Clock", "GZ_TO_ROS"),
        f"/{ns}/{text(control, 'commandSubTopic')}": ("geometry_msgs/msg/Twist", "gz.msgs.Twist",
                                                      "ROS_TO_GZ"),
        f"/{ns}/{text(control, 'enableSubTopic')}": ("std_msgs/msg/Bool", "gz.msgs.Boolean",
                                                     "ROS_TO_GZ"),
        text(odometry, "odom_topic"): ("nav_msgs/msg/Odometry", "gz.msgs.Odometry", "GZ_TO_ROS"),
        text(odometry, "tf_topic"): ("tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V", "GZ_TO_ROS"),
        text(imu, "topic"): ("sensor_msgs/msg/Imu", "gz.msgs.IMU", "GZ_TO_ROS"),
        text(joint_states, "topic"): ("sensor_msgs/msg/JointState", "gz.msgs.Model",
                                      "GZ_TO_ROS"),
    }
    entries = yaml.safe_load((pkg / "config" / f"{pkg.name}_bridge.yaml").read_text())
    got = {e["gz_topic_name"]: (e["ros_type_name"], e["gz_type_name"], e["direction"])
           for e in entries}
    assert got == expected
    ros_topics = {e["gz_topic_name"]: e["ros_topic_name"] for e in entries}
    assert ros_topics[f"/{ns}/gazebo/command/twist"] == f"/{pkg.name}/cmd_vel"
    assert ros_topics[text(joint_states, "topic")] == "/joint_states"  # robot_state_publisher's


# ------------------------------------------------------------------ the model

@pytest.mark.parametrize("frame", FRAMES)
def test_expanded_model_passes_check_urdf(expanded, frame):
    proc = subprocess.run([str(CHECK_URDF), str(expanded[frame])],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Successfully Parsed XML" in proc.stdout


@pytest.mark.parametrize("frame", FRAMES)
def test_validate_is_quiet(packages, frame):
    from reedtool.checks.registry import all_rules

    assert "validate" in SUBCOMMANDS
    # "All families" includes the controller cross-check (C4xx) of the velocity controller.
    assert any(r.code.startswith("C4") for r in all_rules())
    code, output = run_cli("validate", model_file(packages[frame]), "--format", "json")
    report = json.loads(output)
    assert [f for f in report["findings"] if f["severity"] in ("error", "warning")] == [], output
    assert code == 0


def test_validate_cross_checks_the_generated_controller(expanded, tmp_path):
    """The quiet verdict above includes the controller cross-check: it does fire on a
    generated model whose velocity controller is edited against its motors."""
    source = expanded["quad-x"].read_text()
    root = etree.fromstring(source.encode())
    entries = plugins(root, VELOCITY_CONTROL)[0].findall("rotorConfiguration/rotor")
    entries[1].find("direction").text = "-1"                    # motor 1 turns ccw (+1)
    entries[2].find("forceConstant").text = "9.5e-06"           # motorConstant 8.54858e-06
    broken = tmp_path / "broken.urdf"
    broken.write_bytes(etree.tostring(root))
    code, output = run_cli("validate", broken, "--format", "json", "--select", "C")
    assert sorted(f["code"] for f in json.loads(output)["findings"]) == ["C404", "C407"]
    assert code == 1


@pytest.mark.parametrize("frame", FRAMES)
def test_hover_test_passes(packages, frame):
    assert "hover-test" in SUBCOMMANDS, "reedtool hover-test is not registered in reedtool/cli.py"
    code, output = run_cli("hover-test", model_file(packages[frame]))
    assert code == 0, output


def _urdf_tables(urdf: Path):
    """The expanded URDF read with lxml only: joints, motor plugins, the controller table."""
    root = etree.parse(str(urdf)).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}
    children = {j.find("child").get("link") for j in joints.values()}
    roots = [link.get("name") for link in root.findall("link") if link.get("name") not in children]
    motors = {int(text(p, "motorNumber")): p for p in plugins(root, MOTOR_MODEL)}
    control = plugins(root, VELOCITY_CONTROL)
    assert len(control) == 1
    return root, joints, roots, motors, control[0]


@pytest.mark.parametrize("frame", FRAMES)
def test_rotor_configuration_equals_motor_geometry(expanded, frame):
    """What gz-sim's MulticopterVelocityControl will compute from the generated table (angle
    and arm of each named joint in comLinkName, Common.cc) is the frame's PX4 geometry, and
    every constant and direction equals its motor's."""
    bearings_deg, spins, radial = PX4[frame]
    n = len(spins)
    root, joints, roots, motors, control = _urdf_tables(expanded[frame])
    assert sorted(motors) == list(range(n))
    com_link = text(control, "comLinkName")
    assert roots == [com_link]                       # the body frame is the model's root
    entries = control.findall("rotorConfiguration/rotor")
    assert len(entries) == n

    allocation = np.zeros((4, n))                    # gz-sim's calculateAllocationMatrix
    for i, entry in enumerate(entries):
        motor = motors[i]                            # entry i drives motorNumber i
        joint = joints[text(entry, "jointName")]
        assert text(entry, "jointName") == text(motor, "jointName")
        assert joint.get("type") == "continuous"
        assert joint.find("parent").get("link") == com_link
        assert joint.find("child").get("link") == text(motor, "linkName")
        assert [float(v) for v in joint.find("axis").get("xyz").split()] == [0, 0, 1]
        assert [float(v) for v in joint.find("origin").get("rpy").split()] == [0, 0, 0]
        x, y, _z = (float(v) for v in joint.find("origin").get("xyz").split())
        angle_rad, arm_m = math.atan2(y, x), math.hypot(x, y)

        expected_angle = -math.radians(bearings_deg[i])   # clockwise bearing -> from +x to +y
        # Positions written with 10 significant digits (fmt_number): atan2 and hypot of
        # them are within ~1e-10 of the layout's; 1e-9 holds, a wrong slot is >= 30 deg off.
        assert math.remainder(angle_rad - expected_angle, 2 * math.pi) == pytest.approx(0, abs=1e-9)
        assert arm_m == pytest.approx(ARM_LENGTH_M * radial, rel=1e-9)
        assert text(motor, "turningDirection") == spins[i]
        assert int(text(entry, "direction")) == (1 if spins[i] == "ccw" else -1)
        k_f = float(text(entry, "forceConstant"))
        k_m = float(text(entry, "momentConstant"))
        assert k_f == float(text(motor, "motorConstant"))
        assert k_m == float(text(motor, "momentConstant"))
        direction = int(text(entry, "direction"))
        allocation[:, i] = [math.sin(angle_rad) * arm_m * k_f, -math.cos(angle_rad) * arm_m * k_f,
                            -direction * k_f * k_m, k_f]
    assert np.linalg.matrix_rank(allocation, tol=1e-9 * np.abs(allocation).max()) == 4
    # Equal rotor speeds give thrust and no torque: the controller's hover is level.
    wrench = allocation @ np.ones(n)
    # Mirrored rotors are written with the same digits (fmt_number of +-the same value),
    # so their moments cancel in pairs up to the sum's rounding (~1e-16 of the terms);
    # 1e-12 of the thrust holds that, a misplaced rotor is ~1e-1 of it.
    assert np.allclose(wrench[:3], 0, atol=1e-12 * wrench[3])


def _whole_robot(urdf: Path):
    """Total mass and inertia about the COM, summed from the URDF with lxml and numpy
    (joints at zero, no rotations in the generated model: asserted)."""
    root = etree.parse(str(urdf)).getroot()
    offset = {j.find("child").get("link"): np.array(
        [float(v) for v in j.find("origin").get("xyz").split()]) for j in root.findall("joint")}
    parent = {j.find("child").get("link"): j.find("parent").get("link")
              for j in root.findall("joint")}
    for j in root.findall("joint"):
        assert [float(v) for v in j.find("origin").get("rpy").split()] == [0, 0, 0]
    parts = []
    for link in root.findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        name, position = link.get("name"), np.zeros(3)
        while name in parent:
            position, name = position + offset[name], parent[name]
        position = position + np.array([float(v) for v in
                                        inertial.find("origin").get("xyz").split()])
        I = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        tensor = np.array([[I["ixx"], I["ixy"], I["ixz"]], [I["ixy"], I["iyy"], I["iyz"]],
                           [I["ixz"], I["iyz"], I["izz"]]])
        parts.append((float(inertial.find("mass").get("value")), position, tensor))
    mass = sum(m for m, _, _ in parts)
    com = sum(m * p for m, p, _ in parts) / mass
    inertia = sum(I + m * (np.dot(p - com, p - com) * np.eye(3) - np.outer(p - com, p - com))
                  for m, p, I in parts)
    return mass, com, inertia


@pytest.mark.parametrize("frame", ["quad-x", "hex-plus", "y6"])
def test_controller_gains_follow_mass_and_inertia(expanded, frame):
    """gz-sim divides velocityGain by the mass and the attitude/rate gains by the inertia it
    sums from the links; the generated gains make those quotients RotorS firefly's (mass
    1.56779 kg, inertia 0.0347563 0.0458929 0.0977, gains 4.7 / 3 3 0.15 / 0.52 0.52 0.18, lee_controller_firefly.yaml's)."""
    import pinocchio as pin

    mass, com, inertia = _whole_robot(expanded[frame])
    # A free-flyer root, as in flight: with a fixed base Pinocchio folds the body (fixed to
    # the root) into the universe and leaves it out of the total.
    model = pin.buildModelFromUrdf(str(expanded[frame]), pin.JointModelFreeFlyer())
    data = model.createData()
    assert pin.computeTotalMass(model) == pytest.approx(mass, rel=1e-12)   # the sum is right
    assert np.allclose(pin.centerOfMass(model, data, pin.neutral(model)), com, atol=1e-12)
    assert np.allclose(com[:2], 0, atol=1e-12)     # COM over comLinkName's origin
    _, _, _, _, control = _urdf_tables(expanded[frame])
    gains = {tag: np.array([float(v) for v in text(control, tag).split()])
             for tag in ("velocityGain", "attitudeGain", "angularRateGain")}
    firefly_I = np.array([0.0347563, 0.0458929, 0.0977])
    # Gains are printed with 4 significant digits (5e-4 relative) and scaled with the
    # spec's mass estimate; 2e-3 holds both, a gain not scaled with mass is 30 % off.
    assert gains["velocityGain"] / mass == pytest.approx(np.full(3, 4.7 / 1.56779), rel=2e-3)
    # The context estimates the inertia with the rotors' real mass, the links carry RotorS'
    # slowed-down rotor inertia: a few percent apart.
    assert gains["attitudeGain"] / np.diag(inertia) == pytest.approx(
        np.array([3, 3, 0.15]) / firefly_I, rel=0.05)
    assert gains["angularRateGain"] / np.diag(inertia) == pytest.approx(
        np.array([0.52, 0.52, 0.18]) / firefly_I, rel=0.05)


def test_the_rotor_table_is_the_one_source(packages, tmp_path):
    """Flipping one rotor in the xacro's rotor_table flips its motor and its controller
    entry together: they cannot disagree (validate: no controller finding)."""
    import shutil

    pkg = tmp_path / packages["quad-x"].name
    shutil.copytree(packages["quad-x"], pkg)
    xacro_file = model_file(pkg)
    source = xacro_file.read_text()
    row = "(0, 'front_right', 'ccw',"
    assert source.count(row) == 1
    xacro_file.write_text(source.replace(row, "(0, 'front_right', 'cw',"))
    urdf = tmp_path / "flipped.urdf"
    assert run_cli("expand", xacro_file, "-o", urdf)[0] == 0
    _, _, _, motors, control = _urdf_tables(urdf)
    assert text(motors[0], "turningDirection") == "cw"
    assert text(control.findall("rotorConfiguration/rotor")[0], "direction") == "-1"
    code, output = run_cli("validate", xacro_file, "--format", "json")
    codes = [f["code"] for f in json.loads(output)["findings"]]
    assert not [c for c in codes if c.startswith("C")], output
    assert codes, "an unbalanced quad should still be reported by the rotor rules"


# ------------------------------------------------------------------ --sim choices

def test_sim_classic_keeps_the_rotors_package_for_ros2(tmp_path):
    code, output = run_cli("new-package", "classic2", "--ros", "2", "--sim", "classic",
                           "-o", tmp_path)
    assert code == 0, output
    pkg = tmp_path / "classic2"
    assert (pkg / "urdf" / "mav_generic_odometry_sensor.gazebo").is_file()
    assert not (pkg / "worlds").exists()
    from catkin_pkg.package import parse_package

    deps = {d.name for d in parse_package(str(pkg / "package.xml")).exec_depends}
    assert "rotors_description" in deps and "ros_gz_sim" not in deps


def test_spec_file_can_choose_the_simulator(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text("ros: 2\nsim: classic\n")
    code, output = run_cli("new-package", "from_spec", "--spec", spec, "-o", tmp_path)
    assert code == 0, output
    assert (tmp_path / "from_spec" / "urdf" / "from_spec_base.xacro").is_file()


@pytest.mark.parametrize("args,spec_text", [
    (["--sim", "gz", "--ros", "1"], None),                        # gz-sim is ROS 2 only
    (["--ros", "1"], "sim: gz\n"),                                # ... from the spec too
    (["--sim", "gz", "--ros", "2", "--frame", "diff-drive"], None),  # multirotors only
    (["--ros", "2"], "sim: gazebo\n"),                            # unknown simulator
])
def test_refusals_are_one_line_and_write_nothing(tmp_path, args, spec_text):
    out = tmp_path / "out"
    out.mkdir()
    if spec_text is not None:
        spec = tmp_path / "s.yaml"
        spec.write_text(spec_text)
        args = [*args, "--spec", str(spec)]
    code, output = run_cli("new-package", "nope", *args, "-o", out)
    assert code == 2
    assert len(output.strip().splitlines()) == 1
    if spec_text is not None:
        assert "s.yaml" in output                                 # names the file
    assert list(out.iterdir()) == []


def test_body_mesh_resolves_through_package_uri(tmp_path):
    from reedtool.io.stl import stl_bytes

    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([0.25, 0.25, 0.06])
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    stl = tmp_path / "body.stl"
    stl.write_bytes(stl_bytes(corners[np.array(faces)]))
    code, output = run_cli("new-package", "meshy_gz", "--ros", "2", "--mesh", stl,
                           "--mesh-units", "m", "-o", tmp_path)
    # Drawn from its corner: about the CAD origin the rotors cannot hold its COM level.
    assert code == 2 and "cannot hold this body level" in output and "--center com" in output
    code, output = run_cli("new-package", "meshy_gz", "--ros", "2", "--mesh", stl,
                           "--mesh-units", "m", "--center", "com", "-o", tmp_path)
    assert code == 0, output
    pkg = tmp_path / "meshy_gz"
    assert "package://meshy_gz/meshes/body.stl" in model_file(pkg).read_text()
    code, output = run_cli("validate", model_file(pkg), "--format", "json")
    assert code == 0, output
