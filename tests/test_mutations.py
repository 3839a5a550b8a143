"""Mutation suite: one defect at a time planted in models validate passes clean, and the
rule that owns the defect must find it (as an error, on the element mutated).

Each mutation is a small text edit a real model ships (a motor renumbered past the
rotor count, two motors on one number, a direction typo, a negative mass, an inertia
breaking the triangle inequality, a joint naming a link that is not there). The models
span the families the rules read: RotorS with and without its MAVLink interface, PX4
classic with control channels, and gz-sim. A mutation that stops being found is a
regression, whatever the rest of the suite says; the clean model staying clean keeps
each mutation's finding attributable to the edit alone.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot

FIXTURES = Path(__file__).parent / "fixtures"


def _without_mavlink(text: str) -> str:
    """The RotorS model with its MAVLink interface plugin taken out: the shape of a RotorS
    vehicle flown by RotorS' own controller (lee_position_controller), no autopilot."""
    return re.sub(r"\s*<gazebo>\s*<plugin[^>]*mavlink[^>]*>.*?</plugin>\s*</gazebo>", "", text,
                  count=1, flags=re.S)


def _renumber(text: str, tag: str, old: int, new: int) -> str:
    edited = text.replace(f"<{tag}>{old}</{tag}>", f"<{tag}>{new}</{tag}>", 1)
    assert edited != text, f"<{tag}>{old}</{tag}> not in the model"
    return edited


def _highest_number(text: str, tag: str) -> int:
    return max(int(n) for n in re.findall(rf"<{tag}>(\d+)</{tag}>", text))


def _replace_once(old: str, new: str):
    def edit(text: str) -> str:
        assert old in text, f"{old!r} not in the model"
        return text.replace(old, new, 1)
    return edit


BASES = {
    # name: (fixture, how it is prepared, number tag)
    "rotors_mavlink": ("validate/clean_quad_x.urdf", lambda t: t, "motorNumber"),
    "rotors_no_autopilot": ("validate/clean_quad_x.urdf", _without_mavlink, "motorNumber"),
    "rotors_hex_no_autopilot": ("validate/clean_hex.urdf", _without_mavlink, "motorNumber"),
    "px4_classic_channels": ("px4_classic/iris_template_channels.sdf", lambda t: t,
                             "motorNumber"),
}

# (mutation id, rule code that must report it as an error, edit(text, number tag))
MUTATIONS = [
    # A gap: the last motor renumbered to 6 (0,1,2,6 for four rotors, 0..4,6 for six): the
    # controller's command has one entry per rotor and motor 6 never receives one (PX4
    # classic: entry 6 is a flap's position channel, no speed).
    ("motor_number_gap", "R302",
     lambda t, tag: _renumber(t, tag, _highest_number(t, tag), 6)),
    ("motor_number_duplicate", "R301", lambda t, tag: _renumber(t, tag, 3, 2)),
    ("motor_number_unreadable", "R302", lambda t, tag: _renumber(t, tag, 1, -1)
     .replace(f"<{tag}>-1</{tag}>", f"<{tag}>one</{tag}>")),
    ("direction_typo", "R303", lambda t, tag: re.sub(
        r"<turningDirection>cw</turningDirection>", "<turningDirection>CW</turningDirection>",
        t, count=1)),
]


def _codes(path: Path, severity: str = "error") -> set[str]:
    return {f.code for f in run_checks(load_robot(path)) if f.severity == severity}


@pytest.mark.parametrize("base", sorted(BASES))
def test_every_base_is_clean(base, tmp_path):
    fixture, prepare, _tag = BASES[base]
    path = tmp_path / Path(fixture).name
    path.write_text(prepare((FIXTURES / fixture).read_text()))
    assert _codes(path) == set()


@pytest.mark.parametrize("base", sorted(BASES))
@pytest.mark.parametrize("mutation,code,edit", MUTATIONS, ids=[m[0] for m in MUTATIONS])
def test_each_planted_defect_is_found(base, mutation, code, edit, tmp_path):
    fixture, prepare, tag = BASES[base]
    text = prepare((FIXTURES / fixture).read_text())
    mutated = edit(text, tag)
    assert mutated != text
    path = tmp_path / Path(fixture).name
    path.write_text(mutated)
    assert code in _codes(path), f"{mutation} on {base} went unnoticed"


def test_the_gap_names_the_motor_that_never_spins(tmp_path):
    """The finding is on the renumbered motor, and says who sends what."""
    text = _without_mavlink((FIXTURES / "validate/clean_quad_x.urdf").read_text())
    path = tmp_path / "gap.urdf"
    path.write_text(_renumber(text, "motorNumber", 3, 4))
    (finding,) = [f for f in run_checks(load_robot(path)) if f.code == "R302"]
    assert "motor number 4" in finding.message and "entries 0..3" in finding.message and "never receives a command" in finding.message
    assert "4 rotors" in finding.message
    assert finding.line == path.read_text().splitlines().index(
        next(line for line in path.read_text().splitlines()
             if "<motorNumber>4</motorNumber>" in line)) + 1


def test_gz_numbers_are_the_flight_stacks_outputs(tmp_path):
    """gz-sim's motors read what PX4's gz bridge sends (its outputs): a gap there is the
    airframe's business (C414 with --airframe), not an error of the model alone."""
    text = (FIXTURES / "gz/x3_quad.sdf").read_text()
    tag = "actuator_number" if "<actuator_number>" in text else "motorNumber"
    path = tmp_path / "x3_gap.sdf"
    path.write_text(_renumber(text, tag, 3, 4))
    assert "R302" not in _codes(path)


MASS_MUTATIONS = [
    ("negative_mass", "I201", _replace_once('<mass value="1.2"/>', '<mass value="-1.2"/>')),
    # 0.00964 + 0.00964 < 0.05: no body has these principal moments.
    ("triangle", "I203", _replace_once('izz="0.018"', 'izz="0.05"')),
    ("joint_child_missing", "S105", _replace_once('<child link="rotor_2"/>',
                                                  '<child link="rotor_2_link"/>')),
]


@pytest.mark.parametrize("mutation,code,edit", MASS_MUTATIONS, ids=[m[0] for m in MASS_MUTATIONS])
def test_structure_and_mass_defects_are_found(mutation, code, edit, tmp_path):
    path = tmp_path / "quad.urdf"
    path.write_text(edit((FIXTURES / "validate/clean_quad_x.urdf").read_text()))
    assert code in _codes(path), f"{mutation} went unnoticed"
