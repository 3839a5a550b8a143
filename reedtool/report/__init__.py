"""Formatters for validate results: one module per output format.

A run checks one or more models; each formatter takes the list of `ModelResult`s and
returns the whole output as one string, so the command decides where it goes (stdout or
`--output-file`) and tests can compare it. Paths are shown relative to the working
directory when the file is below it, which is also what GitHub annotations and SARIF
`uri`s want.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from reedtool.checks.finding import Finding, severity_counts

FORMATS = ("text", "json", "github", "sarif", "junit")


@dataclass
class ModelResult:
    """What one model of a run gave: its findings, or the input error that stopped it."""

    name: str                                   # as the user named it (display path)
    findings: list[Finding] = field(default_factory=list)
    error: str | None = None                    # one-line input error (exit 2 for the run)
    error_file: str | None = None
    error_line: int | None = None
    suppressed: int = 0                         # findings silenced inline or per file
    baselined: int = 0                          # findings the baseline accepts
    skipped: str | None = None                  # why the file was not checked


def display_path(file: str | None, cwd: Path | None = None) -> str | None:
    if file is None:
        return None
    cwd = cwd or Path.cwd()
    try:
        return os.path.relpath(file, cwd) if Path(file).resolve().is_relative_to(cwd.resolve()) \
            else file
    except (ValueError, OSError):  # different drive, or not a real path
        return file


def plural(n: int, word: str) -> str:
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def summary_line(findings: list[Finding]) -> str:
    counts = severity_counts(findings)
    if not findings:
        return "no findings"
    return ", ".join([plural(counts["error"], "error"), plural(counts["warning"], "warning"),
                      f"{counts['info']} info"])


def all_findings(results: list[ModelResult]) -> list[Finding]:
    return [f for r in results for f in r.findings]


def statistics(results: list[ModelResult]) -> list[tuple[int, str, str, str]]:
    """(count, code, slug, severity) per rule that fired, most frequent first (ruff's order)."""
    counts: dict[tuple[str, str, str], int] = {}
    for finding in all_findings(results):
        key = (finding.code, finding.slug, finding.severity)
        counts[key] = counts.get(key, 0) + 1
    return sorted(((n, *key) for key, n in counts.items()), key=lambda t: (-t[0], t[1]))


def render(results: list[ModelResult], fmt: str, *, color: bool = False,
           show_statistics: bool = False,
           failing: frozenset[str] = frozenset({"error"})) -> str:
    """The whole output of a run in `fmt`; `failing`: the severities that fail it."""
    if fmt == "json":
        from reedtool.report.json_format import format_json

        return format_json(results, show_statistics=show_statistics)
    if fmt == "github":
        from reedtool.report.github import format_github

        return format_github(results)
    if fmt == "sarif":
        from reedtool.report.sarif import format_sarif

        return format_sarif(results)
    if fmt == "junit":
        from reedtool.report.junit import format_junit

        return format_junit(results, failing)
    from reedtool.report.text import format_text

    return format_text(results, color=color, show_statistics=show_statistics)
