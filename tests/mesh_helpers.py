"""Tiny mesh files for tests, written from hand-built triangles (no mesh library)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reedtool.io.stl import stl_bytes


def box_triangles(size, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(12, 3, 3) outward-wound triangles of an axis-aligned box."""
    half = np.asarray(size, dtype=float) / 2.0
    c = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    c = c + np.asarray(centre, dtype=float)
    # corner index = 4 * ix + 2 * iy + iz
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),      # x- , x+
             (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),      # y- , y+
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]      # z- , z+
    return c[np.array(faces)]


def write_stl(path: Path, triangles: np.ndarray) -> Path:
    path.write_bytes(stl_bytes(np.asarray(triangles, dtype=float)))
    return path


def dae_text(triangles: np.ndarray, *, meter: float | None = 1.0, up_axis: str = "Z_UP",
             node_xml: str = "", polylist: bool = False) -> str:
    """A minimal COLLADA 1.4 document holding the triangles as one geometry placed by one
    scene node; `node_xml` goes before the instance (e.g. "<translate>1 0 0</translate>")."""
    tri = np.asarray(triangles, dtype=float)
    positions = " ".join(f"{v:.9g}" for v in tri.reshape(-1))
    count = len(tri) * 3
    indices = " ".join(str(i) for i in range(count))
    unit = f'<unit name="u" meter="{meter:g}"/>' if meter is not None else ""
    if polylist:
        prim = (f'<polylist count="{len(tri)}"><input semantic="VERTEX" source="#v" offset="0"/>'
                f'<vcount>{" ".join("3" for _ in tri)}</vcount><p>{indices}</p></polylist>')
    else:
        prim = (f'<triangles count="{len(tri)}"><input semantic="VERTEX" source="#v" '
                f'offset="0"/><p>{indices}</p></triangles>')
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>{unit}<up_axis>{up_axis}</up_axis></asset>
  <library_geometries>
    <geometry id="g" name="part"><mesh>
      <source id="p"><float_array id="pa" count="{count * 3}">{positions}</float_array>
        <technique_common><accessor source="#pa" count="{count}" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
      {prim}
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="s"><node id="n" name="part">{node_xml}<instance_geometry url="#g"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def write_dae(path: Path, triangles: np.ndarray, **kwargs) -> Path:
    path.write_text(dae_text(triangles, **kwargs))
    return path


def write_obj(path: Path, triangles: np.ndarray) -> Path:
    tri = np.asarray(triangles, dtype=float)
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in tri.reshape(-1, 3)]
    lines += [f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}" for i in range(len(tri))]
    path.write_text("\n".join(lines) + "\n")
    return path
