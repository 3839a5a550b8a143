"""Reports never contradict their own numbers (issue 19).

An infeasible trim's table shows each rotor at what it can give, thrust = k*omega^2 of
the speed beside it, within [0, k*omega_max^2], and says which constraint fails.
`authority` on a vehicle that cannot be controlled says so and names the finding behind
it, instead of "FAILED --require hover: the intact vehicle is controllable" and "needs
thrust-to-weight > never".
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from reedtool.cli import main

FIXTURES = Path(__file__).parent / "fixtures" / "validate"
K = 8.54858e-06          # the fixtures' motorConstant [N/(rad/s)^2]
OMEGA_MAX = 838.0        # and maxRotVelocity [rad/s] (R307's: 1100)
ROW = re.compile(r"^  (\S+)\s+(-?\d+\.\d{4})\s+(-?\d+\.\d{2})\s+(\d+\.\d)%(.*)$")


def run(capsys, *argv) -> tuple[int, str]:
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    return info.value.code, capsys.readouterr().out


@pytest.mark.parametrize("fixture, cause, limit", [
    ("R308_bad_heavy.urdf", "insufficient-thrust", "at max"),     # 3 kg on 24 N of rotors
    ("R307_bad_com_offset.urdf", "com-unbalanced", "at 0"),       # COM 0.2 m off
    ("R304_bad_three_ccw.urdf", "yaw-unbalanced", None),   # inside the limits, unbalanced
])
def test_an_infeasible_trim_table_is_made_of_possible_rotor_states(capsys, fixture, cause,
                                                                   limit):
    code, out = run(capsys, "hover-test", FIXTURES / fixture, "--ignore-validation")
    assert code == 1
    assert f"trim: INFEASIBLE ({cause}):" in out        # which constraint fails
    rows = [ROW.match(line) for line in out.splitlines()]
    rows = [m for m in rows if m]
    assert len(rows) == 4, out
    omega_max = float(re.search(r"<maxRotVelocity>([\d.]+)<",
                                (FIXTURES / fixture).read_text()).group(1))
    t_max = K * omega_max ** 2
    for m in rows:
        thrust, omega = float(m.group(2)), float(m.group(3))
        assert 0.0 <= thrust <= round(t_max, 4) and not m.group(2).startswith("-")
        assert 0.0 <= omega <= omega_max
        # Printed to 4 and 2 decimals: k*omega^2 moves by 2*k*omega*0.005 <= 1e-4 N for a
        # rounding of omega, the thrust by 5e-5 N for its own.
        assert abs(K * omega ** 2 - thrust) <= 2 * K * omega_max * 0.005 + 5e-5
    marks = [m.group(5).strip() for m in rows]
    if limit is None:       # round-off demands (-3e-17 N) are no saturation
        assert not any(marks), marks
    else:
        assert any(mark.startswith(limit) for mark in marks), marks


def test_the_json_trim_carries_the_demand_beside_the_saturated_thrust(capsys):
    code, out = run(capsys, "hover-test", FIXTURES / "R308_bad_heavy.urdf",
                    "--ignore-validation", "--format", "json")
    rotors = json.loads(out)["trim"]["rotors"]
    t_max = K * OMEGA_MAX ** 2
    for r in rotors:
        assert r["limit"] == "max" and r["omega_rad_s"] == OMEGA_MAX
        # k * w_max^2 computed twice the same way: exact.
        assert r["thrust_N"] == t_max and r["demand_N"] > t_max


def test_authority_on_an_uncontrollable_vehicle_says_not_controllable_and_why(capsys):
    code, out = run(capsys, "authority", FIXTURES / "R304_bad_three_ccw.urdf")
    assert code == 1
    assert "not controllable about hover" in out and "never" not in out.splitlines()[1]
    assert "because R304 (yaw-moment-imbalance)" in out
    last = out.strip().splitlines()[-1]
    assert last.startswith("FAILED --require hover: the intact vehicle is not controllable")
    assert "(R304)" in last


def test_authority_json_names_the_causes(capsys):
    code, out = run(capsys, "authority", FIXTURES / "R305_bad_same_side.urdf",
                    "--format", "json")
    report = json.loads(out)
    assert code == 1 and not report["intact"]["controllable"]
    assert [c["code"] for c in report["intact"]["causes"]] == ["R305"]


def test_authority_on_a_controllable_vehicle_is_unchanged(capsys):
    code, out = run(capsys, "authority", FIXTURES / "clean_hex.urdf")
    assert code == 0
    assert "(controllable), needs thrust-to-weight > 1" in out
    assert out.strip().splitlines()[-1] == ("PASSED --require hover: the intact vehicle is "
                                            "controllable about hover")
