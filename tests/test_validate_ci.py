"""`reedtool validate` in CI (issue 13): many models, exit codes over all, output formats,
inline suppressions, per-file ignores, rule names, `reedtool rules`, settings."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest
from cli_helpers import run_validate

from reedtool.checks.registry import all_rules, get_rule
from reedtool.cli import main

FIXTURES = Path(__file__).parent / "fixtures" / "validate"
CLEAN = FIXTURES / "clean_quad_x.urdf"
TWO_ERRORS = FIXTURES / "S105_bad_child_missing.urdf"      # S105 at line 9, S104 at line 13
WARNING_ONLY = FIXTURES / "S114_bad_reference.urdf"       # S114 (warning)
TRIANGLE = FIXTURES / "I203_bad_triangle.urdf"             # I203 (error)


def run_json(argv, capsys):
    code, out, err = run_validate([*argv, "--format", "json"], capsys)
    return code, json.loads(out)


def model_codes(doc) -> dict[str, list[str]]:
    return {Path(m["model"]).name: sorted(f["code"] for f in m["findings"])
            for m in doc["models"]}


# ------------------------------------------------------------------ many models

def test_many_files_one_report_exit_over_all(capsys):
    code, doc = run_json([CLEAN, TWO_ERRORS, WARNING_ONLY], capsys)
    assert code == 1
    assert model_codes(doc) == {"clean_quad_x.urdf": [], "S105_bad_child_missing.urdf":
                                ["S104", "S105"], "S114_bad_reference.urdf": ["S114"]}
    assert doc["summary"] == {"error": 2, "warning": 1, "info": 0, "models": 3,
                              "input_errors": 0}


def test_warnings_only_across_models_exit_0_unless_strict(capsys):
    assert run_validate([CLEAN, WARNING_ONLY], capsys)[0] == 0
    assert run_validate([CLEAN, WARNING_ONLY, "--strict"], capsys)[0] == 1


def test_an_unreadable_model_is_reported_and_the_others_still_checked(capsys, tmp_path):
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'></robot>")
    code, doc = run_json([TWO_ERRORS, broken, tmp_path / "missing.urdf"], capsys)
    assert code == 2
    by_name = {Path(m["model"]).name: m for m in doc["models"]}
    assert sorted(f["code"] for f in by_name["S105_bad_child_missing.urdf"]["findings"]) == \
        ["S104", "S105"]
    assert by_name["broken.urdf"]["error"]["message"]
    assert by_name["missing.urdf"]["error"]["message"] == "file not found"
    assert doc["summary"]["input_errors"] == 2
    # Text: one line per unreadable model, the run's tail counts them.
    code, out, _ = run_validate([TWO_ERRORS, tmp_path / "missing.urdf"], capsys)
    assert code == 2
    assert f"{tmp_path / 'missing.urdf'}: error: file not found" in out
    assert out.rstrip().splitlines()[-1] == ("2 models: 2 errors, 0 warnings, 0 info; "
                                             "1 could not be read")


def test_exit_zero_keeps_exit_2_for_input_errors(capsys, tmp_path):
    assert run_validate([TWO_ERRORS, "--exit-zero"], capsys)[0] == 0
    assert run_validate([TWO_ERRORS, tmp_path / "missing.urdf", "--exit-zero"], capsys)[0] == 2


def test_directory_and_glob(capsys, tmp_path):
    models = tmp_path / "robots"
    (models / "sub").mkdir(parents=True)
    shutil.copy(TWO_ERRORS, models / "a.urdf")
    shutil.copy(TRIANGLE, models / "sub" / "b.urdf")
    # A macro library: defines macros only, is not a model of its own.
    (models / "macros.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <xacro:property name="r" value="0.1"/>\n'
        '  <xacro:macro name="leg" params="n"><link name="${n}"/></xacro:macro>\n</robot>\n')
    (models / "notes.txt").write_text("not a model")
    code, doc = run_json([models], capsys)
    assert code == 1
    assert model_codes(doc) == {"a.urdf": ["S104", "S105"], "b.urdf": ["I203"]}
    code, doc = run_json([f"{models}/**/*.urdf"], capsys)
    assert model_codes(doc) == {"a.urdf": ["S104", "S105"], "b.urdf": ["I203"]}
    code, doc = run_json([f"{models}/*.nothing", CLEAN], capsys)
    assert code == 2
    assert [m["error"]["message"] for m in doc["models"] if m["error"]] == \
        ["no file matches this pattern"]


SEED = Path(__file__).parent / "fixtures" / "seed000" / "reed_gazebo"
SEED_ARGS = {"mav_name": "reed_quad_x", "namespace": "reed_quad_x",
             "enable_mavlink_interface": "true", "enable_ground_truth": "true",
             "enable_logging": "false", "log_file": "reed_quad_x",
             "wait_to_record_bag": "false"}


def test_ros_package_means_its_top_level_models_with_config_args(capsys, tmp_path):
    package = Path(shutil.copytree(SEED, tmp_path / "reed_gazebo"))
    args = ", ".join(f'{k} = "{v}"' for k, v in SEED_ARGS.items())
    (tmp_path / "pyproject.toml").write_text(f"[tool.reedtool]\nargs = {{{args}}}\n")
    code, doc = run_json([package, "--package-path", tmp_path], capsys)
    # reed_quad_x_base.xacro and reed_quad_x.xacro are included by the .gazebo top file;
    # the untouched copy keeps the blog's misspelt macro parameter: an input error.
    names = [Path(m["model"]).name for m in doc["models"]]
    assert names == ["mav_generic_odometry_sensor.gazebo",
                     "mav_generic_odometry_sensor.untouched.gazebo"]
    assert model_codes(doc)["mav_generic_odometry_sensor.gazebo"] == ["I203", "R312", "S115"]
    assert "measurement_pisor" in doc["models"][1]["error"]["message"]
    assert code == 2


def test_a_xacro_part_given_arguments_is_validated_as_itself(capsys, tmp_path):
    """Arguments mean "this model" (issue 18): the mechanics file given the launch
    arguments expands alone into the vehicle, so it is checked as itself, its own I203 on
    its own line, and never skipped for the .gazebo file beside it."""
    package = Path(shutil.copytree(SEED, tmp_path / "reed_gazebo"))
    part = package / "urdf" / "reed_quad_x.xacro"
    code, doc = run_json([part, "--package-path", tmp_path,
                          *(f"{k}:={v}" for k, v in SEED_ARGS.items())], capsys)
    assert [Path(m["model"]).name for m in doc["models"]] == ["reed_quad_x.xacro"]
    assert doc["models"][0]["skipped"] is None
    i203 = [f for f in doc["findings"] if f["code"] == "I203"]
    assert [(Path(f["file"]).name, f["line"]) for f in i203] == [("reed_quad_x.xacro", 30)]
    assert code == 1


# ------------------------------------------------------------------ formats and outputs

def test_junit_counts_failures_per_model(capsys, tmp_path):
    code, out, _ = run_validate([CLEAN, TWO_ERRORS, WARNING_ONLY, "--format", "junit"], capsys)
    assert code == 1
    root = ET.fromstring(out)
    suites = {Path(s.get("name")).name: s for s in root.iter("testsuite")}
    assert {n: (s.get("tests"), s.get("failures")) for n, s in suites.items()} == {
        "clean_quad_x.urdf": ("1", "0"), "S105_bad_child_missing.urdf": ("2", "2"),
        "S114_bad_reference.urdf": ("1", "0")}
    assert sorted(f.get("type") for f in root.iter("failure")) == ["S104", "S105"]
    # --strict: the warning fails too.
    root = ET.fromstring(run_validate([WARNING_ONLY, "--format", "junit", "--strict"], capsys)[1])
    assert [f.get("type") for f in root.iter("failure")] == ["S114"]


def test_github_annotations_for_many_models_and_input_errors(capsys, tmp_path):
    code, out, _ = run_validate([TWO_ERRORS, tmp_path / "gone.urdf", "--format", "github"], capsys)
    assert code == 2
    lines = out.splitlines()
    assert [ln.split(" ")[0] for ln in lines] == ["::error", "::error", "::error"]
    assert sum("title=reedtool input error" in ln for ln in lines) == 1


def test_statistics_counts_per_rule(capsys):
    code, out, _ = run_validate([TWO_ERRORS, TRIANGLE, TRIANGLE.parent / "I203_bad_triangle.urdf",
                        "--statistics"], capsys)
    rows = out.rstrip().splitlines()[-3:]
    # I203_bad_triangle.urdf given twice is checked once.
    assert [r.split() for r in rows] == [["1", "I203", "error", "inertia-triangle-inequality"],
                                         ["1", "S104", "error", "single-root"],
                                         ["1", "S105", "error", "joint-link-missing"]]
    _, doc = run_json([TWO_ERRORS, WARNING_ONLY, "--statistics"], capsys)
    assert {s["code"]: s["count"] for s in doc["statistics"]} == {"S104": 1, "S105": 1,
                                                                   "S114": 1}


def test_output_file_is_written_atomically_and_never_clobbered(capsys, tmp_path):
    report = tmp_path / "out" / "report.sarif"
    code, out, _ = run_validate([TWO_ERRORS, "--format", "sarif", "--output-file", report], capsys)
    assert code == 1 and out == ""
    assert json.loads(report.read_text())["version"] == "2.1.0"
    before = report.read_text()
    code, _, err = run_validate([CLEAN, "--format", "sarif", "--output-file", report], capsys)
    assert code == 2 and "--force" in err and report.read_text() == before
    code, _, _ = run_validate([CLEAN, "--format", "sarif", "-o", report, "--force"], capsys)
    assert code == 0 and json.loads(report.read_text())["runs"][0]["results"] == []


# ------------------------------------------------------------------ rule names, rules

def test_rule_names_accepted_wherever_codes_are(capsys):
    _, doc = run_json([TWO_ERRORS, "--select", "joint-link-missing"], capsys)
    assert [f["code"] for f in doc["findings"]] == ["S105"]
    _, doc = run_json([TWO_ERRORS, "--ignore", "single-root"], capsys)
    assert [f["code"] for f in doc["findings"]] == ["S105"]
    code, out, _ = run_validate(["--explain", "joint-link-missing"], capsys)
    assert code == 0 and out.startswith("S105 joint-link-missing")


def test_rule_names_in_config(capsys, tmp_path):
    shutil.copy(TWO_ERRORS, tmp_path / "m.urdf")
    (tmp_path / "reedtool.toml").write_text(
        'ignore = ["single-root"]\n[severity]\njoint-link-missing = "warning"\n')
    code, doc = run_json([tmp_path / "m.urdf"], capsys)
    assert [(f["code"], f["severity"]) for f in doc["findings"]] == [("S105", "warning")]
    assert code == 0


def test_rules_lists_and_filters_the_registry(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["rules", "--family", "rotors", "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert exc.value.code == 0
    assert doc["schema"] == "reedtool.rules/1" and doc["tool"] == "reedtool"
    assert [r["code"] for r in doc["rules"]] == [r.code for r in all_rules()
                                                 if r.code.startswith("R")]
    with pytest.raises(SystemExit):
        main(["rules", "I20", "mesh-unresolved"])
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in lines] == sorted(
        [r.code for r in all_rules() if r.code.startswith("I20")] + ["S115"],
        key=lambda c: ("SIRC".index(c[0]), c))
    with pytest.raises(SystemExit) as exc:
        main(["rules", "--family", "nope"])
    assert exc.value.code == 2


# ------------------------------------------------------------------ suppressions

def _with_line_inserted(src: Path, dst: Path, before_line: int, text: str) -> Path:
    lines = src.read_text().splitlines(keepends=True)
    lines.insert(before_line - 1, text + "\n")
    dst.write_text("".join(lines))
    return dst


def test_inline_comment_above_the_element(capsys, tmp_path):
    # S105 is reported at the <joint> on line 9; the comment goes above it.
    model = _with_line_inserted(TWO_ERRORS, tmp_path / "m.urdf", 9,
                                "  <!-- reedtool: ignore[S105] -->")
    code, doc = run_json([model], capsys)
    assert [f["code"] for f in doc["findings"]] == ["S104"]
    assert doc["models"][0]["suppressed"] == 1
    assert code == 1


def test_inline_comment_on_the_line_with_names_and_several_codes(capsys, tmp_path):
    lines = TWO_ERRORS.read_text().splitlines()
    lines[8] += "  <!-- reedtool: ignore[single-root, joint-link-missing] -->"   # line 9
    lines[12] += "<!-- reedtool: ignore[S104] -->"                                 # line 13
    model = tmp_path / "m.urdf"
    model.write_text("\n".join(lines) + "\n")
    code, doc = run_json([model], capsys)
    assert doc["models"][0]["suppressed"] == 2 and code == 0
    # S104 (single-root) is reported on line 13, so the name on line 9 silenced nothing:
    # the one finding left is S143 saying so, at the comment (info: exit 0).
    assert [(f["code"], f["line"], f["subject"]) for f in doc["findings"]] == \
        [("S143", 9, "single-root")]


def test_inline_comment_for_another_rule_or_line_does_not_suppress(capsys, tmp_path):
    model = _with_line_inserted(TWO_ERRORS, tmp_path / "m.urdf", 3,
                                "  <!-- reedtool: ignore[S105] -->")   # above base_link
    code, doc = run_json([model], capsys)
    # Both findings stay; the misplaced comment itself is reported unused (S143, line 3).
    assert sorted((f["code"], f["line"]) for f in doc["findings"]) == \
        [("S104", 14), ("S105", 10), ("S143", 3)]


def test_inline_comment_in_the_xacro_the_user_wrote(capsys, tmp_path):
    """Seed quad: I203 points at reed_quad_x.xacro line 30 (the macro call); a comment above
    that line silences it, even though the element comes from a RotorS macro."""
    package = Path(shutil.copytree(SEED, tmp_path / "reed_gazebo"))
    xacro = package / "urdf" / "reed_quad_x.xacro"
    _with_line_inserted(xacro, xacro, 30, "<!-- reedtool: ignore[I203] -->")
    argv = [package / "urdf" / "mav_generic_odometry_sensor.gazebo", "--package-path", tmp_path,
            *(f"{k}:={v}" for k, v in SEED_ARGS.items())]
    _, doc = run_json(argv, capsys)
    assert sorted(f["code"] for f in doc["findings"]) == ["R312", "S115"]


def test_per_file_ignores(capsys, tmp_path):
    (tmp_path / "urdf").mkdir()
    shutil.copy(TWO_ERRORS, tmp_path / "urdf" / "legacy_arm.urdf")
    shutil.copy(TWO_ERRORS, tmp_path / "urdf" / "arm.urdf")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.reedtool.per-file-ignores]\n"urdf/legacy_*.urdf" = ["S104"]\n'
        '"arm.urdf" = ["joint-link-missing"]\n')
    _, doc = run_json([tmp_path / "urdf"], capsys)
    assert model_codes(doc) == {"arm.urdf": ["S104"], "legacy_arm.urdf": ["S105"]}


# ------------------------------------------------------------------ settings

def test_show_settings_names_the_config_that_won(capsys, tmp_path):
    (tmp_path / "models").mkdir()
    model = Path(shutil.copy(CLEAN, tmp_path / "models" / "m.urdf"))
    (tmp_path / "pyproject.toml").write_text('[tool.reedtool]\nstrict = true\n')
    (tmp_path / "models" / "reedtool.toml").write_text(
        'ignore = ["I205"]\nargs = {mav_name = "quad"}\n')
    code, out, _ = run_validate([model, "--show-settings"], capsys)
    assert code == 0
    lines = out.splitlines()
    assert any(ln.startswith("  config: ") and ln.endswith("models/reedtool.toml")
               for ln in lines)
    assert any(ln.startswith("  also found (not used") and ln.endswith("pyproject.toml")
               for ln in lines)
    assert "  ignore: I205" in lines and "  strict: false" in lines
    assert any(ln.startswith("  arg mav_name:=quad  (config ") for ln in lines)


def test_unknown_setting_suggests_the_right_one(capsys, tmp_path):
    shutil.copy(CLEAN, tmp_path / "m.urdf")
    (tmp_path / "reedtool.toml").write_text('per-file-ignore = {"*.urdf" = ["S1"]}\n')
    code, _, err = run_validate([tmp_path / "m.urdf"], capsys)
    assert code == 2 and "did you mean 'per-file-ignores'" in err


def test_every_rule_name_is_a_selector():
    from reedtool.checks.runner import parse_selectors

    for rule in all_rules():
        assert parse_selectors([rule.slug], origin="test") == (rule.code,)
        assert get_rule(rule.slug) is rule


def test_macro_library_named_by_pre_commit_is_skipped_not_failed(capsys, tmp_path):
    library = tmp_path / "macros.xacro"
    library.write_text('<?xml version="1.0"?>\n<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
                       '  <xacro:macro name="leg" params="n"><link name="${n}"/></xacro:macro>\n'
                       '</robot>\n')
    code, doc = run_json([library], capsys)
    assert code == 0 and doc["models"][0]["skipped"].startswith("a xacro macro library")
    code, doc = run_json([library, TRIANGLE], capsys)
    assert code == 1 and [f["code"] for f in doc["findings"]] == ["I203"]


def test_strict_is_per_model_configuration(capsys, tmp_path):
    (tmp_path / "strict").mkdir()
    (tmp_path / "lax").mkdir()
    shutil.copy(WARNING_ONLY, tmp_path / "strict" / "w.urdf")
    shutil.copy(WARNING_ONLY, tmp_path / "lax" / "w.urdf")
    (tmp_path / "strict" / "reedtool.toml").write_text("strict = true\n")
    assert run_validate([tmp_path / "lax" / "w.urdf", CLEAN], capsys)[0] == 0
    assert run_validate([tmp_path / "lax" / "w.urdf", tmp_path / "strict" / "w.urdf"], capsys)[0] == 1
    assert run_validate([tmp_path / "strict" / "w.urdf", "--no-strict"], capsys)[0] == 0
