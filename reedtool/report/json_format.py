"""JSON output for tools. `schema` names the document type and its version."""

from __future__ import annotations

import json

from reedtool import __version__
from reedtool.checks.finding import severity_counts
from reedtool.report import ModelResult, all_findings, display_path, statistics

SCHEMA = "reedtool.validate/1"


def envelope(schema: str) -> dict:
    """The keys every JSON document reedtool prints starts with."""
    return {"schema": schema, "tool": "reedtool", "version": __version__}


def _model(result: ModelResult) -> dict:
    entry = {
        "model": result.name,
        "findings": [{**f.to_dict(), "file": display_path(f.file)} for f in result.findings],
        "summary": severity_counts(result.findings),
        "suppressed": result.suppressed,
        "baselined": result.baselined,
        "error": None,
        "skipped": result.skipped,
    }
    if result.error is not None:
        entry["error"] = {"message": result.error, "file": display_path(result.error_file),
                          "line": result.error_line}
    return entry


def format_json(results: list[ModelResult], *, show_statistics: bool = False) -> str:
    document = {
        **envelope(SCHEMA),
        "models": [_model(r) for r in results],
        # Every finding of the run in one list, each naming its model, for simple consumers.
        "findings": [{**f.to_dict(), "file": display_path(f.file), "model": r.name}
                     for r in results for f in r.findings],
        "summary": {**severity_counts(all_findings(results)),
                    "models": len(results),
                    "input_errors": sum(1 for r in results if r.error is not None)},
    }
    if show_statistics:
        document["statistics"] = [{"count": n, "code": code, "slug": slug, "severity": sev}
                                  for n, code, slug, sev in statistics(results)]
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
