"""Text output for people: findings grouped by file, one line each, the hint below."""

from __future__ import annotations

from itertools import groupby

import click

from reedtool.checks.finding import Finding, severity_counts
from reedtool.report import ModelResult, all_findings, display_path, statistics, summary_line

_COLOURS = {"error": "red", "warning": "yellow", "info": "blue"}
_INDENT = " " * 22


def _styler(color: bool):
    def style(text: str, **kwargs) -> str:
        return click.style(text, **kwargs) if color else text
    return style


def _tail_colour(findings: list[Finding]) -> str:
    counts = severity_counts(findings)
    return "red" if counts["error"] else "yellow" if counts["warning"] else "green"


def _model_block(result: ModelResult, style) -> list[str]:
    lines: list[str] = []
    if result.error is not None:
        lines.append(style(f"{result.name}: error: {result.error}", fg="red", bold=True))
        return lines
    if result.skipped is not None:
        lines.append(style(f"{result.name}: skipped: {result.skipped}", dim=True))
        return lines
    for file, group in groupby(result.findings, key=lambda f: f.file):
        lines.append(style(display_path(file) or "<model>", bold=True))
        for finding in group:
            where = str(finding.line) if finding.line else "-"
            severity = style(f"{finding.severity:<7}", fg=_COLOURS[finding.severity], bold=True)
            subject = f"[{finding.subject}] " if finding.subject else ""
            lines.append(f"  {where:>5}  {severity}  {style(finding.code, bold=True)}  "
                         f"{subject}{finding.message} " + style(f"({finding.slug})", dim=True))
            if finding.macro:
                macro_file, _, macro_line = finding.macro.rpartition(":")
                shown = (f"{display_path(macro_file)}:{macro_line}" if macro_line.isdigit()
                         else display_path(finding.macro))
                lines.append(_INDENT + style(f"in macro body at {shown}", dim=True))
            if finding.hint:
                lines.append(_INDENT + style(f"hint: {finding.hint}", fg="cyan"))
        lines.append("")
    tail = f"{result.name}: {summary_line(result.findings)}"
    if result.suppressed:
        tail += f" ({result.suppressed} suppressed)"
    if result.baselined:
        tail += f" ({result.baselined} in the baseline)"
    lines.append(style(tail, fg=_tail_colour(result.findings), bold=True))
    return lines


def format_text(results: list[ModelResult], *, color: bool = False,
                show_statistics: bool = False) -> str:
    style = _styler(color)
    lines: list[str] = []
    for index, result in enumerate(results):
        if index:
            lines.append("")
        lines.extend(_model_block(result, style))
    if len(results) > 1:
        findings = all_findings(results)
        failed = sum(1 for r in results if r.error is not None)
        tail = f"{len(results)} models: {summary_line(findings)}"
        if failed:
            tail += f"; {failed} could not be read"
        lines += ["", style(tail, fg="red" if failed else _tail_colour(findings), bold=True)]
    if show_statistics:
        rows = statistics(results)
        lines.append("")
        for count, code, slug, severity in rows:
            lines.append(f"{count:>5}  {code}  {severity:<7}  {slug}")
        if not rows:
            lines.append("    0  (no findings)")
    return "\n".join(lines) + "\n"
