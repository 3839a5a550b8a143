"""`reedtool hover-test` end to end: the seed quadrotor, generated frames, broken variants."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from rotors_builder import multirotor_urdf

from reedtool.io.loader import load_robot

TESTS = Path(__file__).parent
SEED_PACKAGE = TESTS / "fixtures" / "seed000" / "reed_gazebo"
SEED_MODEL_NAME = "mav_generic_odometry_sensor.gazebo"
SEED_MODEL = SEED_PACKAGE / "urdf" / SEED_MODEL_NAME
LAUNCH_ARGS = {"mav_name": "reed_quad_x", "namespace": "reed_quad_x",
               "enable_mavlink_interface": "true", "enable_ground_truth": "true",
               "enable_logging": "false", "log_file": "reed_quad_x",
               "wait_to_record_bag": "false"}
# The seed quad has validate errors (I203, S115, R312): the flight physics tests below
# fly it anyway; the refusal itself is tested at the end.
ARGV = [f"{k}:={v}" for k, v in LAUNCH_ARGS.items()] + ["--ignore-validation"]
G = 9.80665


def run_cli(*args: str) -> int:
    from reedtool.cli import main

    with pytest.raises(SystemExit) as info:
        main(list(args))
    return info.value.code


def run_json(capsys, *args: str) -> tuple[int, dict]:
    code = run_cli("hover-test", *args, "--format", "json")
    return code, json.loads(capsys.readouterr().out)


def urdf_mass_and_motor_constants(urdf_xml: str) -> tuple[float, list[float]]:
    """Total mass and motor constants read straight from the URDF text (not via reedtool)."""
    root = etree.fromstring(urdf_xml.encode())
    mass = sum(float(m.get("value")) for m in root.iterfind(".//link/inertial/mass"))
    k = [float(e.text) for e in root.iter("motorConstant")]
    return mass, k


# ------------------------------------------------------------------ the seed quadrotor

def test_seed_quadrotor_hovers_at_the_formula_speed(capsys):
    code, report = run_json(capsys, str(SEED_MODEL), *ARGV)
    assert code == 0 and report["passed"] is True
    assert report["sim"]["status"] == "passed"

    robot = load_robot(SEED_MODEL, LAUNCH_ARGS)
    mass, k = urdf_mass_and_motor_constants(robot.urdf_xml)
    assert len(k) == 4 and len(set(k)) == 1
    hover = math.sqrt(mass * G / (4 * k[0]))
    trim = [r["omega_rad_s"] for r in report["trim"]["rotors"]]
    # Symmetric quad, pseudo-inverse trim vs the closed form: O(10) ulps (see test_trim);
    # the JSON keeps repr precision.
    np.testing.assert_allclose(trim, hover, rtol=1e-9)
    final = list(report["sim"]["final_omega_rad_s"].values())
    # After the flight settles: measured ~1e-9 of the hover speed (test_sim's steady
    # hover test); 1e-6 is a margin, a wrong k or mass is 1e-2.
    np.testing.assert_allclose(final, hover, rtol=1e-6)
    # Products in another order: a few ulps; 1e-9 is margin.
    assert report["trim"]["thrust_to_weight"] == pytest.approx(
        4 * k[0] * 838.0 ** 2 / (mass * G), rel=1e-9)


def test_seed_quadrotor_text_report(capsys):
    assert run_cli("hover-test", str(SEED_MODEL), *ARGV, "--duration", "5") == 0
    out = capsys.readouterr().out
    assert out.rstrip().endswith("PASSED")
    assert "reed_quad_x/rotor_3" in out


def copy_seed(tmp_path: Path) -> Path:
    """A writable copy of the seed package; returns its xacro with the rotor properties."""
    shutil.copytree(SEED_PACKAGE, tmp_path / "reed_gazebo")
    return tmp_path / "reed_gazebo" / "urdf" / "reed_quad_x.xacro"


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, old
    path.write_text(text.replace(old, new))


def run_variant(capsys, tmp_path: Path) -> tuple[int, dict]:
    model = tmp_path / "reed_gazebo" / "urdf" / SEED_MODEL_NAME
    return run_json(capsys, str(model), *ARGV, "--package-path", str(tmp_path),
                    "--duration", "4")


def test_seed_with_one_rotor_direction_flipped_fails_on_yaw(capsys, tmp_path):
    xacro = copy_seed(tmp_path)
    edit(xacro, 'suffix="front_left"\ndirection="cw"', 'suffix="front_left"\ndirection="ccw"')
    code, report = run_variant(capsys, tmp_path)
    assert code == 1 and report["passed"] is False
    assert (report["status"], report["trim"]["cause"]) == ("cannot-hover", "yaw-unbalanced")
    assert report["sim"] is None


def test_seed_with_motor_constant_divided_by_ten_fails_at_trim(capsys, tmp_path):
    xacro = copy_seed(tmp_path)
    edit(xacro, 'name="motor_constant" value="8.54858e-06"',
         'name="motor_constant" value="8.54858e-07"')
    code, report = run_variant(capsys, tmp_path)
    assert code == 1
    assert (report["status"], report["trim"]["cause"]) == ("cannot-hover",
                                                           "insufficient-thrust")


def test_seed_with_com_outside_the_rotor_square_fails(capsys, tmp_path):
    xacro = copy_seed(tmp_path)
    # A 0.5 kg payload 1 m forward: COM x = 0.5 / 2.04 = 0.25 m, beyond the rotors' 0.187 m.
    edit(xacro, "</robot>", """<link name="payload">
<inertial><mass value="0.5" /><origin xyz="0 0 0" rpy="0 0 0" />
<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4" /></inertial>
</link>
<joint name="payload_joint" type="fixed">
<origin xyz="1.0 0 0" rpy="0 0 0" />
<parent link="${namespace}/base_link" /><child link="payload" />
</joint>
</robot>""")
    code, report = run_variant(capsys, tmp_path)
    assert code == 1
    assert report["model"]["com_m"][0] > 0.18738
    assert (report["status"], report["trim"]["cause"]) == ("cannot-hover", "com-unbalanced")


# ------------------------------------------------------------------ generated frames

def frame_urdf(n: int, **changes) -> str:
    """A flat n-rotor frame (0.25 m arms, 0.03 m up) with an IMU link: a 1.2 kg body, 20 g
    rotors, RotorS motor plugins without the slowdown; changes go to the builder."""
    motor = {"rotorVelocitySlowdownSim": None, **changes.pop("motor", {})}
    return multirotor_urdf(n, name=f"frame{n}", arm_m=0.25, height_m=0.03, body_kg=1.2,
                           body_inertia=(0.02, 0.02, 0.04), rotor_kg=0.02,
                           rotor_inertia=(1e-5, 1e-4, 1e-4), imu_kg=0.015,
                           imu_origin='xyz="0 0 -0.02"', motor=motor, **changes)


@pytest.mark.parametrize("n", [4, 6, 8])
def test_symmetric_frames_trim_and_hover_at_the_formula_speed(capsys, tmp_path, n):
    xml = frame_urdf(n)
    path = tmp_path / f"frame{n}.urdf"
    path.write_text(xml)
    code, report = run_json(capsys, str(path))
    assert code == 0, report["message"]
    mass, k = urdf_mass_and_motor_constants(xml)
    # Decimal masses summed: a few roundings of ~1.3 kg; default rel 1e-6 is a ceiling.
    assert mass == pytest.approx(1.2 + 0.015 + n * 0.02)
    hover = math.sqrt(mass * G / (n * k[0]))
    # Pseudo-inverse trim vs closed form: O(10) ulps; 1e-9 allows any LAPACK.
    np.testing.assert_allclose([r["omega_rad_s"] for r in report["trim"]["rotors"]], hover,
                               rtol=1e-9)
    # Settled flight: ~1e-9 measured (test_sim); 1e-6 is a margin.
    np.testing.assert_allclose(list(report["sim"]["final_omega_rad_s"].values()), hover,
                               rtol=1e-6)


def test_model_without_rotors_fails_with_its_cause(capsys, tmp_path):
    path = tmp_path / "brick.urdf"
    path.write_text('<robot name="brick"><link name="base_link"><inertial><mass value="1"/>'
                    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                    '</inertial></link></robot>')
    code, report = run_json(capsys, str(path))
    assert (code, report["trim"]["cause"]) == (1, "no-rotors")


# ------------------------------------------------------------------ outputs and errors

def test_csv_and_plot_are_written_and_never_clobbered(capsys, tmp_path):
    path = tmp_path / "quad.urdf"
    path.write_text(frame_urdf(4))
    csv_path, png_path = tmp_path / "run.csv", tmp_path / "run.png"
    args = [str(path), "--duration", "2", "--csv", str(csv_path), "--plot", str(png_path)]
    assert run_cli("hover-test", *args) in (0, 1)
    rows = csv_path.read_text().splitlines()
    header = rows[0].split(",")
    assert header[:4] == ["t_s", "x_m", "y_m", "z_m"]
    assert sum(h.startswith("omega_") for h in header) == 4
    assert len(rows) == 1 + 2 * 100 + 1              # 100 Hz samples, both ends
    first = dict(zip(header, map(float, rows[1].split(","))))
    assert (first["x_m"], first["z_m"], first["roll_rad"]) == (0.5, 2.0, 0.2)
    assert png_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    capsys.readouterr()
    csv_path.write_text("keep")
    assert run_cli("hover-test", *args) == 2
    assert "--force" in capsys.readouterr().err
    assert csv_path.read_text() == "keep"
    assert run_cli("hover-test", *args, "--force") in (0, 1)
    assert csv_path.read_text().startswith("t_s,")


def test_batch_reports_pass_rate_reproducibly(capsys, tmp_path):
    path = tmp_path / "quad.urdf"
    path.write_text(frame_urdf(4))
    args = [str(path), "--duration", "4", "--samples", "6", "--seed", "5"]
    code, first = run_json(capsys, *args)
    _, again = run_json(capsys, *args)
    assert first["batch"] == again["batch"]
    assert first["batch"]["samples"] == 6
    assert sum(first["batch"]["counts"].values()) == 6
    assert code == (0 if first["sim"]["passed"] and first["batch"]["pass_rate"] >= 0.95 else 1)


@pytest.mark.parametrize("args, needle", [
    (["missing.urdf"], "not found"),
    (["{model}", "--duration", "0"], "duration"),
    (["{model}", "--rate", "-5"], "rate"),
    (["{model}", "not_a_mapping"], "name:=value"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, args, needle):
    path = tmp_path / "quad.urdf"
    path.write_text(frame_urdf(4))
    argv = [a.replace("{model}", str(path)) if "{model}" in a else
            str(tmp_path / a) if a.endswith(".urdf") else a for a in args]
    assert run_cli("hover-test", *argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err
    assert "Traceback" not in err


# ------------------------------------------------------------------ validation first

def test_seed_with_validate_errors_is_refused_not_passed(capsys):
    """The seed quad hovers, but validate reports errors: hover-test must not say PASSED."""
    argv = [a for a in ARGV if a != "--ignore-validation"]
    assert run_cli("hover-test", str(SEED_MODEL), *argv, "--duration", "2") == 1
    out = capsys.readouterr().out
    assert "PASSED" not in out
    assert "I203" in out and "--ignore-validation" in out
    assert out.rstrip().splitlines()[-1].startswith("FAILED: validate reports 3 errors")

    code, report = run_json(capsys, str(SEED_MODEL), *argv, "--duration", "2")
    assert code == 1 and report["status"] == "refused" and report["passed"] is False
    assert report["schema"] == "reedtool.hover-test/1" and report["tool"] == "reedtool"
    assert sorted(e["code"] for e in report["validation"]["errors"]) == ["I203", "R312",
                                                                         "S115"]


def test_ignore_validation_flies_and_lists_the_errors(capsys):
    assert run_cli("hover-test", str(SEED_MODEL), *ARGV, "--duration", "5") == 0
    out = capsys.readouterr().out
    assert "I203" in out and "flying it anyway" in out
    assert out.rstrip().endswith("PASSED")


def test_an_omni_frame_claims_no_roll_pitch_yaw_authority(capsys):
    """The 6-DoF trim computes no 4-row torque authority: the text leaves it out and JSON
    says null, never 'roll 0, pitch 0, yaw 0 N*m' for a frame with authority to spare."""
    omni = TESTS / "fixtures" / "omni" / "omni_reversible.sdf"
    code, doc = run_json(capsys, str(omni), "--require", "stable")
    assert code == 0 and doc["status"] == "not-flown" and doc["outcome"] == "accepted"
    assert doc["trim"]["torque_authority_N_m"] == {"roll": None, "pitch": None, "yaw": None}
    run_cli("hover-test", str(omni))
    assert "torque authority" not in capsys.readouterr().out


def test_absent_time_constants_take_the_motor_plugins_defaults(capsys, tmp_path):
    """RotorS, PX4 classic and gz-sim's MulticopterMotorModel all use kDefaultTimeConstantUp
    = 1/80 s and kDefaultTimeConstantDown = 1/40 s when the elements are not written
    (Bitcraze's gz crazyflie writes neither): the model flies, as in Gazebo, instead of
    being refused as bad input. Written but unreadable stays an error (control)."""
    from reedtool.physics.rotors import discover_rotors

    xml = frame_urdf(4, motor={"timeConstantUp": None, "timeConstantDown": None})
    path = tmp_path / "no_tau.urdf"
    path.write_text(xml)
    rotors = discover_rotors(load_robot(path))
    assert {r.time_constant_up_s for r in rotors} == {1.0 / 80.0}       # exact: the default
    assert {r.time_constant_down_s for r in rotors} == {1.0 / 40.0}
    code, report = run_json(capsys, str(path))
    assert code == 0 and report["status"] == "flies"
    bad = tmp_path / "bad_tau.urdf"
    bad.write_text(frame_urdf(4, motor={"timeConstantUp": "x"}))
    assert run_cli("hover-test", str(bad)) == 2
