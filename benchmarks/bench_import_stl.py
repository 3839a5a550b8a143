"""Benchmark: `reedtool import-stl`'s core path on a 1,000,000-triangle STL.

Compares reedtool (read, checks, watertightness, mm -> m, NED -> FLU, mass properties,
binary STL written atomically into a package) with trimesh's own load + export of the same
file. Target: reedtool within 1.5x of trimesh. Run: python benchmarks/bench_import_stl.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def torus_triangles(n_major: int, n_minor: int, R_mm: float = 150.0, r_mm: float = 40.0):
    """A closed, outward-wound torus of 2 * n_major * n_minor triangles (millimetres)."""
    u = np.linspace(0, 2 * np.pi, n_major, endpoint=False)
    v = np.linspace(0, 2 * np.pi, n_minor, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    vertices = np.stack([(R_mm + r_mm * np.cos(vv)) * np.cos(uu),
                         (R_mm + r_mm * np.cos(vv)) * np.sin(uu),
                         r_mm * np.sin(vv)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a = i * n_minor + j
    b = ((i + 1) % n_major) * n_minor + j
    c = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
    d = i * n_minor + (j + 1) % n_minor
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)])
    return vertices, faces


def best_of(runs: int, fn) -> float:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> int:
    import trimesh

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from reedtool.workflows.import_mesh import run_import

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        vertices, faces = torus_triangles(1000, 500)
        source = tmp / "torus_mm.stl"
        trimesh.Trimesh(vertices, faces, process=False).export(source)
        print(f"input: {len(faces):,} triangles, {source.stat().st_size / 1e6:.1f} MB binary STL")

        package = tmp / "pkg"
        package.mkdir()
        (package / "package.xml").write_text("<package><name>bench</name></package>")

        def reedtool_import():
            outcome = run_import(source, package, name="torus", units="mm", from_frame="ned",
                                 mass_kg=0.5, force=True)
            assert outcome.imported.topology.closed

        def trimesh_round_trip():
            mesh = trimesh.load(source)
            mesh.export(tmp / "trimesh_out.stl")

        t_reedtool = best_of(3, reedtool_import)
        t_trimesh = best_of(3, trimesh_round_trip)
    ratio = t_reedtool / t_trimesh
    print(f"reedtool import-stl core path : {t_reedtool:6.3f} s")
    print(f"trimesh load + export         : {t_trimesh:6.3f} s")
    print(f"ratio reedtool / trimesh      : {ratio:6.2f}x  (target <= 1.5x: "
          f"{'met' if ratio <= 1.5 else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
