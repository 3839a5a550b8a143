"""The COLLADA reader's number parsing (numpy in C, issue 27's speed item) against the
word-by-word parse it replaced and against trimesh's COLLADA loader (pycollada), an
independent reader: the same triangles, whatever path the numbers took."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reedtool.errors import ReedtoolError
from reedtool.io.dae import _parse_numbers, parse_dae, read_dae
from reedtool.io.meshes import corner_bounds, read_mesh, triangle_areas


XYZ = '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'


def _ellipsoid_dae(radii_mm, segments=40, rings=25) -> str:
    """A closed ellipsoid exported as RotorS's meshes are: millimetres with <unit>, Y up,
    a NORMAL input beside VERTEX (two indices per corner)."""
    theta = np.linspace(0, math.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    unit = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    unit = np.vstack([[0, 0, 1], unit, [0, 0, -1]])
    positions = unit * radii_mm
    faces = []
    for s in range(segments):
        faces.append((0, 1 + s, 1 + (s + 1) % segments))
        base = 1 + (rings - 2) * segments
        faces.append((len(unit) - 1, base + (s + 1) % segments, base + s))
    for r in range(rings - 2):
        for s in range(segments):
            a, b = 1 + r * segments + s, 1 + r * segments + (s + 1) % segments
            c, d = a + segments, b + segments
            faces += [(a, c, b), (b, c, d)]
    faces = np.asarray(faces)
    corners = np.stack([faces, faces], -1).reshape(-1)
    floats = " ".join(f"{v:.9g}" for v in positions.reshape(-1))
    normals = " ".join(f"{v:.6f}" for v in unit.reshape(-1))
    return f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="{positions.size}">{floats}</float_array>
      <technique_common><accessor source="#pa" count="{len(positions)}" stride="3">{XYZ}</accessor></technique_common></source>
    <source id="n"><float_array id="na" count="{unit.size}">{normals}</float_array>
      <technique_common><accessor source="#na" count="{len(unit)}" stride="3">{XYZ}</accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="{len(faces)}"><input semantic="VERTEX" source="#v" offset="0"/>
      <input semantic="NORMAL" source="#n" offset="1"/><p>{" ".join(map(str, corners))}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="b"><instance_geometry url="#g"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def test_a_rotors_shaped_export_reads_as_trimesh_reads_it(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    path = tmp_path / "body.dae"
    path.write_text(_ellipsoid_dae((120.0, 80.0, 45.0)))
    ours = read_mesh(path)
    theirs = trimesh.load(str(path), force="mesh", process=False)
    # pycollada applies neither <unit> nor <up_axis>; Gazebo (and reedtool) apply both.
    assert len(ours.triangles) == len(theirs.faces) == 2 * 40 * 24
    # Area is invariant under the up-axis rotation; millimetres squared to metres squared.
    # pycollada reads float32 (epsilon 1.2e-7), reedtool float64 of the same 9-digit text:
    # they agree to float32's resolution, 2.4e-7 relative (two roundings).
    assert triangle_areas(ours.triangles_m).sum() == pytest.approx(theirs.area * 1e-6,
                                                                   rel=2.4e-7)
    # Y up turned to Z up: the file's (x, y, z) is Gazebo's (x, -z, y).
    low, high = corner_bounds(ours.triangles_m)
    t_low, t_high = np.asarray(theirs.bounds) * 1e-3
    np.testing.assert_allclose(high, [t_high[0], -t_low[2], t_high[1]], rtol=1.2e-7)
    np.testing.assert_allclose(low, [t_low[0], -t_high[2], t_low[1]], rtol=1.2e-7)


def test_numpy_parse_equals_the_word_by_word_parse():
    rng = np.random.default_rng(27)
    values = rng.normal(scale=1e3, size=5000)
    text = "\n".join(" ".join(f"{v:.17g}" for v in row) for row in values.reshape(-1, 10))
    fast = _parse_numbers(text, np.float64)
    assert np.array_equal(fast, np.array(text.split(), dtype=np.float64))   # bit for bit
    ints = " ".join(str(n) for n in rng.integers(0, 2 ** 40, 3000))
    assert np.array_equal(_parse_numbers(ints, np.int64), np.array(ints.split(), dtype=np.int64))


@pytest.mark.parametrize("text, expected", [
    ("", []), ("   \n\t ", []),           # numpy alone reads blank text as one number
    ("1 2\n3\t4 ", [1, 2, 3, 4]),
    ("nan inf -inf", [math.nan, math.inf, -math.inf]),   # read; check_triangles refuses them
])
def test_edge_texts(text, expected):
    np.testing.assert_array_equal(_parse_numbers(text, np.float64), np.array(expected, float))


def test_a_bad_number_is_still_refused_with_its_line(tmp_path):
    text = _ellipsoid_dae((10.0, 10.0, 10.0), segments=6, rings=4)
    start = text.index('count="', text.index("<float_array")) + 1
    bad = text[:text.index(">", start) + 1] + "1,5 " + text[text.index(">", start) + 1:]
    with pytest.raises(ReedtoolError, match="bad number in <float_array>") as info:
        parse_dae(bad.encode(), "bad.dae")
    assert info.value.line == 5
    bad_index = text.replace("<p>0 0 ", "<p>0 0.5 ")
    with pytest.raises(ReedtoolError, match="bad index in <p>"):
        parse_dae(bad_index.encode(), "bad.dae")


def test_normals_are_not_read(tmp_path):
    """Only positions are used (extents, units, mass properties); a damaged normal array
    does not stop the mesh, as it does not stop Gazebo drawing its shape."""
    text = _ellipsoid_dae((10.0, 10.0, 10.0), segments=6, rings=4)
    damaged = text.replace('count="', 'count="', 1)
    start = damaged.index('<float_array id="na"')
    damaged = damaged[:damaged.index(">", start) + 1] + "x " + damaged[damaged.index(">", start) + 1:]
    path = tmp_path / "m.dae"
    path.write_text(damaged)
    assert len(read_dae(path).triangles) == 2 * 6 * 3
