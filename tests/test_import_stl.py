"""`reedtool import-stl` end to end: files written, vertices where a hand computation says."""

import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh

from reedtool.cli import main

EXAMPLES = Path(__file__).parents[1] / "meshes"
FIXTURES = Path(__file__).parent / "fixtures" / "meshes"
from oracles import CHECK_URDF

# L-bracket corners as written (mm, NED): profile (x, z) over y in {0, 40}.
L_PROFILE_XZ_MM = [(0, 0), (60, 0), (60, 5), (5, 5), (5, 30), (0, 30)]


def run(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(["import-stl", *(str(a) for a in args)])
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.fixture
def package(tmp_path):
    pkg = tmp_path / "my_quad"
    pkg.mkdir()
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2">\n  <name>reed_gazebo</name>\n'
        "  <version>0.1.0</version>\n</package>\n")
    return pkg


def vertex_set(path):
    triangles = trimesh.load(path, process=False).triangles     # an independent reader
    return {tuple(v) for v in np.round(triangles.reshape(-1, 3), 7)}


def test_l_bracket_in_mm_ned_lands_in_metres_flu(package, capsys):
    code, out, err = run([EXAMPLES / "l_bracket_mm_ned.stl", "--package", package,
                          "--name", "bracket", "--units", "mm", "--from-frame", "ned",
                          "--mass", "0.05"], capsys)
    assert code == 0, err
    written = package / "meshes" / "bracket.stl"
    # By hand: NED -> FLU keeps x and negates y and z (180 deg about x); mm -> m is /1000.
    expected = {(round(x / 1000, 7), round(-y / 1000, 7) + 0.0, round(-z / 1000, 7) + 0.0)
                for x, z in L_PROFILE_XZ_MM for y in (0, 40)}
    assert vertex_set(written) == expected
    assert written.read_bytes()[:5] != b"solid"
    assert trimesh.load(written).is_watertight           # trimesh merges vertices on load
    assert "180° about x" in out
    assert "watertight: yes" in out
    # COM by hand, in FLU metres: x = (300*30 + 125*2.5)/425 mm, y = -20 mm, z = -(300*2.5 + 125*17.5)/425 mm
    com = (9312.5 / 425 / 1000, -0.020, -2937.5 / 425 / 1000)
    snippet = out[out.index("<!--"):]
    origin = snippet.split('<origin xyz="')[3].split('"')[0]
    # The snippet prints the COM with ~10 significant digits: 1e-8 holds that rounding.
    np.testing.assert_allclose([float(v) for v in origin.split()], com, rtol=1e-8)
    assert 'filename="package://reed_gazebo/meshes/bracket.stl"' in snippet
    assert '<mass value="0.05"/>' in snippet


def test_snippet_is_a_valid_urdf_link_for_check_urdf(package, tmp_path, capsys):
    snippet_file = tmp_path / "bracket.xml"
    code, out, err = run([EXAMPLES / "l_bracket_mm_ned.stl", "--package", package,
                          "--units", "mm", "--from-frame", "ned", "--density", "2700",
                          "--collision", "hull", "--snippet", snippet_file], capsys)
    assert code == 0, err
    urdf = tmp_path / "robot.urdf"
    urdf.write_text('<?xml version="1.0"?>\n<robot name="t">\n' + snippet_file.read_text()
                    + "</robot>\n")
    result = subprocess.run([CHECK_URDF, str(urdf)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    from lxml import etree  # stricter than check_urdf's parser (e.g. "--" in comments)
    etree.parse(str(urdf))
    assert "package://reed_gazebo/meshes/l_bracket_mm_ned_collision.stl" in snippet_file.read_text()
    hull = trimesh.load(package / "meshes" / "l_bracket_mm_ned_collision.stl")
    assert hull.is_watertight and hull.is_convex
    # density 2700 x 17000 mm^3
    assert '<mass value="0.0459"/>' in snippet_file.read_text()


def test_auto_units_say_why_and_recenter_com(package, capsys):
    code, out, err = run([EXAMPLES / "quad_body_mm.stl", "--package", package,
                          "--recenter", "com", "--mass", "0.4"], capsys)
    assert code == 0, err
    assert "units: mm (largest extent" in out
    vertices = np.array(sorted(vertex_set(package / "meshes" / "quad_body_mm.stl")))
    # X frame: arm tips reach 125 mm along the diagonals; 10 mm thick, centred on z = 0
    assert np.max(np.abs(vertices[:, 2])) == pytest.approx(0.005)
    assert np.max(np.linalg.norm(vertices[:, :2], axis=1)) == pytest.approx(np.hypot(0.125, 0.01), rel=1e-6)


def test_refuses_to_overwrite_without_force(package, capsys):
    args = [EXAMPLES / "quad_body_mm.stl", "--package", package, "--units", "mm"]
    assert run(args, capsys)[0] == 0
    before = (package / "meshes" / "quad_body_mm.stl").read_bytes()
    code, out, err = run(args + ["--from-frame", "ned"], capsys)
    assert code == 2 and "refusing to overwrite" in err and "--force" in err
    assert (package / "meshes" / "quad_body_mm.stl").read_bytes() == before
    code, out, err = run(args + ["--from-frame", "ned", "--force"], capsys)
    assert code == 0
    assert (package / "meshes" / "quad_body_mm.stl").read_bytes() != before


def test_open_mesh_says_it_uses_the_convex_hull(package, capsys):
    code, out, err = run([FIXTURES / "l_bracket_open.stl", "--package", package, "--units", "mm"],
                         capsys)
    assert code == 0, err
    assert "watertight: NO" in out and "convex hull" in out


@pytest.mark.parametrize("make, message", [
    (lambda d: d / "nonexistent_pkg", "package directory not found"),
    (lambda d: d, "no package.xml"),
])
def test_package_errors(tmp_path, capsys, make, message):
    code, out, err = run([EXAMPLES / "quad_body_mm.stl", "--package", make(tmp_path)], capsys)
    assert code == 2 and message in err
    assert len(err.strip().splitlines()) == 1


def test_user_errors_are_one_line_exit_2(package, tmp_path, capsys):
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"solid empty\nendsolid empty\n")
    cases = [
        ([empty, "--package", package], "no triangles"),
        ([tmp_path / "missing.stl", "--package", package], "not found"),
        ([EXAMPLES / "quad_body_mm.stl", "--package", package, "--from-frame", "upside"],
         "unknown axis convention"),
        ([EXAMPLES / "quad_body_mm.stl", "--package", package, "--mass", "1", "--density", "2"],
         "not both"),
        ([EXAMPLES / "quad_body_mm.stl", "--package", package, "--mass", "-1"], "positive"),
        ([EXAMPLES / "quad_body_mm.stl", "--package", package, "--collision", "simplify:0"],
         "--collision"),
        ([EXAMPLES / "quad_body_mm.stl", "--package", package, "--name", "../evil"], "--name"),
    ]
    for args, message in cases:
        code, out, err = run(args, capsys)
        assert code == 2, (args, err)
        assert message in err and len(err.strip().splitlines()) == 1
        assert "Traceback" not in err
    assert not (package / "meshes").exists()


def test_simplified_collision_mesh_respects_the_budget(package, tmp_path, capsys):
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=50.0)   # mm
    path = tmp_path / "ball.stl"
    sphere.export(path)
    code, out, err = run([path, "--package", package, "--units", "mm",
                          "--collision", "simplify:300"], capsys)
    assert code == 0, err
    collision = trimesh.load(package / "meshes" / "ball_collision.stl", process=False)
    assert 50 <= len(collision.faces) <= 300
