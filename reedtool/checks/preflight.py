"""Refuse to compute mass properties or fly a model that is not a sound URDF tree.

`inertia` and `hover-test` hand the model to Pinocchio, whose URDF parser (urdfdom) does
not stop on many broken elements: it prints to stderr and drops the element, so an
<inertial> with mass="nan" becomes a massless link and every number printed afterwards
is that of another robot. `validate` reports such problems as findings; the commands that
compute stop at the first one, naming its file and line (exit 2).
"""

from __future__ import annotations

from reedtool.errors import ReedtoolError
from reedtool.model import Robot

# Structure rules whose errors leave nothing sound to compute on: unreadable or
# non-finite numbers, missing attributes, no single root, dangling or duplicated names,
# cycles, unknown joint types, limits urdfdom requires.
BLOCKING_RULES = ("S101", "S102", "S104", "S105", "S106", "S107", "S108", "S109", "S110",
                  "S111")


def require_sound_model(robot: Robot) -> None:
    """Raise a one-line ReedtoolError for the first blocking structure problem, if any."""
    from reedtool.checks.runner import Selection, run_checks

    findings = [f for f in run_checks(robot, Selection(select=BLOCKING_RULES))
                if f.severity == "error"]
    if not findings:
        return
    first = findings[0]
    more = f" (and {len(findings) - 1} more problem(s))" if len(findings) > 1 else ""
    subject = f"[{first.subject}] " if first.subject and first.subject not in first.message \
        else ""
    hint = "; ".join(part for part in (first.hint, "`reedtool validate MODEL` lists every "
                                                   "problem with its line") if part)
    raise ReedtoolError(f"{subject}{first.message}{more}", file=first.file, line=first.line,
                        hint=hint)
