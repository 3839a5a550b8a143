"""docs/rules.md is generated from the registry; this fails when they drift apart."""

from __future__ import annotations

import re
from pathlib import Path

from reedtool.checks.registry import all_rules
from reedtool.checks.rules_doc import render

# The checkout's docs, not the installed package's location: CI tests the installed wheel.
DOCS_RULES_MD = Path(__file__).resolve().parent.parent / "docs" / "rules.md"


def test_rules_md_is_up_to_date():
    assert DOCS_RULES_MD.read_text(encoding="utf-8") == render(), (
        "docs/rules.md is stale: run `python -m reedtool.checks.rules_doc --write`")


def test_every_rule_is_documented_once():
    text = render()
    rules = all_rules()
    assert len({r.code for r in rules}) == len(rules)
    assert len({r.slug for r in rules}) == len(rules)
    for rule in rules:
        assert re.fullmatch(r"[A-Z]\d{3}", rule.code)
        assert text.count(f"\n### {rule.code} {rule.slug}\n") == 1
        assert len(rule.explanation) > 80, f"{rule.code} needs a real explanation"
        assert "\n" not in rule.summary


def test_every_rule_states_its_severity_clause():
    """The severity policy (docs/validate.md): each rule names the clause that gives its
    default severity, the clause allows that severity, and docs/rules.md shows it."""
    from reedtool.checks.registry import POLICY_CLAUSES

    text = render()
    for rule in all_rules():
        allowed, wording = POLICY_CLAUSES[rule.clause]
        assert rule.severity in allowed, rule.code
        # ... and its docstring says why, in its own words.
        assert f"Severity ({rule.severity}" in rule.explanation, rule.code
        assert f"| {rule.severity} | {rule.clause} |" in text
        assert f"*Default severity: {rule.severity}* ({rule.clause}: {wording})" in text
    # The policy's error clauses are few on purpose; every warning-or-softer rule that can
    # meet a convention says so in words.
    assert {r.clause for r in all_rules()} == set(POLICY_CLAUSES)
    validate_md = (DOCS_RULES_MD.parent / "validate.md").read_text(encoding="utf-8")
    assert "## Severity policy" in validate_md
    for key in POLICY_CLAUSES:
        assert f"**{key}**" in validate_md
