"""The CI features of issue 27, each driven from a user's pyproject.toml in a fresh project
directory, the way a team keeps them: exclude/extend-exclude/force-exclude, a baseline of
accepted findings, unknown and unused suppressions (S142/S143), argument variants, the
did-you-mean for paths and rule families, package.xml, and --jobs' choice of workers.

The expected findings are derived by hand from the files each test writes: I203 fires on
a link whose principal moments break the triangle inequality (0.0005 + 0.0005 < 0.004
kg m^2), and on nothing else these models hold.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from cli_helpers import run_cli, run_validate

FIXTURES = Path(__file__).parent / "fixtures" / "validate"
TRIANGLE = FIXTURES / "I203_bad_triangle.urdf"       # one I203 error, on link1
CLEAN = FIXTURES / "clean_quad_x.urdf"

# A link breaking the triangle inequality: 0.0005 + 0.0005 = 0.001 < 0.004 (I203); on a
# moving joint, so Gazebo keeps it a link of its own (a fixed one would be lumped).
BAD_LINK = """  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.0005" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.004"/></inertial>
  </link>
  <joint name="arm_joint" type="continuous"><axis xyz="0 0 1"/>
    <parent link="base_link"/><child link="arm"/></joint>
"""
BASE_LINK = """  <link name="base_link">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
"""


def project(tmp_path: Path, monkeypatch, toml: str) -> Path:
    """A user's repository: pyproject.toml with [tool.reedtool], the working directory."""
    (tmp_path / "pyproject.toml").write_text("[project]\nname = 'drones'\n\n[tool.reedtool]\n"
                                             + toml)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run_json(argv, capsys):
    code, out, err = run_validate([*argv, "--format", "json"], capsys)
    return code, json.loads(out), err


def codes_by_model(doc) -> dict[str, list[str]]:
    return {m["model"]: sorted(f["code"] for f in m["findings"]) for m in doc["models"]}


# ------------------------------------------------------------------ exclude

def test_extend_exclude_and_the_default_exclude_of_build_trees(tmp_path, monkeypatch, capsys):
    root = project(tmp_path, monkeypatch, 'extend-exclude = ["urdf/old/*"]\n')
    for where in ("urdf/a.urdf", "urdf/old/b.urdf", "install/share/c.urdf", "build/d.urdf"):
        (root / where).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(TRIANGLE, root / where)
    code, doc, _ = run_json(["."], capsys)
    # urdf/old/* by the setting; install/ and build/ (colcon's copies) by the default.
    assert [m["model"] for m in doc["models"]] == ["urdf/a.urdf"]
    assert code == 1
    # ruff's rule: a file named on the command line is checked even when excluded ...
    code, doc, _ = run_json(["urdf/old/b.urdf"], capsys)
    assert codes_by_model(doc) == {"urdf/old/b.urdf": ["I203"]}
    # ... unless --force-exclude (pre-commit passes every changed file).
    code, doc, _ = run_json(["urdf/old/b.urdf", "urdf/a.urdf", "--force-exclude"], capsys)
    skipped = {m["model"]: m["skipped"] for m in doc["models"]}
    assert skipped == {"urdf/old/b.urdf": "excluded by 'urdf/old/*' (extend-exclude in "
                                          "pyproject.toml)", "urdf/a.urdf": None}


def test_the_pre_commit_hook_honours_exclude_for_files_it_names(tmp_path, monkeypatch,
                                                                capsys):
    """The hook's own entry (.pre-commit-hooks.yaml), given the changed files by name."""
    import shlex

    import yaml

    hooks = yaml.safe_load((Path(__file__).parents[1] / ".pre-commit-hooks.yaml").read_text())
    entry = shlex.split(hooks[0]["entry"])
    assert entry[:2] == ["reedtool", "validate"]
    root = project(tmp_path, monkeypatch, 'extend-exclude = ["urdf/old"]\n')
    for where in ("urdf/a.urdf", "urdf/old/b.urdf"):
        (root / where).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(TRIANGLE, root / where)
    code, out, _ = run_validate([*entry[2:], "urdf/old/b.urdf", "urdf/a.urdf"], capsys)
    assert "urdf/old/b.urdf: skipped: excluded by 'urdf/old'" in out
    assert "urdf/a.urdf: 1 error" in out and code == 1


def test_exclude_replaces_the_default_and_force_exclude_is_a_setting(tmp_path, monkeypatch,
                                                                     capsys):
    root = project(tmp_path, monkeypatch, 'exclude = ["legacy_*"]\nforce-exclude = true\n')
    for where in ("urdf/legacy_arm.urdf", "install/c.urdf"):
        (root / where).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(TRIANGLE, root / where)
    _, doc, _ = run_json(["."], capsys)
    assert [m["model"] for m in doc["models"]] == ["install/c.urdf"]   # build trees back in
    code, doc, _ = run_json(["urdf/legacy_arm.urdf"], capsys)
    assert doc["models"][0]["skipped"].startswith("excluded by 'legacy_*'") and code == 0


def test_a_bad_exclude_value_is_one_line_exit_2(tmp_path, monkeypatch, capsys):
    project(tmp_path, monkeypatch, "extend-exclude = 3\n")
    shutil.copy(CLEAN, tmp_path / "a.urdf")
    code, _, err = run_validate(["a.urdf"], capsys)
    assert code == 2 and "'extend-exclude' must be a list of file or directory globs" in err


# ------------------------------------------------------------------ baseline

def _model_with_two_bad_arms(path: Path, blank_lines: int = 0, third: bool = False) -> None:
    arms = "".join(BAD_LINK.replace('"arm', f'"arm{i}') for i in range(3 if third else 2))
    path.write_text('<?xml version="1.0"?>\n<robot name="m">\n' + "\n" * blank_lines
                    + BASE_LINK + arms + "</robot>\n")


def test_baseline_accepts_what_was_there_and_fails_on_what_is_new(tmp_path, monkeypatch,
                                                                 capsys):
    root = project(tmp_path, monkeypatch, 'baseline = "reedtool-baseline.json"\n')
    model = root / "urdf" / "m.urdf"
    model.parent.mkdir()
    _model_with_two_bad_arms(model)
    code, doc, _ = run_json(["urdf"], capsys)
    assert code == 1 and codes_by_model(doc) == {"urdf/m.urdf": ["I203", "I203"]}
    # The setting names a file that is not there yet: one line, exit 2, how to write it.
    code, out, err = run_validate(["urdf", "--write-baseline", "reedtool-baseline.json"],
                                  capsys)
    assert code == 0 and "wrote 2 finding(s) of 1 model(s)" in out
    written = json.loads((root / "reedtool-baseline.json").read_text())
    assert written["schema"] == "reedtool.baseline/1"
    assert [(e["model"], e["file"], e["code"], e["subject"]) for e in written["findings"]] == \
        [("urdf/m.urdf", "urdf/m.urdf", "I203", "arm0"), ("urdf/m.urdf", "urdf/m.urdf", "I203",
                                                           "arm1")]
    code, doc, _ = run_json(["urdf"], capsys)
    assert code == 0 and doc["findings"] == [] and doc["models"][0]["baselined"] == 2
    # Lines added above the accepted findings: still accepted (no line numbers in the key).
    _model_with_two_bad_arms(model, blank_lines=7)
    code, doc, _ = run_json(["urdf"], capsys)
    assert code == 0 and doc["models"][0]["baselined"] == 2
    # A third bad link is new: only it is reported, and it fails the run.
    _model_with_two_bad_arms(model, third=True)
    code, doc, _ = run_json(["urdf"], capsys)
    assert code == 1 and [f["subject"] for f in doc["findings"]] == ["arm2"]
    # Writing over the baseline needs --force, as every write of a user's file.
    code, _, err = run_validate(["urdf", "--write-baseline", "reedtool-baseline.json"], capsys)
    assert code == 2 and "--force" in err


def test_baseline_counts_entries_and_notes_fixed_ones(tmp_path, monkeypatch, capsys):
    root = project(tmp_path, monkeypatch, "")
    model = root / "m.urdf"
    _model_with_two_bad_arms(model)
    run_validate(["m.urdf", "--write-baseline", "accepted.json"], capsys)
    model.write_text('<?xml version="1.0"?>\n<robot name="m">\n' + BASE_LINK + "</robot>\n")
    code, out, err = run_validate(["m.urdf", "--baseline", "accepted.json"], capsys)
    assert code == 0
    assert "accepted.json: 2 accepted finding(s) no longer occur" in out + err


def test_a_file_that_is_not_a_baseline_is_one_line_exit_2(tmp_path, monkeypatch, capsys):
    project(tmp_path, monkeypatch, "")
    shutil.copy(CLEAN, tmp_path / "a.urdf")
    (tmp_path / "b.json").write_text('{"findings": []}')
    code, _, err = run_validate(["a.urdf", "--baseline", "b.json"], capsys)
    assert code == 2 and "not a reedtool baseline" in err and len(err.strip().splitlines()) == 1


# ------------------------------------------------------------------ suppressions

def _triangle_with_comment(path: Path, comment: str) -> None:
    lines = TRIANGLE.read_text().splitlines(keepends=True)
    number = next(n for n, line in enumerate(lines) if 'izz="0.0040625"' in line)
    lines.insert(number, f"      <!-- reedtool: {comment} -->\n")
    path.write_text("".join(lines))


def test_a_typo_in_a_suppression_is_reported_with_the_code_meant(tmp_path, monkeypatch, capsys):
    project(tmp_path, monkeypatch, "")
    _triangle_with_comment(tmp_path / "m.urdf", "ignore[I2O3]")     # letter O for zero
    code, doc, _ = run_json(["m.urdf"], capsys)
    by_code = {f["code"]: f for f in doc["findings"]}
    assert sorted(by_code) == ["I203", "S142"] and code == 1     # I203 still reported
    assert by_code["S142"]["severity"] == "warning"
    assert by_code["S142"]["line"] == by_code["I203"]["line"] - 1   # at the comment
    assert by_code["S142"]["hint"].startswith("did you mean 'I203'?")
    _triangle_with_comment(tmp_path / "m.urdf", "ignore[I2]")       # a prefix, not a code
    _, doc, _ = run_json(["m.urdf"], capsys)
    assert sorted(f["code"] for f in doc["findings"]) == ["I203", "S142"]
    _triangle_with_comment(tmp_path / "m.urdf", "ignore[I203]")     # fixed
    code, doc, _ = run_json(["m.urdf"], capsys)
    assert doc["findings"] == [] and doc["models"][0]["suppressed"] == 1 and code == 0


def test_an_unused_suppression_is_info_and_the_config_can_raise_it(tmp_path, monkeypatch,
                                                                  capsys):
    project(tmp_path, monkeypatch, "")
    _triangle_with_comment(tmp_path / "m.urdf", "ignore[I203, I204]")   # I204 does not fire
    code, doc, _ = run_json(["m.urdf"], capsys)
    assert [(f["code"], f["subject"], f["severity"]) for f in doc["findings"]] == \
        [("S143", "I204", "info")] and code == 0
    # --select that leaves I204 out: the name is not judged.
    _, doc, _ = run_json(["m.urdf", "--select", "I203,S143"], capsys)
    assert doc["findings"] == []
    project(tmp_path, monkeypatch, 'strict = true\n[tool.reedtool.severity]\nS143 = "warning"\n')
    code, doc, _ = run_json(["m.urdf"], capsys)
    assert [(f["code"], f["severity"]) for f in doc["findings"]] == [("S143", "warning")]
    assert code == 1


# ------------------------------------------------------------------ argument variants

TOP = """<?xml version="1.0"?>
<robot name="$(arg mav_name)" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:arg name="mav_name" default="light"/>
""" + BASE_LINK + """  <xacro:include filename="body.xacro"/>
</robot>
"""
# A part both variants read; its arm (and the suppression above it) only in `heavy`.
BODY = """<?xml version="1.0"?>
<robot xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:if value="${'$(arg mav_name)' == 'heavy'}">
""" + BAD_LINK + """  </xacro:if>
</robot>
"""
# The same, with the I203 the arm's <inertia> line gets silenced above that line.
BODY_SUPPRESSED = BODY.replace("      <inertia", "      <!-- reedtool: ignore[I203] -->\n"
                                                 "      <inertia")


def _variant_project(tmp_path, monkeypatch, variants: str) -> Path:
    root = project(tmp_path, monkeypatch, "[tool.reedtool.per-file-args]\n"
                                          f'"urdf/*.gazebo" = {variants}\n')
    (root / "urdf").mkdir(exist_ok=True)
    (root / "urdf" / "mav.gazebo").write_text(TOP)
    (root / "urdf" / "body.xacro").write_text(BODY)
    return root


def test_each_variant_is_its_own_model_in_every_format(tmp_path, monkeypatch, capsys):
    _variant_project(tmp_path, monkeypatch,
                     '[{mav_name = "light"}, {mav_name = "heavy"}]')
    code, doc, _ = run_json(["urdf/mav.gazebo"], capsys)
    assert codes_by_model(doc) == {"urdf/mav.gazebo [mav_name:=light]": [],
                                   "urdf/mav.gazebo [mav_name:=heavy]": ["I203"]}
    assert code == 1
    # The directory finds the top file and checks it once per variant too.
    _, doc, _ = run_json(["urdf"], capsys)
    assert list(codes_by_model(doc)) == ["urdf/mav.gazebo [mav_name:=light]",
                                         "urdf/mav.gazebo [mav_name:=heavy]"]
    code, out, _ = run_validate(["urdf/mav.gazebo", "--format", "sarif"], capsys)
    results = json.loads(out)["runs"][0]["results"]
    assert [(r["ruleId"], r["properties"]["model"]) for r in results] == \
        [("I203", "urdf/mav.gazebo [mav_name:=heavy]")]
    assert results[0]["message"]["text"].endswith("[mav_name:=heavy]")
    code, out, _ = run_validate(["urdf/mav.gazebo", "--format", "junit"], capsys)
    from xml.etree import ElementTree as ET

    suites = {s.get("name"): int(s.get("failures")) for s in ET.fromstring(out).iter("testsuite")}
    assert suites == {"urdf/mav.gazebo [mav_name:=light]": 0,
                      "urdf/mav.gazebo [mav_name:=heavy]": 1}
    code, out, _ = run_validate(["urdf/mav.gazebo"], capsys)
    assert "urdf/mav.gazebo [mav_name:=heavy]: 1 error, 0 warnings, 0 info" in out
    # The command line still wins over a variant, as over every configured argument: the
    # variants then differ in nothing, and the model is checked once, with what was typed.
    _, doc, _ = run_json(["urdf/mav.gazebo", "mav_name:=heavy"], capsys)
    assert codes_by_model(doc) == {"urdf/mav.gazebo": ["I203"]}


def test_a_suppression_in_a_shared_part_is_used_if_any_variant_needs_it(tmp_path, monkeypatch,
                                                                       capsys):
    root = _variant_project(tmp_path, monkeypatch,
                            '[{mav_name = "light"}, {mav_name = "heavy"}]')
    (root / "urdf" / "body.xacro").write_text(BODY_SUPPRESSED)
    code, doc, _ = run_json(["urdf/mav.gazebo"], capsys)
    assert doc["findings"] == [] and code == 0       # heavy needed it; light's run is fine
    # Heavy alone with a second name nobody needs: that name alone is unused, at its line.
    (root / "urdf" / "body.xacro").write_text(BODY_SUPPRESSED.replace("[I203]", "[I203, I204]"))
    _variant_project(tmp_path, monkeypatch, '[{mav_name = "heavy"}]')
    (root / "urdf" / "body.xacro").write_text(BODY_SUPPRESSED.replace("[I203]", "[I203, I204]"))
    _, doc, _ = run_json(["urdf/mav.gazebo"], capsys)
    assert [(f["code"], f["file"], f["line"], f["subject"]) for f in doc["findings"]] == \
        [("S143", "urdf/body.xacro", 6, "I204")]
    # Light alone reads no element of the part's `if`: the comments of a file are judged
    # where the run read an element from it, so light's run says nothing about them.
    _variant_project(tmp_path, monkeypatch, '[{mav_name = "light"}]')
    (root / "urdf" / "body.xacro").write_text(BODY_SUPPRESSED)
    _, doc, _ = run_json(["urdf/mav.gazebo"], capsys)
    assert doc["findings"] == []


def test_variants_of_a_top_file_that_picks_its_vehicle_by_argument(tmp_path, monkeypatch,
                                                                    capsys):
    """RotorS's shape: the .gazebo top file includes `$(arg mav_name)_base.xacro`. With
    variants for mav_name, every *_base.xacro is still a part of the top file (found in a
    directory), and each variant reads its own."""
    root = project(tmp_path, monkeypatch, "[tool.reedtool.per-file-args]\n"
                   '"urdf/*.gazebo" = [{mav_name = "light"}, {mav_name = "heavy"}]\n')
    (root / "urdf").mkdir()
    (root / "urdf" / "mav.gazebo").write_text(
        '<?xml version="1.0"?>\n<robot name="$(arg mav_name)" '
        'xmlns:xacro="http://ros.org/wiki/xacro">\n  <xacro:arg name="mav_name" '
        'default="light"/>\n' + BASE_LINK
        + '  <xacro:include filename="$(arg mav_name)_base.xacro"/>\n</robot>\n')
    for name, arm in (("light", ""), ("heavy", BAD_LINK)):
        (root / "urdf" / f"{name}_base.xacro").write_text(
            '<?xml version="1.0"?>\n<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
            + arm + "</robot>\n")
    code, doc, _ = run_json(["urdf"], capsys)
    assert codes_by_model(doc) == {"urdf/mav.gazebo [mav_name:=light]": [],
                                   "urdf/mav.gazebo [mav_name:=heavy]": ["I203"]}
    assert code == 1


def test_an_empty_variant_list_is_one_line_exit_2(tmp_path, monkeypatch, capsys):
    _variant_project(tmp_path, monkeypatch, "[]")
    code, _, err = run_validate(["urdf/mav.gazebo"], capsys)
    assert code == 2 and "empty list of variants" in err


# ------------------------------------------------------------------ did you mean, package.xml

def test_a_mistyped_path_suggests_the_file_beside_it(tmp_path, monkeypatch, capsys):
    project(tmp_path, monkeypatch, "")
    (tmp_path / "urdf").mkdir()
    shutil.copy(CLEAN, tmp_path / "urdf" / "mav_generic_odometry_sensor.urdf")
    code, _, err = run_validate(["urdf/mav_generic_odometry_sensr.urdf"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "did you mean 'urdf/mav_generic_odometry_sensor.urdf'?" in err
    code, _, err = run_validate(["urfd/mav_generic_odometry_sensor.urdf"], capsys)   # the dir
    assert "did you mean 'urdf/mav_generic_odometry_sensor.urdf'?" in err
    code, _, err = run_validate(["nothing_like_it.urdf"], capsys)
    assert code == 2 and "did you mean" not in err
    # The single-model commands say the same.
    code, out = run_cli("inertia", "urdf/mav_generic_odometry_sensr.urdf")
    assert code == 2 and "did you mean 'urdf/mav_generic_odometry_sensor.urdf'?" in out


def test_rules_family_did_you_mean(capsys):
    code, out = run_cli("rules", "--family", "rotor")
    assert code == 2 and "did you mean 'rotors'?" in out
    code, out = run_cli("rules", "--family", "inertai")
    assert code == 2 and "did you mean 'inertia'?" in out


def test_validate_package_xml_names_the_directory_to_pass(tmp_path, monkeypatch, capsys):
    project(tmp_path, monkeypatch, "")
    package = tmp_path / "my_drone_description"
    package.mkdir()
    (package / "package.xml").write_text("<package format='2'><name>x</name></package>")
    code, out, err = run_validate(["my_drone_description/package.xml"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "pass the package directory: reedtool validate my_drone_description" in err


# ------------------------------------------------------------------ --jobs

@pytest.mark.parametrize("jobs, items, load, expected", [
    (2, 14, 0.9, 2),     # an idle 2-core machine (this run is the load): two workers
    (2, 14, 5.0, 1),     # busy: the workers would take turns on one core, so serial
    (2, 3, 0.0, 1),      # three models: not worth a fork
    (2, 4, 0.0, 2),
    (8, 14, 0.0, 2),     # never more than the available CPUs (2 here, or as many as there are)
])
def test_jobs_start_workers_only_where_they_help(jobs, items, load, expected, monkeypatch):
    from reedtool.workflows import parallel

    monkeypatch.setattr(parallel, "available_cpus", lambda: 2)
    assert parallel.workers_for(jobs, items, load) == expected


def test_parallel_map_keeps_order_and_raises_the_first_error(monkeypatch):
    from reedtool.workflows import parallel
    from reedtool.errors import ReedtoolError

    monkeypatch.setattr(parallel, "idle_cpus", lambda load=None: 2)
    monkeypatch.setattr(parallel, "available_cpus", lambda: 2)
    assert parallel.map_models(_square, list(range(9)), jobs=2) == [n * n for n in range(9)]
    with pytest.raises(ReedtoolError, match="item 3"):
        parallel.map_models(_fail_from_3, list(range(9)), jobs=2)


def _square(n: int) -> int:
    return n * n


def _fail_from_3(n: int) -> int:
    from reedtool.errors import ReedtoolError

    if n >= 3:
        raise ReedtoolError(f"item {n}")
    return n


# ------------------------------------------------------------------ installation, as documented

def test_no_doc_installs_reedtool_from_a_package_index():
    """reedtool is installed from its repository or a wheel: an instruction to install it
    by name (`pip install reedtool`, `pip install 'reedtool[fast]'`) sends users to an
    index that does not have it. Docs, README and the product's own messages."""
    import re

    root = Path(__file__).resolve().parents[1]
    by_name = re.compile(r"pip install\s+['\"]?reedtool(\[[^\]]*\])?(?![\w@ ]*@)['\"]?(?=[\s`)]|$)")
    texts = {p: p.read_text(encoding="utf-8") for p in
             [root / "README.md", *(root / "docs").glob("*.md"),
              *(root / "reedtool").rglob("*.py")]}
    offenders = [f"{p.relative_to(root)}: {m.group(0)}" for p, text in texts.items()
                 for m in by_name.finditer(text)]
    assert offenders == []
    ci = texts[root / "docs" / "ci.md"]
    assert 'pip install "reedtool @ git+https://github.com/reedtool/reedtool@v' in ci
    assert "pip install dist/reedtool-" in ci
