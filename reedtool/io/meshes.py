"""Any mesh file as triangles, refused when nothing sensible can be computed from it.

STL is read here; other formats go through trimesh.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.io.stl import read_stl


def load_triangles(path: str | Path) -> np.ndarray:
    """Any mesh file as (n, 3, 3) triangles in its own units: STL here, others via trimesh."""
    path = Path(path)
    if path.suffix.lower() == ".stl":
        triangles = read_stl(path).triangles
    else:
        triangles = _load_with_trimesh(path)
    check_triangles(triangles, path)
    return triangles


def _load_with_trimesh(path: Path) -> np.ndarray:
    import trimesh

    from reedtool.io.fileio import MAX_MESH_BYTES, open_regular_input

    open_regular_input(path, what="mesh file", max_bytes=MAX_MESH_BYTES).close()
    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for bad files
        raise ReedtoolError(f"cannot read mesh: {' '.join(str(exc).split()) or type(exc).__name__}",
                            file=path, hint="export it as STL") from exc
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    return vertices[faces] if len(faces) else np.zeros((0, 3, 3))


@dataclass
class MeshCheck:
    triangles: int
    zero_area_triangles: int
    area: float                      # in the file's units squared
    extent: np.ndarray               # bounding box size, file units


def triangle_areas(triangles: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(triangles[:, 1] - triangles[:, 0],
                                         triangles[:, 2] - triangles[:, 0]), axis=1)


def check_triangles(triangles: np.ndarray, source: str | Path) -> MeshCheck:
    """Refuse meshes nothing sensible can be computed from: empty, NaN, zero-area, flat."""
    if len(triangles) == 0:
        raise ReedtoolError("mesh contains no triangles", file=source,
                            hint="the export is empty; select the body before exporting")
    finite = np.isfinite(triangles).all(axis=(1, 2))
    if not finite.all():
        first = int(np.argmin(finite))
        raise ReedtoolError(f"{int((~finite).sum())} of {len(triangles)} triangles have NaN or "
                            f"infinite coordinates (first: triangle {first})", file=source,
                            hint="export the part again; the file is damaged")
    from reedtool.io.fileio import check_mesh_coordinates

    check_mesh_coordinates(triangles, source)
    areas = triangle_areas(triangles)
    total_area = float(areas.sum())
    vertices = triangles.reshape(-1, 3)
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    if total_area == 0.0:
        raise ReedtoolError(f"all {len(triangles)} triangles have zero area", file=source,
                            hint="the mesh is degenerate; export the part again")
    # Relative to the part's size: a triangle this small is a sliver, not geometry.
    zero_area = int((areas <= 1e-12 * float(extent.max()) ** 2).sum())
    if np.min(extent) <= 1e-9 * float(extent.max()):
        flat_axis = "xyz"[int(np.argmin(extent))]
        raise ReedtoolError(f"mesh is degenerate: it is flat (zero thickness along {flat_axis})",
                            file=source, hint="a flat surface has no volume, so no mass "
                                              "properties; export the solid body")
    return MeshCheck(len(triangles), zero_area, total_area, extent)
