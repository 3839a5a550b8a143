"""What a path on the command line means (issue 18 item 4, issue 19 item 4).

Arguments mean "this model"; a file that cannot stand alone is checked through a model
that includes it, and a broken sibling never refuses the user's file. Directory discovery
and the pre-commit hook know every model file a ROS/Gazebo package uses.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from cli_helpers import run_validate

FIXTURES = Path(__file__).parent / "fixtures"
FLIE = FIXTURES / "discovery" / "flie_description"
SEED = FIXTURES / "seed000" / "reed_gazebo"
FLIE_ARGS = {"mav_name": "flie", "namespace": "flie", "enable_ground_truth": "true"}
SEED_ARGS = {"mav_name": "reed_quad_x", "namespace": "reed_quad_x",
             "enable_mavlink_interface": "true", "enable_ground_truth": "true",
             "enable_logging": "false", "log_file": "reed_quad_x",
             "wait_to_record_bag": "false"}


def run_json(argv, capsys):
    code, out, _ = run_validate([*argv, "--format", "json"], capsys)
    return code, json.loads(out)


def by_name(doc) -> dict[str, dict]:
    return {Path(m["model"]).name: m for m in doc["models"]}


def config_text(args: dict[str, str]) -> str:
    table = ", ".join(f'{k} = "{v}"' for k, v in args.items())
    return f"[tool.reedtool]\nargs = {{{table}}}\n"


@pytest.fixture
def flie(tmp_path) -> Path:
    """The CrazyS-shaped package in a workspace of its own (tmp/ws/flie_description)."""
    return Path(shutil.copytree(FLIE, tmp_path / "ws" / "flie_description"))


# ------------------------------------------------------------------ arguments mean this model

def test_a_model_given_arguments_is_validated_as_itself_beside_a_broken_sibling(flie, capsys):
    """CrazyS: `crazyflie2_base.xacro mav_name:=crazyflie2 ...` was "skipped: part of
    asymmetric_quadrotor_two_cameras.gazebo", which then failed to expand (exit 2)."""
    base = flie / "urdf" / "flie_base.xacro"
    code, doc = run_json([base, "--package-path", flie.parent,
                          *(f"{k}:={v}" for k, v in FLIE_ARGS.items())], capsys)
    assert list(by_name(doc)) == ["flie_base.xacro"]
    model = doc["models"][0]
    assert model["skipped"] is None and model["error"] is None
    assert doc["summary"]["input_errors"] == 0
    # It was really loaded and checked: its rotors are there for the rotor rules, and the
    # one argument the vehicle never reads (mav_name picks it, upstream) is told about.
    assert [f["code"] for f in doc["findings"] if f["severity"] == "error"] == []
    # (S141, information: near no name the file knows; S140 warns about near misses only.)
    assert [f["subject"] for f in doc["findings"] if f["code"] == "S141"] == ["mav_name"]
    assert code == 0


def test_config_arguments_let_a_changed_model_stand_alone(flie, capsys):
    """pre-commit passes the changed file with no arguments of its own; the repository's
    config carries them. The vehicle expands alone with them: it is validated as itself."""
    (flie.parent / "pyproject.toml").write_text(config_text(FLIE_ARGS))
    code, doc = run_json([flie / "urdf" / "flie_base.xacro", "--package-path", flie.parent],
                         capsys)
    assert list(by_name(doc)) == ["flie_base.xacro"]
    assert doc["models"][0]["skipped"] is None and doc["summary"]["input_errors"] == 0
    assert code == 0


def test_a_part_that_cannot_stand_alone_names_itself_in_its_includers_failure(flie, capsys):
    """flie.xacro without arguments cannot expand alone (it reads namespace); the model
    beside it that includes it is checked instead, and that model's failure is reported
    against that model, naming the part."""
    code, doc = run_json([flie / "urdf" / "flie.xacro", "--package-path", flie.parent],
                         capsys)
    models = by_name(doc)
    assert models["flie.xacro"]["skipped"].startswith("part of ")
    assert "flie_base.xacro" in models["flie.xacro"]["skipped"]
    error = models["flie_base.xacro"]["error"]["message"]
    assert "argument 'namespace' is not set" in error
    assert re.search(r"checked for \S*flie\.xacro, which it includes", error)
    assert code == 2


def test_a_part_is_checked_through_an_includer_that_loads_not_a_broken_one(tmp_path, capsys):
    """Two models include one part (a fragment that uses its includer's property); the one
    sorted first is broken. The part is checked through the one that loads."""
    def robot(body: str) -> str:
        return ('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://ros.org/wiki/'
                f'xacro">\n{body}\n</robot>\n')

    link = ('<link name="{n}"><inertial><mass value="{m}"/><inertia ixx="0.01" ixy="0" '
            'ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>')
    (tmp_path / "arm.xacro").write_text(robot(
        link.format(n="arm", m="${arm_mass}") + '\n<joint name="arm_joint" type="fixed">'
        '<parent link="base"/><child link="arm"/></joint>'))
    (tmp_path / "a_broken.xacro").write_text(robot(
        link.format(n="base", m="${base_mass}") + '\n<xacro:property name="arm_mass" '
        'value="0.1"/>\n<xacro:include filename="arm.xacro"/>'))
    (tmp_path / "b_good.xacro").write_text(robot(
        link.format(n="base", m="1.0") + '\n<xacro:property name="arm_mass" value="-1"/>\n'
        '<xacro:include filename="arm.xacro"/>'))
    code, doc = run_json([tmp_path / "arm.xacro"], capsys)
    models = by_name(doc)
    assert list(models) == ["arm.xacro", "b_good.xacro"]
    assert models["arm.xacro"]["skipped"] == f"part of {tmp_path / 'b_good.xacro'}, " \
                                             "checked through it"
    # The part's own mistake (mass -1, from the includer's property) is found on its line.
    i201 = [(Path(f["file"]).name, f["line"]) for f in doc["findings"] if f["code"] == "I201"]
    assert i201 == [("arm.xacro", 3)]
    assert doc["summary"]["input_errors"] == 0
    assert code == 1


# ------------------------------------------------------------------ discovery

def test_a_directory_finds_the_gazebo_top_file_not_the_base_xacro(tmp_path, capsys):
    """A workspace directory (not a package) holding a RotorS vehicle: the top model is the
    .gazebo file no other file includes; <mav>_base.xacro is the part it includes through
    `$(arg mav_name)_base.xacro`, with or without the arguments."""
    shutil.copytree(SEED, tmp_path / "reed_gazebo")
    from reedtool.workflows.targets import expand_targets, include_globs_of, include_tree_of

    for mappings in ({}, SEED_ARGS):
        targets = expand_targets([str(tmp_path)],
                                 include_tree_of(lambda _p: mappings, [tmp_path]),
                                 include_globs=include_globs_of(lambda _p: mappings,
                                                                [tmp_path]))
        assert [t.path.name for t in targets] == [
            "mav_generic_odometry_sensor.gazebo",
            "mav_generic_odometry_sensor.untouched.gazebo"], mappings


def test_an_include_pattern_needs_an_argument_without_a_value(tmp_path):
    from reedtool.workflows.targets import include_globs_of

    top = tmp_path / "top.gazebo"
    top.write_text('<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
                   '<xacro:include filename="$(arg mav_name)_base.xacro"/>\n'
                   '<xacro:include filename="$(arg mav_name)"/>\n'
                   '<xacro:include filename="fixed.xacro"/>\n</robot>\n')
    assert include_globs_of(lambda _p: {}, [])(top) == [str(tmp_path / "*_base.xacro")]
    # With the argument set, the include tree follows the file exactly: no pattern.
    assert include_globs_of(lambda _p: {"mav_name": "m"}, [])(top) == []


def test_a_changed_config_means_the_models_it_configures(tmp_path, capsys):
    """The hook passes pyproject.toml when it changes; validate checks the models below
    it and never reads the TOML as a model. Without [tool.reedtool] it is not ours."""
    package = Path(shutil.copytree(SEED, tmp_path / "reed_gazebo"))
    pyproject = tmp_path / "pyproject.toml"
    pyproject.write_text("[project]\nname = 'x'\n")
    code, doc = run_json([pyproject], capsys)
    assert code == 0 and doc["models"][0]["skipped"].startswith("not a model")
    pyproject.write_text(config_text(SEED_ARGS))
    code, doc = run_json([pyproject, "--package-path", tmp_path], capsys)
    assert [Path(m["model"]).name for m in doc["models"]] == [
        "mav_generic_odometry_sensor.gazebo", "mav_generic_odometry_sensor.untouched.gazebo"]
    assert sorted(f["code"] for f in doc["findings"] if f["severity"] == "error") == \
        ["I203", "R312", "S115"]
    assert code == 2   # the untouched copy keeps its misspelt macro parameter
    assert package.is_dir()


def test_the_hook_and_discovery_know_the_same_model_files():
    """.pre-commit-hooks.yaml's `files` regex matches exactly the model suffixes directory
    discovery uses, plus the configuration files that carry xacro arguments."""
    import yaml

    from reedtool.workflows.targets import CONFIG_NAMES, MODEL_SUFFIXES

    hooks = yaml.safe_load((Path(__file__).parents[1] / ".pre-commit-hooks.yaml").read_text())
    pattern = re.compile(hooks[0]["files"])
    for suffix in MODEL_SUFFIXES:
        assert pattern.search(f"pkg/urdf/robot{suffix}"), suffix
    assert pattern.search("pkg/urdf/robot.urdf.xacro")
    assert pattern.search("pkg/urdf/mav_generic_odometry_sensor.gazebo")
    for name in CONFIG_NAMES:
        assert pattern.search(name) and pattern.search(f"sub/{name}"), name
    for other in ("README.md", "meshes/body.stl", "notpyproject.toml", "setup.cfg",
                  "launch/a.launch"):
        assert not pattern.search(other), other


# ------------------------------------------------------------------ messages that lead

def test_an_argument_without_colon_suggests_the_mapping(capsys):
    code, out, err = run_validate([FLIE / "urdf" / "flie_base.xacro", "mav_name=foo"], capsys)
    assert code == 2
    line, = [l for l in err.splitlines() if "error" in l]
    assert "mav_name=foo" in line and "did you mean 'mav_name:=foo'?" in line


@pytest.mark.parametrize("name", ["frame.stl", "FRAME.STL", "body.dae", "arm.obj"])
def test_a_mesh_given_as_a_model_says_so_and_names_import_stl(tmp_path, capsys, name):
    import numpy as np

    from reedtool.io.stl import stl_bytes

    mesh = tmp_path / name
    # A real mesh (one triangle); the refusal must not depend on reading it as XML.
    mesh.write_bytes(stl_bytes(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float), "t"))
    code, out, err = run_validate([mesh], capsys)
    assert code == 2 and out == ""
    line, = err.strip().splitlines()
    assert str(mesh) in line and "is a mesh" in line and "reedtool import-stl" in line
    assert "malformed XML" not in line


def test_a_mesh_given_to_another_command_says_so(tmp_path):
    from cli_helpers import run_cli

    mesh = tmp_path / "frame.stl"
    mesh.write_text("solid x\nendsolid x\n")
    code, out = run_cli("inertia", mesh)
    assert code == 2 and "is a mesh" in out and "import-stl" in out


def test_a_bare_px4_airframe_name_says_where_px4_keeps_airframes(capsys):
    model = FIXTURES / "flightstack" / "x500_flat.sdf"
    code, out, err = run_validate([model, "--airframe", "4001_gz_x500"], capsys)
    assert code == 2
    line, = err.strip().splitlines()
    assert line.startswith("reedtool: error: 4001_gz_x500: no such file")
    assert "PX4-Autopilot" in line and "ROMFS/px4fmu_common/init.d-posix/airframes/" in line
    # A path that is missing is an ordinary missing file, not a lecture about PX4.
    code, _, err = run_validate([model, "--airframe", "px4/4001_gz_x500"], capsys)
    assert code == 2 and "ROMFS" not in err


@pytest.mark.parametrize("option, word, meant", [
    ("--select", "R3O4", "R304"), ("--ignore", "i2O3", "I203"),
    ("--select", "inertia-triangle-inequalty", "inertia-triangle-inequality")])
def test_a_rule_selector_gets_did_you_mean(capsys, option, word, meant):
    model = FIXTURES / "validate" / "clean_quad_x.urdf"
    code, _, err = run_validate([model, option, word], capsys)
    assert code == 2 and f"did you mean '{meant}'?" in err


def test_a_selector_like_no_rule_gets_no_guess():
    from reedtool.checks.registry import suggest_selector

    assert suggest_selector("X999") is None and suggest_selector("zzzz-yyyy") is None


def test_a_clean_cross_check_says_what_it_compared(capsys):
    """A cross-check that finds nothing above information prints one line naming what it
    compared; machine formats keep it off stdout."""
    flight = FIXTURES / "flightstack"
    code, out, _ = run_validate([flight / "x500_flat.sdf", "--airframe",
                                 flight / "x500_airframe"], capsys)
    assert code == 0
    line, = [l for l in out.splitlines() if l.startswith("flight stack:")]
    assert line.endswith("x500_flat.sdf agree with x500_airframe (CA_ROTOR0..3, SIM_GZ_EC_*)")
    assert line.startswith("flight stack: 4 rotors of ")
    code, out, _ = run_validate([flight / "iris_ardupilot.sdf", "--autopilot-params",
                                 flight / "iris_quad_x.parm"], capsys)
    line, = [l for l in out.splitlines() if l.startswith("flight stack:")]
    assert line.endswith("agree with iris_quad_x.parm (FRAME_CLASS/FRAME_TYPE, "
                         "SERVOn_FUNCTION)")
    code, out, err = run_validate([flight / "x500_flat.sdf", "--airframe",
                                   flight / "x500_airframe", "--format", "json"], capsys)
    json.loads(out)
    assert "flight stack: 4 rotors" in err


def test_a_cross_check_with_findings_claims_no_agreement(tmp_path, capsys):
    flight = FIXTURES / "flightstack"
    airframe = tmp_path / "x500_airframe"
    # Motor 0 commanded the other way round: C416, so no "agree" line.
    text = (flight / "x500_airframe").read_text()
    assert "CA_ROTOR0_KM  0.05" in text
    airframe.write_text(text.replace("CA_ROTOR0_KM  0.05", "CA_ROTOR0_KM -0.05"))
    code, out, _ = run_validate([flight / "x500_flat.sdf", "--airframe", airframe], capsys)
    assert code == 1 and "C416" in out and "flight stack:" not in out


def test_a_changed_macro_library_is_checked_through_a_model_beside_it(flie, capsys):
    """A macro library cannot stand alone; with a model beside it that includes it, that
    model is where its mistakes show."""
    (flie / "urdf" / "flie_macros.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <xacro:macro name="payload" params="parent">\n'
        '    <link name="payload"><inertial><mass value="-0.01"/><inertia ixx="1e-6" '
        'ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial></link>\n'
        '    <joint name="payload_joint" type="fixed"><parent link="${parent}"/>'
        '<child link="payload"/></joint>\n  </xacro:macro>\n</robot>\n')
    base = flie / "urdf" / "flie_base.xacro"
    base.write_text(base.read_text().replace(
        "</robot>", '  <xacro:include filename="flie_macros.xacro" />\n'
                    '  <xacro:payload parent="${namespace}/base_link" />\n</robot>'))
    (flie.parent / "pyproject.toml").write_text(config_text(FLIE_ARGS))
    code, doc = run_json([flie / "urdf" / "flie_macros.xacro", "--package-path", flie.parent],
                         capsys)
    models = by_name(doc)
    assert models["flie_macros.xacro"]["skipped"].startswith("part of ")
    i201 = [(Path(f["file"]).name, f["line"]) for f in doc["findings"] if f["code"] == "I201"]
    call_line = next(n for n, line in enumerate(base.read_text().splitlines(), 1)
                     if "<xacro:payload " in line)
    assert i201 == [("flie_base.xacro", call_line)]     # the call site in the user's file
    assert code == 1


def test_every_command_suggests_the_mapping():
    """Commands that take one model read the words after it as arguments (resolve.mappings)."""
    from cli_helpers import run_cli

    code, out = run_cli("inertia", FLIE / "urdf" / "flie_base.xacro", "namespace=flie")
    assert code == 2 and "did you mean 'namespace:=flie'?" in out


def _hector_shaped(tmp_path: Path, body: str) -> Path:
    """A hector_quadrotor-shaped package: the file its launch files pass as the model is
    `<robot name=...>` holding nothing but includes; the included file lays out the links."""
    pkg = tmp_path / "hq_description"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>hq_description</name></package>")
    (pkg / "urdf" / "body.urdf.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">' + body + "</robot>")
    model = pkg / "urdf" / "quadrotor.gazebo.xacro"
    model.write_text('<robot name="quadrotor" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                     '<xacro:include filename="$(find hq_description)/urdf/body.urdf.xacro"/>'
                     "</robot>")
    return model


LINK = ('<link name="base_link"><inertial><mass value="{mass}"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial>'
        '</link>')


def test_a_file_of_includes_that_expands_into_links_is_validated_as_itself(tmp_path, capsys):
    """Issue 18 item 4: judged by its expansion, not its text. A file whose own children
    are only includes is a model when those includes lay out links (was 'skipped: a xacro
    macro library', exit 0, on hector_quadrotor's spawn models)."""
    model = _hector_shaped(tmp_path, LINK.format(mass="-1"))
    code, doc = run_json([str(model)], capsys)
    (entry,) = doc["models"]
    assert entry.get("skipped") is None and code == 1
    assert "I201" in {f["code"] for f in doc["findings"]}     # the mass of -1 is seen


def test_a_file_of_includes_that_lays_out_no_link_is_still_a_library(tmp_path, capsys):
    """Control: the same file including only macro definitions has no robot of its own."""
    model = _hector_shaped(tmp_path, '<xacro:macro name="arm"><link name="a"/></xacro:macro>')
    code, doc = run_json([str(model)], capsys)
    (entry,) = doc["models"]
    assert code == 0 and "macro library" in (entry.get("skipped") or "")
