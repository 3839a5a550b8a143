"""validate's findings on a model, as every command sees them: the nearest configuration's
selection, severities and suppressions, then the command line's `--select`/`--ignore`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from reedtool.workflows.robots import ModelRequest, argument_use, load_models, model_arguments
from reedtool.errors import ReedtoolError


def selection_for(config, select: Sequence[str] = (), ignore: Sequence[str] = ()):
    """The rule selection of a model: the command line over its configuration."""
    from reedtool.checks.runner import Selection, parse_selectors, parse_severity_overrides

    origin = str(config.path) if config.path else "config"
    if select and not parse_selectors(select, origin="--select"):
        # `--select ""` would run no rule and report a clean model.
        raise ReedtoolError("--select names no rule", hint="give a code, prefix or rule name "
                            "such as S, I203 or R; ALL selects every rule")
    return Selection(
        select=(parse_selectors(select, origin="--select") if select
                else parse_selectors(config.select, origin=origin) if config.select is not None
                else ("",)),
        ignore=(parse_selectors(config.ignore, origin=origin)
                + parse_selectors(ignore, origin="--ignore")),
        severity=parse_severity_overrides(config.severity, origin=origin),
    )


def _ignores_for(config, model: Path):
    from reedtool.checks.runner import parse_selectors

    origin = str(config.path) if config.path else "config"

    def ignores_for(file: str | None) -> tuple[str, ...]:
        return parse_selectors(config.ignores_for(file or model), origin=origin)

    return ignores_for


@dataclass
class CheckedModel:
    """One robot of a model path with validate's findings on it."""

    suffix: str                  # "" or " [model NAME]" for each model of a world
    robot: object                # reedtool.model.Robot
    findings: list = field(default_factory=list)     # kept after suppressions
    suppressed: list = field(default_factory=list)


@dataclass
class CheckedPath:
    """What one model path gave: its robots with findings, or the input error that
    stopped it (the other paths of a run are still checked)."""

    models: list[CheckedModel] = field(default_factory=list)
    error: ReedtoolError | None = None


def check_model_path(model: Path, request: ModelRequest, *, controllers=(),
                     flight_params=()) -> CheckedPath:
    """Load `model` with its arguments and run validate's rules on each of its robots.

    A model that cannot be read gives its error in the result; a bad configuration (or
    --select) raises before anything is loaded.
    """
    from reedtool.checks.runner import apply_suppressions, run_checks
    from reedtool.config import load_config

    config = load_config(model)
    selection = selection_for(config, request.select, request.ignore)
    ignores_for = _ignores_for(config, model)
    ignores_for(model)   # a bad per-file-ignores selector is a config error, raised now
    mappings, given, origins, checked = model_arguments(model, config, request)
    try:
        arguments = argument_use(model, mappings, given, origins, checked, config, request)
        pairs = (request.preloaded.pop(model.resolve(), None)
                 or load_models(model, mappings, request.package_paths, request.model_name))
    except ReedtoolError as exc:
        return CheckedPath(error=exc)
    out = CheckedPath()
    for suffix, robot in pairs:
        findings = run_checks(robot, selection, controllers=list(controllers),
                              flight_params=list(flight_params), arguments=arguments)
        kept, dropped = apply_suppressions(findings, ignores_for)
        out.models.append(CheckedModel(suffix, robot, kept, dropped))
    return out


# ------------------------------------------------------------------ what a command refuses
#
# The computing commands run validate's rules first (the model's configuration, then
# --select/--ignore). An error in what a command builds on makes its result meaningless,
# so it refuses the model (exit 1, the errors listed; --ignore CODE or --ignore-validation
# flies it anyway). Every other error is reported beside the result. The groups are read
# from the rule registry: a rule family (its title in checks.registry.FAMILIES) less the
# rules named, or the rules named.


@dataclass(frozen=True)
class RefusalGroup:
    family: str | None = None                  # every rule of this family ...
    leave_out: frozenset[str] = frozenset()    # ... except these
    codes: frozenset[str] = frozenset()        # (or exactly these rules)

    def holds(self, rule) -> bool:
        if self.family is not None:
            return rule.family == self.family and rule.code not in self.leave_out
        return rule.code in self.codes


REFUSAL_GROUPS: dict[str, RefusalGroup] = {
    # The tree Gazebo and Pinocchio build: unreadable or non-finite numbers, links, joints,
    # limits, geometry sizes, links Gazebo drops. The mesh files (S115 unresolved, S130
    # format, S131 escaping URI) are the look and the collisions, not the dynamics; S140 is
    # an argument the model never declares. libsdformat's refusals of names, frame
    # references and materials (S160-S171) stop Gazebo, not the computation: reedtool read
    # the tree (an unreadable frame is S101's).
    "structure": RefusalGroup("Structure", frozenset(
        {"S115", "S130", "S131", "S140", *(f"S{n}" for n in range(160, 172))})),
    # The masses and inertias every number is computed from. I210 (a mesh in the wrong
    # unit) is a mesh's size, not a declared mass.
    "mass": RefusalGroup("Inertia", frozenset({"I210"})),
    # A rotor as written is not a rotor: no direction, no usable constants, its plugin
    # names nothing, it does not turn, it spins against its blades. Motor numbering (R301,
    # R302) and the MAVLink rotor count (R312) are the flight stack's wiring; yaw balance,
    # rank, trim and thrust-to-weight (R304, R305, R307, R308) are what hover-test and
    # authority compute and report themselves.
    "rotors": RefusalGroup(codes=frozenset({"R303", "R313", "R314", "R315", "R316", "R318"})),
}
# An impossible tensor (I202 not positive definite, I203 the triangle inequality) is about
# the link's own tensor. Where that tensor is smaller than the inertia spread hover-test's
# robustness batch already flies (sim.batch.Spreads.inertia_rel: each principal moment
# +-10 %) against the whole robot's smallest moment, any valid tensor in its place flies
# the same: reported beside the result, not refused (a rotor's disc tensor on a quad).
OWN_TENSOR_CODES = ("I202", "I203")
# What each command builds on. inertia's own output is the mass verdicts and layout's the
# rotors (drawn, the rotors findings name in red), so neither refuses on those.
COMMAND_NEEDS: dict[str, tuple[str, ...]] = {
    "hover-test": ("structure", "mass", "rotors"),
    "authority": ("structure", "mass", "rotors"),
    "inertia": ("structure",),
    "layout": ("structure",),
}


def refuses(code: str, groups: Sequence[str]) -> bool:
    """Does an error of rule `code` make a result built on `groups` meaningless?"""
    from reedtool.checks.registry import get_rule

    rule = get_rule(code)
    return rule is not None and any(REFUSAL_GROUPS[group].holds(rule) for group in groups)


@dataclass
class Verdict:
    """validate's errors on a model, split by what a command does with them."""

    refusing: list = field(default_factory=list)   # the result would be meaningless
    reported: list = field(default_factory=list)   # shown beside the result
    findings: list = field(default_factory=list)   # every kept finding, any severity

    @property
    def errors(self) -> list:
        return [*self.refusing, *self.reported]


def validation_findings(model: Path, robot, request: ModelRequest) -> list:
    """validate's findings on `robot`, every severity (its configuration, then the
    request's --select and --ignore, then the suppressions)."""
    from reedtool.checks.runner import apply_suppressions, run_checks
    from reedtool.config import load_config

    config = load_config(model)
    findings = run_checks(robot, selection_for(config, request.select, request.ignore))
    kept, _ = apply_suppressions(findings, _ignores_for(config, model))
    return kept


def judge(model: Path, robot, request: ModelRequest, command: str) -> Verdict:
    """validate's errors on `robot` (its configuration, then the request's --select and
    --ignore), split into those `command` refuses on and those it reports."""
    kept = validation_findings(model, robot, request)
    needs = COMMAND_NEEDS[command]
    verdict = Verdict(findings=kept)
    for f in kept:
        if f.severity == "error":
            refusing = refuses(f.code, needs) and not _flies_the_same(robot, f)
            (verdict.refusing if refusing else verdict.reported).append(f)
    return verdict


def _flies_the_same(robot, finding) -> bool:
    """An impossible tensor too small to change the flight (OWN_TENSOR_CODES)."""
    from reedtool.physics.inertia import own_tensor_share
    from reedtool.sim.batch import Spreads

    if finding.code not in OWN_TENSOR_CODES or not finding.subject:
        return False
    share = own_tensor_share(robot, finding.subject)
    return share is not None and share < Spreads().inertia_rel


def refusal_table() -> list[tuple[str, str, str]]:
    """(command, groups, rule codes) rows for the docs and --help."""
    from reedtool.checks.registry import all_rules

    rows = []
    for command, needs in COMMAND_NEEDS.items():
        codes = [r.code for r in all_rules() if r.severity == "error" and refuses(r.code, needs)]
        rows.append((command, ", ".join(needs), " ".join(codes)))
    return rows


# ------------------------------------------------------------------ inertia's link verdicts
#
# `reedtool inertia` shows physics.inertia.compare_links' verdict per link, the same verdict
# the I2xx rules word as findings. Its severity is the reporting rule's, with the model's
# configuration and the command line applied exactly as for validate: the registry holds
# the default, `[tool.reedtool] severity` may change it, `ignore` may switch it off.

# Verdicts reported by one rule whatever the link; the others are decided in verdict_code.
VERDICT_RULES: dict[str, str] = {
    "negative-mass": "I201",       # mass-not-positive
    "massless-moving": "I201",
    "implausible": "I204",         # inertia-implausible-for-geometry
    "way-off": "I209",
}
# An impossible tensor, by physics.inertia.tensor_problem: NaN/inf is a non-finite number.
INVALID_TENSOR_RULES: dict[str, str] = {"non-finite": "S102", "not-positive-definite": "I202",
                                        "triangle": "I203"}


def verdict_code(comparison, moving: bool) -> str | None:
    """The code of the rule that reports a link's inertia verdict; None when none does
    (ok, differs, slowdown-scaled, placeholder, ...: nothing to judge)."""
    if comparison.verdict == "invalid":
        return INVALID_TENSOR_RULES.get(comparison.tensor_problem, "I202")
    if comparison.verdict == "massless-inertia":
        # On a link that moves, the zero mass itself is I201 (I208 stays quiet there).
        return "I201" if moving else "I208"
    return VERDICT_RULES.get(comparison.verdict)


def judge_links(model: Path, robot, request: ModelRequest, comparisons: list) -> list:
    """`comparisons` (physics.inertia.compare_links) with each link's severity: that of the
    rule reporting its verdict, under the model's configuration and --select/--ignore; None
    where no rule reports it or the rule is switched off (also for the link's file by
    per-file-ignores)."""
    from dataclasses import replace

    from reedtool.checks.registry import get_rule
    from reedtool.config import load_config
    from reedtool.physics.inertia import moving_links

    config = load_config(model)
    selection = selection_for(config, request.select, request.ignore)
    ignores_for = _ignores_for(config, model)
    moving = moving_links(robot)
    judged = []
    for c in comparisons:
        code = verdict_code(c, c.link in moving)
        rule = get_rule(code) if code else None
        on = (rule is not None and selection.enabled(code)
              and not any(code.startswith(s) for s in ignores_for(c.loc.file)))
        judged.append(replace(c, severity=selection.severity_of(rule) if on else None))
    return judged
