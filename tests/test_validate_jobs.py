"""`validate --jobs N`: models checked in several processes give the report of one process,
in the same order; and what a run shares between models (mesh files) follows edits."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from cli_helpers import run_validate

FIXTURES = Path(__file__).parent / "fixtures"
MODELS = sorted((FIXTURES / "validate").glob("I20*_bad_*.urdf"))[:6] + [
    FIXTURES / "core" / "quad_x_rotors.urdf"]


def test_jobs_give_the_one_process_report_in_order(capsys, tmp_path):
    assert len(MODELS) >= 5
    files = []
    for i, model in enumerate(MODELS):        # names sort in a different order than given
        target = tmp_path / f"{len(MODELS) - i:02d}_{model.name}"
        shutil.copy(model, target)
        files.append(target)
    one = run_validate([*files, "--format", "json"], capsys)
    two = run_validate([*files, "--format", "json", "--jobs", "2"], capsys)
    assert one[0] == two[0] == 1
    # The same findings, model by model, in the order given (not sorted, not finish order).
    assert json.loads(one[1]) == json.loads(two[1])
    names = [m["model"] for m in json.loads(two[1])["models"]]
    assert [Path(n).name for n in names] == [f.name for f in files]
    assert names != sorted(names)
    text_one = run_validate(files, capsys)[1]
    text_all = run_validate([*files, "--jobs", "0"], capsys)[1]
    assert text_one == text_all


def test_jobs_keep_an_unreadable_model_in_the_report(capsys, tmp_path):
    good = tmp_path / "a.urdf"
    shutil.copy(FIXTURES / "core" / "quad_x_rotors.urdf", good)
    broken = tmp_path / "b.urdf"
    broken.write_text("<robot name='x'><link name='a'></robot>")
    code, out, _ = run_validate([good, broken, "--jobs", "2"], capsys)
    assert code == 2
    assert "b.urdf" in out and "a.urdf" in out


def test_jobs_raise_a_configuration_error_as_one_line(capsys, tmp_path):
    for name in ("a.urdf", "b.urdf"):
        shutil.copy(FIXTURES / "core" / "quad_x_rotors.urdf", tmp_path / name)
    (tmp_path / "reedtool.toml").write_text('select = ["NOPE_NOT_A_RULE"]\n')
    serial = run_validate([tmp_path / "a.urdf", tmp_path / "b.urdf"], capsys)
    parallel = run_validate([tmp_path / "a.urdf", tmp_path / "b.urdf", "--jobs", "2"], capsys)
    assert serial[0] == parallel[0] == 2
    assert serial[2] == parallel[2] and len(parallel[2].strip().splitlines()) == 1


def test_a_mesh_edited_between_runs_is_read_again(capsys, tmp_path):
    """Meshes are shared between the models of a run; a changed file is not the same file."""
    mesh = tmp_path / "body.stl"
    model = tmp_path / "m.urdf"
    model.write_text(
        '<robot name="m"><link name="base_link"><visual><geometry>'
        '<mesh filename="body.stl"/></geometry></visual><inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
        '</link></robot>')
    mesh.write_text("solid x\nendsolid x\n")          # an empty export: S115
    first = run_validate([model, "--select", "S115", "--format", "json"], capsys)
    assert [f["code"] for f in json.loads(first[1])["findings"]] == ["S115"]
    mesh.write_text("solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
                    "   vertex 0.1 0 0\n   vertex 0 0.1 0\n  endloop\n endfacet\nendsolid x\n")
    second = run_validate([model, "--select", "S115", "--format", "json"], capsys)
    assert json.loads(second[1])["findings"] == []


@pytest.mark.parametrize("jobs", ["-1", "x"])
def test_bad_jobs_is_a_usage_error(capsys, jobs):
    code, _, err = run_validate([MODELS[0], "--jobs", jobs], capsys)
    assert code == 2 and "--jobs" in err


def _mesh_model(path: Path, package: str) -> None:
    path.write_text(
        f'<robot name="{path.stem}"><link name="base_link"><visual><geometry>'
        f'<mesh filename="package://{package}/meshes/body.stl"/></geometry></visual>'
        '<inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
        '</link></robot>')


def _package(root: Path, name: str) -> None:
    (root / name / "meshes").mkdir(parents=True)
    (root / name / "package.xml").write_text(
        f'<package format="2"><name>{name}</name></package>')
    (root / name / "meshes" / "body.stl").write_text(
        "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 0.1 0 0\n"
        "   vertex 0 0.1 0\n  endloop\n endfacet\nendsolid x\n")


def test_a_run_crawls_each_package_root_once(capsys, tmp_path, monkeypatch):
    from reedtool.resolve import packages

    workspace = tmp_path / "ws"
    for i in range(5):
        _package(workspace / f"repo{i}", f"pkg{i}")
    models = tmp_path / "models"
    models.mkdir()
    for i in range(4):
        _mesh_model(models / f"m{i}.urdf", f"pkg{i}")
    crawled = []
    real = packages._crawl
    monkeypatch.setattr(packages, "_crawl",
                        lambda root, *a, **k: crawled.append(Path(root)) or real(root, *a, **k))
    code, out, _ = run_validate([models, "--package-path", workspace, "--select", "S115"],
                                capsys)
    assert code == 0, out
    assert crawled.count(workspace) == 1


def test_a_package_added_between_runs_is_found(capsys, tmp_path):
    """Crawls are shared within a run only: the next run sees the workspace as it is."""
    workspace = tmp_path / "ws"
    workspace.mkdir()
    model = tmp_path / "m.urdf"
    _mesh_model(model, "late_pkg")
    args = [model, "--package-path", workspace, "--select", "S115", "--format", "json"]
    first = run_validate(args, capsys)
    assert [f["code"] for f in json.loads(first[1])["findings"]] == ["S115"]
    _package(workspace, "late_pkg")
    second = run_validate(args, capsys)
    assert second[0] == 0 and json.loads(second[1])["findings"] == []
