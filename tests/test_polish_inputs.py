"""Inputs a new user gets wrong, found by using the product: each is one line naming the
file and what to do, exit 2, and never a computation on a model the user did not name."""

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


def test_world_model_option_still_picks_one():
    code, out = run_cli("hover-test", WORLDS / "several_models.sdf", "--package-path", MODELS,
                        "--model", "x500_1", "--format", "json")
    assert code in (0, 1), out
    assert '"x500_1"' in out and "x500_0" not in out


def test_world_with_one_multirotor_is_read_without_model():
    code, out = run_cli("inertia", WORLDS / "quadcopter.sdf")
    assert code in (0, 1), out


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
