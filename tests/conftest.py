"""Suite-wide settings.

Hypothesis draws new examples on every run, which is how a property test finds what no
one wrote down; in CI (CI=true) it draws the same examples every time, so a submission
lands or fails on its own merits, never on a draw. Run `REEDTOOL_PROPERTY_EXAMPLES=1000
pytest tests/test_rules_property.py` locally to search wider.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True)
if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
    settings.load_profile("ci")


# The modules whose assertions a CPU's numpy kernels can move: closed-loop flights (an
# ulp at step one grows over 10 000 steps), engine-to-engine agreement held near 1e-8,
# mass properties and frames compared near machine precision, hulls and allocation
# decided by floating-point comparisons, and hypothesis' random robots. CI runs these
# again with numpy's SIMD dispatch held to its baseline (`pytest -m numeric`); the rest of
# the suite compares text, structure and findings, which no kernel changes.
NUMERIC_MODULES = {
    "test_sim", "test_compiled", "test_hover_tuning", "test_mujoco_oracle",
    "test_failure_flight", "test_authority", "test_trim", "test_inertia", "test_frames",
    "test_convex_hull", "test_rules_property", "test_hover_test_cli", "test_rotors",
    "test_mesh_readers",
}


def pytest_collection_modifyitems(config, items):
    import pytest

    for item in items:
        if item.module is not None and item.module.__name__.rpartition(".")[2] in NUMERIC_MODULES:
            item.add_marker(pytest.mark.numeric)


def pytest_sessionstart(session):
    """Compile the numba kernels once, in the process that hands out the work, before the
    workers start (`pytest -n N`): on a cold cache (every CI run) each worker, and each
    hover-test subprocess a test starts, would otherwise compile them itself (~30 s of CPU
    each) until one of them had written numba's cache. A run in one process compiles them
    on first use, as before."""
    config = session.config
    distributed = getattr(config.option, "numprocesses", None) not in (None, 0)
    if hasattr(config, "workerinput") or not distributed:
        return
    from reedtool.sim import compiled

    if compiled.available():
        compiled.warm_up()
