"""What the docs state about the code, checked against the code (issue 19 item 8).

The rules anchors are checked in test_sarif.py (every helpUri against rules.md)."""

from __future__ import annotations

import re
from pathlib import Path

import reedtool
from reedtool.checks.registry import FAMILIES

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_pre_commit_rev_in_ci_md_is_this_version_tag():
    # The release tag is v<version>; a pinned rev naming another version points users
    # at a tag that does not exist (or at an old hook).
    revs = re.findall(r"^\s*rev:\s*(\S+)", (DOCS / "ci.md").read_text(), flags=re.M)
    assert revs and set(revs) == {f"v{reedtool.__version__}"}


def test_the_rule_family_table_lists_each_family_once():
    text = (DOCS / "validate.md").read_text()
    table = text[text.index("| Family | Codes | Checks |"):]
    table = table[:table.index("\n\n")]
    rows = [line.split("|")[1:3] for line in table.splitlines()[2:]]
    families = [(name.strip(), codes.strip()) for name, codes in rows]
    assert families == [(title, f"{letter}{digit}xx")
                        for (letter, (_module, title)), digit in zip(FAMILIES.items(), "1234")]
    count = re.search(r"(\w+) families:", text).group(1)
    assert count.lower() == ["one", "two", "three", "four", "five", "six"][len(FAMILIES) - 1]


def test_validate_md_does_not_say_hover_test_refuses_ardupilot_rotors():
    # It flies them with the time constant their joint PID implies (docs/hover-test.md).
    text = " ".join((DOCS / "validate.md").read_text().split())
    assert not re.search(r"ArduPilot rotors have no time constants, so `hover-test`[^.]*"
                         r"refuses them", text)
    assert "derived:" in text
