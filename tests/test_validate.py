"""`reedtool validate`: exit codes, formats, selection, configuration, --explain."""

from __future__ import annotations

import io
import json
import shutil
import sys
from pathlib import Path

import pytest
from cli_helpers import run_validate

from reedtool.checks.registry import get_rule
from reedtool.checks.runner import Selection, parse_selectors
from reedtool.errors import ReedtoolError

FIXTURES = Path(__file__).parent / "fixtures" / "validate"
CLEAN = FIXTURES / "clean_quad_x.urdf"
TWO_ERRORS = FIXTURES / "S105_bad_child_missing.urdf"      # S104 + S105
WARNING_ONLY = FIXTURES / "S114_bad_reference.urdf"       # S114 (warning)


# ------------------------------------------------------------------ exit codes

def test_clean_model_exits_0(capsys):
    code, out, _ = run_validate([CLEAN], capsys)
    assert code == 0
    assert "no findings" in out


def test_errors_exit_1(capsys):
    code, out, _ = run_validate([TWO_ERRORS], capsys)
    assert code == 1
    assert "S105" in out and "S104" in out


def test_warnings_exit_0_unless_strict(capsys):
    assert run_validate([WARNING_ONLY], capsys)[0] == 0
    assert run_validate([WARNING_ONLY, "--strict"], capsys)[0] == 1


def test_missing_model_is_one_line_exit_2(capsys, tmp_path):
    code, out, err = run_validate([tmp_path / "nope.urdf"], capsys)
    assert code == 2
    assert err.count("\n") == 1 and "nope.urdf" in err and "Traceback" not in err


def test_malformed_xml_exit_2(capsys, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    code, _, err = run_validate([bad], capsys)
    assert code == 2 and "bad.urdf" in err and err.count("\n") == 1


def test_bad_mapping_and_selector_exit_2(capsys):
    assert run_validate([CLEAN, "not_a_mapping"], capsys)[0] == 2
    code, _, err = run_validate([CLEAN, "--select", "Q9"], capsys)
    assert code == 2 and "Q9" in err


def test_no_model_is_a_usage_error(capsys):
    assert run_validate([], capsys)[0] == 2


# --------------------------------------------------------------------- explain

def test_explain_prints_rule_docs(capsys):
    code, out, _ = run_validate(["--explain", "i203"], capsys)
    assert code == 0
    rule = get_rule("I203")
    assert out.startswith("I203 inertia-triangle-inequality (error, Inertia)")
    assert rule.explanation.splitlines()[0] in out


def test_explain_unknown_code_exit_2(capsys):
    code, _, err = run_validate(["--explain", "X999"], capsys)
    assert code == 2 and "X999" in err


# --------------------------------------------------------------------- formats

def test_json_schema_and_determinism(capsys):
    code, out, _ = run_validate([TWO_ERRORS, "--format", "json"], capsys)
    assert code == 1
    doc = json.loads(out)
    assert doc["schema"] == "reedtool.validate/1" and doc["tool"] == "reedtool" and doc["version"]
    assert [Path(m["model"]).resolve() for m in doc["models"]] == [TWO_ERRORS.resolve()]
    assert [f["code"] for f in doc["findings"]] == ["S105", "S104"]  # by line: joint, link
    for finding in doc["findings"]:
        assert list(finding) == ["code", "slug", "severity", "message", "subject", "file",
                                 "line", "hint", "model"]
        assert isinstance(finding["line"], int)
    assert doc["summary"] == {"error": 2, "warning": 0, "info": 0, "models": 1,
                              "input_errors": 0}
    assert run_validate([TWO_ERRORS, "--format", "json"], capsys)[1] == out


def test_github_annotations(capsys):
    _, out, _ = run_validate([WARNING_ONLY, "--format", "github"], capsys)
    (line,) = out.splitlines()
    assert line.startswith("::warning file=")
    assert ",title=S114 gazebo-reference-missing::" in line
    src = WARNING_ONLY.read_text().splitlines()
    lineno = int(line.split(",line=")[1].split(",")[0])
    assert 'reference="link_1"' in src[lineno - 1]


def test_text_has_no_colour_unless_a_terminal(capsys):
    _, out, _ = run_validate([TWO_ERRORS], capsys)
    assert "\x1b[" not in out
    from reedtool.checks.runner import run_checks
    from reedtool.io.loader import load_robot
    from reedtool.report import ModelResult, render

    result = ModelResult(str(TWO_ERRORS), run_checks(load_robot(TWO_ERRORS)))
    coloured = render([result], "text", color=True)
    assert "\x1b[" in coloured


class _Terminal(io.StringIO):
    """A stdout that says it is a terminal, where validate colours its text."""

    def isatty(self) -> bool:
        return True


# no-color.org: NO_COLOR "present and not an empty string" turns colour off, whatever
# its value; an empty NO_COLOR is as if it were not set.
@pytest.mark.parametrize("no_color, coloured", [(None, True), ("1", False), ("0", False),
                                                ("", True)])
def test_no_color_env(monkeypatch, no_color, coloured):
    """On a terminal validate colours its text (the control case), and NO_COLOR wins."""
    from reedtool.cli import main

    monkeypatch.delenv("NO_COLOR", raising=False)
    if no_color is not None:
        monkeypatch.setenv("NO_COLOR", no_color)
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stdout", terminal)
    with pytest.raises(SystemExit) as exc:
        main(["validate", str(TWO_ERRORS)])
    assert exc.value.code == 1
    out = terminal.getvalue()
    assert "S105" in out
    assert ("\x1b[" in out) is coloured


# ------------------------------------------------------------------- selection

def test_longest_prefix_wins():
    s = Selection(select=("", "I203"), ignore=("I2",))
    assert s.enabled("S101") and s.enabled("I203") and not s.enabled("I204")
    s = Selection(select=("R",), ignore=())
    assert s.enabled("R301") and not s.enabled("S101")
    s = Selection(select=("R3",), ignore=("R3",))  # a tie goes to ignore
    assert not s.enabled("R301")


def test_selectors_validated_and_normalised():
    assert parse_selectors(["s1, i203", "ALL"], origin="--select") == ("S1", "I203", "")
    with pytest.raises(ReedtoolError):
        parse_selectors(["S9"], origin="--select")


def test_select_and_ignore_on_the_command_line(capsys):
    _, out, _ = run_validate([TWO_ERRORS, "--select", "S105", "--format", "json"], capsys)
    assert [f["code"] for f in json.loads(out)["findings"]] == ["S105"]
    code, out, _ = run_validate([TWO_ERRORS, "--ignore", "S104,S105", "--format", "json"], capsys)
    assert code == 0 and json.loads(out)["findings"] == []


# ---------------------------------------------------------------------- config

def _copy(tmp_path, fixture, sub="models/urdf"):
    target = tmp_path / sub
    target.mkdir(parents=True)
    return Path(shutil.copy(fixture, target))


def test_pyproject_config_found_above_the_model(tmp_path, capsys):
    model = _copy(tmp_path, TWO_ERRORS)
    (tmp_path / "pyproject.toml").write_text(
        '[project]\nname = "x"\n\n[tool.reedtool]\nignore = ["S104"]\n'
        '[tool.reedtool.severity]\nS105 = "warning"\n')
    code, out, _ = run_validate([model, "--format", "json"], capsys)
    doc = json.loads(out)
    assert [(f["code"], f["severity"]) for f in doc["findings"]] == [("S105", "warning")]
    assert code == 0


def test_reedtool_toml_wins_over_a_pyproject_further_up(tmp_path, capsys):
    model = _copy(tmp_path, WARNING_ONLY)
    (tmp_path / "pyproject.toml").write_text('[tool.reedtool]\nignore = ["S"]\n')
    (tmp_path / "models" / "reedtool.toml").write_text("strict = true\n")
    code, out, _ = run_validate([model], capsys)
    assert code == 1 and "S114" in out  # strict from reedtool.toml, S not ignored


def test_pyproject_without_section_is_skipped(tmp_path, capsys):
    model = _copy(tmp_path, WARNING_ONLY)
    (tmp_path / "models" / "pyproject.toml").write_text('[project]\nname = "m"\n')
    (tmp_path / "pyproject.toml").write_text("[tool.reedtool]\nstrict = true\n")
    assert run_validate([model], capsys)[0] == 1
    assert run_validate([model, "--no-strict"], capsys)[0] == 0


@pytest.mark.parametrize("text", ['[tool.reedtool]\nselct = ["S"]\n',
                                  '[tool.reedtool]\nselect = ["Z1"]\n',
                                  '[tool.reedtool.severity]\nS101 = "fatal"\n',
                                  "[tool.reedtool\n"])
def test_bad_config_is_exit_2(tmp_path, capsys, text):
    model = _copy(tmp_path, CLEAN)
    (tmp_path / "pyproject.toml").write_text(text)
    code, _, err = run_validate([model], capsys)
    assert code == 2 and "pyproject.toml" in err and err.count("\n") == 1
