"""The run-level suppression check (S143): which inline suppressions no model of the run
needed, each reported once, on the first model of the run that read its file."""

from __future__ import annotations

from reedtool.checks.finding import Finding
from reedtool.checks.suppression_rules import SuppressionUse

CODE = "S143"


def suppression_use(robot, dropped, selection) -> tuple[SuppressionUse, str | None]:
    """What one checked robot tells the run (its files, the comments that silenced its
    `dropped` findings, its rules), and S143's severity for it (None: not selected)."""
    from reedtool.checks.registry import all_rules, get_rule
    from reedtool.checks.suppressions import silencers, source_files

    used = {entry for f in dropped for entry in silencers(f.code, f.slug, f.file, f.line)}
    enabled = frozenset(r.code for r in all_rules() if selection.enabled(r.code))
    rule = get_rule(CODE)
    severity = selection.severity_of(rule) if CODE in enabled else None
    return SuppressionUse(source_files(robot), used, enabled), severity


def unused_suppressions(uses: list[tuple[str, SuppressionUse, str | None]]
                        ) -> dict[str, list[Finding]]:
    """S143's findings by model name, from each model's (name, use, S143 severity)."""
    from reedtool.checks.registry import get_rule

    rule = get_rule(CODE)
    judged = [(name, use, severity) for name, use, severity in uses if severity is not None]
    out: dict[str, list[Finding]] = {}
    for issue in rule.check([use for _, use, _ in judged]):
        owner = next(((name, use, severity) for name, use, severity in judged
                      if issue.loc.file in use.files), None)
        if owner is None:
            continue
        name, use, severity = owner
        out.setdefault(name, []).append(Finding(
            code=rule.code, slug=rule.slug, severity=severity, message=issue.message,
            subject=issue.subject, file=use.files[issue.loc.file], line=issue.loc.line,
            hint=issue.hint))
    return out
