"""`validate --launch`: the model and xacro arguments of a launch file, read without ROS;
and rule S140 (xacro-argument-unknown) for an argument the model never declares."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reedtool.cli import main
from reedtool.io.launch import read_launch

TESTS = Path(__file__).parent
CI = TESTS / "fixtures" / "ci"
SEED_PACKAGES = TESTS / "fixtures" / "seed000"
SEED_MODEL = SEED_PACKAGES / "reed_gazebo" / "urdf" / "mav_generic_odometry_sensor.gazebo"
HOVERING = CI / "reed_gazebo_launch" / "launch" / "mav_hovering_example.launch"
ROS2 = CI / "ros2_pkg"


def run_json(argv, capsys) -> tuple[int, dict]:
    with pytest.raises(SystemExit) as exc:
        main(["validate", *map(str, argv), "--format", "json"])
    return exc.value.code, json.loads(capsys.readouterr().out)


def findings(doc) -> list[tuple]:
    return sorted((f["code"], f["file"], f["line"]) for f in doc["findings"])


# ------------------------------------------------------------------ RotorS shape (ROS 1)

def test_rotors_launch_files_give_the_seed_its_arguments():
    call = read_launch(HOVERING, package_paths=[SEED_PACKAGES])
    # mav_hovering_example passes mav_name, model, enable_mavlink_interface...; spawn_mav
    # holds the xacro call and fills the rest from its defaults (namespace <- mav_name).
    assert call.model.resolve() == SEED_MODEL.resolve()
    assert call.mappings == {"enable_logging": "false", "enable_ground_truth": "true",
                             "enable_mavlink_interface": "true", "log_file": "reed_quad_x",
                             "wait_to_record_bag": "false", "mav_name": "reed_quad_x",
                             "namespace": "reed_quad_x"}
    spawn = HOVERING.parent / "spawn_mav.launch"
    lines = spawn.read_text().splitlines()
    for name, loc in call.locs.items():       # each argument points at its own line
        assert loc.file.endswith("spawn_mav.launch")
        assert lines[loc.line - 1].strip().startswith(f"{name}:=")


def test_seed_validates_from_its_launch_file_as_with_the_arguments_typed(capsys):
    code, from_launch = run_json(["--launch", HOVERING, "--package-path", SEED_PACKAGES],
                                 capsys)
    typed = [f"{k}:={v}" for k, v in read_launch(
        HOVERING, package_paths=[SEED_PACKAGES]).mappings.items()]
    code_typed, by_hand = run_json([SEED_MODEL, *typed], capsys)
    assert findings(from_launch) == findings(by_hand)
    assert sorted(f["code"] for f in from_launch["findings"]) == ["I203", "R312", "S115"]
    assert code == code_typed == 1


# ------------------------------------------------------------------ S140

def test_S140_good_launch_has_no_finding(capsys):
    code, doc = run_json(["--launch", CI / "S140_good_launch.launch"], capsys)
    assert (code, doc["findings"]) == (0, [])


def test_S140_bad_launch_points_at_the_misspelt_word_with_did_you_mean(capsys):
    code, doc = run_json(["--launch", CI / "S140_bad_launch.launch"], capsys)
    (finding,) = doc["findings"]
    assert (finding["code"], finding["severity"], finding["subject"]) == \
        ("S140", "warning", "mav_nmae")
    assert finding["file"].endswith("S140_bad_launch.launch") and finding["line"] == 6
    assert finding["hint"] == "did you mean 'mav_name'?"
    assert code == 0
    with pytest.raises(SystemExit) as exc:
        main(["validate", "--launch", str(CI / "S140_bad_launch.launch"), "--strict"])
    assert exc.value.code == 1


def test_misspelt_command_line_argument_is_a_warning(capsys):
    code, doc = run_json([CI / "S140_args_quad.xacro", "foo:=bar", "mav_nam:=x"], capsys)
    # 'mav_nam' is a near miss (a warning); 'foo' near nothing, maybe meant for another
    # node of the launch (information).
    assert sorted((f["code"], f["severity"], f["subject"], f["hint"])
                  for f in doc["findings"]) == [
        ("S140", "warning", "mav_nam", "did you mean 'mav_name'?"),
        ("S141", "info", "foo", "the model declares enable_logging, mav_name")]
    assert code == 0
    code, doc = run_json([CI / "S140_args_quad.xacro", "mav_name:=x", "enable_logging:=1"],
                         capsys)
    assert doc["findings"] == []


def test_misspelt_argument_on_the_seed_keeps_its_errors(capsys):
    args = [f"{k}:={v}" for k, v in read_launch(
        HOVERING, package_paths=[SEED_PACKAGES]).mappings.items()]
    code, doc = run_json([SEED_MODEL, *args, "foo:=bar"], capsys)
    assert sorted(f["code"] for f in doc["findings"]) == ["I203", "R312", "S115", "S141"]
    assert code == 1


def test_config_args_are_checked_only_for_models_that_read_them(capsys, tmp_path):
    import shutil

    shutil.copy(CI / "S140_args_quad.xacro", tmp_path / "quad.xacro")
    plain = tmp_path / "plain.xacro"
    plain.write_text((TESTS / "fixtures" / "validate" / "clean_quad_x.urdf").read_text()
                     .replace('<robot name="clean_quad_x">',
                              '<robot name="plain" xmlns:xacro="http://ros.org/wiki/xacro">'))
    (tmp_path / "reedtool.toml").write_text(
        'args = {mav_name = "q", enable_loging = "true"}\n'
        '[per-file-args]\n"plain.xacro" = {namespace = "n"}\n')
    code, doc = run_json([tmp_path / "quad.xacro", plain], capsys)
    got = {(Path(m["model"]).name, f["subject"], f["file"].endswith("reedtool.toml"), f["line"])
           for m in doc["models"] for f in m["findings"]}
    # quad reads mav_name, so the config's args are meant for it: the typo is reported at
    # its config line; plain reads no argument: only its own per-file argument is checked.
    assert got == {("quad.xacro", "enable_loging", True, 1),
                   ("plain.xacro", "namespace", True, 3)}


# ------------------------------------------------------------------ ROS 2

def test_ros2_python_command_launch(capsys):
    call = read_launch(ROS2 / "launch" / "display.launch.py")
    assert call.model.resolve() == (ROS2 / "urdf" / "args_quad.urdf.xacro").resolve()
    # mav_name comes from the DeclareLaunchArgument default, declared after its use.
    assert call.mappings == {"mav_name": "quad_py", "enable_logig": "true"}
    code, doc = run_json(["--launch", ROS2 / "launch" / "display.launch.py"], capsys)
    assert [(f["code"], f["line"], f["hint"]) for f in doc["findings"]] == [
        ("S140", 17, "did you mean 'enable_logging'?")]


def test_ros2_python_process_file_launch():
    call = read_launch(ROS2 / "launch" / "process_file.launch.py")
    assert call.model.resolve() == (ROS2 / "urdf" / "args_quad.urdf.xacro").resolve()
    assert call.mappings == {"mav_name": "quad_pf", "enable_logging": "true"}


def test_ros2_xml_launch():
    call = read_launch(ROS2 / "launch" / "display.launch.xml")
    assert call.model.resolve() == (ROS2 / "urdf" / "args_quad.urdf.xacro").resolve()
    assert call.mappings == {"mav_name": "quad_xml"}


def test_launch_without_xacro_call_is_one_line_exit_2(capsys, tmp_path):
    launch = tmp_path / "empty.launch"
    launch.write_text('<launch><arg name="a" default="1"/></launch>\n')
    with pytest.raises(SystemExit) as exc:
        main(["validate", "--launch", str(launch)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and err.count("\n") == 1 and "no xacro call" in err


def test_include_with_pass_all_args(tmp_path):
    (tmp_path / "inner.launch").write_text(
        '<launch>\n  <arg name="mav_name"/>\n'
        '  <param name="robot_description" command="xacro model.xacro mav_name:=$(arg mav_name)"/>\n'
        '</launch>\n')
    (tmp_path / "outer.launch").write_text(
        '<launch>\n  <arg name="mav_name" default="outer_quad"/>\n'
        '  <include file="$(dirname)/inner.launch" pass_all_args="true"/>\n</launch>\n')
    call = read_launch(tmp_path / "outer.launch")
    assert call.mappings == {"mav_name": "outer_quad"}
    assert call.locs["mav_name"].line == 3 and call.locs["mav_name"].file.endswith("inner.launch")
