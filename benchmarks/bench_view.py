"""`reedtool view` on the seed quadrotor: under 2 s per picture (issues 22, 28).

Runs the console command as a user would (a fresh interpreter: imports included), for each
output format, and prints the time against the target and against two yardsticks measured
in the same run: `reedtool expand` of the same model (loading the model is most of the
work), and trimesh's own scene export of the same geometry (yourdfpy builds the expanded
URDF's scene, trimesh exports it as GLB, in a fresh interpreter). It also prints the HTML
page's size against its 3 MB budget (the vendored viewer is 1.1 MB of it).
Wall time suffers when other jobs share the cores, so the CPU time of the child process
(user + system) is printed beside it; on an idle machine the two agree.

    python benchmarks/bench_view.py
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples/reed_quad_x/urdf/mav_generic_odometry_sensor.gazebo"
TARGET_S = 2.0
REPEATS = 3


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _best(argv: list[str]) -> tuple[float, float]:
    """(best wall time, best CPU time) over REPEATS runs, in seconds."""
    wall, cpu = float("inf"), float("inf")
    for _ in range(REPEATS):
        start, start_cpu = time.perf_counter(), _cpu_s()
        subprocess.run([str(Path(sys.executable).with_name("reedtool")), *argv], check=True,
                       capture_output=True)
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, _cpu_s() - start_cpu)
    return wall, cpu


PAGE_BUDGET_BYTES = 3_000_000
TRIMESH_EXPORT = """
import sys, yourdfpy
scene = yourdfpy.URDF.load(sys.argv[1], build_scene_graph=True, load_meshes=True).scene
open(sys.argv[2], "wb").write(scene.export(file_type="glb"))
"""


def _best_python(argv: list[str]) -> tuple[float, float]:
    wall, cpu = float("inf"), float("inf")
    for _ in range(REPEATS):
        start, start_cpu = time.perf_counter(), _cpu_s()
        subprocess.run([sys.executable, "-c", TRIMESH_EXPORT, *argv], check=True,
                       capture_output=True)
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, _cpu_s() - start_cpu)
    return wall, cpu


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        yardstick, yardstick_cpu = _best(["expand", str(MODEL), "-o", f"{tmp}/quad.urdf",
                                          "--force"])
        print(f"expand (yardstick): {yardstick:.2f} s wall, {yardstick_cpu:.2f} s CPU")
        trimesh_wall, trimesh_cpu = _best_python([f"{tmp}/quad.urdf", f"{tmp}/trimesh.glb"])
        print(f"trimesh scene export (yardstick): {trimesh_wall:.2f} s wall, "
              f"{trimesh_cpu:.2f} s CPU")
        for suffix in ("glb", "png", "html"):
            took, cpu = _best(["view", str(MODEL), "-o", f"{tmp}/quad.{suffix}", "--force"])
            print(f"view -o .{suffix}: {took:.2f} s wall, {cpu:.2f} s CPU "
                  f"({cpu / TARGET_S:.2f} of the {TARGET_S} s target, "
                  f"{cpu / yardstick_cpu:.2f}x expand's CPU, "
                  f"{cpu / trimesh_cpu:.2f}x trimesh's export)")
        size = Path(f"{tmp}/quad.html").stat().st_size
        print(f"page: {size / 1e6:.2f} MB ({size / PAGE_BUDGET_BYTES:.2f} of the 3 MB budget)")


if __name__ == "__main__":
    main()
