"""What a rule reports: `Issue` (what the rule knows) and `Finding` (what the user sees).

A rule function only knows what is wrong, where, and how to fix it; the runner stamps the
rule's code, slug and (possibly overridden) severity on each issue. Keeping rule metadata
out of rule bodies is what lets `--select`, severity overrides and docs/rules.md work from
the registry alone.
"""

from __future__ import annotations

from dataclasses import dataclass

from reedtool.model import SourceLoc

SEVERITIES = ("error", "warning", "info")
JSON_FIELDS = ("code", "slug", "severity", "message", "subject", "file", "line", "hint")


@dataclass(frozen=True)
class Issue:
    """One problem found by a rule, before the rule's identity is attached."""

    message: str                     # with the numbers that matter and their units
    loc: SourceLoc | None = None     # where to edit; None: the robot element
    subject: str | None = None       # link, joint, rotor or plugin name
    hint: str | None = None          # how to fix, with the correct value where known


@dataclass(frozen=True)
class Finding:
    code: str
    slug: str
    severity: str
    message: str
    subject: str | None
    file: str | None
    line: int | None
    hint: str | None
    # The macro-body line behind `line` when the element came from a macro (text output
    # only; the JSON schema keeps to the fields above).
    macro: str | None = None

    def sort_key(self) -> tuple:
        # Deterministic output: by file, line, then code; findings without a file last.
        return (self.file is None, self.file or "", self.line or 0, self.code,
                self.subject or "", self.message, self.macro or "")

    def to_dict(self) -> dict:
        return {name: getattr(self, name) for name in JSON_FIELDS}


def severity_counts(findings: list[Finding]) -> dict[str, int]:
    counts = {severity: 0 for severity in SEVERITIES}
    for finding in findings:
        counts[finding.severity] += 1
    return counts
