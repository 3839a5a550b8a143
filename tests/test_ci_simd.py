"""The CI's second run (.ci/run) really runs numpy on other kernels."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HELPER = Path(__file__).resolve().parents[1] / ".ci" / "simd_features.py"


def run_helper(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(HELPER), *args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})}, timeout=60)


def test_restriction_names_only_dispatch_targets_this_cpu_has_and_takes():
    try:
        from numpy._core._multiarray_umath import (
            __cpu_baseline__, __cpu_dispatch__, __cpu_features__)
    except ImportError:     # numpy < 2.0
        from numpy.core._multiarray_umath import (
            __cpu_baseline__, __cpu_dispatch__, __cpu_features__)

    names = run_helper().stdout.split()
    # Disabling a baseline feature is an error in numpy; a feature the CPU lacks is moot.
    assert all(n in __cpu_dispatch__ and n not in __cpu_baseline__ and __cpu_features__[n]
               for n in names)
    if not names:       # a CPU with only the baseline: nothing to restrict
        return
    restricted = run_helper("--check", *names, env={"NPY_DISABLE_CPU_FEATURES": " ".join(names)})
    assert restricted.returncode == 0, restricted.stderr
    # Without the variable the same check fails: it looks at what numpy really dispatches.
    assert run_helper("--check", *names, env={"NPY_DISABLE_CPU_FEATURES": ""}).returncode == 1


def test_ci_runs_the_suite_again_restricted():
    script = (HELPER.parent / "run").read_text()
    assert "NPY_DISABLE_CPU_FEATURES" in script
    assert script.count("\npytest") == 2
