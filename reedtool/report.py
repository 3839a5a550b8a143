"""Formatters for validate findings: text (people), json (tools), github (CI annotations).

Each formatter returns the whole output as one string, so the command decides where it
goes and tests can compare it. Paths are shown relative to the working directory when the
file is below it, which is also what GitHub annotations need.
"""

from __future__ import annotations

import json
import os
from itertools import groupby
from pathlib import Path

import click

from reedtool import __version__
from reedtool.checks.finding import Finding, severity_counts

FORMATS = ("text", "json", "github")

_COLOURS = {"error": "red", "warning": "yellow", "info": "blue"}
_GITHUB_LEVEL = {"error": "error", "warning": "warning", "info": "notice"}


def display_path(file: str | None, cwd: Path | None = None) -> str | None:
    if file is None:
        return None
    cwd = cwd or Path.cwd()
    try:
        return os.path.relpath(file, cwd) if Path(file).resolve().is_relative_to(cwd.resolve()) \
            else file
    except (ValueError, OSError):  # different drive, or not a real path
        return file


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def summary_line(findings: list[Finding]) -> str:
    counts = severity_counts(findings)
    if not findings:
        return "no findings"
    return ", ".join([_plural(counts["error"], "error"), _plural(counts["warning"], "warning"),
                      f"{counts['info']} info"])


def format_text(findings: list[Finding], model: str, *, color: bool = False) -> str:
    """Findings grouped by file; one line each, the hint indented below it."""

    def style(text: str, **kwargs) -> str:
        return click.style(text, **kwargs) if color else text

    lines: list[str] = []
    indent = " " * 22
    for file, group in groupby(findings, key=lambda f: f.file):
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
                lines.append(f"{indent}" + style(f"in macro body at {shown}", dim=True))
            if finding.hint:
                lines.append(f"{indent}" + style(f"hint: {finding.hint}", fg="cyan"))
        lines.append("")
    tail = f"{display_path(model)}: {summary_line(findings)}"
    counts = severity_counts(findings)
    if counts["error"]:
        tail = style(tail, fg="red", bold=True)
    elif counts["warning"]:
        tail = style(tail, fg="yellow", bold=True)
    else:
        tail = style(tail, fg="green", bold=True)
    lines.append(tail)
    return "\n".join(lines) + "\n"


def format_json(findings: list[Finding], model: str) -> str:
    document = {
        "schema": 1,
        "tool": "reedtool",
        "version": __version__,
        "model": display_path(model),
        "findings": [{**f.to_dict(), "file": display_path(f.file)} for f in findings],
        "summary": severity_counts(findings),
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def _escape_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_property(text: str) -> str:
    return _escape_data(text).replace(":", "%3A").replace(",", "%2C")


def format_github(findings: list[Finding], model: str) -> str:
    """GitHub Actions workflow commands: `::error file=F,line=L,title=CODE slug::message`."""
    lines = []
    for finding in findings:
        props = []
        path = display_path(finding.file)
        if path:
            props.append(f"file={_escape_property(path)}")
            if finding.line:
                props.append(f"line={finding.line}")
        props.append(f"title={_escape_property(f'{finding.code} {finding.slug}')}")
        subject = f"[{finding.subject}] " if finding.subject else ""
        message = f"{subject}{finding.message}"
        if finding.hint:
            message += f"\nhint: {finding.hint}"
        lines.append(f"::{_GITHUB_LEVEL[finding.severity]} {','.join(props)}"
                     f"::{_escape_data(message)}")
    return "".join(line + "\n" for line in lines)


def render(findings: list[Finding], model: str, fmt: str, *, color: bool = False) -> str:
    if fmt == "json":
        return format_json(findings, model)
    if fmt == "github":
        return format_github(findings, model)
    return format_text(findings, model, color=color)

