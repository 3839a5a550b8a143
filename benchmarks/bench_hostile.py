"""Peak memory and wall time of every refused hostile input (issue 14).

Run on demand: python benchmarks/bench_hostile.py
Target: every input the table in tests/test_hostile_input.py refuses (exit 2) peaks under
200 MB and answers within 5 s. Each case runs in its own process; its peak resident set
comes from os.wait4 (the kernel's ru_maxrss of that child alone). The yardstick is the
same interpreter importing reedtool's CLI and exiting, measured in the same run: the
ratio says how much a refusal costs on top of starting up.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

from test_hostile_input import CASES, make_tree  # the one table of cases

TARGET_PEAK_MB = 200.0
TARGET_WALL_S = 5.0


def measure(args: list[str], cwd: Path) -> tuple[int, float, float]:
    """(exit code, wall seconds, peak RSS MB) of one CLI run in a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", *args], cwd=cwd, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, wall, usage.ru_maxrss / 1024.0   # ru_maxrss is in KiB on Linux


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="bench_hostile.") as tmp:
        root = Path(tmp)
        make_tree(root)
        _, base_wall, base_mb = measure(["import reedtool.cli"], root)
        print(f"yardstick (import reedtool.cli): {base_wall:.2f} s, {base_mb:.0f} MB")
        print(f"{'case':34} {'exit':>4} {'wall s':>7} {'peak MB':>8} {'x yardstick':>11}")
        worst_mb = worst_s = 0.0
        failures = []
        for case in CASES:
            if case.code != 2:
                continue
            code, wall, peak = measure(
                ["from reedtool.cli import main; main()", *case.args], root)
            worst_mb, worst_s = max(worst_mb, peak), max(worst_s, wall)
            flag = "" if code == 2 and peak < TARGET_PEAK_MB and wall < TARGET_WALL_S else "  <--"
            if flag:
                failures.append(case.id)
            print(f"{case.id:34} {code:>4} {wall:7.2f} {peak:8.0f} {peak / base_mb:11.2f}{flag}")
        print(f"worst: {worst_mb:.0f} MB (target < {TARGET_PEAK_MB:.0f} MB, "
              f"{worst_mb / TARGET_PEAK_MB:.2f} of it), {worst_s:.2f} s "
              f"(target < {TARGET_WALL_S:.0f} s)")
        if failures:
            print("over target:", ", ".join(failures))
            sys.exit(1)


if __name__ == "__main__":
    main()
