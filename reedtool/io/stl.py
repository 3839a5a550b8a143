"""STL, the format CAD tools export: binary or ASCII in, binary out.

Meshes are handled as a plain (n, 3, 3) float64 array of triangles - what an STL is -
so every step is a vectorised numpy operation.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

# One binary STL facet: normal, three vertices, attribute byte count.
STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])


assert STL_RECORD.itemsize == 50


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
    from reedtool.io.fileio import MAX_MESH_BYTES, open_regular_input

    path = Path(path)
    # Type and size are checked on the open file before its body is read (issue 14).
    with open_regular_input(path, what="mesh file", max_bytes=MAX_MESH_BYTES) as handle:
        head = handle.read(84)
        check_facet_count(head, os.fstat(handle.fileno()).st_size, path)
        data = head + handle.read()
    return parse_stl(data, path)


def check_facet_count(head: bytes, size: int, source) -> None:
    """Refuse a binary STL whose header announces more facets than reedtool handles."""
    from reedtool.io.fileio import MAX_MESH_TRIANGLES

    if len(head) < 84:
        return
    count = int.from_bytes(head[80:84], "little")
    if size == 84 + 50 * count and count > MAX_MESH_TRIANGLES:
        raise ReedtoolError(f"binary STL with {count:,} triangles, more than the "
                            f"{MAX_MESH_TRIANGLES:,} reedtool handles", file=source,
                            hint="decimate the mesh in your CAD or mesh tool first")


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
