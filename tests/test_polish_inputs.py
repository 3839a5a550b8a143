"""Inputs a new user gets wrong, found by using the product: each is one line naming the
file and what to do, exit 2, and never a computation on a model the user did not name."""

import json
import re
from pathlib import Path

import pytest
from cli_helpers import run_cli

FIXTURES = Path(__file__).parent / "fixtures"
WORLDS = FIXTURES / "gz_worlds"
MODELS = FIXTURES / "px4_gz" / "models"
MESH = FIXTURES / "meshes" / "l_bracket_open.stl"


@pytest.mark.parametrize("command", ["inertia", "hover-test", "authority", "layout", "view",
                                     "migrate"])
def test_world_with_several_multirotors_needs_model(command, tmp_path):
    """Two x500s in one world: a one-model command used to compute on the first silently."""
    extra = {"layout": ["-o", tmp_path / "l.svg"], "view": ["-o", tmp_path / "v.glb"],
             "migrate": ["--to", "gz", "-o", tmp_path / "port"]}.get(command, [])
    code, out = run_cli(command, WORLDS / "several_models.sdf", "--package-path", MODELS,
                        *extra)
    assert code == 2, out
    last = out.strip().splitlines()[-1]
    assert "several_models.sdf" in last and "'x500_0', 'x500_1'" in last
    assert "--model NAME" in last
    assert not list(tmp_path.iterdir())          # nothing written for a refused input


def _include_uris(world: Path) -> list[str]:
    return [uri.strip() for uri in re.findall(r"<include>\s*<uri>([^<]+)</uri>",
                                              world.read_text())]


def test_world_model_option_still_picks_one():
    # Both models are PX4's stock x500 (model://x500), which flies: exit 0 exactly (a
    # refusal of the world would be 2, a model that cannot hover 1).
    assert [u for u in _include_uris(WORLDS / "several_models.sdf")
            if u.startswith("model://")] == ["model://x500"] * 2
    code, out = run_cli("hover-test", WORLDS / "several_models.sdf", "--package-path", MODELS,
                        "--model", "x500_1", "--format", "json")
    assert code == 0, out
    assert '"x500_1"' in out and "x500_0" not in out
    assert json.loads(out)["verdict"]["status"] == "flies"


def test_world_with_one_multirotor_is_read_without_model():
    """gz-sim's X3 example: its declared inertias match their geometry, so inertia exits 0,
    and the whole robot is the world's one model: its mass is the sum of the <mass>
    elements read from the file here (1.5 kg body and four 5 g rotors)."""
    world = WORLDS / "quadcopter.sdf"
    # Read with a regular expression: the file's comment holds "--", which Python's XML
    # parsers refuse and libsdformat reads. The ground plane is static and has no <mass>.
    masses = [float(m) for m in re.findall(r"<mass>([^<]+)</mass>", world.read_text())]
    assert len(masses) == 5
    code, out = run_cli("inertia", world, "--format", "json")
    assert code == 0, out
    doc = json.loads(out)
    assert doc["failing"] == 0
    # Two sums of five decimal masses in a different order: a few ulps; rel 1e-12 holds.
    assert doc["whole_robot"]["mass_kg"] == pytest.approx(sum(masses), rel=1e-12)


@pytest.mark.parametrize("model, says", [
    (MESH, "is a mesh (STL)"),
    (WORLDS / "quadcopter.sdf", "is SDF"),
    (MODELS / "x500", "is a Gazebo model directory (SDF)"),
])
def test_expand_names_what_it_was_given(model, says):
    """expand read an STL as XML ("malformed XML at column 1") and echoed SDF back under
    a header telling the user to edit .xacro sources."""
    code, out = run_cli("expand", model)
    assert code == 2
    last = out.strip().splitlines()[-1]
    assert str(model) in last and says in last


def test_new_ros2_package_reads_as_one_model(tmp_path):
    """`new-package --ros 2` writes worlds/NAME.sdf, a stage the launch file spawns the
    robot into; `validate PKG` used to fail on it (exit 2) and every one-model command
    refused the package as holding two models."""
    code, out = run_cli("new-package", "stage_quad", "--ros", "2", "--sim", "gz",
                        "-o", tmp_path)
    assert code == 0, out
    package = tmp_path / "stage_quad"
    world = package / "worlds" / "stage_quad.sdf"
    assert world.is_file()
    code, out = run_cli("validate", package)
    assert code == 0, out
    assert "stage_quad.urdf.xacro" in out and "could not be read" not in out
    code, out = run_cli("inertia", package, "--format", "json")
    assert code == 0, out
    code, out = run_cli("validate", world)         # named on its own: says what it is
    assert code == 2 and "stage_quad.sdf" in out and "spawns the robot" in out and "--launch" in out


def test_world_with_an_include_is_still_a_model(tmp_path):
    """Only a world with nothing but static models is a stage: an included vehicle is read."""
    (tmp_path / "package.xml").write_text("<package format='3'><name>w</name></package>")
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "w.sdf").write_text(
        "<sdf version='1.9'><world name='w'><include><uri>model://x500</uri></include>"
        "</world></sdf>")
    code, out = run_cli("hover-test", tmp_path, "--package-path", MODELS, "--format", "json")
    # the stock x500 flies: exit 0 exactly (a world read as an empty stage would be 2)
    assert code == 0, out
    assert json.loads(out)["model"]["name"] == "x500"


def test_authority_refuses_an_omnidirectional_frame():
    """Its one-way 4-D ACAI called the omnicopter (which trims to hover, T/W 5 by the 6-DoF
    allocation) 'not controllable at any thrust-to-weight', with thrust-to-weight 1.6e-8."""
    model = FIXTURES / "omni" / "omni_reversible.sdf"
    code, out = run_cli("hover-test", model, "--format", "json", "--require", "stable")
    assert code == 0, out                      # the 6-DoF trim holds: a frame that hovers
    assert json.loads(out)["outcome"] == "accepted"     # not flown: never a pass (issue 26)
    code, out = run_cli("authority", model)
    assert code == 2
    last = out.strip().splitlines()[-1]
    assert "omni_reversible.sdf" in last and "omnidirectional" in last


def test_authority_on_a_fixed_wing_says_no_rotor_lifts():
    """A plane has a motor plugin; 'no motor plugins found' was untrue."""
    code, out = run_cli("authority", FIXTURES / "ardupilot" / "zephyr_pusher.sdf")
    assert code == 2
    assert "no lift rotors" in out and "no motor plugins" not in out


@pytest.mark.parametrize("command", ["validate", "hover-test", "expand"])
def test_an_empty_word_is_refused_not_read_as_the_working_directory(command, tmp_path,
                                                                    monkeypatch):
    """`reedtool validate "$MODEL"` with MODEL unset: '' was read as '.', so validate
    checked whatever lay under the working directory (and passed on a broken model it
    never saw) and hover-test listed its 70-odd models."""
    good = tmp_path / "good"
    good.mkdir()
    (good / "a.urdf").write_text("<robot name='a'><link name='a'/></robot>")
    monkeypatch.chdir(good)
    code, out = run_cli(command, "")
    assert code == 2
    assert "empty word" in out.strip().splitlines()[-1]


def test_validate_diagram_draws_one_picture_per_model_even_when_names_repeat(tmp_path):
    """Six of the VTOL fixtures are all called standard_vtol_like: with --force their
    pictures overwrote one another (FILE-ROBOT.svg), leaving 2 files for 7 models."""
    vtol = FIXTURES / "vtol"
    models = sorted(vtol.glob("*.sdf"))
    code, out = run_cli("validate", vtol, "--diagram", tmp_path / "d.svg", "--force")
    # The folder holds the bad fixtures of error rules (R301_bad_duplicate_actuator.sdf):
    # exit 1 exactly, the diagrams drawn all the same.
    from reedtool.checks.registry import get_rule

    bad = [m for m in models if "_bad_" in m.name]
    assert any(get_rule(m.name.split("_")[0]).severity == "error" for m in bad)
    assert code == 1, out
    assert all(m.name.split("_")[0] in out for m in bad)
    drawn = sorted(p.name for p in tmp_path.glob("d-*.svg"))
    assert drawn == sorted(f"d-{m.stem}.svg" for m in models)


def test_validate_diagram_skips_a_model_without_rotors(tmp_path):
    """A ground robot beside a multirotor aborted the whole run (exit 2, no report)."""
    mixed = tmp_path / "mixed"
    mixed.mkdir()
    (mixed / "cart.urdf").write_text(
        "<robot name='cart'><link name='body'><inertial><mass value='2'/>"
        "<inertia ixx='0.1' ixy='0' ixz='0' iyy='0.1' iyz='0' izz='0.1'/></inertial>"
        "</link></robot>")
    (mixed / "vtol.sdf").write_text((FIXTURES / "vtol" / "vtol_pusher.sdf").read_text())
    code, out = run_cli("validate", mixed, "--diagram", tmp_path / "m.svg")
    assert code == 0, out
    assert "cart.urdf" in out and "no rotors" in out
    assert sorted(p.name for p in tmp_path.glob("m-*.svg")) == ["m-vtol.svg"]
