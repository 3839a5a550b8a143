"""Rule tests compare lists of codes, never wording (as catkin_lint's tests do)."""

from pathlib import Path

from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot

FIXTURES = Path(__file__).parent / "fixtures" / "validate"


def codes(name: str, prefix: str = "") -> list[str]:
    """Sorted rule codes validate reports for the fixture `name` (rules under `prefix`)."""
    findings = run_checks(load_robot(FIXTURES / name), Selection(select=(prefix,)))
    return sorted(f.code for f in findings)
