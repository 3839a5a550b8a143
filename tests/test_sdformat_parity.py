"""validate refuses what libsdformat refuses: Drake's parser (libsdformat inside) against
validate's structure rules, on a corpus of mutated models (tests/sdf_mutants.py).

For every mutant: libsdformat refuses it => validate reports an error (S rules), never
"clean". Mutants libsdformat accepts by design (a plugin named `gz::sim::...`, a scoped
canonical_link, a static model without links, a visual and a collision of one name) must
stay free of errors in validate too.

Agreement matrix (160 mutants of 7 bases: an x500-like quad merged from an included
model, SDF 1.9; a rig with a nested arm, frames and relative_to poses, 1.9 and 1.8; a
Classic iris including a GPS model, 1.6, 1.7, and 1.9 including a 1.6 model; a world
with a static ground plane, a world frame, the quad included relative to it and a cart
validate does not read as a vehicle, given to validate with --package-path as Drake is
given the model folders):

    libsdformat refuses, validate errs ....... 133
    both accept .............................. 23
    libsdformat accepts, validate errs ....... 0
    libsdformat refuses, validate clean ...... 0 (+4 Drake-only refusals, below)

Drake-only refusals, told apart by their message and the file's version, are not
libsdformat's and are not counted against validate:

* "Non-unique name[...] detected N times" in an SDF < 1.7 file where a link and a joint
  share a name: libsdformat renames the newcomer with a *warning* (Model.cc), Gazebo's
  default policy; Drake's parser runs libsdformat with WarningsPolicy ERR.
* "GetFrameByName(): There is no Frame named ..." (or GetModelInstanceByName) for a name
  holding `::` in an SDF < 1.8 file: libsdformat allows `::` there (the check starts at
  1.8), Drake's own name lookup reads `::` as its scope delimiter.

The corpus is written as files for validate and given to Drake as strings (with includes
resolved through its package map): a string loads in milliseconds, a file in a tenth of
a second.
"""

from __future__ import annotations


import pytest

import sdf_mutants
from reedtool.checks.runner import Selection, run_checks
from reedtool.errors import ReedtoolError
from reedtool.io.loader import load_robots

# Mutations libsdformat must accept (each a case validate must not refuse either).
ACCEPTED_BY_DESIGN = {"unmutated", "dc_plugin_name", "canonical_nested",
                      "nested_without_link_static", "visual_collision_same_name",
                      "world_frame_in_model"}


def drake_only(error: str, version: str) -> str | None:
    import sdformat_oracle

    return sdformat_oracle.drake_only_reason(error, version)


def validate_errors(path, package_paths=()) -> list[str]:
    """The error codes of validate's structure rules (an exit-2 refusal counts);
    `package_paths` as `--package-path` gives them, the model folders Drake is given."""
    try:
        robots = load_robots(path, package_paths=package_paths)
    except ReedtoolError as exc:
        return [f"refused: {exc.message}"]
    return sorted({f.code for robot in robots
                   for f in run_checks(robot, Selection(select=("S",)))
                   if f.severity == "error"})


def _verdicts(tmp_path):
    import sdformat_oracle

    rows = []
    for index, mutant in enumerate(sdf_mutants.mutants()):
        root = tmp_path / str(index)
        top = mutant.write(root)
        models = root / "models"
        rows.append((mutant, sdformat_oracle.libsdformat_error_text(mutant.text, [models]),
                     validate_errors(top, [models])))
    return rows


def test_validate_never_calls_clean_what_libsdformat_refuses(tmp_path):
    rows = _verdicts(tmp_path)
    missed, false_alarms, matrix = [], [], {"refused/errs": 0, "accepted/clean": 0,
                                            "accepted/errs": 0, "refused/clean": 0,
                                            "drake-only": 0}
    for mutant, error, codes in rows:
        if error and not codes and drake_only(error, mutant.base.version):
            matrix["drake-only"] += 1
            continue
        key = f"{'refused' if error else 'accepted'}/{'errs' if codes else 'clean'}"
        matrix[key] += 1
        if error and not codes:
            missed.append(f"{mutant.id}: {error.splitlines()[0][:200]}")
        if not error and codes:
            false_alarms.append(f"{mutant.id}: {codes}")
    assert not missed, "libsdformat refuses, validate says clean:\n" + "\n".join(missed)
    assert not false_alarms, "validate errs, libsdformat accepts:\n" + "\n".join(false_alarms)
    # The corpus holds both verdicts in numbers (a corpus of one kind proves nothing).
    assert matrix["refused/errs"] >= 100 and matrix["accepted/clean"] >= 15, matrix
    assert matrix["drake-only"] <= 4, matrix


def test_mutations_meant_to_load_do_load(tmp_path):
    """The bases and the accepted-by-design mutations load in libsdformat: a corpus whose
    bases were refused would make every refusal above meaningless."""
    import sdformat_oracle

    for index, mutant in enumerate(m for m in sdf_mutants.mutants()
                                   if m.mutation in ACCEPTED_BY_DESIGN and not m.models):
        mutant.write(tmp_path / str(index))
        models = tmp_path / str(index) / "models"
        assert sdformat_oracle.libsdformat_error_text(mutant.text, [models]) is None, mutant.id


@pytest.mark.parametrize("version, refused", [("1.7", False), ("1.8", True), ("1.9", True)])
def test_double_colon_by_declared_version(tmp_path, version, refused):
    """The issue's case: a flattened GPS include `gps0::link`, refused from 1.8 on by
    libsdformat and by S160, accepted below by both."""
    import sdformat_oracle

    text = (f'<sdf version="{version}"><model name="iris">'
            '<link name="base_link"><inertial><mass>1.5</mass><inertia><ixx>0.03</ixx>'
            "<iyy>0.03</iyy><izz>0.05</izz></inertia></inertial></link>"
            '<link name="gps0::link"><pose>0.1 0 0.1 0 0 0</pose><inertial><mass>0.015</mass>'
            "<inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial></link>"
            '<joint name="gps0_joint" type="fixed"><parent>base_link</parent>'
            "<child>gps0::link</child></joint></model></sdf>")
    path = tmp_path / "iris.sdf"
    path.write_text(text)
    error = sdformat_oracle.libsdformat_error_text(text)
    assert (error is not None and not drake_only(error, version)) == refused, error
    assert ("S160" in validate_errors(path)) == refused


def test_validate_never_imports_drake():
    """Drake is the tests' judge, not a dependency: `reedtool validate` (an SDF with
    includes and a world, through the console entry point) runs without importing it."""
    import subprocess
    import sys
    from pathlib import Path

    fixtures = Path(__file__).parent / "fixtures"
    script = (
        "import sys\n"
        "from reedtool.cli import main\n"
        "for path in sys.argv[1:]:\n"
        "    try:\n"
        "        main(['validate', path])\n"
        "    except SystemExit:\n"
        "        pass\n"
        "print('drake imported:', sorted(m for m in sys.modules if 'drake' in m))\n")
    result = subprocess.run(
        [sys.executable, "-c", script,
         str(fixtures / "px4_gz" / "models" / "x500" / "model.sdf"),
         str(fixtures / "validate" / "S160_bad_double_colon_1_9.sdf")],
        capture_output=True, text=True, timeout=120)
    assert "S160" in result.stdout, result.stdout + result.stderr   # validate did run
    assert "drake imported: []" in result.stdout, result.stdout
