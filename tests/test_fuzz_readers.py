"""Fuzz over the readers: model text (URDF, SDF, xacro) mutated the way damaged files are
(a number replaced by nan, inf, 1e400, garbage or nothing, an attribute or element given
the wrong count of numbers, an element dropped or duplicated), then loaded and checked by
every rule.

What must hold for every mutant: the model is either refused with one ReedtoolError (exit
2: the input is bad) or reported in full, and no rule ends in "internal error in this
rule" (exit 3 is for reedtool bugs only). The mutations are drawn from a fixed seed, so a
failure names a reproducible mutant.
"""

from __future__ import annotations

import copy
import random
import re
import shutil
from pathlib import Path

import pytest
from lxml import etree

from reedtool.checks.runner import INTERNAL_ERROR, run_checks
from reedtool.errors import ReedtoolError

# NaN and inf are what this test feeds the readers: numpy warns on their arithmetic, and
# the readers' findings, not numpy's warnings, are what is judged.
pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")
from reedtool.io.loader import load_robots

FIXTURES = Path(__file__).parent / "fixtures"
SEEDS = [
    "validate/clean_quad_x.urdf",
    "validate/clean_hex.urdf",
    "validate/clean_arm.urdf",
    "gz/x3_quad.sdf",
    "gz/frames.sdf",
    "px4_classic/iris_template_channels.sdf",
    "omni/omni_reversible.sdf",
    "rotors_neo/omav_tilt_servos.sdf",
    "upstream_shapes/tiltrotor/model.sdf",
    "upstream_shapes/quad_tailsitter/model.sdf",
    "upstream_shapes/rotors_plus_quad/plusquad.xacro",
]
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
REPLACEMENTS = ["nan", "inf", "-inf", "NaN", "1e400", "-1e400", "abc", "", "1,5", "0x10",
                "1e-320", "-0"]
MUTANTS_PER_SEED = 24


def _mutate(text: str, rng: random.Random) -> str:
    kind = rng.choice(["number", "number", "count", "drop", "duplicate"])
    if kind in ("number", "count"):
        spans = list(NUMBER.finditer(text))
        if not spans:
            return text
        span = rng.choice(spans)
        replacement = (rng.choice(REPLACEMENTS) if kind == "number"
                       else " ".join(["0"] * rng.choice([1, 2, 4, 5, 7])))
        return text[:span.start()] + replacement + text[span.end():]
    try:
        root = etree.fromstring(text.encode())
    except etree.XMLSyntaxError:
        return text         # an earlier mutation broke the XML itself: that stays the mutant
    elements = [el for el in root.iter() if isinstance(el.tag, str) and el is not root]
    element = rng.choice(elements)
    if kind == "drop":
        element.getparent().remove(element)
    else:
        element.addnext(copy.deepcopy(element))
    return etree.tostring(root, encoding="unicode")


def _mutants(seed: str):
    rng = random.Random(seed)
    text = (FIXTURES / seed).read_text()
    for index in range(MUTANTS_PER_SEED):
        mutant = text
        for _ in range(rng.choice([1, 1, 2, 3])):
            mutant = _mutate(mutant, rng)
        yield index, mutant


@pytest.mark.parametrize("seed", SEEDS)
def test_no_mutant_crashes_a_reader_or_a_rule(seed, tmp_path):
    source = FIXTURES / seed
    # The mutant sits where the original does (meshes and includes next to it resolve).
    workdir = tmp_path / "model"
    shutil.copytree(source.parent, workdir)
    crashed = []
    for index, mutant in _mutants(seed):
        path = workdir / source.name
        path.write_text(mutant)
        try:
            robots = load_robots(path)
        except ReedtoolError:
            continue        # refused with one line: exit 2, a bad input
        for robot in robots:
            for finding in run_checks(robot):
                if finding.message.startswith(INTERNAL_ERROR):
                    crashed.append((index, finding.code, finding.message))
    assert not crashed, f"{seed}: rules crashed on mutants {crashed[:3]}"


def test_a_five_number_pose_is_one_finding_and_the_rest_still_runs(tmp_path):
    """libsdformat refuses `<pose>` with five numbers ("must have 6 values, but 5 were
    found"): one finding on that element; the other rules still judge the rest (a
    duplicate motor number elsewhere is still found), and nothing crashes."""
    text = (FIXTURES / "gz/x3_quad.sdf").read_text()
    poses = re.findall(r"<pose>([^<]*)</pose>", text)
    target = next(p for p in poses if len(p.split()) == 6)
    short = " ".join(target.split()[:5])
    text = text.replace(f"<pose>{target}</pose>", f"<pose>{short}</pose>", 1)
    tag = "actuator_number" if "<actuator_number>" in text else "motorNumber"
    text = text.replace(f"<{tag}>3</{tag}>", f"<{tag}>2</{tag}>", 1)
    path = tmp_path / "x3.sdf"
    path.write_text(text)
    findings = [f for robot in load_robots(path) for f in run_checks(robot)]
    line = next(i for i, row in enumerate(text.splitlines(), 1) if f"<pose>{short}</pose>" in row)
    on_pose = [f for f in findings if f.line == line and f.severity == "error"]
    assert len(on_pose) == 1 and "5 number(s)" in on_pose[0].message
    assert "R301" in {f.code for f in findings}
    assert not [f for f in findings if f.message.startswith(INTERNAL_ERROR)]


def test_cli_exit_is_never_3_on_a_broken_pose(tmp_path, capsys):
    from cli_helpers import run_validate

    text = (FIXTURES / "validate/clean_arm.urdf").read_text()
    text = re.sub(r'rpy="0 0 0"', 'rpy="0 0 0 0 0 0 0"', text, count=2)
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    code, out, err = run_validate([path], capsys)
    assert code in (0, 1, 2) and code != 3
    assert "Traceback" not in out + err and "internal error" not in out + err
