"""Acceptance of issue 3 on the seed models and the clean reference models."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from reedtool.checks.runner import run_checks
from reedtool.cli import main
from reedtool.io.loader import load_robot

TESTS = Path(__file__).parent
SEED_QUAD = TESTS / "fixtures" / "seed000" / "reed_gazebo" / "urdf" / "mav_generic_odometry_sensor.gazebo"
SEED_ARGS = {"mav_name": "reed_quad_x", "namespace": "reed_quad_x",
             "enable_mavlink_interface": "true", "enable_ground_truth": "true",
             "enable_logging": "false", "log_file": "reed_quad_x", "wait_to_record_bag": "false"}
# Seed 001's smartcar with legacy tags fixed and its smartcar_sim macro called.
SMARTCAR = TESTS / "fixtures" / "validate" / "smartcar_description" / "urdf" / "smartcar.urdf.xacro"


@pytest.fixture(scope="module")
def seed_findings():
    return run_checks(load_robot(SEED_QUAD, SEED_ARGS))


def _source_line(finding) -> str:
    return Path(finding.file).read_text().splitlines()[finding.line - 1]


def test_seed_quad_mavlink_rotor_count(seed_findings):
    (finding,) = [f for f in seed_findings if f.code == "R312"]
    assert finding.severity == "error"
    assert Path(finding.file).name == "reed_quad_x_base.xacro"
    # Both numbers from the sources: the interface's rotor_count on the line the finding
    # names, and the rotor macro calls in the robot's xacro.
    (declared,) = re.findall(r'rotor_count="(\d+)"', _source_line(finding))
    calls = (SEED_QUAD.parent / "reed_quad_x.xacro").read_text().count("<xacro:vertical_rotor")
    assert (int(declared), calls) == (6, 4)
    assert set(re.findall(r"\b\d+\b", finding.message)) >= {declared, str(calls)}


def test_seed_quad_body_triangle_inequality(seed_findings):
    (finding,) = [f for f in seed_findings if f.code == "I203"]
    assert Path(finding.file).name == "reed_quad_x.xacro"
    # The principal moments of the tensor written on the line the finding names, by numpy:
    # A + B < C beyond the rule's 0.1 % of C, and the message quotes them (:.6g) and A + B.
    written = dict(re.findall(r'(i[xyz]{2})="([^"]+)"', _source_line(finding)))
    tensor = np.array([[float(v) for v in row] for row in
                       [[written["ixx"], written["ixy"], written["ixz"]],
                        [written["ixy"], written["iyy"], written["iyz"]],
                        [written["ixz"], written["iyz"], written["izz"]]]])
    a, b, c = np.linalg.eigvalsh(tensor)
    assert a + b < c * (1 - 1e-3)
    for value in (a, b, a + b, c):
        assert f"{value:.6g}" in finding.message


def test_seed_quad_rotors_are_numbered_and_turning_correctly(seed_findings):
    assert not [f for f in seed_findings if f.code in ("R301", "R302", "R303", "R304", "R305")]


def test_smartcar_missing_reference_and_wheel_inertia():
    findings = run_checks(load_robot(SMARTCAR))
    assert {f.subject for f in findings if f.code == "S114"} == {"regular"}
    # 1.0 kg m^2 on 0.1 kg wheels: orders of magnitude off the geometry, an error (I209).
    wheels = [f for f in findings if f.code == "I209" and f.subject.endswith("_wheel")]
    assert all(f.severity == "error" for f in wheels)
    assert len(wheels) == 4
    m, r, length = 0.1, 0.025, 0.02
    transverse, axial = m * (3 * r * r + length * length) / 12, m * r * r / 2
    for finding in wheels:
        assert "0.1 kg cylinder of radius 0.025 m" in finding.message
        values = sorted(float(v) for k, v in re.findall(r'(i[xyz]{2})="([^"]+)"', finding.hint)
                        if k in ("ixx", "iyy", "izz"))
        # The hint prints 4 significant digits (:.4g): 5e-5 relative rounding; rel 1e-4 holds.
        assert values == pytest.approx(sorted([transverse, transverse, axial]), rel=1e-4)


@pytest.mark.parametrize("name", ["clean_quad_x.urdf", "clean_octo.urdf", "clean_car.urdf"])
def test_clean_models_quiet_even_when_strict(name, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["validate", str(TESTS / "fixtures" / "validate" / name), "--strict"])
    assert exc.value.code == 0
    assert "no findings" in capsys.readouterr().out


def test_clean_hex_has_only_the_spin_order_information_even_when_strict(capsys):
    # R350 is information (the alternating hexacopter cannot keep full control after a
    # rotor failure); it never fails validate.
    with pytest.raises(SystemExit) as exc:
        main(["validate", str(TESTS / "fixtures" / "validate" / "clean_hex.urdf"), "--strict"])
    assert exc.value.code == 0
    assert "0 errors, 0 warnings, 1 info" in capsys.readouterr().out


def test_clean_quad_whole_robot_mass_matches_pinocchio():
    """The context's mass properties (used by trim rules) agree with Pinocchio."""
    pinocchio = pytest.importorskip("pinocchio")
    import numpy as np

    from reedtool.checks.context import CheckContext

    path = TESTS / "fixtures" / "validate" / "clean_hex.urdf"
    ctx = CheckContext(load_robot(path))
    # A free-flyer root, as in Gazebo: the root link's own mass counts.
    model = pinocchio.buildModelFromUrdf(str(path), pinocchio.JointModelFreeFlyer())
    data = model.createData()
    q = pinocchio.neutral(model)
    # Two sums of the same decimal masses: a few ulps; default rel 1e-6 is a ceiling.
    assert ctx.whole_robot.mass_kg == pytest.approx(pinocchio.computeTotalMass(model))
    # Two implementations of the same weighted sum: a few ulps of ~0.1 m; 1e-9 is margin.
    assert np.allclose(ctx.whole_robot.com_m, pinocchio.centerOfMass(model, data, q), atol=1e-9)
