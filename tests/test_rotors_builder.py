"""tests/rotors_builder.py writes what urdfdom and xacro read, and its default model is
RotorS' firefly as firefly.xacro places and sizes it (numbers written here from the
xacro, not from the builder)."""

from __future__ import annotations

import math
import re
import subprocess

import numpy as np
import pytest
from oracles import CHECK_URDF
from rotors_builder import multirotor_urdf

from reedtool.checks.context import CheckContext
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import discover_rotors

G = 9.80665


@pytest.mark.parametrize("kw, children", [
    ({}, 6),
    ({"n": 4, "imu_kg": 0.015, "imu_origin": 'xyz="0 0 -0.02"'}, 5),
    ({"n": 8, "plugin": "gz", "digits": 5, "per_rotor": {1: {"arm_m": 0.3, "spin": "ccw"}}}, 8),
])
def test_check_urdf_reads_what_it_writes(tmp_path, kw, children):
    path = tmp_path / "m.urdf"
    path.write_text(multirotor_urdf(**kw))
    result = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert f"root Link: base_link has {children} child(ren)" in result.stdout


def test_xacro_text_expands_with_its_argument(tmp_path):
    import xacro

    path = tmp_path / "m.urdf.xacro"
    path.write_text(multirotor_urdf(4, xacro=True, body_kg="$(arg body_kg)"))
    expanded = xacro.process_file(str(path), mappings={"body_kg": "1.7"}).toxml()
    assert re.search(r'<link name="base_link">\s*<inertial>\s*<mass value="1.7"/>', expanded)
    out = tmp_path / "m.urdf"
    out.write_text(expanded)
    assert subprocess.run([CHECK_URDF, str(out)], capture_output=True,
                          timeout=60).returncode == 0


def test_the_default_is_the_firefly(tmp_path):
    """firefly.xacro: six rotors at arm_length 0.215 m, rotor_offset_top 0.037 m, the
    front-left one at 30 degrees and each next one 60 degrees on, spins ccw, cw, ...;
    mass 1.5 kg plus six 0.005 kg rotors; motor_constant 8.54858e-06, so the hover speed
    is sqrt(m g / (6 k))."""
    path = tmp_path / "firefly.urdf"
    path.write_text(multirotor_urdf())
    robot = load_robot(path)
    rotors = sorted(discover_rotors(robot), key=lambda r: r.motor_number)
    assert [r.direction for r in rotors] == ["ccw", "cw"] * 3
    for i, rotor in enumerate(rotors):
        angle = math.radians(30 + 60 * i)
        # Written with repr() floats and read back: exact to a few ulps; 1e-12 m holds.
        np.testing.assert_allclose(rotor.position_m, [0.215 * math.cos(angle),
                                                      0.215 * math.sin(angle), 0.037],
                                   atol=1e-12)
        assert (rotor.motor_constant, rotor.moment_constant) == (8.54858e-06, 0.016)
        assert rotor.max_rot_velocity_rad_s == 838
    mass_kg = 1.5 + 6 * 0.005
    # Pseudo-inverse trim vs closed form: O(10) ulps (see test_trim); 1e-9 holds.
    np.testing.assert_allclose(CheckContext(robot).trim.omega_rad_s,
                               math.sqrt(mass_kg * G / (6 * 8.54858e-06)), rtol=1e-9)
