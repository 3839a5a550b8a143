"""What `reedtool validate` does before its findings (issue 29 item 7: the seed's validate
within 3x of check_urdf, benchmarks/bench_validate.py).

A check of the seed quadrotor reads xacro, parses URDF and runs the rules; a module that
only a write (tempfile, shutil), a baseline file or a template's overrides (json), an error
message's "did you mean" (difflib) or another command (jinja2, trimesh, matplotlib,
Pinocchio, numba, MuJoCo, Drake) needs is imported where it is used, not at start-up. So is
what only some models or files need: PX4's parameter table (an --airframe file), RotorS'
Lee controller model (Lee gain files), the failure search over spin orders (six rotors or
more), a mesh's topology and unit detector (a mesh to measure), the xacro argument reader
(arguments given). And the process does no work for nobody: numpy's OpenBLAS starts no
thread pool (it would spin idle) and the cycle collector does not walk the start-up heap
again and again.

Timing is the benchmark's job; these tests hold what is loaded and done, which does not
drift with the machine's load.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SEED = (ROOT / "tests" / "fixtures" / "seed000" / "reed_gazebo" / "urdf"
        / "mav_generic_odometry_sensor.gazebo")
SEED_ARGS = ["mav_name:=reed_quad_x", "namespace:=reed_quad_x", "enable_mavlink_interface:=true",
             "enable_ground_truth:=true", "enable_logging:=false", "log_file:=reed_quad_x",
             "wait_to_record_bag:=false"]
# The README's quick start: the bundled example, no arguments.
README_SEED = ROOT / "examples" / "reed_quad_x" / "urdf" / "mav_generic_odometry_sensor.gazebo"
NOT_AT_START_UP = ("tempfile", "shutil", "json", "difflib", "jinja2", "trimesh", "scipy",
                   "matplotlib", "pinocchio", "numba", "mujoco", "pydrake",
                   "reedtool.flightstack.px4", "reedtool.flightstack.rotors_lee",
                   "reedtool.physics.authority", "reedtool.physics.mesh_topology",
                   "reedtool.physics.mesh_units")
# Only without arguments: with them, S140/S141 read the model's declared arguments.
NOT_WITHOUT_ARGUMENTS = ("reedtool.io.xacro_args",)

# Runs validate as the console script does (sys.argv, main() without arguments: the
# process is reedtool's own), then reports what it loaded and did.
SCRIPT = """\
import gc, os, sys
names = {names!r}
from reedtool.cli import main
collections = []
gc.callbacks.append(lambda phase, info: collections.append(info) if phase == "stop" else None)
sys.argv = ["reedtool", "validate", *sys.argv[1:]]
try:
    main()
except SystemExit:
    pass
print("loaded:", sorted(m for m in sys.modules
                        if m in names or m.split(".")[0] in names))
tasks = "/proc/self/task"
print("threads:", len(os.listdir(tasks)) if os.path.isdir(tasks) else "unknown")
print("collections:", len(collections))
"""


def _validate(model: Path, *args: str, names=NOT_AT_START_UP) -> str:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    for chosen in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"):
        env.pop(chosen, None)          # as a user's shell has it: no thread count chosen
    result = subprocess.run([sys.executable, "-c", SCRIPT.format(names=tuple(names)),
                             str(model), *args],
                            capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
    return result.stdout + result.stderr


def _blas_name() -> str:
    import numpy

    try:
        return str(numpy.show_config(mode="dicts")["Build Dependencies"]["blas"]["name"]).lower()
    except (TypeError, KeyError):      # numpy < 1.26 has no mode="dicts"
        return ""


def test_seed_validate_imports_only_what_its_findings_need():
    out = _validate(SEED, *SEED_ARGS)
    # validate did run to its findings: the seed's three errors (README of the fixture).
    assert "I203" in out and "R312" in out, out
    assert "loaded: []" in out, out


def test_readme_seed_validate_loads_nothing_its_findings_do_not_need():
    out = _validate(README_SEED, names=NOT_AT_START_UP + NOT_WITHOUT_ARGUMENTS)
    assert "no findings" in out, out      # the bundled example is clean (README)
    assert "loaded: []" in out, out


def test_validate_starts_no_thread_and_does_not_collect_its_start_up():
    out = _validate(README_SEED)
    assert "no findings" in out, out
    if "threads: unknown" in out:
        pytest.skip("no /proc/self/task on this system to count the process's threads")
    if "openblas" not in _blas_name():
        pytest.skip("numpy is not built on OpenBLAS here (its thread setting is OpenBLAS's)")
    # One thread: OpenBLAS's idle pool (one thread per further core) was not started.
    # On a one-core machine OpenBLAS starts none anyway; this holds where it would.
    assert "threads: 1" in out, out
    # At CPython's default threshold (700) this run makes about 80 collections, each
    # walking the just-imported modules; reedtool's threshold (cli.GC_YOUNG_THRESHOLD)
    # leaves the seed's ~60 000 allocations below one collection.
    assert "collections: 0" in out, out
