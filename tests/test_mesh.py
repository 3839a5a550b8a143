"""STL reading, checks, topology, units and writing, against trimesh and hand-made bytes."""

import struct
from pathlib import Path

import numpy as np
import pytest
import trimesh

from reedtool.errors import ReedtoolError
from reedtool.io.meshes import check_triangles
from reedtool.io.stl import parse_stl, read_stl, stl_bytes
from reedtool.physics.mesh_import import CollisionSpec
from reedtool.physics.mesh_topology import cluster_decimate, convex_hull_triangles, topology

FIXTURES = Path(__file__).parent / "fixtures" / "meshes"
EXAMPLES = Path(__file__).parents[1] / "meshes"

# The L-bracket's 12 corners in its file (mm, NED): profile (x, z) extruded over y = 0, 40.
L_PROFILE_XZ = [(0, 0), (60, 0), (60, 5), (5, 5), (5, 30), (0, 30)]
L_CORNERS_MM = {(x, y, z) for x, z in L_PROFILE_XZ for y in (0.0, 40.0)}


def corners(triangles):
    return {tuple(float(c) for c in v) for v in np.round(triangles.reshape(-1, 3), 9)}


def binary_stl(triangles, header=b"test") -> bytes:
    """A binary STL written with struct, independently of reedtool's writer."""
    out = header.ljust(80, b" ") + struct.pack("<I", len(triangles))
    for tri in triangles:
        out += struct.pack("<3f", 0, 0, 0) + struct.pack("<9f", *np.ravel(tri)) + b"\0\0"
    return out


def test_binary_ascii_and_solid_header_variants_read_the_same_triangles():
    binary = read_stl(EXAMPLES / "l_bracket_mm_ned.stl")
    solid_header = read_stl(FIXTURES / "l_bracket_solid_header.stl")
    ascii_ = read_stl(FIXTURES / "l_bracket_ascii.stl")
    assert (binary.format, solid_header.format, ascii_.format) == ("binary", "binary", "ascii")
    assert (FIXTURES / "l_bracket_solid_header.stl").read_bytes()[:5] == b"solid"
    assert corners(binary.triangles) == L_CORNERS_MM
    # Exact: the same float32 bytes read twice.
    np.testing.assert_array_equal(binary.triangles, solid_header.triangles)
    np.testing.assert_allclose(binary.triangles, ascii_.triangles, atol=1e-9)
    # trimesh, an independent reader, sees the same triangles
    reference = trimesh.load(EXAMPLES / "l_bracket_mm_ned.stl", process=False)
    np.testing.assert_allclose(binary.triangles, reference.triangles, atol=0)


def test_binary_header_starting_with_solid_and_containing_facet_is_still_binary():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], dtype=float)
    data = binary_stl(tri, header=b"solid facet normal vertex endsolid")
    stl = parse_stl(data)
    assert stl.format == "binary"
    # Exact: float32 values written and read back bit for bit.
    np.testing.assert_array_equal(stl.triangles, tri)


@pytest.mark.parametrize("data, message", [
    (b"", "only 0 bytes"),
    (b"hello world, not a mesh" * 10, "not an STL file"),
    (b"x" * 80 + struct.pack("<I", 3) + b"\0" * 60, "not 84 \\+ 50 x 3"),
    (b"solid empty\nendsolid empty\n", "no triangles"),
    (b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
     b"endfacet\nendsolid a\n", "not a multiple of 3"),
    (b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\nvertex 0 1 0\n"
     b"endloop\nendfacet\nendsolid a\n", "bad vertex coordinate"),
])
def test_unreadable_stl_raises_reedtool_error(tmp_path, data, message):
    path = tmp_path / "bad.stl"
    path.write_bytes(data)
    with pytest.raises(ReedtoolError, match=message) as info:
        triangles = read_stl(path).triangles
        check_triangles(triangles, path)
    assert info.value.file == str(path)


def test_bad_ascii_coordinate_names_its_line(tmp_path):
    path = tmp_path / "bad.stl"
    path.write_bytes(b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\n"
                     b"vertex 0 1 0\nendloop\nendfacet\nendsolid a\n")
    with pytest.raises(ReedtoolError) as info:
        read_stl(path)
    assert info.value.line == 5


def test_empty_nan_zero_area_and_flat_meshes_are_refused(tmp_path):
    good = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [0, 1, 0], [0, 0, 1]]], float)
    nan = good.copy()
    nan[1, 2, 0] = np.nan
    zero_area = np.zeros((4, 3, 3))
    flat = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[1, 1, 0], [0, 1, 0], [1, 0, 0]]], float)
    cases = {"empty": (np.zeros((0, 3, 3)), "no triangles"), "nan": (nan, "NaN"),
             "zero": (zero_area, "zero area"), "flat": (flat, "flat")}
    for name, (triangles, message) in cases.items():
        path = tmp_path / f"{name}.stl"
        path.write_bytes(binary_stl(triangles))
        with pytest.raises(ReedtoolError, match=message):
            check_triangles(read_stl(path).triangles, path)
    assert check_triangles(good, "good").triangles == 2


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(ReedtoolError, match="not found"):
        read_stl(tmp_path / "nope.stl")
    with pytest.raises(ReedtoolError, match="directory"):
        read_stl(tmp_path)


def test_topology_agrees_with_trimesh():
    closed = trimesh.creation.icosphere(subdivisions=2)
    open_ = trimesh.Trimesh(closed.vertices, closed.faces[1:], process=False)
    flipped_faces = closed.faces.copy()
    flipped_faces[0] = flipped_faces[0][::-1]
    flipped = trimesh.Trimesh(closed.vertices, flipped_faces, process=False)
    for mesh in (closed, open_, flipped):
        topo = topology(mesh.triangles)
        assert topo.watertight == mesh.is_watertight
        assert topo.closed == (mesh.is_watertight and mesh.is_winding_consistent)
    assert topology(closed.triangles).vertices == len(closed.vertices)
    assert not topology(flipped.triangles).winding_consistent


def test_topology_of_fixtures():
    assert topology(read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles).closed
    assert not topology(read_stl(FIXTURES / "l_bracket_open.stl").triangles).watertight


# The unit reading is tested in tests/test_mesh_units.py (physics/mesh_units.py).


def test_stl_bytes_round_trip_through_trimesh(tmp_path):
    triangles = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles / 1000.0
    data = stl_bytes(triangles, header="solid-looking header must be avoided")
    assert not data[:5].lower().startswith(b"solid")
    assert len(data) == 84 + 50 * len(triangles)
    path = tmp_path / "out.stl"
    path.write_bytes(data)
    loaded = trimesh.load(path, process=False)
    np.testing.assert_allclose(loaded.triangles, triangles, rtol=1e-6, atol=1e-9)
    # normals are unit and outward (same as trimesh's face normals)
    records = np.frombuffer(data, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")],
                            offset=84)
    np.testing.assert_allclose(records["n"], loaded.face_normals, atol=1e-6)


def test_collision_specs():
    assert CollisionSpec.parse("hull") == CollisionSpec("hull")
    assert CollisionSpec.parse("simplify:200") == CollisionSpec("simplify", 200)
    for bad in ("simplify:", "simplify:2", "decimate", "simplify:x"):
        with pytest.raises(ReedtoolError, match="--collision"):
            CollisionSpec.parse(bad)


def test_convex_hull_of_the_l_bracket_is_its_bounding_prism():
    triangles = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles
    hull = trimesh.Trimesh(**trimesh.triangles.to_kwargs(convex_hull_triangles(triangles)))
    # The hull of the L profile is the polygon (0,0) (60,0) (60,5) (5,30) (0,30): area by hand
    area_mm2 = 60 * 5 + 5 * 25 + 0.5 * 55 * 25
    assert hull.is_watertight
    assert hull.volume == pytest.approx(area_mm2 * 40, rel=1e-9)


def test_cluster_decimate_meets_the_face_budget():
    sphere = trimesh.creation.icosphere(subdivisions=4)          # 5120 faces
    small = cluster_decimate(sphere.triangles, 500)
    assert 100 <= len(small) <= 500
    # still roughly the same sphere: every vertex near radius 1
    radii = np.linalg.norm(small.reshape(-1, 3), axis=1)
    assert np.all(np.abs(radii - 1.0) < 0.2)
    assert len(cluster_decimate(sphere.triangles, 10_000)) == len(sphere.triangles)


def test_merge_vertices_falls_back_when_hashes_collide(monkeypatch):
    import reedtool.physics.mesh_topology as mesh_module

    sphere = trimesh.creation.icosphere(subdivisions=2)
    expected = topology(sphere.triangles)
    # every vertex gets the same hash: only the exact (lexsort) path can merge correctly
    monkeypatch.setattr(mesh_module, "_vertex_hash", lambda wide: np.zeros(len(wide), np.uint64))
    vertices, faces = mesh_module.merge_vertices(sphere.triangles)
    assert len(vertices) == len(sphere.vertices)
    # Exact: indexing copies the vertices, no arithmetic.
    np.testing.assert_array_equal(vertices[faces], sphere.triangles)
    assert topology(sphere.triangles) == expected
