"""Every model command alike (issue 19 item 3): the same inputs (files, directories, globs,
ROS packages), the same model options (--launch, --model, --package-path, name:=value,
`[tool.reedtool] args`), one validation policy, and help that names the formats.

The vehicle is our own xacro quad whose body mass is a required xacro argument: a command
that did not get the argument cannot load it, and the whole-robot mass each command
reports is checked against the hand sum body_kg + 4 rotors.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cli_helpers import run_cli
from rotors_builder import multirotor_urdf

ROTOR_KG = 0.02
ALIKE = ("inertia", "hover-test", "authority", "layout", "expand")
FLYING = ("hover-test", "authority")


def quad_xacro(*, rotor_ixx: float = 1e-5, visual_mesh: str | None = None) -> str:
    """A flat quad (RotorS plugins, x layout, alternating spin) whose body mass is the
    required argument `body_kg`."""
    visual = (f'<visual><geometry><mesh filename="{visual_mesh}"/></geometry></visual>'
              if visual_mesh else "")
    # No <xacro:arg>: xacro then requires body_kg from the caller (no default).
    return multirotor_urdf(
        4, name="alike_quad", xacro=True, arm_m=0.25, height_m=0.03, digits=6,
        body_kg="$(arg body_kg)", body_inertia=(0.02, 0.02, 0.04), body_xml=visual,
        rotor_kg=ROTOR_KG, rotor_inertia=(rotor_ixx, 1e-4, 1e-4),
        rotor_xml='<collision><geometry><cylinder radius="0.1" length="0.005"/></geometry>'
                  '</collision>')


def make_package(root: Path, xacro_text: str | None = None, *, name: str = "alike_description",
                 launch_kg: float = 1.5) -> Path:
    """A ROS 2 package: package.xml, urdf/quad.urdf.xacro and a launch file passing body_kg."""
    package = root / name
    (package / "urdf").mkdir(parents=True)
    (package / "launch").mkdir()
    (package / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.0.1'
        '</version><description>t</description><maintainer email="a@b.c">a</maintainer>'
        '<license>MIT</license></package>\n')
    (package / "urdf" / "quad.urdf.xacro").write_text(xacro_text or quad_xacro())
    (package / "launch" / "display.launch.xml").write_text(
        '<launch>\n  <node pkg="robot_state_publisher" exec="robot_state_publisher">\n'
        '    <param name="robot_description" value="$(command \'xacro '
        f'$(find-pkg-share {name})/urdf/quad.urdf.xacro body_kg:={launch_kg}\')"/>\n'
        '  </node>\n</launch>\n')
    return package


def tail(command: str, tmp_path: Path) -> list[str]:
    """What each command needs besides the model to do its job quickly."""
    return {"inertia": ["--format", "json"],
            "hover-test": ["--format", "json", "--duration", "4"],
            "authority": ["--format", "json"],
            "layout": ["-o", str(tmp_path / "layout.svg"), "--force"],
            "expand": []}[command]


def mass_read(command: str, out: str, tmp_path: Path) -> float | None:
    """The whole-robot mass a command reports (None where it reports none)."""
    if command == "inertia":
        return json.loads(out)["whole_robot"]["mass_kg"]
    if command == "hover-test":
        return json.loads(out)["model"]["mass_kg"]
    if command == "authority":
        return json.loads(out)["mass_kg"]
    if command == "expand":
        from lxml import etree

        root = etree.fromstring(out.encode())
        return sum(float(m.get("value")) for m in root.iterfind(".//link/inertial/mass"))
    svg = (tmp_path / "layout.svg").read_text()
    assert all(f'id="rotor-{n}"' in svg for n in range(1, 5))
    return None


def run(command: str, *args, tmp_path: Path) -> tuple[int, str]:
    return run_cli(command, *args, *tail(command, tmp_path))


# ------------------------------------------------------------------ inputs


@pytest.mark.parametrize("command", ALIKE)
def test_file_package_directory_and_glob_name_the_same_model(command, tmp_path,
                                                           monkeypatch):
    package = make_package(tmp_path)
    monkeypatch.chdir(tmp_path)
    expected_kg = 1.2 + 4 * ROTOR_KG
    for model in (package / "urdf" / "quad.urdf.xacro", package, "alike_description/urdf/*"):
        code, out = run(command, model, "body_kg:=1.2", tmp_path=tmp_path)
        assert code in (0, 1), out            # read and computed (not an input error)
        mass = mass_read(command, out, tmp_path)
        if mass is not None:
            # Sums of five decimal masses: a few ulps of 1.28.
            assert mass == pytest.approx(expected_kg, rel=1e-12), model


@pytest.mark.parametrize("command", ALIKE)
def test_several_models_are_refused_naming_them(command, tmp_path):
    package = make_package(tmp_path)
    (package / "urdf" / "other.urdf.xacro").write_text(quad_xacro())
    code, out = run(command, package, "body_kg:=1.2", tmp_path=tmp_path)
    assert code == 2
    assert "2 models found" in out and "quad.urdf.xacro" in out and "other.urdf.xacro" in out
    assert f"{command} reads one model at a time" in out


@pytest.mark.parametrize("command", ALIKE)
def test_a_word_that_is_neither_a_path_nor_an_argument_is_refused(command, tmp_path):
    package = make_package(tmp_path)
    code, out = run(command, package / "urdf" / "quad.urdf.xacro", "body_kg=1.2",
                    tmp_path=tmp_path)
    assert code == 2 and "name:=value" in out


# ------------------------------------------------------------------ model options


@pytest.mark.parametrize("command", ALIKE)
def test_launch_file_gives_the_model_and_its_arguments(command, tmp_path):
    package = make_package(tmp_path, launch_kg=1.5)
    code, out = run(command, "--launch", package / "launch" / "display.launch.xml",
                    "--package-path", tmp_path, tmp_path=tmp_path)
    assert code in (0, 1), out
    mass = mass_read(command, out, tmp_path)
    if mass is not None:
        assert mass == pytest.approx(1.5 + 4 * ROTOR_KG, rel=1e-12)


@pytest.mark.parametrize("command", ALIKE)
def test_config_args_apply_and_the_command_line_wins(command, tmp_path):
    package = make_package(tmp_path)
    (package / "pyproject.toml").write_text('[tool.reedtool]\nargs = {body_kg = "1.7"}\n')
    model = package / "urdf" / "quad.urdf.xacro"
    for extra, body_kg in (((), 1.7), (("body_kg:=1.1",), 1.1)):
        code, out = run(command, model, *extra, tmp_path=tmp_path)
        assert code in (0, 1), out
        mass = mass_read(command, out, tmp_path)
        if mass is not None:
            assert mass == pytest.approx(body_kg + 4 * ROTOR_KG, rel=1e-12)


WORLD = """<?xml version="1.0"?>
<sdf version="1.9"><world name="w">
{models}
</world></sdf>
"""


def sdf_box_model(name: str, mass_kg: float, x_m: float) -> str:
    return (f'<model name="{name}"><pose>{x_m} 0 0 0 0 0</pose><link name="body">'
            f'<inertial><mass>{mass_kg}</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy>'
            '<izz>0.01</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>'
            '</link></model>')


@pytest.mark.parametrize("command", ("inertia", "hover-test", "authority", "layout"))
def test_model_option_picks_one_model_of_a_world(command, tmp_path):
    world = tmp_path / "two.sdf"
    world.write_text(WORLD.format(models=sdf_box_model("a", 2.0, 0) +
                                  sdf_box_model("b", 3.0, 5)))
    code, out = run_cli(command, world, "--model", "b", *tail(command, tmp_path))
    if command in ("inertia", "hover-test"):
        # A box of 3 kg: its own mass, exactly as written.
        assert mass_read(command, out, tmp_path) == 3.0
        assert code == (0 if command == "inertia" else 1)    # a box cannot hover
    else:
        # Model b was read and found to have no rotors (rather than refused as unknown).
        assert code == 2 and ("no motor plugins" in out or "no rotors" in out), out
    code, out = run_cli(command, world, "--model", "c", *tail(command, tmp_path))
    assert code == 2 and "--model c: no such model" in out


def test_expand_refuses_model_option(tmp_path):
    package = make_package(tmp_path)
    code, out = run_cli("expand", package / "urdf" / "quad.urdf.xacro", "body_kg:=1",
                        "--model", "x")
    assert code == 2 and "--model" in out


def test_model_options_are_declared_once():
    """The same option objects' declarations and help in every model command."""
    import importlib

    from reedtool.cli import SUBCOMMANDS

    def params(name):
        command = importlib.import_module(SUBCOMMANDS[name][0]).command
        return {p.name: p for p in command.params}

    shared = ("inputs", "package_paths", "model_name", "launch_file")
    reference = params("validate")
    for name in ALIKE:
        here = params(name)
        for key in shared:
            assert key in here, (name, key)
            assert here[key].opts == reference[key].opts, (name, key)
            assert getattr(here[key], "help", None) == getattr(reference[key], "help", None)
    for name in ("inertia", "hover-test", "authority", "layout"):
        here = params(name)
        assert here["ignore"].opts == reference["ignore"].opts
        assert "ignore_validation" in here


@pytest.mark.parametrize("command", ALIKE + ("validate",))
def test_help_names_every_format_read(command):
    code, out = run_cli(command, "--help")
    text = " ".join(out.split())
    assert code == 0
    # expand writes a xacro's URDF: SDF is not among what it reads.
    formats = ((".urdf", ".xacro", ".gazebo") if command == "expand"
               else (".urdf", ".xacro", ".gazebo", ".sdf", ".world"))
    for suffix in formats:
        assert suffix in text, (command, suffix)
    assert "(.urdf or .xacro" not in text
    assert "directory" in text or "directories" in text


# ------------------------------------------------------------------ validation policy


@pytest.mark.parametrize("command", FLYING + ("inertia", "layout"))
def test_a_missing_visual_mesh_is_reported_not_refused(command, tmp_path):
    """S115 on a visual: the look, not the dynamics. hover-test used to refuse it."""
    package = make_package(tmp_path, quad_xacro(
        visual_mesh="package://alike_description/meshes/missing.stl"))
    code, out = run_cli(command, package, "body_kg:=1.2", "--package-path", tmp_path,
                        *[a for a in tail(command, tmp_path) if a != "json" and
                          a != "--format"])
    assert "S115" in out
    assert "not flying" not in out and "not analysing" not in out and "FAILED: validate" \
        not in out
    if command == "hover-test":
        assert code == 0 and out.rstrip().endswith("PASSED")
    if command == "authority":
        assert code == 0 and "PASSED --require hover" in out


@pytest.mark.parametrize("command", FLYING)
def test_a_mass_error_refuses_every_flying_command_alike(command, tmp_path):
    """I203 (rotor moments 1 > 1e-4 + 1e-4) makes a flight or authority meaningless."""
    package = make_package(tmp_path, quad_xacro(rotor_ixx=1.0))
    model = package / "urdf" / "quad.urdf.xacro"
    code, out = run_cli(command, model, "body_kg:=1.2")
    assert code == 1
    assert "I203" in out and out.rstrip().splitlines()[-1].startswith(
        "FAILED: validate reports 4 errors")
    assert "--ignore I203" in out
    code, report = run_cli(command, model, "body_kg:=1.2", "--format", "json")
    doc = json.loads(report)
    assert code == 1 and doc["status"] == "refused" and doc["passed"] is False
    assert doc["validation"]["refusing"] == ["I203"] and doc["validation"]["refused"]
    # What is held here is the validation policy, not the flight: hover-test flies 2 s (past
    # its 1 s hold) instead of the default 10 s.
    short = ("--duration", "2") if command == "hover-test" else ()
    for escape in (("--ignore", "I203"), ("--ignore-validation",)):
        code, out = run_cli(command, model, "body_kg:=1.2", *escape, *short, "--format", "json")
        doc = json.loads(out)
        assert doc.get("status") != "refused", escape
        assert doc["validation"]["refused"] is False


def test_inertia_reports_its_own_mass_verdicts_instead_of_refusing(tmp_path):
    package = make_package(tmp_path, quad_xacro(rotor_ixx=1.0))
    code, out = run_cli("inertia", package, "body_kg:=1.2", "--format", "json")
    doc = json.loads(out)
    assert code == 1 and "status" not in doc
    assert {c["link"] for c in doc["links"] if c["severity"] == "error"} == {
        f"rotor_{i}" for i in range(4)}


def test_refusal_groups_by_code():
    """The policy's groups read as documented: a family less the codes it leaves out, or the
    codes named (read from the rule registry, never from a code's prefix)."""
    from reedtool.workflows.validation import refuses

    needs = ("structure", "mass", "rotors")
    for code in ("S101", "S112", "S113", "S116", "S117", "I201", "I203", "I209", "R303",
                 "R316", "R318"):
        assert refuses(code, needs), code
    for code in ("S115", "S130", "S131", "I210", "R301", "R302", "R304", "R305", "R307",
                 "R308", "R312", "C404", "C416"):
        assert not refuses(code, needs), code
    assert not refuses("I203", ("structure",)) and refuses("S113", ("structure",))


def test_the_documented_refusal_table_is_the_code():
    """docs/commands.md shows refusal_table(); regenerate the block when the rules change."""
    from reedtool.workflows.validation import refusal_table

    doc = (Path(__file__).parent.parent / "docs" / "commands.md").read_text()
    block = doc.split("<!-- refusal-table")[1].split("<!-- end refusal-table -->")[0]
    rows = [line for line in block.splitlines() if line.startswith("| `")]
    assert rows == ["| `%s` | %s | %s |" % row for row in refusal_table()]
