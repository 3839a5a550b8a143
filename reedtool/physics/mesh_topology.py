"""Mesh topology: shared vertices, watertightness, winding, convex hull, decimation.

The convex hull is reedtool's own Quickhull (physics.convex_hull) for meshes with up to
LIGHT_HULL_MAX_POINTS hull candidates, so `validate` stays free of trimesh/scipy; beyond
that qhull through trimesh is faster than the Python loop. The rest is vectorised numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reedtool.errors import ReedtoolError


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


# Candidate points up to which the numpy Quickhull beats importing trimesh + scipy (~0.5 s).
LIGHT_HULL_MAX_POINTS = 1000


def convex_hull_triangles(triangles: np.ndarray) -> np.ndarray:
    """Outward-wound triangles of the convex hull of the mesh's vertices."""
    from reedtool.physics.convex_hull import convex_hull, hull_candidates

    vertices, _ = merge_vertices(triangles)
    candidates = hull_candidates(vertices)
    if len(candidates) <= LIGHT_HULL_MAX_POINTS:
        hull_vertices, hull_faces = convex_hull(candidates)
        return hull_vertices[hull_faces]
    import trimesh

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
