"""`inertia` as a call: the model loaded and judged by validate's refusal policy, each
link's declared inertia against its geometry's with the verdict's severity from its rule
(workflows.validation.judge_links), the whole robot's mass properties by Pinocchio and by
reedtool's own sum, and the findings `inertia` shares with `validate`. Then, on --fix, the
xacro edit (workflows.inertia_fix) and what still fails. Nothing here prints.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from reedtool.errors import ReedtoolError
from reedtool.workflows.robots import ModelRequest

# Model-level findings `inertia` shares with `validate`: what makes the geometry it compares
# against meaningless (a mesh Gazebo cannot load, leaving its package, in the wrong unit)
# and a robot without mass. The per-link verdicts cover I201-I204, I208 and I209.
SHARED_CODES = ("S130", "S131", "I207", "I210")


def shared_findings(verdict) -> list:
    """validate's findings of SHARED_CODES (its configuration's severities and ignores)."""
    return [f for f in verdict.findings if f.code in SHARED_CODES]


@dataclass
class InertiaReport:
    """One model's inertia report. A refused model (`refused`) has only `verdict`."""

    model: Path
    robot: object                       # reedtool.model.Robot
    verdict: object                     # workflows.validation.Verdict
    refused: bool = False
    comparisons: list = field(default_factory=list)   # physics.inertia comparisons, judged
    whole: object = None                # Pinocchio's whole-robot MassProperties
    own: object = None                  # reedtool's own sum over links
    own_agrees: bool = True             # the two sums agree (mass and COM to 1e-9)
    findings: list = field(default_factory=list)      # shared findings, then other errors

    @property
    def failing(self) -> list:
        return [c for c in self.comparisons if c.failing]

    def exit_code(self, failing: list | None = None) -> int:
        """1 when a link (of `failing`, default every failing one) or a shared finding is
        an error; else 0."""
        failing = self.failing if failing is None else failing
        errors = [f for f in self.findings if f.severity == "error" and f.code in SHARED_CODES]
        return 1 if self.refused or failing or errors else 0


def _sums_agree(own, whole) -> bool:
    import numpy as np

    mass_gap = abs(own.mass_kg - whole.mass_kg)
    com_gap = float(np.linalg.norm(own.com_m - whole.com_m))
    return mass_gap <= 1e-9 * max(1.0, whole.mass_kg) and com_gap <= 1e-9


def check_inertia(model: Path, request: ModelRequest, *, fix: bool = False,
                  ignore_validation: bool = False) -> InertiaReport:
    """The inertia report of one model (refused when validate's errors make it
    meaningless, unless `ignore_validation`); `fix` refuses a model --fix cannot edit."""
    from reedtool.checks.preflight import require_sound_model
    from reedtool.physics.inertia import compare_links, whole_robot
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.workflows.validation import judge, judge_links

    robot, _ = load_robot_for(model, request, require_sound=False)
    if fix and robot.source_format != "urdf":
        # The blocks --fix writes or prints are URDF <inertial>; SDF spells them differently.
        raise ReedtoolError("--fix edits URDF and xacro models only", file=model,
                            hint="run without --fix and copy the geometry values into the "
                                 "SDF <inertial> by hand")
    if not robot.links:
        raise ReedtoolError("the model has no links", file=model)
    require_sound_model(robot)
    verdict = judge(model, robot, request, "inertia")
    if verdict.refusing and not ignore_validation:
        return InertiaReport(model, robot, verdict, refused=True)
    # Each verdict's severity is its rule's, as the configuration sets it for validate.
    comparisons = judge_links(model, robot, request, compare_links(robot))
    own, whole = whole_robot(robot), whole_robot_pinocchio(robot)
    # The shared model-level findings (any severity), then validate's other errors.
    findings = shared_findings(verdict)
    shown = {(f.code, f.subject, f.message) for f in findings}
    findings += [f for f in verdict.errors if (f.code, f.subject, f.message) not in shown]
    return InertiaReport(model, robot, verdict, False, comparisons, whole, own,
                         _sums_agree(own, whole), findings)


def still_failing(report: InertiaReport, fixed: set[str], is_urdf: bool) -> list:
    """What --fix rewrote no longer fails; what it could only print still does."""
    return [c for c in report.failing if c.corrected() is None
            or (not is_urdf and c.link not in fixed)]
