"""`reedtool migrate --to gz`: the port, read independently, against the original.

Every fixture is ported through the CLI; every port is loaded by libsdformat (through
Drake, tests/sdformat_oracle.py); then the written files are read with lxml (not
with the code that wrote them) and compared with the original as reedtool's loader reads
it: one motor-model system per rotor with the original motorNumber, the same total mass,
no link left without <inertial> (SDF would give it 1 kg), hover trims equal, no new
validate error. The proof itself is shown to fail on a port that differs.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli
from lxml import etree

from reedtool.io.fileio import reset_inputs
from reedtool.io.loader import load_robot

FIXTURES = Path(__file__).parent / "fixtures"
SEED_MODEL = FIXTURES / "seed000" / "reed_gazebo" / "urdf" / "mav_generic_odometry_sensor.gazebo"
SEED_ARGS = ("mav_name:=reed_quad_x", "namespace:=reed_quad_x", "enable_mavlink_interface:=true",
             "enable_ground_truth:=true", "enable_logging:=false", "log_file:=reed_quad_x",
             "wait_to_record_bag:=false")
MOTOR_SYSTEM = "gz-sim-multicopter-motor-model-system"

CASES = {
    "firefly_hex": (FIXTURES / "migrate" / "firefly_hex.xacro", ()),
    "hummingbird_plus": (FIXTURES / "upstream_shapes" / "rotors_plus_quad" / "plusquad.xacro", ()),
    "pelican_quad": (FIXTURES / "migrate" / "pelican_quad.xacro", ()),
    "neo_tilted_hex": (FIXTURES / "rotors_neo" / "neo_balanced_tilt.sdf", ()),
    "iris_px4_classic": (FIXTURES / "migrate" / "iris_classic.sdf", ()),
    "seed_quad": (SEED_MODEL, SEED_ARGS),
}


def migrate(tmp_path: Path, model: Path, args=(), *options) -> tuple[int, dict, Path]:
    reset_inputs()  # a new run, as the console script starts each (run_cli does not)
    out = tmp_path / "out"
    code, text = run_cli("migrate", model, *args, "--to", "gz", "-o", out, "--format", "json",
                         *options)
    assert code in (0, 1), text
    document = json.loads(text)
    target = Path(document["target"])
    assert_loads_in_libsdformat(target, document)
    return code, document, target


def assert_loads_in_libsdformat(target: Path, document: dict) -> None:
    """Every port a test writes is judged by libsdformat (through Drake), the library
    Gazebo Sim loads it with: the model, and the world including it by model://. A world
    libsdformat refuses must be one whose model validate calls wrong on the port (RotorS'
    firefly inertia breaks the triangle inequality, I203, in the source already: the port
    carries it and migrate says so); anything else is a port reedtool broke."""
    import sdformat_oracle

    # PX4's layout (--autopilot px4) holds the model under models/NAME, as PX4-gazebo-models
    models = target / "models" if (target / "models").is_dir() else target.parent
    model_sdf = models / target.name / "model.sdf" if models != target.parent \
        else target / "model.sdf"
    assert sdformat_oracle.libsdformat_error(model_sdf, [models]) is None
    world = target / "worlds" / f"{target.name}.sdf"
    error = sdformat_oracle.libsdformat_error(world, [models])
    port_errors = [f for f in document["proof"]["side_by_side"]["findings"]["port"]
                   if f.split(" ")[1].startswith("error")]
    assert error is None or port_errors, (world, error)


def original_robot(model: Path, args=()):
    return load_robot(model, dict(a.split(":=", 1) for a in args), [])


def motor_numbers(robot) -> dict[str, int]:
    """jointName -> motorNumber of the original's velocity motor plugins."""
    out = {}
    for _block, plugin in robot.plugins():
        if plugin.library in ("rotors_gazebo_motor_model", "gazebo_motor_model") and \
                (plugin.param("motorType") or "velocity") == "velocity":
            out[plugin.param("jointName")] = int(plugin.param("motorNumber"))
    return out


@pytest.fixture(scope="module", params=sorted(CASES))
def ported(request, tmp_path_factory):
    model, args = CASES[request.param]
    code, document, target = migrate(tmp_path_factory.mktemp(request.param), model, args)
    return request.param, model, args, code, document, target


def test_the_port_reads_back_equal(ported):
    name, _model, _args, code, document, _target = ported
    proof = document["proof"]
    assert (code, proof["differences"]) == (0, []), name
    # Everything was compared: each section holds numbers (a vacuous "equal" is a bug).
    # (findings: a clean model has none to compare.)
    for section in ("links", "joints", "mass", "rotors", "trim"):
        assert proof["compared"].get(section, 0) > 0, section


def test_one_motor_system_per_rotor_with_the_original_number(ported):
    _name, model, args, _code, _document, target = ported
    sdf = etree.parse(str(target / "model.sdf"))
    assert sdf.getroot().get("version") == "1.9"
    systems = sdf.findall(f".//plugin[@filename='{MOTOR_SYSTEM}']")
    written = {p.findtext("jointName"): int(p.findtext("actuator_number")) for p in systems}
    assert len(systems) == len(written)
    assert written == motor_numbers(original_robot(model, args))
    # Only gz systems remain in the model: no Classic library survives the port.
    for plugin in sdf.iter("plugin"):
        assert not plugin.get("filename", "").startswith("lib"), plugin.get("filename")


def test_mass_and_links_as_sdf_reads_them(ported):
    """Total mass summed from the written <mass> elements equals Pinocchio's mass of the
    original (an independent sum: only the order of addition differs, a few ulps, so
    1e-12); and no link lacks <inertial>, which SDF would fill with 1 kg."""
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

    _name, model, args, _code, _document, target = ported
    sdf = etree.parse(str(target / "model.sdf"))
    links = sdf.findall("./model/link")
    assert links and all(link.find("inertial/mass") is not None for link in links)
    total = sum(float(link.findtext("inertial/mass")) for link in links)
    expected = whole_robot_pinocchio(original_robot(model, args)).mass_kg
    assert total == pytest.approx(expected, rel=1e-12)


def test_hover_trim_equal_and_no_new_error(ported):
    """A second computation beside the proof's: trim both robots as validate does."""
    from reedtool.checks.runner import run_checks
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, lift_rotors
    from reedtool.physics.trim import solve_trim

    _name, model, args, _code, _document, target = ported
    robots = [original_robot(model, args), load_robot(target / "model.sdf", {}, [])]
    trims = []
    for robot in robots:
        props = whole_robot_pinocchio(robot)
        trims.append(solve_trim(props.mass_kg, props.com_m, lift_rotors(discover_rotors(robot))))
    assert trims[0].feasible and trims[1].feasible
    # 1e-9 relative: the inputs are the same floats (written shortest-roundtrip); only
    # the summation order of the mass properties may differ, ~1e-15.
    np.testing.assert_allclose(trims[1].thrust_N, trims[0].thrust_N, rtol=1e-9, atol=0)
    np.testing.assert_allclose(trims[1].omega_rad_s, trims[0].omega_rad_s, rtol=1e-9, atol=0)
    errors = [{f.code for f in run_checks(robot) if f.severity == "error"} for robot in robots]
    assert errors[1] <= errors[0]


def test_every_source_element_has_a_row(ported):
    """Each plugin of the original appears in the report, mapped or dropped with a reason."""
    _name, model, args, _code, document, _target = ported
    robot = original_robot(model, args)
    reported = {row["element"] for row in document["elements"]}
    for _block, plugin in robot.plugins():
        assert any(f"plugin {plugin.name} " in element for element in reported), plugin.name
    assert all(row["why"] for row in document["elements"])


# ------------------------------------------------------------------ seed quad details

def test_seed_quad_folds_the_massless_root_and_carries_constants(tmp_path):
    code, document, target = migrate(tmp_path, SEED_MODEL, SEED_ARGS)
    assert code == 0
    sdf = etree.parse(str(target / "model.sdf"))
    # base_link has no <inertial> in the URDF: base_link_inertia is folded into it.
    names = [link.get("name") for link in sdf.findall("./model/link")]
    assert "reed_quad_x/base_link_inertia" not in names
    frame = sdf.find("./model/frame[@name='reed_quad_x/base_link_inertia']")
    assert frame is not None and frame.get("attached_to") == "reed_quad_x/base_link"
    assert sdf.findtext("./model/link[@name='reed_quad_x/base_link']/inertial/mass") == "1.5"
    # Constants as the xacro wrote them, the slowdown once (rotor inertia unscaled again).
    motor = sdf.find(f".//plugin[@filename='{MOTOR_SYSTEM}']")
    assert motor.findtext("motorConstant") == "8.54858e-06"
    assert motor.findtext("rotorVelocitySlowdownSim") == "10"
    assert sdf.findtext("./model/link[@name='reed_quad_x/rotor_0']/inertial/inertia/iyy") == \
        "4.170416666666668e-05"
    # The IMU: a sensor on imu_link, the world runs the IMU system; white noise density
    # becomes a per-sample deviation at the sensor's 250 Hz: 0.0003394 * sqrt(250).
    sensor = sdf.find("./model/link[@name='reed_quad_x/imu_link']/sensor[@type='imu']")
    assert sensor is not None
    assert float(sensor.findtext("imu/angular_velocity/x/noise/stddev")) == \
        pytest.approx(0.0003394 * math.sqrt(250.0), rel=1e-15)
    world = etree.parse(str(target / "worlds" / "reed_quad_x.sdf"))
    systems = {p.get("filename") for p in world.iter("plugin")}
    assert {"gz-sim-physics-system", "gz-sim-imu-system"} <= systems
    assert world.findtext(".//include/uri") == "model://reed_quad_x"
    assert etree.parse(str(target / "model.config")).findtext("sdf") == "model.sdf"
    # MAVLink dropped with its reason; its R312 goes with it (a note, not hidden).
    rows = {row["element"]: row for row in document["elements"]}
    mavlink = next(row for element, row in rows.items() if "mavlink_interface" in element)
    assert mavlink["action"] == "dropped" and "gz bridge" in mavlink["why"]
    assert any(note.startswith("R312") for note in document["proof"]["notes"])
    # The missing body mesh stays missing on both sides: S115 carried, not hidden.
    findings = document["proof"]["side_by_side"]["findings"]
    assert any(f.startswith("S115") for f in findings["original"])
    assert any(f.startswith("S115") for f in findings["port"])


def test_meshes_are_copied_and_referenced_relatively(tmp_path):
    model = FIXTURES / "px4_gz" / "models" / "x500_base" / "model.sdf"
    code, document, target = migrate(tmp_path, model)
    assert code == 0, document["proof"]["differences"]
    sdf = etree.parse(str(target / "model.sdf"))
    uris = {u.text for u in sdf.iter("uri")}
    assert uris == {"meshes/frame.stl"}
    assert (target / "meshes" / "frame.stl").read_bytes() == \
        (model.parent / "meshes" / "frame.stl").read_bytes()


# ------------------------------------------------------------------ spins and unknowns

@pytest.mark.parametrize("model, flipped_joint", [
    (FIXTURES / "migrate" / "firefly_hex_flipped.xacro", "firefly/rotor_3_joint"),
    (FIXTURES / "migrate" / "iris_classic_flipped.sdf", "rotor_1_joint"),
])
def test_a_flipped_spin_is_still_reported_on_the_port(tmp_path, model, flipped_joint):
    from reedtool.checks.runner import run_checks

    code, document, target = migrate(tmp_path, model)
    assert code == 0, document["proof"]["differences"]
    clean = original_robot(Path(str(model).replace("_flipped", "")))
    clean_spin = next(p.param("turningDirection") for _b, p in clean.plugins()
                      if p.param("jointName") == flipped_joint)
    sdf = etree.parse(str(target / "model.sdf"))
    ported_spin = next(p.findtext("turningDirection") for p in sdf.iter("plugin")
                       if p.findtext("jointName") == flipped_joint)
    assert {clean_spin, ported_spin} == {"ccw", "cw"}
    port = load_robot(target / "model.sdf", {}, [])
    assert "R304" in {f.code for f in run_checks(port) if f.severity == "error"}


def test_an_unknown_plugin_is_kept_out_and_listed(tmp_path):
    code, document, target = migrate(tmp_path, FIXTURES / "migrate" / "firefly_hex_hector.xacro")
    assert code == 0
    unknown = [row for row in document["elements"] if row["action"] == "unknown"]
    assert [row["element"] for row in unknown] == [
        "plugin quadrotor_aerodynamics (libhector_gazebo_quadrotor_aerodynamics.so)"]
    assert "no gz-sim counterpart" in unknown[0]["why"]
    assert "libhector" not in (target / "model.sdf").read_text()


def test_position_servos_become_joint_position_controllers(tmp_path):
    model = FIXTURES / "rotors_neo" / "omav_tilt_servos.sdf"
    code, document, target = migrate(tmp_path, model)
    assert code == 0, document["proof"]["differences"]
    servos = [p for _b, p in original_robot(model).plugins() if p.param("motorType") == "position"]
    sdf = etree.parse(str(target / "model.sdf"))
    controllers = sdf.findall(".//plugin[@filename='gz-sim-joint-position-controller-system']")
    assert sorted(c.findtext("joint_name") for c in controllers) == \
        sorted(p.param("jointName") for p in servos)
    assert {c.findtext("p_gain") for c in controllers} == {"5"}


# ------------------------------------------------------------------ autopilot, controller

def test_px4_airframe_matches_the_port(tmp_path):
    """--autopilot px4: validate --airframe on the port finds no flight-stack error, and
    each SIM_GZ_EC_FUNC output is the actuator_number + 1 of a motor system."""
    from reedtool.checks.runner import run_checks
    from reedtool.flightstack.px4 import load_px4_params

    model = FIXTURES / "migrate" / "firefly_hex.xacro"
    code, _document, target = migrate(tmp_path, model, (), "--autopilot", "px4")
    assert code == 0
    airframe = target / "airframes" / "4900_gz_firefly"     # PX4-gazebo-models' layout
    text = airframe.read_text()
    outputs = sorted(int(line.split()[2][len("SIM_GZ_EC_FUNC"):]) for line in text.splitlines()
                     if line.startswith("param set-default SIM_GZ_EC_FUNC"))
    assert outputs == [n + 1 for n in sorted(motor_numbers(original_robot(model)).values())]
    # The motors listen where PX4's gz bridge publishes (/<instance>/command/motor_speed).
    sdf = etree.parse(str(target / "models" / "firefly" / "model.sdf"))
    for motor in sdf.findall(f".//plugin[@filename='{MOTOR_SYSTEM}']"):
        assert motor.findtext("commandSubTopic") == "command/motor_speed"
        assert motor.find("robotNamespace") is None
    port = load_robot(target / "models" / "firefly" / "model.sdf", {}, [])
    codes = {f.code for f in run_checks(port, flight_params=[load_px4_params(airframe)])
             if f.severity == "error"}
    assert not {c for c in codes if c.startswith("C")}, codes


def test_velocity_control_lists_every_rotor(tmp_path):
    from reedtool.checks.runner import run_checks

    model = FIXTURES / "migrate" / "pelican_quad.xacro"
    code, _document, target = migrate(tmp_path, model, (), "--velocity-control")
    assert code == 0
    sdf = etree.parse(str(target / "model.sdf"))
    control = sdf.find(".//plugin[@filename='gz-sim-multicopter-control-system']")
    rotors = control.findall("rotorConfiguration/rotor")
    assert sorted(r.findtext("jointName") for r in rotors) == sorted(motor_numbers(
        original_robot(model)))
    # The controller rules compare the table with the motor models: nothing to report.
    port = load_robot(target / "model.sdf", {}, [])
    assert not [f for f in run_checks(port) if f.code.startswith("C") and f.severity != "info"]


# ------------------------------------------------------------------ refusals and failures

def test_an_existing_output_is_refused_without_force(tmp_path):
    model = FIXTURES / "migrate" / "pelican_quad.xacro"
    migrate(tmp_path, model)
    sdf = tmp_path / "out" / "pelican" / "model.sdf"
    before = sdf.read_bytes()
    reset_inputs()
    code, text = run_cli("migrate", model, "--to", "gz", "-o", tmp_path / "out")
    assert code == 2 and "exists and is not empty" in text and "--force" in text
    assert sdf.read_bytes() == before
    reset_inputs()
    code, _text = run_cli("migrate", model, "--to", "gz", "-o", tmp_path / "out", "--force")
    assert code == 0


def test_bad_input_is_exit_2(tmp_path):
    code, text = run_cli("migrate", tmp_path / "missing.urdf", "--to", "gz", "-o", tmp_path)
    assert code == 2 and "not found" in text
    code, text = run_cli("migrate", FIXTURES / "migrate" / "pelican_quad.xacro", "--to", "gz",
                         "-o", tmp_path, "--name", "bad name")
    assert code == 2 and "--name" in text


def test_the_proof_fails_on_a_port_that_differs(tmp_path, monkeypatch):
    """A writer that loses the spin direction: the proof lists it and exits 1."""
    from reedtool.port import gz_port

    monkeypatch.setattr(gz_port, "GZ_MOTOR_PARAMS",
                        tuple(p for p in gz_port.GZ_MOTOR_PARAMS if p != "turningDirection"))
    code, document, _target = migrate(tmp_path, FIXTURES / "migrate" / "pelican_quad.xacro")
    assert code == 1
    lost = {(d["section"], d["quantity"]) for d in document["proof"]["differences"]}
    assert ("rotors", "direction") in lost and ("rotors", "turning_sign") in lost


def test_the_proof_catches_an_edited_constant(tmp_path):
    """Read back a port whose motorConstant was changed in the last digit."""
    from reedtool.workflows.migration import MigrateRequest, prove
    from reedtool.port.gz_port import plan_port

    model = FIXTURES / "migrate" / "pelican_quad.xacro"
    _code, _document, target = migrate(tmp_path, model)
    sdf = target / "model.sdf"
    sdf.write_text(sdf.read_text().replace("<motorConstant>9.9865e-06<", "<motorConstant>9.9866e-06<", 1))
    robot = original_robot(model)
    proof = prove(robot, sdf, plan_port(robot, "pelican"), MigrateRequest(model, tmp_path))
    changed = {(d.section, d.quantity) for d in proof.differences}
    assert ("rotors", "motor_constant") in changed


# ------------------------------------------------------------------ ArduPilot

@pytest.mark.parametrize("model, args", [
    (FIXTURES / "migrate" / "iris_classic.sdf", ()),
    (FIXTURES / "migrate" / "pelican_quad.xacro", ()),
    (SEED_MODEL, SEED_ARGS),
])
def test_ardupilot_drives_the_port(tmp_path, model, args):
    """--autopilot ardupilot: ArduPilotPlugin channels are the original motor numbers,
    multipliers carry the spin, blades give the motor constants back (a hand sum of the
    LiftDrag formula), and validate --autopilot-params finds no flight-stack error on
    either side with the written .parm."""
    from reedtool.checks.runner import run_checks
    from reedtool.flightstack.ardupilot import load_parm

    code, document, target = migrate(tmp_path, model, args, "--autopilot", "ardupilot")
    assert code == 0, document["proof"]["differences"]
    sdf = etree.parse(str(target / "model.sdf"))
    assert not sdf.findall(f".//plugin[@filename='{MOTOR_SYSTEM}']")  # no double thrust
    original = original_robot(model, args)
    numbers = motor_numbers(original)
    spins = {p.param("jointName"): p.param("turningDirection") for _b, p in original.plugins()
             if p.param("jointName") in numbers}
    constants = {p.param("jointName"): (float(p.param("motorConstant")),
                                        float(p.param("momentConstant")))
                 for _b, p in original.plugins() if p.param("jointName") in numbers}
    controls = sdf.findall(".//plugin[@name='ArduPilotPlugin']/control")
    assert {c.findtext("jointName"): int(c.get("channel")) for c in controls} == numbers
    for c in controls:   # rotor joints turn about +z: the multiplier's sign is the spin
        sign = 1 if float(c.findtext("multiplier")) > 0 else -1
        assert {1: "ccw", -1: "cw"}[sign] == spins[c.findtext("jointName")]
    link_of = {j.name: j.child for j in original.joints}
    for joint, (k_f, k_m) in constants.items():
        blades = [p for p in sdf.iter("plugin") if p.get("filename") == "gz-sim-lift-drag-system"
                  and p.findtext("link_name") == link_of[joint]]
        assert len(blades) == 2
        lift = drag_torque = 0.0
        for b in blades:
            r = np.linalg.norm([float(v) for v in b.findtext("cp").split()])
            q = 0.5 * float(b.findtext("air_density")) * r * r * float(b.findtext("area"))
            lift += q * float(b.findtext("cla")) * float(b.findtext("a0"))
            drag_torque += q * float(b.findtext("cda")) * float(b.findtext("a0")) * r
        # Written shortest-roundtrip, recomputed in another order: a few ulps, 1e-12.
        assert lift == pytest.approx(k_f, rel=1e-12)
        assert drag_torque / lift == pytest.approx(k_m, rel=1e-12)
    parm = target / "ardupilot" / f"{target.name}.parm"
    params = [load_parm(parm)]
    port = load_robot(target / "model.sdf", {}, [])
    for robot in (original, port):
        errors = {f.code for f in run_checks(robot, flight_params=params)
                  if f.severity == "error" and f.code.startswith("C")}
        assert not errors, errors


def test_ardupilot_refuses_a_layout_it_has_no_frame_for(tmp_path):
    """RotorS' firefly spins every rotor the other way from ArduPilot's HEXA/X."""
    code, text = run_cli("migrate", FIXTURES / "migrate" / "firefly_hex.xacro", "--to", "gz",
                         "-o", tmp_path, "--autopilot", "ardupilot")
    assert code == 2 and "no ArduPilot frame" in text
    assert not any(tmp_path.iterdir())


# ------------------------------------------------------------------ the ROS 2 form

def test_urdf_form_is_the_same_vehicle_with_gz_systems(tmp_path):
    """--urdf: check_urdf (urdfdom) parses it; its rotors are the gz motor systems with the
    original numbers and spins; its hover trim equals the original's (to 1e-9)."""
    import shutil
    import subprocess

    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, lift_rotors
    from reedtool.physics.trim import solve_trim

    code, _document, target = migrate(tmp_path, SEED_MODEL, SEED_ARGS, "--urdf")
    assert code == 0
    urdf = target / "urdf" / "reed_quad_x.urdf"
    check_urdf = shutil.which("check_urdf")
    if check_urdf is not None:
        done = subprocess.run([check_urdf, str(urdf)], capture_output=True, text=True)
        assert done.returncode == 0, done.stdout + done.stderr
    text = urdf.read_text()
    assert "librotors" not in text
    original, ported = original_robot(SEED_MODEL, SEED_ARGS), load_robot(urdf, {}, [])
    rotors = {r.joint: r for r in discover_rotors(ported)}
    assert {r.kind for r in rotors.values()} == {"gz"}
    for rotor in discover_rotors(original):
        assert (rotors[rotor.joint].motor_number, rotors[rotor.joint].direction) == \
            (rotor.motor_number, rotor.direction)
    trims = []
    for robot in (original, ported):
        props = whole_robot_pinocchio(robot)
        trims.append(solve_trim(props.mass_kg, props.com_m, lift_rotors(discover_rotors(robot))))
    np.testing.assert_allclose(trims[1].thrust_N, trims[0].thrust_N, rtol=1e-9, atol=0)
