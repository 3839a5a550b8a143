"""SARIF 2.1.0 for GitHub code scanning (github/codeql-action/upload-sarif) and other viewers.

One run; `tool.driver.rules` lists the rules that fired (with their documentation), each
result points at its rule by id and index. An input error becomes a tool execution
notification and makes the invocation unsuccessful, as SARIF intends.
"""

from __future__ import annotations

import json

from reedtool import __version__
from reedtool.report import ModelResult, display_path

SCHEMA_URI = "https://json.schemastore.org/sarif-2.1.0.json"
_LEVEL = {"error": "error", "warning": "warning", "info": "note"}
_HELP_URI = "https://github.com/reedtool/reedtool/blob/main/docs/rules.md#{anchor}"


def _uri(path: str) -> str:
    # A relative path is a relative URI reference; backslashes are not URI separators.
    return path.replace("\\", "/")


def _rule_descriptor(code: str) -> dict:
    from reedtool.checks.registry import get_rule

    rule = get_rule(code)
    return {
        "id": code,
        "name": rule.slug,
        "shortDescription": {"text": rule.summary},
        "fullDescription": {"text": rule.explanation or rule.summary},
        "defaultConfiguration": {"level": _LEVEL[rule.severity]},
        "helpUri": _HELP_URI.format(anchor=code.lower()),
        "properties": {"family": rule.family},
    }


def format_sarif(results: list[ModelResult]) -> str:
    codes = sorted({f.code for r in results for f in r.findings})
    index = {code: i for i, code in enumerate(codes)}
    sarif_results = []
    for result in results:
        for finding in result.findings:
            message = f"[{finding.subject}] {finding.message}" if finding.subject \
                else finding.message
            if finding.hint:
                message += f" (hint: {finding.hint})"
            entry: dict = {
                "ruleId": finding.code,
                "ruleIndex": index[finding.code],
                "level": _LEVEL[finding.severity],
                "message": {"text": message},
                "properties": {"model": result.name, "slug": finding.slug},
            }
            path = display_path(finding.file) or result.name
            physical: dict = {"artifactLocation": {"uri": _uri(path)}}
            if finding.line:
                physical["region"] = {"startLine": finding.line}
            entry["locations"] = [{"physicalLocation": physical}]
            sarif_results.append(entry)
    notifications = []
    for result in results:
        if result.error is None:
            continue
        note: dict = {"level": "error", "message": {"text": f"{result.name}: {result.error}"}}
        path = display_path(result.error_file) or result.name
        physical = {"artifactLocation": {"uri": _uri(path)}}
        if result.error_line:
            physical["region"] = {"startLine": result.error_line}
        note["locations"] = [{"physicalLocation": physical}]
        notifications.append(note)
    invocation: dict = {"executionSuccessful": not notifications}
    if notifications:
        invocation["toolExecutionNotifications"] = notifications
    document = {
        "$schema": SCHEMA_URI,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": "reedtool",
                "version": __version__,
                "informationUri": "https://github.com/reedtool/reedtool",
                "rules": [_rule_descriptor(code) for code in codes],
            }},
            "invocations": [invocation],
            "results": sarif_results,
        }],
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
