"""What `reedtool validate` imports before its findings (issue 29 item 7: the seed's
validate within 3x of check_urdf, benchmarks/bench_validate.py).

A check of the seed quadrotor reads xacro, parses URDF and runs the rules; a module that
only a write (tempfile, shutil), a baseline file or a template's overrides (json), an error
message's "did you mean" (difflib) or another command (jinja2, trimesh, matplotlib,
Pinocchio, numba, MuJoCo, Drake) needs is imported where it is used, not at start-up.
Timing is the benchmark's job; this test holds the import list, which does not drift with
the machine's load.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SEED = (ROOT / "tests" / "fixtures" / "seed000" / "reed_gazebo" / "urdf"
        / "mav_generic_odometry_sensor.gazebo")
SEED_ARGS = ["mav_name:=reed_quad_x", "namespace:=reed_quad_x", "enable_mavlink_interface:=true",
             "enable_ground_truth:=true", "enable_logging:=false", "log_file:=reed_quad_x",
             "wait_to_record_bag:=false"]
NOT_AT_START_UP = ("tempfile", "shutil", "json", "difflib", "jinja2", "trimesh", "scipy",
                   "matplotlib", "pinocchio", "numba", "mujoco", "pydrake")


def test_seed_validate_imports_only_what_its_findings_need():
    script = (
        "import sys\n"
        "from reedtool.cli import main\n"
        "try:\n"
        "    main(['validate', *sys.argv[1:]])\n"
        "except SystemExit:\n"
        "    pass\n"
        f"print('loaded:', sorted(m for m in sys.modules if m.split('.')[0] in {NOT_AT_START_UP!r}))\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    result = subprocess.run([sys.executable, "-c", script, str(SEED), *SEED_ARGS],
                            capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
    # validate did run to its findings: the seed's three errors (README of the fixture).
    assert "I203" in result.stdout and "R312" in result.stdout, result.stdout + result.stderr
    assert "loaded: []" in result.stdout, result.stdout
