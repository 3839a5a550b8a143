"""3-D convex hull by Quickhull (Barber, Dobkin & Huhdanpaa 1996), numpy only.

`validate` needs the hull of an open visual mesh for its mass properties; qhull through
trimesh/scipy costs more to import than the whole check takes. Points are first thinned
to those outside the polytope of their extreme points along 26 directions (vectorised),
so the Python loop runs once per hull face, each step vectorised over the points left.
"""

from __future__ import annotations

import numpy as np

from reedtool.errors import ReedtoolError

_DIRECTIONS = np.array([(x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)
                        if (x, y, z) != (0, 0, 0)], dtype=float)


def _degenerate() -> ReedtoolError:
    return ReedtoolError("mesh is degenerate: its convex hull has no volume",
                         hint="export the solid body, not a surface")


def _initial_simplex(points: np.ndarray, eps: float) -> list[int]:
    """Four affinely independent points, far apart."""
    extremes = np.unique(np.concatenate([np.argmin(points, axis=0), np.argmax(points, axis=0)]))
    a, b = max(((i, j) for i in extremes for j in extremes),
               key=lambda ij: float(np.sum((points[ij[0]] - points[ij[1]]) ** 2)))
    ab = points[b] - points[a]
    if float(np.linalg.norm(ab)) <= eps:
        raise _degenerate()
    cross = np.cross(points - points[a], ab)
    c = int(np.argmax(np.einsum("ij,ij->i", cross, cross)))
    normal = np.cross(ab, points[c] - points[a])
    if float(np.linalg.norm(normal)) <= eps * float(np.linalg.norm(ab)):
        raise _degenerate()
    normal /= np.linalg.norm(normal)
    heights = (points - points[a]) @ normal
    d = int(np.argmax(np.abs(heights)))
    if abs(float(heights[d])) <= eps:
        raise _degenerate()
    return [int(a), int(b), c, d]


def hull_candidates(points: np.ndarray) -> np.ndarray:
    """The points that may lie on the hull: all but those strictly inside the hull of the
    extreme points along 26 directions (a vectorised cut that removes most of a CAD mesh's
    interior and concave vertices)."""
    points = np.asarray(points, dtype=np.float64)
    if len(points) < 8 or not np.all(np.isfinite(points)):
        return points
    eps = _eps(points)
    centre = points.mean(axis=0)
    extreme_idx = np.unique(np.argmax((points - centre) @ _DIRECTIONS.T, axis=0))
    keep = np.ones(len(points), dtype=bool)
    if len(extreme_idx) >= 4:
        try:
            ev, ef = _quickhull(points[extreme_idx], eps)
        except ReedtoolError:
            return points
        normals, offsets = _planes(ev, ef)
        keep &= ~np.all(points @ normals.T - offsets < -eps, axis=1)
    keep[extreme_idx] = True
    return points[keep]


def _eps(points: np.ndarray) -> float:
    return 1e-10 * (float(np.max(np.abs(points - points.mean(axis=0)))) or 1.0)


def convex_hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (m, 3), faces (k, 3)) of the convex hull, faces wound outwards.

    Raises ReedtoolError when the points span no volume (flat, a line, one point). The
    loop runs once per hull face: fast for a few thousand candidate points (see
    hull_candidates), slow for a finely tessellated sphere.
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) < 4 or not np.all(np.isfinite(points)):
        raise _degenerate()
    return _quickhull(hull_candidates(points), _eps(points))


def _planes(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    p0, p1, p2 = (vertices[faces[:, k]] for k in range(3))
    normals = np.cross(p1 - p0, p2 - p0)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals, np.einsum("ij,ij->i", normals, p0)


def _quickhull(points: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    simplex = _initial_simplex(points, eps)
    interior = points[simplex].mean(axis=0)
    faces: dict[int, tuple[int, int, int]] = {}
    planes: dict[int, tuple[np.ndarray, float]] = {}
    outside: dict[int, np.ndarray] = {}
    edge_face: dict[tuple[int, int], int] = {}      # directed edge -> the face that has it
    next_id = 0

    def add_face(a: int, b: int, c: int) -> int:
        nonlocal next_id
        normal = np.cross(points[b] - points[a], points[c] - points[a])
        length = float(np.linalg.norm(normal))
        normal = normal / length if length > 0 else normal
        offset = float(normal @ points[a])
        if normal @ interior - offset > 0:        # keep every face wound outwards
            b, c = c, b
            normal, offset = -normal, -offset
        fid = next_id
        next_id += 1
        faces[fid] = (a, b, c)
        planes[fid] = (normal, offset)
        for u, v in ((a, b), (b, c), (c, a)):
            edge_face[(u, v)] = fid
        return fid

    def assign(candidate_idx: np.ndarray, new_faces: list[int]) -> None:
        if not len(candidate_idx) or not new_faces:
            for fid in new_faces:
                outside[fid] = np.zeros(0, dtype=np.int64)
            return
        normals = np.array([planes[f][0] for f in new_faces])
        offsets = np.array([planes[f][1] for f in new_faces])
        dist = points[candidate_idx] @ normals.T - offsets
        best = np.argmax(dist, axis=1)
        above = dist[np.arange(len(candidate_idx)), best] > eps
        for k, fid in enumerate(new_faces):
            outside[fid] = candidate_idx[above & (best == k)]

    a, b, c, d = simplex
    start = [add_face(a, b, c), add_face(a, c, d), add_face(a, d, b), add_face(b, d, c)]
    rest = np.setdiff1d(np.arange(len(points)), simplex)
    assign(rest, start)

    pending = [f for f in start if len(outside[f])]
    while pending:
        fid = pending.pop()
        if fid not in faces or not len(outside[fid]):
            continue
        normal, offset = planes[fid]
        idx = outside[fid]
        apex = int(idx[np.argmax(points[idx] @ normal - offset)])
        p = points[apex]
        # Faces the apex sees, by flood fill from this one across shared edges.
        visible, stack = {fid}, [fid]
        while stack:
            f = stack.pop()
            u, v, w = faces[f]
            for x, y in ((u, v), (v, w), (w, u)):
                g = edge_face.get((y, x))
                if g is None or g in visible:
                    continue
                gn, go = planes[g]
                if gn @ p - go > eps:
                    visible.add(g)
                    stack.append(g)
        horizon = []
        for f in visible:
            u, v, w = faces[f]
            for x, y in ((u, v), (v, w), (w, u)):
                if edge_face.get((y, x)) not in visible:
                    horizon.append((x, y))
        orphans = np.concatenate([outside[f] for f in visible])
        for f in visible:
            u, v, w = faces.pop(f)
            for x, y in ((u, v), (v, w), (w, u)):
                if edge_face.get((x, y)) == f:
                    del edge_face[(x, y)]
            planes.pop(f)
            outside.pop(f)
        new_faces = []
        for x, y in horizon:
            new_id = next_id
            next_id += 1
            faces[new_id] = (x, y, apex)         # horizon edges keep their orientation
            normal_new = np.cross(points[y] - points[x], p - points[x])
            length = float(np.linalg.norm(normal_new))
            normal_new = normal_new / length if length > 0 else normal_new
            planes[new_id] = (normal_new, float(normal_new @ points[x]))
            for u, v in ((x, y), (y, apex), (apex, x)):
                edge_face[(u, v)] = new_id
            new_faces.append(new_id)
        assign(orphans[orphans != apex], new_faces)
        pending.extend(f for f in new_faces if len(outside[f]))

    used = np.array(sorted({i for face in faces.values() for i in face}))
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    face_array = remap[np.array(list(faces.values()), dtype=np.int64)]
    return points[used], face_array
