"""SARIF 2.1.0 for GitHub code scanning (github/codeql-action/upload-sarif) and other viewers.

One run; `tool.driver.rules` lists the rules that fired (with their documentation), each
result points at its rule by id and index. An input error becomes a tool execution
notification and makes the invocation unsuccessful, as SARIF intends.

Every artifact URI is relative, with `uriBaseId` SRCROOT (`originalUriBaseIds` gives its
absolute file: URI): GitHub joins relative URIs to the checkout, and an absolute path of
the CI machine links nowhere. SRCROOT is the git work tree holding the working
directory (else the working directory), widened to a common ancestor when a model lies
outside it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from urllib.parse import quote

from reedtool import __version__
from reedtool.report import ModelResult

SCHEMA_URI = "https://json.schemastore.org/sarif-2.1.0.json"
SRCROOT = "SRCROOT"
_LEVEL = {"error": "error", "warning": "warning", "info": "note"}
_HELP_URI = "https://github.com/reedtool/reedtool/blob/main/docs/rules.md#{anchor}"


def rule_anchor(code: str, slug: str) -> str:
    """The anchor GitHub gives docs/rules.md's heading "### S101 urdf-parse-error":
    lower case, spaces to hyphens (codes and slugs hold nothing else it strips)."""
    return f"{code} {slug}".lower().replace(" ", "-")


def _git_root(directory: Path) -> Path | None:
    for candidate in (directory, *directory.parents):
        if (candidate / ".git").exists():
            return candidate
    return None


def source_root(files: list[str], cwd: Path | None = None) -> Path:
    """SRCROOT for these files: see the module docstring."""
    cwd = (cwd or Path.cwd()).resolve()
    root = _git_root(cwd) or cwd
    resolved = [Path(os.path.abspath(f)) for f in files]
    if all(f.is_relative_to(root) for f in resolved):
        return root
    try:
        return Path(os.path.commonpath([str(root), *map(str, resolved)]))
    except ValueError:          # another drive (Windows): the files' own common root
        return Path(os.path.commonpath(list(map(str, resolved)))) if resolved else root


def _directory_uri(root: Path) -> str:
    uri = root.as_uri()        # SARIF: a base URI ends with a slash ("file:///" for /)
    return uri if uri.endswith("/") else uri + "/"


def _location(path: str, root: Path) -> dict:
    relative = Path(os.path.relpath(os.path.abspath(path), root)).as_posix()
    return {"uri": quote(relative, safe="/-._~"), "uriBaseId": SRCROOT}


def _rule_descriptor(code: str) -> dict:
    from reedtool.checks.registry import get_rule

    rule = get_rule(code)
    return {
        "id": code,
        "name": rule.slug,
        "shortDescription": {"text": rule.summary},
        "fullDescription": {"text": rule.explanation or rule.summary},
        "defaultConfiguration": {"level": _LEVEL[rule.severity]},
        "helpUri": _HELP_URI.format(anchor=rule_anchor(code, rule.slug)),
        "properties": {"family": rule.family},
    }


def format_sarif(results: list[ModelResult]) -> str:
    def file_of(path: str | None, result: ModelResult) -> str:
        return path or result.name

    files = [file_of(f.file, r) for r in results for f in r.findings] + \
            [file_of(r.error_file, r) for r in results if r.error is not None]
    root = source_root(files)
    codes = sorted({f.code for r in results for f in r.findings})
    index = {code: i for i, code in enumerate(codes)}
    sarif_results = []
    for result in results:
        for finding in result.findings:
            message = f"[{finding.subject}] {finding.message}" if finding.subject \
                else finding.message
            if finding.hint:
                message += f" (hint: {finding.hint})"
            _path, bracket, which = result.name.partition(" [")
            if bracket:
                # An argument variant or one model of a world: the same line may carry a
                # finding in one variant and not in another, so the alert names which.
                message += f" [{which}"
            entry: dict = {
                "ruleId": finding.code,
                "ruleIndex": index[finding.code],
                "level": _LEVEL[finding.severity],
                "message": {"text": message},
                "properties": {"model": result.name, "slug": finding.slug},
            }
            physical: dict = {"artifactLocation": _location(file_of(finding.file, result),
                                                            root)}
            if finding.line:
                physical["region"] = {"startLine": finding.line}
            entry["locations"] = [{"physicalLocation": physical}]
            sarif_results.append(entry)
    notifications = []
    for result in results:
        if result.error is None:
            continue
        note: dict = {"level": "error", "message": {"text": f"{result.name}: {result.error}"}}
        physical = {"artifactLocation": _location(file_of(result.error_file, result), root)}
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
            "originalUriBaseIds": {SRCROOT: {"uri": _directory_uri(root)}},
            "invocations": [invocation],
            "results": sarif_results,
        }],
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
