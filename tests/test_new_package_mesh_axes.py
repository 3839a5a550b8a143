"""`new-package --mesh` says what it assumed about the mesh (issue 19 item 6): its unit and
axis reasoning, as import-stl states it, and a refusal naming the choices when the mesh's
extents say it stands on another axis than the FLU default."""

from __future__ import annotations

import numpy as np
import pytest
from cli_helpers import run_cli

from reedtool.io.stl import stl_bytes

_FACES = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
                   (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])


def box_stl(path, lo_mm, hi_mm):
    """A closed box from corner lo to corner hi (mm, in the mesh's own axes)."""
    corners = np.array([[x, y, z] for x in (lo_mm[0], hi_mm[0]) for y in (lo_mm[1], hi_mm[1])
                        for z in (lo_mm[2], hi_mm[2])], float)
    path.write_bytes(stl_bytes(corners[_FACES]))
    return path


def new_package(tmp_path, name, mesh, *extra):
    return run_cli("new-package", name, "--frame", "quad-x", "--mesh", mesh, "--mass", "1.2",
                   "-o", tmp_path, *extra)


def written_vertices(tmp_path, name):
    """The body mesh the package was generated with (metres), read by trimesh."""
    import trimesh

    mesh = trimesh.load(tmp_path / name / "meshes" / "body.stl", process=False)
    return {tuple(v) for v in np.round(mesh.vertices, 6)}


def test_a_y_up_body_is_refused_without_mesh_frame_and_names_the_choices(tmp_path):
    # 300 x 60 x 350 mm, Y-up: 60 mm is the height, 350 mm the length (along z, forward).
    mesh = box_stl(tmp_path / "body.stl", (0, 0, 0), (300, 60, 350))
    code, out = new_package(tmp_path, "yup", mesh)
    assert code == 2 and not (tmp_path / "yup").exists()
    line, = out.strip().splitlines()
    assert str(mesh) in line and "350 mm tall" in line and "60 mm along y" in line
    assert "--mesh-frame y-up" in line and "--mesh-frame flu" in line


def test_the_named_frame_is_taken_and_reported(tmp_path):
    mesh = box_stl(tmp_path / "body.stl", (0, 0, 0), (300, 60, 350))
    code, out = new_package(tmp_path, "yup", mesh, "--mesh-frame", "y-up", "--center", "com")
    assert code == 0, out
    assert "  units: mm (largest extent 350 units; as mm: 0.35 m across" in out
    assert "  frame: Y-UP → FLU" in out
    # Y-up (luf): source z is forward, x left, y up -> FLU 0.35 x 0.3 x 0.06 m.
    assert "  size: 0.35 x 0.3 x 0.06 m (x, y, z in FLU)" in out
    # By hand: FLU (x, y, z) = source (z, x, y) / 1000, with no translation (the CAD
    # origin is kept): the corners of [0, 0.35] x [0, 0.3] x [0, 0.06].
    corners = {(x, y, z) for x in (0.0, 0.35) for y in (0.0, 0.3) for z in (0.0, 0.06)}
    assert written_vertices(tmp_path, "yup") == corners


def test_keeping_flu_on_purpose_is_allowed(tmp_path):
    mesh = box_stl(tmp_path / "body.stl", (0, 0, 0), (300, 60, 350))
    code, out = new_package(tmp_path, "tall", mesh, "--mesh-frame", "flu", "--center", "com")
    assert code == 0, out
    assert "350 mm tall and 60 mm along y" in out   # said, not refused: the user chose


def test_a_body_wholly_below_its_origin_reads_z_down(tmp_path):
    # Drawn upward from its CAD origin in a Z-down (NED/FRD) export: z from -60 to 0 mm.
    mesh = box_stl(tmp_path / "body.stl", (-150, -150, -60), (150, 150, 0))
    code, out = new_package(tmp_path, "zdown", mesh)
    assert code == 2
    assert "wholly below its origin" in out and "--mesh-frame ned" in out
    assert "--mesh-frame frd" in out
    code, out = new_package(tmp_path, "zdown", mesh, "--mesh-frame", "ned")
    assert code == 0, out


def test_a_flat_z_up_body_is_taken_as_flu_and_says_why(tmp_path):
    mesh = box_stl(tmp_path / "body.stl", (-150, -120, 0), (150, 120, 60))
    code, out = new_package(tmp_path, "flat", mesh)
    assert code == 0, out
    assert "  units: mm (" in out and "  frame: FLU → FLU" in out
    assert "thinnest in height, as a body is" in out


def test_the_reading_is_one_implementation_with_import_stl(tmp_path):
    """import-stl prints the same unit and frame lines new-package does."""
    from reedtool.physics.mesh_import import assumption_lines, import_mesh

    mesh = box_stl(tmp_path / "body.stl", (0, 0, 0), (300, 60, 350))
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "package.xml").write_text(
        "<package format='2'><name>pkg</name></package>")
    code, out = run_cli("import-stl", mesh, "--package", tmp_path / "pkg", "--from-frame",
                        "y-up", "--mass", "1.2")
    assert code == 0, out
    for line in assumption_lines(import_mesh(mesh, from_frame="y-up", mass_kg=1.2)):
        assert line in out.splitlines()
