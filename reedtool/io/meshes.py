"""Any mesh file as triangles, refused when nothing sensible can be computed from it.

One loader table, `MESH_READERS` (suffix -> reader), and one return type, `MeshFile`: every
caller (validate's mesh checks, inertia, the view and layout pictures, import-stl and
new-package --mesh) reads meshes through `read_mesh`. STL, COLLADA and OBJ are read with
light readers (numpy, lxml: io/stl.py, io/dae.py, io/obj.py): `validate` needs their
extents and units and must not pay for trimesh/scipy. Other formats go through trimesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from reedtool.errors import ReedtoolError

# What each simulator's mesh loader reads (gazebo classic: common::MeshManager; gz-sim:
# gz-common's MeshManager, which adds glTF/GLB and FBX through assimp).
CLASSIC_MESH_SUFFIXES = (".stl", ".dae", ".obj")
GZ_MESH_SUFFIXES = CLASSIC_MESH_SUFFIXES + (".glb", ".gltf", ".fbx")


@dataclass
class MeshFile:
    triangles: np.ndarray           # (n, 3, 3) in the file's units
    metres_per_unit: float          # what Gazebo multiplies them by (COLLADA <unit>), else 1
    format: str                     # stl-binary | stl-ascii | dae | obj | other
    unit_declared: bool = False     # the file states its unit (COLLADA)
    notes: list[str] = field(default_factory=list)
    up_axis: str | None = None      # what the file declares (COLLADA), already applied
    source: Path | None = None      # the file read

    @property
    def triangles_m(self) -> np.ndarray:
        return self.triangles * self.metres_per_unit if self.metres_per_unit != 1.0 \
            else self.triangles

    def bounds_m(self) -> np.ndarray | None:
        """(2, 3) min/max corners in metres (the file's unit applied); None when empty.
        Computed once: a shared mesh is measured by every model that uses it."""
        if not hasattr(self, "_bounds_m"):
            bounds = (corner_bounds(self.triangles) * self.metres_per_unit
                      if len(self.triangles) else None)
            if bounds is not None:
                bounds.flags.writeable = False
            self._bounds_m = bounds
        return self._bounds_m


# Every mesh file is read once per process: a repository's models share a few propeller
# and sensor meshes, and one model's checks ask for a mesh more than once (its extent, its
# units, its mass properties). Keyed by the file's identity (path, device, inode, size,
# mtime), so an edited file is read again; files above SHARED_MESH_MAX_BYTES are not kept.
SHARED_MESHES_MAX = 64
SHARED_MESH_MAX_BYTES = 8 * 1024 * 1024
_read_meshes: dict[tuple, "MeshFile | ReedtoolError"] = {}


def file_identity(path: Path) -> tuple | None:
    """(path, device, inode, size, mtime) of a mesh small enough to keep, else None."""
    import os

    try:
        st = os.stat(path)
    except OSError:
        return None
    if st.st_size > SHARED_MESH_MAX_BYTES:
        return None
    return (os.path.abspath(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def read_mesh(path: str | Path) -> MeshFile:
    """A mesh file as Gazebo reads it, without the `<mesh scale>`; unreadable -> ReedtoolError.

    Read once per process (see `_read_meshes`): the triangles are shared, so read-only."""
    path = Path(path)
    key = file_identity(path)
    found = _read_meshes.get(key) if key is not None else None
    if found is None:
        try:
            found = _read_mesh(path)
            found.triangles.flags.writeable = False
        except ReedtoolError as exc:
            found = exc
        if key is not None:
            if len(_read_meshes) >= SHARED_MESHES_MAX:
                _read_meshes.pop(next(iter(_read_meshes)))      # the oldest first
            _read_meshes[key] = found
    if isinstance(found, ReedtoolError):
        raise ReedtoolError(found.message, file=found.file, line=found.line, hint=found.hint)
    return found


def _read_stl(path: Path) -> MeshFile:
    from reedtool.io.stl import read_stl

    stl = read_stl(path)
    return MeshFile(stl.triangles, 1.0, f"stl-{stl.format}", notes=list(stl.notes))


def _read_dae(path: Path) -> MeshFile:
    from reedtool.io.dae import read_dae

    dae = read_dae(path)
    return MeshFile(dae.triangles, dae.metres_per_unit, "dae", dae.unit_declared, dae.notes,
                    up_axis=dae.up_axis)


def _read_obj(path: Path) -> MeshFile:
    from reedtool.io.obj import read_obj

    return MeshFile(read_obj(path), 1.0, "obj")


def _read_with_trimesh(path: Path) -> MeshFile:
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
    return MeshFile(vertices[faces] if len(faces) else np.zeros((0, 3, 3)), 1.0, "other")


# The loader table: file suffix (lower case) -> reader. These are the light readers
# validate runs; any other suffix is read by `OTHER_READER` (trimesh).
MESH_READERS: dict[str, Callable[[Path], MeshFile]] = {
    ".stl": _read_stl,
    ".dae": _read_dae,
    ".obj": _read_obj,
}
OTHER_READER: Callable[[Path], MeshFile] = _read_with_trimesh
LIGHT_SUFFIXES = tuple(MESH_READERS)


def _read_mesh(path: Path) -> MeshFile:
    read = MESH_READERS.get(path.suffix.lower(), OTHER_READER)(path)
    read.source = path
    return read


def load_triangles(path: str | Path) -> np.ndarray:
    """Any mesh file as (n, 3, 3) triangles in metres as Gazebo reads it (COLLADA <unit>
    applied, `<mesh scale>` not), checked for content mass properties can be computed from."""
    triangles = read_mesh(path).triangles_m
    check_triangles(triangles, path)
    return triangles


@dataclass
class MeshCheck:
    triangles: int
    zero_area_triangles: int
    area: float                      # in the file's units squared
    extent: np.ndarray               # bounding box size, file units


def corner_bounds(triangles: np.ndarray) -> np.ndarray:
    """(2, 3) min and max corner of (n, 3, 3) triangles (or (n, 3) points). Reduced per
    coordinate over a contiguous row: numpy's reduction along axis 0 of an (n, 3) array
    is ten times slower on the 10^5 corners of an exported mesh."""
    columns = np.ascontiguousarray(np.asarray(triangles).reshape(-1, 3).T)
    return np.vstack([columns.min(axis=1), columns.max(axis=1)])


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
    low, high = corner_bounds(triangles)
    extent = high - low
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


# ------------------------------------------------------------ formats Gazebo loads

def format_problem(uri: str, simulator: str) -> str | None:
    """Why Gazebo cannot load this mesh file format, or None.

    `simulator`: "classic" (STL, COLLADA, OBJ) or "gz" (also glTF/GLB and FBX).
    """
    name = uri.rsplit("/", 1)[-1]
    suffix = Path(name).suffix.lower()
    allowed = GZ_MESH_SUFFIXES if simulator == "gz" else CLASSIC_MESH_SUFFIXES
    if suffix in allowed:
        return None
    which = "gz-sim" if simulator == "gz" else "Gazebo classic"
    if not suffix:
        return f"'{name}' has no file extension; {which} picks its mesh loader by extension"
    if suffix in GZ_MESH_SUFFIXES:
        return f"{which} does not load {suffix} meshes (gz-sim does)"
    return (f"{which} does not load {suffix} files (it loads "
            f"{', '.join(s.lstrip('.').upper() for s in allowed)})")
