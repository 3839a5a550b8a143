"""new-package --autopilot: every multirotor frame validates clean against its own autopilot file."""

from __future__ import annotations

import pytest

from reedtool.checks.runner import Selection, run_checks
from reedtool.workflows.new_package import model_path, new_package
from reedtool.flightstack import ardupilot, px4
from reedtool.io.loader import load_robot
from reedtool.generate.airframes import MULTIROTOR_FRAMES
from reedtool.generate.package_spec import build_spec


def _generate(tmp_path, frame: str, autopilot: str, ros: int = 2, sim: str | None = None):
    name = f"ap_{frame.replace('-', '_')}_{autopilot}"
    spec = build_spec(name, frame=frame, ros=ros, flags={}, sim=sim)
    result = new_package(spec, tmp_path, autopilot=autopilot)
    # The rotor table: ardupilot/NAME.parm, px4/airframes/NNNN_gz_NAME (gz: with the model
    # in PX4's layout beside it) or px4/airframe_gazebo-classic_NAME (Classic).
    extra = [f for f in result.files if f.parts[0] == autopilot and (
        f.suffix == ".parm" or "airframes" in f.parts or f.name.startswith("airframe"))]
    assert len(extra) == 1
    return result.target / model_path(spec), result.target / extra[0], spec


@pytest.mark.parametrize("frame", MULTIROTOR_FRAMES)
@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_generated_autopilot_file_is_clean(tmp_path, frame, autopilot):
    model, table, _spec = _generate(tmp_path, frame, autopilot)
    params = px4.load_px4_params(table) if autopilot == "px4" else ardupilot.load_parm(table)
    findings = run_checks(load_robot(model), Selection(), flight_params=[params])
    assert [f for f in findings if f.severity != "info"] == []
    # PX4: only the hover-throttle comparison, no position offset, no KM mismatch; a
    # hexacopter's alternating spins also get the fault-tolerance information (R350).
    # ArduPilot (gz): its plugin drives every rotor through LiftDrag blades, whose
    # constants validate estimates (R317, info, one per rotor).
    rotors = len(load_robot(model).joints) - 1          # base_joint + one joint per rotor
    expected = (["C421"] if autopilot == "px4" else ["R317"] * rotors) + (
        ["R350"] if frame.startswith("hex") else [])
    assert sorted(f.code for f in findings) == sorted(expected)
    if autopilot == "px4":
        assert px4.out_of_range(params) == []               # PX4's documented ranges
        assert params.rotor_count == len(params.rotors()) > 0


def test_rotors_classic_package_with_px4(tmp_path):
    """A RotorS (Gazebo Classic) package gets a Classic airframe: PX4's simulator_mavlink
    outputs (PWM_MAIN_FUNC), no SIM_GZ parameter (those start the gz bridge), so validate
    finds no simulator mismatch (C435) and no gz command-range rule applies; the RotorS
    interface declares no control channels, so there is no command range to compare."""
    model, table, _spec = _generate(tmp_path, "quad-x", "px4", ros=1, sim="classic")
    params = px4.load_px4_params(table)
    assert params.simulator().simulator == "classic"
    assert not any(name.startswith("SIM_GZ") for name in params.values)
    assert [params.get(f"PWM_MAIN_FUNC{k}").value for k in range(1, 5)] == [101, 102, 103, 104]
    findings = run_checks(load_robot(model), Selection(select=("C",)), flight_params=[params])
    assert sorted(f.code for f in findings) == []


def test_quad_x_airframe_values_by_hand(tmp_path):
    _model, table, spec = _generate(tmp_path, "quad-x", "px4")
    params = px4.load_px4_params(table)
    arm = spec["arm_length"]
    # Motor 1 (CA rotor 0) front-right ccw: FRD (+L, +L), KM +momentConstant.
    assert params.get("CA_ROTOR0_PX").value == pytest.approx(arm, abs=1e-6)
    assert params.get("CA_ROTOR0_PY").value == pytest.approx(arm, abs=1e-6)
    assert params.get("CA_ROTOR0_KM").value == pytest.approx(spec["moment_constant"])
    # Written as decimal text and parsed: exact up to the printed digits; default rel
    # 1e-6 covers a %g-style print.
    assert params.get("CA_ROTOR2_KM").value == pytest.approx(-spec["moment_constant"])
    assert params.get("SIM_GZ_EC_MAX1").value == pytest.approx(spec["max_rot_velocity"])


def test_octo_x_for_ardupilot_takes_its_spins(tmp_path):
    # ArduPilot's octa X spins every rotor the other way from the catalogue's PX4 octo X.
    _model, table, spec = _generate(tmp_path, "octo-x", "ardupilot")
    params = ardupilot.load_parm(table)
    assert (params.get("FRAME_CLASS").value, params.get("FRAME_TYPE").value) == (3, 1)
    assert spec.frame.rotors[0].direction == "cw"          # AP motor 1 at 22.5°: CW


@pytest.mark.parametrize("frame", ["quad-x", "hex-x", "octo-x"])
def test_ardupilot_gz_package_is_driven_by_the_plugin(tmp_path, frame):
    """--sim gz --autopilot ardupilot: the rotors are ArduPilotPlugin controls on channel =
    motor number whose SERVO(channel+1)_FUNCTION is the AP motor at that rotor's bearing
    (C431/C432 clean above), spinning as the .parm's frame spins them, with the constants
    the catalogue gives (R317's estimate from the blades, to round-off)."""
    from reedtool.physics.rotors import discover_rotors

    model, table, spec = _generate(tmp_path, frame, "ardupilot")
    rotors = discover_rotors(load_robot(model))
    assert {r.kind for r in rotors} == {"ardupilot"}
    assert sorted(r.channel for r in rotors) == sorted(s.motor_number for s in spec.frame.rotors)
    spins = {s.motor_number: s.direction for s in spec.frame.rotors}
    for rotor in rotors:
        assert rotor.direction == spins[rotor.channel]
        assert rotor.motor_constant == pytest.approx(spec["motor_constant"], rel=1e-12)
        assert rotor.moment_constant == pytest.approx(spec["moment_constant"], rel=1e-12)
        assert rotor.max_rot_velocity_rad_s == pytest.approx(spec["max_rot_velocity"], rel=1e-12)
    text = model.read_text()
    assert 'name="gz::sim::systems::MulticopterMotorModel"' not in text
    assert 'name="gz::sim::systems::MulticopterVelocityControl"' not in text



def test_ardupilot_on_gazebo_classic_is_refused_with_the_reason(tmp_path):
    """ardupilot_gazebo's ArduPilotPlugin supports Gazebo Garden and later (its README): a
    ROS 1 / RotorS package (Gazebo Classic) would carry no plugin SITL talks to."""
    from reedtool.workflows.new_package import new_package
    from reedtool.errors import ReedtoolError

    spec = build_spec("ap_ros1", frame="quad-x", ros=1, flags={}, sim="classic")
    with pytest.raises(ReedtoolError, match="needs Gazebo Sim") as refusal:
        new_package(spec, tmp_path, autopilot="ardupilot")
    assert "--ros 2 --sim gz" in refusal.value.hint
    assert not (tmp_path / "ap_ros1").exists()


def test_ardupilot_package_readme_and_bridge_match_the_model(tmp_path):
    """The README starts SITL the way ardupilot_gazebo's README does (sim_vehicle.py with
    the JSON model) with the .parm and the address and port the model's ArduPilotPlugin
    listens on (read from the expanded model, not from the writer); the bridge offers no
    topic the model does not publish or read (no velocity controller: no cmd_vel)."""
    import re

    from lxml import etree

    from reedtool.io.xacro_expand import expand_xacro

    model, _table, spec = _generate(tmp_path, "quad-x", "ardupilot")
    package = model.parent.parent
    urdf = etree.fromstring(expand_xacro(model, {}, []).urdf_xml.encode())
    plugin = next(p for p in urdf.iter("plugin") if p.get("name") == "ArduPilotPlugin")
    addr, port = plugin.findtext("fdm_addr"), plugin.findtext("fdm_port_in")
    readme = (package / "README.md").read_text()
    assert re.search(r"sim_vehicle\.py -v ArduCopter -f JSON --add-param-file=\S*ardupilot/"
                     + spec.name + r"\.parm", readme)
    assert f"{addr}:{port}" in readme
    assert "cmd_vel" not in readme and "/enable" not in readme
    bridge = (package / "config" / f"{spec.name}_bridge.yaml").read_text()
    gz_topics = re.findall(r'gz_topic_name: "([^"]+)"', bridge)
    text = model.read_text().replace("${namespace}", spec.name)
    for topic in gz_topics:
        assert topic == "/clock" or topic in text, topic
