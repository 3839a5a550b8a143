"""Issue 26 item 4: import-stl into a package sets that package's body; `inertia --fix`
edits the user's own file (the body_inertia property in NAME.xacro), never reedtool's.
References: the box formulas, by hand."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli

import reedtool
from reedtool.io.stl import stl_bytes

BUNDLED_BASE = (Path(reedtool.__file__).parent / "ros_packages" / "rotors_description" / "urdf"
                / "multirotor_base.xacro")
FACES = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
                  (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])


def box_stl(path, lo_mm, hi_mm):
    corners = np.array([[x, y, z] for x in (lo_mm[0], hi_mm[0]) for y in (lo_mm[1], hi_mm[1])
                        for z in (lo_mm[2], hi_mm[2])], float)
    path.write_bytes(stl_bytes(corners[FACES]))
    return path


def box_moments(mass, a, b, c):
    return [mass / 12 * (b * b + c * c), mass / 12 * (a * a + c * c), mass / 12 * (a * a + b * b)]


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def body_inertial(urdf_text: str, name: str):
    block = urdf_text[urdf_text.index(f'<link name="{name}/base_link_inertia">'):]
    block = block[:block.index("</inertial>")]
    origin = [float(v) for v in re.search(r'<origin[^>]*xyz="([^"]+)"', block).group(1).split()]
    inertia = re.search(r"<inertia ([^>]+)/>", block).group(1)
    values = dict(re.findall(r'(\w+)="([^"]+)"', inertia))
    return np.array(origin), {k: float(v) for k, v in values.items()}


def expand(pkg: Path) -> str:
    code, out = run_cli("expand", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                        "--package-path", pkg.parent)
    assert code == 0, out
    return out[out.index("<?xml"):]


def test_inertia_fix_edits_the_package_property_not_reedtools_macro(tmp_path):
    code, out = run_cli("new-package", "boxq", "-o", tmp_path)
    assert code == 0, out
    pkg = tmp_path / "boxq"
    xacro = pkg / "urdf" / "boxq.xacro"
    # The user changes the body mass and forgets the inertia.
    text = xacro.read_text()
    assert '<xacro:property name="mass" value="1.5" />' in text
    xacro.write_text(text.replace('<xacro:property name="mass" value="1.5" />',
                                  '<xacro:property name="mass" value="15" />'))
    before = xacro.read_text()
    bundled = digest(BUNDLED_BASE)
    code, out = run_cli("inertia", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                        "--package-path", tmp_path, "--fix")
    assert "site-packages" not in out and str(BUNDLED_BASE) not in out
    assert f"--fix: rewrote the <inertia/> at {xacro}:" in out
    assert digest(BUNDLED_BASE) == bundled                  # reedtool's file untouched
    assert (pkg / "urdf" / "boxq.xacro.bak").read_text() == before
    # The body_inertia property now holds a 15 kg solid box 0.2 x 0.2 x 0.06 m (the
    # package's body box) by the formula; 10 significant digits written.
    block = xacro.read_text().split('<xacro:property name="body_inertia">')[1]
    values = dict(re.findall(r'(i\w\w)="([^"]+)"', block.split("</xacro:property>")[0]))
    ixx, iyy, izz = box_moments(15.0, 0.2, 0.2, 0.06)
    assert [float(values[k]) for k in ("ixx", "iyy", "izz")] == pytest.approx([ixx, iyy, izz],
                                                                             rel=1e-9)
    # Only that element changed: the rest of the file byte for byte.
    old_lines, new_lines = before.splitlines(), xacro.read_text().splitlines()
    assert len(old_lines) == len(new_lines)
    assert sum(a != b for a, b in zip(old_lines, new_lines)) == 1
    code, out = run_cli("inertia", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                        "--package-path", tmp_path)
    assert re.search(r"boxq/base_link_inertia  \[ok\]", out), out


def test_import_stl_prints_then_sets_the_body_of_a_generated_package(tmp_path):
    seed = Path(__file__).parents[1] / "meshes" / "quadx_body_mm_ned.stl"
    code, out = run_cli("new-package", "cadq", "--mesh", seed, "--mesh-frame", "ned",
                        "--mass", "1.2", "-o", tmp_path)
    assert code == 0, out
    pkg = tmp_path / "cadq"
    xacro = pkg / "urdf" / "cadq.xacro"
    before = xacro.read_text()
    # A new body: a 300 x 240 x 40 mm box from its CAD origin at the bottom centre, FLU.
    body = box_stl(tmp_path / "body_v2.stl", (-150, -120, 0), (150, 120, 40))
    code, out = run_cli("import-stl", body, "--package", pkg)
    assert code == 0, out
    assert xacro.read_text() == before                      # printed, not written
    assert f"to make it the body of {xacro}, change these lines" in out
    assert 'value="package://cadq/meshes/body_v2.stl" />' in out
    assert 'name="body_com_xyz" value="0 0 0.02" />' in out
    code, out = run_cli("import-stl", body, "--package", pkg, "--set-body", "--force")
    assert code == 0, out
    assert (pkg / "urdf" / "cadq.xacro.bak").read_text() == before
    urdf = expand(pkg)
    origin, inertia = body_inertial(urdf, "cadq")
    # Box COM by symmetry (0, 0, 20 mm); the package's 1.2 kg (no --mass given) in the box
    # formula; float32 STL of whole millimetres: exact to 1e-9 relative.
    np.testing.assert_allclose(origin, [0.0, 0.0, 0.02], atol=1e-9)
    expected = box_moments(1.2, 0.3, 0.24, 0.04)
    assert [inertia[k] for k in ("ixx", "iyy", "izz")] == pytest.approx(expected, rel=1e-8)
    assert 'filename="package://cadq/meshes/body_v2.stl"' in urdf
    code, report = run_cli("validate", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                           "--package-path", tmp_path)
    assert code == 0, report


def test_a_box_package_takes_a_centred_mesh_and_refuses_an_off_centre_one(tmp_path):
    code, out = run_cli("new-package", "plainq", "-o", tmp_path)
    assert code == 0, out
    pkg = tmp_path / "plainq"
    xacro = pkg / "urdf" / "plainq.xacro"
    before = xacro.read_text()
    off = box_stl(tmp_path / "off.stl", (0, 0, 0), (200, 200, 40))
    code, out = run_cli("import-stl", off, "--package", pkg, "--set-body")
    assert code == 2 and "has no body_com_xyz property" in out and "new-package" in out
    assert xacro.read_text() == before and not (pkg / "meshes" / "off.stl").exists()
    centred = box_stl(tmp_path / "centred.stl", (-100, -100, -20), (100, 100, 20))
    code, out = run_cli("import-stl", centred, "--package", pkg, "--set-body")
    assert code == 0, out
    urdf = expand(pkg)
    origin, inertia = body_inertial(urdf, "plainq")
    np.testing.assert_allclose(origin, 0.0, atol=1e-12)
    expected = box_moments(1.5, 0.2, 0.2, 0.04)            # the package's 1.5 kg
    assert [inertia[k] for k in ("ixx", "iyy", "izz")] == pytest.approx(expected, rel=1e-8)
    assert 'filename="package://plainq/meshes/centred.stl"' in urdf
