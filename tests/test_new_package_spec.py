"""Parameters for new-package: names, units, precedence and the refusals."""

from __future__ import annotations

import pytest

from reedtool.errors import ReedtoolError
from reedtool.generate.package_spec import build_spec, check_package_name, thrust_to_weight


@pytest.mark.parametrize("name", ["reed_gazebo", "a", "quad2", "my_robot_description"])
def test_rep144_accepts(name):
    check_package_name(name)


@pytest.mark.parametrize("name", ["Reed", "2quad", "_x", "x_", "a__b", "a-b", "a b", ""])
def test_rep144_refuses(name):
    with pytest.raises(ReedtoolError):
        check_package_name(name)


def test_spec_units_and_flag_precedence(tmp_path):
    spec_file = tmp_path / "s.yaml"
    spec_file.write_text("frame: hex-x\narm_length: 300 mm\nmass: '1800 g'\n"
                         "max_rot_velocity: 9000 rpm\n")
    spec = build_spec("p", spec_file=spec_file, flags={"mass": "2.0"})
    assert spec.frame.name == "hex-x"
    # Unit conversions of decimal text (300 mm, 1800 g, 9000 rpm): one or two roundings;
    # approx's default rel 1e-6 is a ceiling, a wrong unit is a factor of 10 or more.
    assert spec["arm_length"] == pytest.approx(0.3)
    assert spec["mass"] == pytest.approx(2.0)                      # the flag wins
    assert spec["max_rot_velocity"] == pytest.approx(9000 * 2 * 3.141592653589793 / 60)
    assert spec.origin["mass"] == "--mass" and spec.origin["arm_length"] == "spec"


def test_unknown_key_suggests(tmp_path):
    spec_file = tmp_path / "s.yaml"
    spec_file.write_text("arm_lenght: 0.2\n")
    with pytest.raises(ReedtoolError) as info:
        build_spec("p", spec_file=spec_file)
    assert "arm_length" in info.value.one_line() and str(spec_file) in info.value.one_line()


@pytest.mark.parametrize("text", ["mass: -1\n", "mass: .nan\n", "mass: 3 parsecs\n",
                                  "mass: [1]\n", "wheel_radius: 0.1\n", "ros: 3\n", "[1, 2]\n"])
def test_bad_values_are_user_errors(tmp_path, text):
    spec_file = tmp_path / "s.yaml"
    spec_file.write_text(text)
    with pytest.raises(ReedtoolError):
        build_spec("p", frame="quad-x", spec_file=spec_file)


def test_cannot_lift_is_refused():
    # Seed rotors: 4 x 8.54858e-06 x 838^2 = 24.0 N of thrust; 2 kg weighs 19.6 N.
    # The same products in another order: a few ulps; default rel 1e-6 is a ceiling.
    assert thrust_to_weight(build_spec("p", frame="quad-x")) == pytest.approx(
        4 * 8.54858e-06 * 838 ** 2 / ((1.5 + 4 * 0.005 + 0.01503) * 9.80665))
    with pytest.raises(ReedtoolError, match="cannot lift"):
        build_spec("p", frame="quad-x", flags={"mass": "2"})


def test_overlapping_propellers_are_refused():
    # Octo at 0.2 m: neighbours 2 * 0.2 * sin(22.5 deg) = 0.153 m apart < 2 * 0.1 m.
    with pytest.raises(ReedtoolError, match="propellers overlap"):
        build_spec("p", frame="octo-x", flags={"arm_length": "0.2"})


def test_ground_parameter_on_a_multirotor_flag_is_refused():
    with pytest.raises(ReedtoolError, match="does not apply"):
        build_spec("p", frame="car-4w", flags={"arm_length": "0.2"})
