"""Package search order and URI resolution (reedtool.resolve.packages)."""

from __future__ import annotations

from pathlib import Path

import pytest

from reedtool.errors import ReedtoolError
from reedtool.resolve.packages import BUNDLED_PACKAGES_DIR, PackageResolver
from reedtool.model import SourceLoc


def make_package(directory: Path, name: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="2"><name>{name}</name></package>\n')
    return directory


@pytest.fixture(autouse=True)
def clean_env(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def test_name_comes_from_package_xml_not_directory(tmp_path):
    pkg = make_package(tmp_path / "ws" / "src" / "repo" / "some_dir", "real_name")
    resolver = PackageResolver([tmp_path / "ws"])
    assert resolver.find("real_name") == pkg.absolute()
    with pytest.raises(ReedtoolError):
        resolver.find("some_dir")


def test_search_order(tmp_path, monkeypatch):
    cli = make_package(tmp_path / "cli" / "p", "p")
    ros = make_package(tmp_path / "ros" / "p", "p")
    ament = make_package(tmp_path / "prefix" / "share" / "p", "p")
    make_package(tmp_path / "ros" / "only_ros", "only_ros")
    make_package(tmp_path / "prefix" / "share" / "only_ament", "only_ament")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ros"))
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "prefix"))
    assert PackageResolver([tmp_path / "cli"]).find("p") == cli.absolute()
    assert PackageResolver().find("p") == ros.absolute()
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    assert PackageResolver().find("p") == ament.absolute()
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ros"))
    assert PackageResolver().find("only_ament").name == "only_ament"
    assert PackageResolver().find("only_ros").name == "only_ros"


def test_model_package_then_bundled(tmp_path):
    own = make_package(tmp_path / "my_pkg", "my_pkg")
    model = own / "urdf" / "robot.xacro"
    model.parent.mkdir()
    model.write_text("<robot/>")
    resolver = PackageResolver(model_path=model)
    assert resolver.find("my_pkg") == own.absolute()
    assert resolver.find("rotors_description") == BUNDLED_PACKAGES_DIR / "rotors_description"
    # a real rotors_description earlier on the path wins over the bundled one
    real = make_package(tmp_path / "ws" / "rotors_description", "rotors_description")
    assert PackageResolver([tmp_path / "ws"], model).find("rotors_description") == real.absolute()


def test_hidden_and_ignored_directories_are_skipped(tmp_path):
    make_package(tmp_path / ".git" / "p", "p")
    make_package(tmp_path / "build" / "p", "p")
    (tmp_path / "build" / "CATKIN_IGNORE").write_text("")
    with pytest.raises(ReedtoolError):
        PackageResolver([tmp_path]).find("p")


def test_packages_do_not_nest(tmp_path):
    make_package(tmp_path / "outer", "outer")
    make_package(tmp_path / "outer" / "test" / "inner", "inner")
    with pytest.raises(ReedtoolError):
        PackageResolver([tmp_path]).find("inner")


def test_missing_package_error_names_package_requester_and_places(tmp_path):
    (tmp_path / "extra").mkdir()
    resolver = PackageResolver([tmp_path / "extra"])
    with pytest.raises(ReedtoolError) as info:
        resolver.find("nope", requested_by=SourceLoc("robot.xacro", 12))
    err = info.value
    assert (err.file, err.line) == ("robot.xacro", 12)
    text = err.one_line()
    assert "'nope'" in text
    assert str(tmp_path / "extra") in text and str(BUNDLED_PACKAGES_DIR) in text
    assert "--package-path" in text


def test_resolve_uri_forms(tmp_path):
    pkg = make_package(tmp_path / "meshes_pkg", "meshes_pkg")
    resolver = PackageResolver([tmp_path])
    base = tmp_path / "urdf"
    assert resolver.resolve_uri("package://meshes_pkg/meshes/a b.stl", base) == \
        pkg.absolute() / "meshes" / "a b.stl"
    assert resolver.resolve_uri("file:///opt/m/x.dae", base) == Path("/opt/m/x.dae")
    assert resolver.resolve_uri("/abs/x.stl", base) == Path("/abs/x.stl")
    assert resolver.resolve_uri("../meshes/x.stl", base) == base / "../meshes/x.stl"
    # existence is the caller's business
    assert not resolver.resolve_uri("package://meshes_pkg/missing.stl", base).exists()
    with pytest.raises(ReedtoolError, match="'other'"):
        resolver.resolve_uri("package://other/x.stl", base)
    with pytest.raises(ReedtoolError, match="model://"):
        resolver.resolve_uri("model://x/mesh.dae", base)


def test_bundled_package_ships_as_package_data():
    """The bundled files live inside the reedtool package, so a wheel carries them."""
    import reedtool

    root = Path(reedtool.__file__).parent / "ros_packages" / "rotors_description"
    assert root == BUNDLED_PACKAGES_DIR / "rotors_description"
    for rel in ("package.xml", "urdf/component_snippets.xacro", "urdf/multirotor_base.xacro"):
        assert (root / rel).is_file()


def _twin_workspace(root: Path, copies: int) -> Path:
    """A workspace with `copies` packages named 'twin' and a model using one of its meshes."""
    import numpy as np

    from reedtool.io.stl import stl_bytes

    for i in range(copies):
        pkg = root / "src" / f"twin_{i}"
        (pkg / "meshes").mkdir(parents=True)
        (pkg / "package.xml").write_text("<package><name>twin</name></package>")
        box = np.array([[[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], [[0, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
                        [[0, 0, 0], [0, 0, 0.1], [0.1, 0, 0]], [[0.1, 0, 0], [0, 0, 0.1], [0, 0.1, 0]]])
        (pkg / "meshes" / "body.stl").write_bytes(stl_bytes(box.astype(float)))
    model = root / "robot.urdf"
    model.write_text('<robot name="r"><link name="base"><visual><geometry>'
                     '<mesh filename="package://twin/meshes/body.stl"/></geometry></visual>'
                     '</link></robot>')
    return model


@pytest.mark.parametrize("copies,expected", [(2, ["S150"]), (1, [])])
def test_two_packages_with_one_name_are_reported(tmp_path, copies, expected):
    """S150: the copy that is ignored is named beside the one used (bad: two, good: one)."""
    from reedtool.checks.runner import Selection, run_checks
    from reedtool.io.loader import load_robot

    model = _twin_workspace(tmp_path, copies)
    robot = load_robot(model, {}, [tmp_path / "src"])
    findings = run_checks(robot, Selection(select=("S",)))
    assert [f.code for f in findings] == expected
    if expected:
        assert "twin_0" in findings[0].message and "twin_1" in findings[0].message


def test_a_twin_of_a_package_the_model_never_reads_is_not_reported(tmp_path):
    """S150 good: two packages named 'other' on the search path cannot change a model that
    reads only 'twin' (a workspace crawl finds every duplicate; only used ones matter)."""
    from reedtool.checks.runner import Selection, run_checks
    from reedtool.io.loader import load_robot

    model = _twin_workspace(tmp_path, 1)
    for i in range(2):
        other = tmp_path / "src" / f"other_{i}"
        other.mkdir()
        (other / "package.xml").write_text("<package><name>other</name></package>")
    robot = load_robot(model, {}, [tmp_path / "src"])
    assert [f.code for f in run_checks(robot, Selection(select=("S",)))] == []


def test_one_package_reached_through_a_symlink_is_one_package(tmp_path):
    """S150 good: an install space whose share/twin links to the sources (colcon
    --symlink-install, catkin's devel space) holds one package, reached twice."""
    from reedtool.checks.runner import Selection, run_checks
    from reedtool.io.loader import load_robot

    model = _twin_workspace(tmp_path, 1)
    share = tmp_path / "src" / "install" / "share"
    share.mkdir(parents=True)
    (share / "twin").symlink_to(tmp_path / "src" / "twin_0", target_is_directory=True)
    robot = load_robot(model, {}, [tmp_path / "src"])
    assert [f.code for f in run_checks(robot, Selection(select=("S",)))] == []
    # Control: a real copy in the same place is still two packages.
    (share / "twin").unlink()
    import shutil
    shutil.copytree(tmp_path / "src" / "twin_0", share / "twin")
    robot = load_robot(model, {}, [tmp_path / "src"])
    assert [f.code for f in run_checks(robot, Selection(select=("S",)))] == ["S150"]
