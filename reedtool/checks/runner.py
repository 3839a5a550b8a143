"""Run the selected rules over one robot and collect findings.

Selection follows ruff: `select` and `ignore` are code prefixes (or rule names, which
stand for their code) and, for each rule, the longest prefix that matches it decides (an
ignore wins a tie). Severity overrides are prefixes too, longest match wins.

Each rule runs on its own: an exception in one becomes one error finding of that rule
("internal error in this rule: ..."), the other rules' findings are kept, and `validate`
exits 3 (`has_internal_errors`). REEDTOOL_DEBUG=1 lets the exception through instead.

A static SDF model is scenery: the inertia (I) and rotor (R) families, which judge a
vehicle, do not run on it (SCENERY_EXEMPT_FAMILIES).

After the rules ran, `apply_suppressions` drops findings silenced by an inline XML comment
(reedtool.checks.suppressions) or by a per-file ignore of the configuration.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import SEVERITIES, Finding, Issue
from reedtool.checks.registry import Rule, all_rules, suggest_selector
from reedtool.errors import ReedtoolError, shorten, shorten_names
from reedtool.model import Robot

_SELECTOR = re.compile(r"^[A-Z]\d{0,3}$")
INTERNAL_ERROR = "internal error in this rule: "
# A static SDF model (a warehouse floor, a runway) is never moved by the physics engine:
# the inertia family (masses, tensors, mesh units against a vehicle's size) and the rotor
# family judge a vehicle, and libsdformat loads a static model whatever they would say.
# Families by their registry title (checks.registry.FAMILIES), read from each rule.
SCENERY_EXEMPT_FAMILIES = ("Inertia", "Rotors")


def has_internal_errors(findings: Iterable[Finding]) -> bool:
    """Whether a rule crashed (a reedtool bug): the report is then incomplete."""
    return any(f.message.startswith(INTERNAL_ERROR) for f in findings)


def _issues_of(rule: Rule, ctx: CheckContext) -> tuple[list[Issue], bool]:
    """The rule's issues, and whether it crashed: then its issues so far plus one naming
    the exception, so one rule's bug cannot take the rest of the report with it."""
    issues: list[Issue] = []
    try:
        for issue in rule.check(ctx):
            issues.append(issue)
    except Exception as exc:  # noqa: BLE001 - isolates a bug to its own rule
        if os.environ.get("REEDTOOL_DEBUG"):
            raise
        detail = " ".join(str(exc).split()) or "no message"
        issues.append(Issue(f"{INTERNAL_ERROR}{type(exc).__name__}: {detail}",
                            hint="this is a reedtool bug, not a finding about the model: "
                                 "rerun with REEDTOOL_DEBUG=1 for the traceback and report it"))
        return issues, True
    return issues, False


def _longest(prefixes: Iterable[str], code: str) -> int:
    return max((len(p) for p in prefixes if code.startswith(p)), default=-1)


@dataclass(frozen=True)
class Selection:
    select: tuple[str, ...] = ("",)
    ignore: tuple[str, ...] = ()
    severity: Mapping[str, str] = field(default_factory=dict)  # code prefix -> severity

    def enabled(self, code: str) -> bool:
        selected, ignored = _longest(self.select, code), _longest(self.ignore, code)
        return selected >= 0 and selected > ignored

    def severity_of(self, rule: Rule) -> str:
        best, severity = -1, rule.severity
        for prefix, value in self.severity.items():
            if rule.code.startswith(prefix) and len(prefix) > best:
                best, severity = len(prefix), value
        return severity


def parse_selectors(values: Iterable[str], *, origin: str) -> tuple[str, ...]:
    """Normalise user selectors ("R3", "i203", "ALL") and reject ones that match no rule.

    `origin` names where they came from (an option or a config file) for the error.
    """
    rules = all_rules()
    codes = [r.code for r in rules]
    by_slug = {r.slug: r.code for r in rules}
    out: list[str] = []
    for raw in values:
        for part in str(raw).split(","):
            selector = part.strip().upper()
            if not selector:
                continue
            if part.strip().lower() in by_slug:      # a rule name stands for its code
                selector = by_slug[part.strip().lower()]
            elif selector == "ALL":
                selector = ""
            elif not _SELECTOR.match(selector) or not any(c.startswith(selector) for c in codes):
                guess = suggest_selector(part)
                raise ReedtoolError(f"unknown rule selector '{part.strip()}' in {origin}",
                                    hint=(f"did you mean '{guess}'? " if guess else "")
                                    + "use a code, code prefix or rule name such as S1, I203, "
                                      "R or inertia-triangle-inequality; "
                                      "`reedtool rules` lists them")
            out.append(selector)
    return tuple(out)


def parse_severity_overrides(values: Mapping[str, str], *, origin: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for key, value in values.items():
        (prefix,) = parse_selectors([key], origin=origin) or ("",)
        severity = str(value).strip().lower()
        if severity not in SEVERITIES:
            raise ReedtoolError(f"severity for '{key}' in {origin} must be one of "
                                f"{', '.join(SEVERITIES)}, not '{value}'")
        out[prefix] = severity
    return out


def run_checks(robot: Robot, selection: Selection | None = None, *,
               controllers: Sequence = (), flight_params: Sequence = (),
               arguments=None) -> list[Finding]:
    """Every finding of every selected rule, in deterministic order, duplicates removed.

    `controllers`: controller rotor tables read from files (reedtool.flightstack.controller_tables).
    `arguments`: the xacro arguments given and known (reedtool.io.xacro_args.ArgumentUse).
    """
    selection = selection or Selection()
    ctx = CheckContext(robot, controllers, flight_params, arguments)
    findings: set[Finding] = set()
    for rule in all_rules():
        if rule.run_level or not selection.enabled(rule.code):
            continue      # a run-level rule is judged over the whole run (validate)
        if robot.static and rule.family in SCENERY_EXEMPT_FAMILIES:
            continue    # scenery: Gazebo never moves a static model, its masses are unused
        severity = selection.severity_of(rule)
        issues, crashed = _issues_of(rule, ctx)
        for issue in issues:
            if crashed and issue is issues[-1]:
                severity = "error"  # whatever the rule's severity: the report is incomplete
            loc = issue.loc or robot.loc
            # Names the user wrote are shown at most ~80 characters long (a 1 MB link name
            # would otherwise be echoed whole); errors.shorten is the one place for that.
            findings.add(Finding(code=rule.code, slug=rule.slug, severity=severity,
                                 message=shorten_names(issue.message),
                                 subject=shorten(issue.subject) if issue.subject else None,
                                 file=loc.file if loc else None,
                                 line=loc.line if loc else None,
                                 hint=shorten_names(issue.hint) if issue.hint else None,
                                 macro=loc.macro if loc else None))
    return sorted(findings, key=Finding.sort_key)


def apply_suppressions(findings: Sequence[Finding], ignores_for=None
                       ) -> tuple[list[Finding], list[Finding]]:
    """Findings left after inline comments and per-file ignores; and those dropped (what
    the unused-suppression check S143 learns which comments silenced something from).

    `ignores_for(file) -> selectors` gives the per-file ignore selectors (already parsed
    by `parse_selectors`) that apply to a file; None: no per-file ignores.
    """
    from reedtool.checks.suppressions import is_suppressed

    kept: list[Finding] = []
    for finding in findings:
        if finding.message.startswith(INTERNAL_ERROR):
            kept.append(finding)    # a crashed rule is a reedtool bug, not the user's to silence
            continue
        if is_suppressed(finding.code, finding.slug, finding.file, finding.line):
            continue
        if ignores_for is not None:
            selectors = ignores_for(finding.file)
            if any(finding.code.startswith(s) for s in selectors):
                continue
        kept.append(finding)
    kept_ids = {id(f) for f in kept}
    return kept, [f for f in findings if id(f) not in kept_ids]
