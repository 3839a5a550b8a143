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
