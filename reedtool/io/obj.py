"""Wavefront OBJ (.obj): `v` and `f` lines as triangles, numpy only.

OBJ declares no unit; Gazebo reads its coordinates as metres. Faces with more than three
corners are fan-triangulated; `v/vt/vn` corners and negative (relative) indices are read.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

HINT = "export it again as OBJ or STL"


def parse_obj(data: bytes, source: str | Path = "<obj>") -> np.ndarray:
    """(n, 3, 3) triangles in the file's units (metres to Gazebo)."""
    vertices: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []
    for number, raw in enumerate(data.splitlines(), start=1):
        words = raw.split()
        if not words:
            continue
        if words[0] == b"v":
            try:
                vertices.append((float(words[1]), float(words[2]), float(words[3])))
            except (IndexError, ValueError) as exc:
                raise ReedtoolError(f"bad vertex line {raw[:60].decode(errors='replace')!r}",
                                    file=source, line=number, hint=HINT) from exc
        elif words[0] == b"f":
            try:
                corners = [int(w.split(b"/", 1)[0]) for w in words[1:]]
            except ValueError as exc:
                raise ReedtoolError(f"bad face line {raw[:60].decode(errors='replace')!r}",
                                    file=source, line=number, hint=HINT) from exc
            count = len(vertices)
            resolved = [c - 1 if c > 0 else count + c for c in corners]
            if len(resolved) < 3 or any(c < 0 or c >= count or 0 == corners[i]
                                        for i, c in enumerate(resolved)):
                raise ReedtoolError(f"face refers to a vertex the file does not define "
                                    f"({len(vertices)} defined so far)", file=source,
                                    line=number, hint=HINT)
            faces.extend((resolved[0], resolved[i], resolved[i + 1])
                         for i in range(1, len(resolved) - 1))
    if not faces:
        if not vertices and data.strip() and b"\0" in data[:1024]:
            raise ReedtoolError("not an OBJ file: binary content", file=source, hint=HINT)
        return np.zeros((0, 3, 3))
    return np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]


def read_obj(path: str | Path) -> np.ndarray:
    from reedtool.io.fileio import MAX_MESH_BYTES, read_bytes

    path = Path(path)
    return parse_obj(read_bytes(path, what="mesh file", max_bytes=MAX_MESH_BYTES), path)
