"""GitHub Actions workflow commands: `::error file=F,line=L,title=CODE slug::message`."""

from __future__ import annotations

from reedtool.report import ModelResult, display_path

_LEVEL = {"error": "error", "warning": "warning", "info": "notice"}


def _escape_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_property(text: str) -> str:
    return _escape_data(text).replace(":", "%3A").replace(",", "%2C")


def _command(level: str, file: str | None, line: int | None, title: str, message: str) -> str:
    props = []
    if file:
        props.append(f"file={_escape_property(file)}")
        if line:
            props.append(f"line={line}")
    props.append(f"title={_escape_property(title)}")
    return f"::{level} {','.join(props)}::{_escape_data(message)}"


def format_github(results: list[ModelResult]) -> str:
    lines = []
    for result in results:
        if result.error is not None:
            lines.append(_command("error", display_path(result.error_file) or result.name,
                                  result.error_line, "reedtool input error", result.error))
        for finding in result.findings:
            subject = f"[{finding.subject}] " if finding.subject else ""
            message = f"{subject}{finding.message}"
            if finding.hint:
                message += f"\nhint: {finding.hint}"
            lines.append(_command(_LEVEL[finding.severity], display_path(finding.file),
                                  finding.line, f"{finding.code} {finding.slug}", message))
    return "".join(line + "\n" for line in lines)
