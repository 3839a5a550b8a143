"""`rules`' listing: one line per rule (code, name, default severity, summary), or the
catalogue as JSON with each rule's metadata and documentation. Computes nothing."""

from __future__ import annotations

import json

SCHEMA = "reedtool.rules/1"


def rules_json(rules) -> str:
    from reedtool.report.json_format import envelope

    doc = {**envelope(SCHEMA), "rules": [
        {"code": r.code, "slug": r.slug, "severity": r.severity, "family": r.family,
         "summary": r.summary, "clause": r.clause, "stack": r.stack,
         "lifecycle": r.lifecycle, "explanation": r.explanation}
        for r in rules]}
    return json.dumps(doc, indent=2, ensure_ascii=False)


def rules_lines(rules) -> list[str]:
    if not rules:
        return ["no rule matches"]
    width = max(len(r.slug) for r in rules)
    return [f"{r.code}  {r.slug:<{width}}  {r.severity:<7}  {r.summary}" for r in rules]


def explanation_text(rule) -> str:
    """`validate --explain CODE`: the rule's heading, summary, documentation and the
    severity policy's clause behind its default severity."""
    return (f"{rule.code} {rule.slug} ({rule.severity}, {rule.family})\n\n"
            f"{rule.summary}\n\n"
            f"{rule.explanation}\n"
            f"\nSeverity policy ({rule.clause}): {rule.policy}.")
