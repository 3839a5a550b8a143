"""Triangle meshes: read STL, check it, fix units and axes, and write it back.

Meshes are handled as a plain (n, 3, 3) float64 array of triangles — what an STL is —
so every step is a vectorised numpy operation and a million triangles take about a
second. trimesh is used where it adds something: other file formats and convex hulls.

`import_mesh` is the pipeline behind `reedtool import-stl`:
read -> check -> units -> axes to FLU -> recentre -> mass properties -> collision mesh.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import ReedtoolError
from .frames import AxisConvention, axis_convention
from .inertia import MassProperties, mesh_mass_properties

# One binary STL facet: normal, three vertices, attribute byte count.
STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
assert STL_RECORD.itemsize == 50

UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}

# A part of a multirotor is between a screw and a large airframe.
PLAUSIBLE_SIZE_M = (0.01, 5.0)


# ---------------------------------------------------------------- reading

@dataclass
class StlFile:
    triangles: np.ndarray          # (n, 3, 3) float64, in the file's units
    format: str                    # "binary" | "ascii"
    notes: list[str] = field(default_factory=list)


def parse_stl(data: bytes, source: str | Path = "<stl>") -> StlFile:
    """Binary or ASCII STL, decided from the content, never from the first five bytes.

    A binary STL is an 80-byte header, a uint32 facet count n and 50 bytes per facet, so
    its size is exactly 84 + 50 n. Some exporters start the binary header with "solid",
    which is why that word alone says nothing.
    """
    size = len(data)
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0]) if size >= 84 else -1
    if count >= 0 and size == 84 + 50 * count:
        return _parse_binary(data, count, source)
    head = data[:1024].lstrip()
    looks_ascii = b"facet" in data[:4096].lower() or b"endsolid" in head.lower()
    if head[:5].lower() == b"solid" and looks_ascii:
        return _parse_ascii(data, source)
    if count > 0 and size > 84 + 50 * count:
        stl = _parse_binary(data, count, source)
        stl.notes.append(f"ignored {size - 84 - 50 * count} bytes after the last facet")
        return stl
    if size < 84:
        raise ReedtoolError(f"not an STL file: only {size} bytes", file=source,
                            hint="export the part again as STL")
    raise ReedtoolError(
        f"not an STL file: {size} bytes is not 84 + 50 x {count} facets (binary) "
        "and the text does not start with 'solid ... facet' (ASCII)", file=source,
        hint="the file is truncated or in another format; export it again as STL")


def _parse_binary(data: bytes, count: int, source) -> StlFile:
    records = np.frombuffer(data, dtype=STL_RECORD, count=count, offset=84)
    return StlFile(records["vertices"].astype(np.float64), "binary")


_VERTEX_RE = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", re.IGNORECASE)


def _parse_ascii(data: bytes, source) -> StlFile:
    coords = _VERTEX_RE.findall(data)
    try:
        values = np.array(coords, dtype=np.float64) if coords else np.zeros((0, 3))
    except ValueError as exc:
        bad = next(c for c in coords if not _all_floats(c))
        line = data[: data.find(b" ".join(bad))].count(b"\n") + 1
        raise ReedtoolError(f"bad vertex coordinate {b' '.join(bad).decode(errors='replace')!r}",
                            file=source, line=line, hint="the ASCII STL is damaged") from exc
    if len(values) % 3:
        raise ReedtoolError(f"ASCII STL has {len(values)} vertices, not a multiple of 3",
                            file=source, hint="the file is truncated or damaged")
    return StlFile(values.reshape(-1, 3, 3), "ascii")


def _all_floats(words) -> bool:
    try:
        [float(w) for w in words]
    except ValueError:
        return False
    return True


def read_stl(path: str | Path) -> StlFile:
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError as exc:
        raise ReedtoolError("mesh file not found", file=path) from exc
    except IsADirectoryError as exc:
        raise ReedtoolError("is a directory, not a mesh file", file=path) from exc
    except OSError as exc:
        raise ReedtoolError(f"cannot read mesh: {exc.strerror}", file=path) from exc
    return parse_stl(data, path)


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

    if not path.is_file():
        raise ReedtoolError("mesh file not found", file=path)
    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for bad files
        raise ReedtoolError(f"cannot read mesh: {' '.join(str(exc).split()) or type(exc).__name__}",
                            file=path, hint="export it as STL") from exc
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    return vertices[faces] if len(faces) else np.zeros((0, 3, 3))


# ---------------------------------------------------------------- checks

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


@dataclass
class Topology:
    vertices: int                    # after merging bit-identical coordinates
    watertight: bool                 # every edge shared by exactly two triangles
    winding_consistent: bool         # neighbours traverse their shared edge in opposite senses

    @property
    def closed(self) -> bool:
        """A closed, consistently oriented surface: its volume integrals mean something."""
        return self.watertight and self.winding_consistent


def _vertex_hash(wide: np.ndarray) -> np.ndarray:
    """64-bit multiplicative hash of (n, 3) coordinate bit patterns (as uint64)."""
    return ((wide[:, 0] * np.uint64(0x9E3779B97F4A7C15))
            ^ (wide[:, 1] * np.uint64(0xC2B2AE3D27D4EB4F))
            ^ (wide[:, 2] * np.uint64(0x165667B19E3779F9)))


def merge_vertices(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(unique vertices (m, 3), faces (n, 3)) by merging bit-identical float32 coordinates.

    STL stores float32, and CAD exporters write a shared corner with identical bits, so
    exact matching after rounding to float32 is the right notion of "same vertex".
    """
    flat = triangles.reshape(-1, 3).astype(np.float32) + np.float32(0.0)   # folds -0.0 into 0.0
    bits = flat.view(np.uint32)
    # Sort by a 64-bit hash of the three coordinates (one argsort, several times faster
    # than a three-key lexsort); equal vertices end up adjacent. Should two different
    # vertices share a hash, they could interleave, so that case falls back to lexsort.
    wide = bits.astype(np.uint64)
    key = _vertex_hash(wide)
    xy = (wide[:, 0] << np.uint64(32)) | wide[:, 1]     # exact identity = (xy, z)
    z = bits[:, 2]

    def boundaries(order):
        xy_sorted, z_sorted = xy[order], z[order]
        return (xy_sorted[1:] != xy_sorted[:-1]) | (z_sorted[1:] != z_sorted[:-1])

    order = np.argsort(key)
    differs = boundaries(order)
    key_sorted = key[order]
    if np.any((key_sorted[1:] == key_sorted[:-1]) & differs):
        order = np.lexsort((z, xy))
        differs = boundaries(order)
    starts = np.concatenate(([True], differs))
    group = np.cumsum(starts) - 1
    inverse = np.empty(len(order), dtype=np.int64)
    inverse[order] = group
    # Each merged vertex keeps one of its original (float64) coordinates, not the float32 key.
    unique = np.asarray(triangles, dtype=np.float64).reshape(-1, 3)[order[starts]]
    return unique, inverse.reshape(-1, 3)


def topology(triangles: np.ndarray) -> Topology:
    vertices, faces = merge_vertices(triangles)
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                  & (faces[:, 2] != faces[:, 0])]
    n = np.int64(len(vertices))
    heads = faces.reshape(-1)
    tails = np.roll(faces, -1, axis=1).reshape(-1)
    lo, hi = np.minimum(heads, tails), np.maximum(heads, tails)
    undirected = np.sort(lo * n + hi)
    # Watertight: every undirected edge appears exactly twice. In a sorted list that is
    # "even length, pairs equal, and no pair equal to the next one".
    watertight = bool(len(undirected) and len(undirected) % 2 == 0
                      and np.all(undirected[0::2] == undirected[1::2])
                      and np.all(undirected[1:-1:2] != undirected[2::2]))
    winding = False
    if watertight:
        # Each edge is used twice; consistent winding means once in each direction,
        # i.e. no directed edge repeats.
        directed = np.sort(heads * n + tails)
        winding = bool(np.all(directed[1:] != directed[:-1]))
    return Topology(len(vertices), watertight, winding)


# ---------------------------------------------------------------- units

@dataclass(frozen=True)
class UnitChoice:
    unit: str
    metres_per_unit: float
    reason: str
    guessed: bool


def guess_units(extent: np.ndarray) -> UnitChoice:
    """Pick the unit that makes the part's largest extent a plausible multirotor part size."""
    largest = float(np.max(extent))
    low, high = PLAUSIBLE_SIZE_M
    for unit in ("m", "mm", "cm", "in"):
        size_m = largest * UNITS_M[unit]
        if low <= size_m <= high:
            return UnitChoice(unit, UNITS_M[unit],
                              f"largest extent {largest:g} units; as {unit} that is "
                              f"{size_m:g} m, within the plausible {low:g}-{high:g} m", True)
    unit = "mm" if largest > high else "m"
    return UnitChoice(unit, UNITS_M[unit],
                      f"largest extent {largest:g} units fits no unit's plausible "
                      f"{low:g}-{high:g} m; assuming {unit} — pass --units to be sure", True)


def choose_units(name: str, extent: np.ndarray) -> UnitChoice:
    if name == "auto":
        return guess_units(extent)
    if name not in UNITS_M:
        raise ReedtoolError(f"unknown unit '{name}'", hint="use one of: auto, "
                            + ", ".join(UNITS_M))
    return UnitChoice(name, UNITS_M[name], "given with --units", False)


# ---------------------------------------------------------------- collision

def convex_hull_triangles(triangles: np.ndarray) -> np.ndarray:
    """Outward-wound triangles of the convex hull of the mesh's vertices."""
    import trimesh

    vertices, _ = merge_vertices(triangles)
    try:
        hull = trimesh.convex.convex_hull(vertices)
    except Exception as exc:  # noqa: BLE001 - qhull errors for flat or tiny inputs
        raise ReedtoolError("mesh is degenerate: its convex hull has no volume",
                            hint="export the solid body, not a surface") from exc
    return np.asarray(hull.vertices, dtype=np.float64)[np.asarray(hull.faces)]


def cluster_decimate(triangles: np.ndarray, max_faces: int) -> np.ndarray:
    """At most `max_faces` triangles by vertex clustering on a uniform grid.

    Vertices in one grid cell collapse to their mean and triangles that lose a corner
    vanish (Rossignac & Borrel). Coarse but robust and dependency-free, which is what a
    collision mesh needs. The grid is refined by bisection on cells per axis.
    """
    if len(triangles) <= max_faces:
        return triangles
    vertices, faces = merge_vertices(triangles)
    lo = vertices.min(axis=0)
    size = float((vertices.max(axis=0) - lo).max())

    def clustered(cells: int) -> np.ndarray:
        index = np.minimum(((vertices - lo) / size * cells).astype(np.int64), cells - 1)
        keys = (index[:, 0] * cells + index[:, 1]) * cells + index[:, 2]
        _, cell_of, counts = np.unique(keys, return_inverse=True, return_counts=True)
        centres = np.zeros((len(counts), 3))
        np.add.at(centres, cell_of, vertices)
        centres /= counts[:, None]
        new_faces = cell_of[faces]
        keep = ((new_faces[:, 0] != new_faces[:, 1]) & (new_faces[:, 1] != new_faces[:, 2])
                & (new_faces[:, 2] != new_faces[:, 0]))
        new_faces = new_faces[keep]
        # Two triangles on the same three cells are one triangle (either winding).
        _, first = np.unique(np.sort(new_faces, axis=1), axis=0, return_index=True)
        return centres[new_faces[np.sort(first)]]

    low, high = 1, 2
    while len(clustered(high)) <= max_faces and high < 4096:
        low, high = high, high * 2
    best = clustered(low)
    while high - low > 1:
        mid = (low + high) // 2
        candidate = clustered(mid)
        if len(candidate) <= max_faces:
            low, best = mid, candidate
        else:
            high = mid
    if len(best) < 4:
        raise ReedtoolError(f"cannot simplify to {max_faces} faces and keep a solid",
                            hint="ask for more faces, or use --collision hull")
    return best


@dataclass(frozen=True)
class CollisionSpec:
    kind: str                        # "same" | "hull" | "simplify"
    max_faces: int | None = None

    @classmethod
    def parse(cls, text: str) -> "CollisionSpec":
        text = text.strip().lower()
        if text in ("same", "hull"):
            return cls(text)
        if text.startswith("simplify:"):
            number = text.split(":", 1)[1]
            if number.isdigit() and int(number) >= 4:
                return cls("simplify", int(number))
        raise ReedtoolError(f"bad --collision value '{text}'",
                            hint="use hull, same, or simplify:N with N >= 4 faces")


def collision_triangles(triangles: np.ndarray, spec: CollisionSpec) -> np.ndarray | None:
    """The collision mesh to write, or None when collision uses the visual mesh."""
    if spec.kind == "same":
        return None
    if spec.kind == "hull":
        return convex_hull_triangles(triangles)
    return cluster_decimate(triangles, spec.max_faces)


# ---------------------------------------------------------------- writing

def stl_bytes(triangles: np.ndarray, header: str = "reedtool") -> bytes:
    """Binary STL with unit normals; the header never starts with 'solid'."""
    header_bytes = header.encode("ascii", "replace")[:80]
    if header_bytes[:5].lower() == b"solid":
        header_bytes = b"binary " + header_bytes[:73]
    records = np.zeros(len(triangles), dtype=STL_RECORD)
    records["vertices"] = triangles
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    np.divide(normals, lengths, out=normals, where=lengths > 0)
    records["normal"] = normals
    return (header_bytes.ljust(80, b" ") + np.uint32(len(triangles)).tobytes()
            + records.tobytes())


# ---------------------------------------------------------------- pipeline

@dataclass
class ImportedMesh:
    source: Path
    file_format: str                 # binary | ascii
    triangles_m: np.ndarray          # (n, 3, 3), metres, FLU, recentred
    units: UnitChoice
    frame: AxisConvention
    offset_m: np.ndarray             # translation applied after rotation (recentring)
    recenter: str
    check: MeshCheck
    topology: Topology
    mass: MassProperties             # in the written mesh's frame
    mass_source: str                 # "given mass", "density ... x volume", "DEFAULT density ..."
    collision_m: np.ndarray | None   # collision triangles, None = use the visual mesh
    collision: CollisionSpec
    notes: list[str] = field(default_factory=list)

    @property
    def size_m(self) -> np.ndarray:
        vertices = self.triangles_m.reshape(-1, 3)
        return vertices.max(axis=0) - vertices.min(axis=0)


DEFAULT_DENSITY_KG_M3 = 1000.0


def import_mesh(path: str | Path, *, units: str = "auto", from_frame: str = "flu",
                mass_kg: float | None = None, density_kg_m3: float | None = None,
                recenter: str = "none", collision: str = "same", progress=None) -> ImportedMesh:
    """Read a CAD STL and return it in metres and FLU with its mass properties.

    `progress(stage_name)` is called before each stage, for a progress bar.
    """
    step = progress or (lambda _stage: None)
    path = Path(path)
    frame = axis_convention(from_frame)
    spec = CollisionSpec.parse(collision)
    if recenter not in ("none", "com", "bbox"):
        raise ReedtoolError(f"bad --recenter value '{recenter}'", hint="use none, com or bbox")
    if mass_kg is not None and density_kg_m3 is not None:
        raise ReedtoolError("give --mass or --density, not both")
    for value, flag in ((mass_kg, "--mass"), (density_kg_m3, "--density")):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise ReedtoolError(f"{flag} must be a positive number, not {value}")

    step("reading")
    stl = read_stl(path)
    step("checking")
    check = check_triangles(stl.triangles, path)
    topo = topology(stl.triangles)
    choice = choose_units(units, check.extent)

    step("transforming")
    # Uniform scale and a rotation commute; one matrix does both.
    M = frame.R_flu_src * choice.metres_per_unit
    triangles = stl.triangles @ M.T

    step("mass properties")
    try:
        unit_props = mesh_mass_properties(triangles, 1.0, closed=topo.closed)
    except ReedtoolError as exc:
        raise ReedtoolError(exc.message, file=path, hint=exc.hint) from exc
    volume = float(unit_props.volume_m3)
    if mass_kg is not None:
        props, mass_source = unit_props.scaled_to_mass(mass_kg), "given mass"
    else:
        density = density_kg_m3 if density_kg_m3 is not None else DEFAULT_DENSITY_KG_M3
        props = unit_props.scaled_to_mass(density * volume)
        mass_source = (f"density {density:g} kg/m^3 x volume" if density_kg_m3 is not None
                       else f"DEFAULT density {density:g} kg/m^3 x volume")

    if recenter == "com":
        offset = -props.com_m
    elif recenter == "bbox":
        vertices = triangles.reshape(-1, 3)
        offset = -(vertices.min(axis=0) + vertices.max(axis=0)) / 2.0
    else:
        offset = np.zeros(3)
    if recenter != "none":
        triangles = triangles + offset
        props = MassProperties(props.mass_kg, props.com_m + offset, props.inertia_kg_m2,
                               props.volume_m3, props.from_hull)

    step("collision mesh")
    collision_m = collision_triangles(triangles, spec)

    notes = list(stl.notes)
    if check.zero_area_triangles:
        notes.append(f"{check.zero_area_triangles} zero-area triangles (kept; they add nothing)")
    if props.from_hull:
        why = "not watertight" if not topo.watertight else "inconsistently wound"
        notes.append(f"mesh is {why}: mass properties are those of its convex hull")
    return ImportedMesh(path, stl.format, triangles, choice, frame, offset, recenter, check,
                        topo, props, mass_source, collision_m, spec, notes)
