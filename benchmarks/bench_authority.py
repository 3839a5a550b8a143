"""`reedtool authority` speed: the failure table for every frame `new-package` makes.

Run on demand: python benchmarks/bench_authority.py [--repeats 5]
Target (issue 12): the table (load the model, mass properties, ACAI of the intact vehicle
and every single failure, with and without yaw, rendered) in < 1 s per frame. Prints the
median per frame, its ratio to the target, and the yardstick measured in the same run:
loading the model alone (xacro expansion and parsing), which the table cannot beat.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from click.testing import CliRunner

from reedtool.cli import cli
from reedtool.io.loader import load_robot
from reedtool.resolve.mappings import parse_mappings
from reedtool.generate.airframes import MULTIROTOR_FRAMES

TARGET_S = 1.0


def median_time(repeats: int, fn) -> float:
    out = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return statistics.median(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    runner = CliRunner()
    with tempfile.TemporaryDirectory() as tmp:
        print(f"{'frame':<10} {'table s':>8} {'/target':>8} {'load s':>8} {'table/load':>10}")
        for frame in MULTIROTOR_FRAMES:
            name = "b_" + frame.replace("-", "_")
            result = runner.invoke(cli, ["new-package", name, "--frame", frame, "-o", tmp])
            assert result.exit_code == 0, result.output
            model = Path(tmp) / name / "urdf" / f"{name}.xacro"
            argv = ["authority", str(model), "namespace:=b", "--package-path", tmp]

            def table(argv=argv):
                result = runner.invoke(cli, argv, standalone_mode=False)
                assert result.exception is None and "single failures:" in result.output, \
                    result.output

            def load(model=model):
                load_robot(model, parse_mappings(["namespace:=b"]), [Path(tmp)])

            table()                                  # warm imports
            t_table = median_time(args.repeats, table)
            t_load = median_time(args.repeats, load)
            print(f"{frame:<10} {t_table:8.3f} {t_table / TARGET_S:8.2f} {t_load:8.3f} "
                  f"{t_table / t_load:10.2f}")


if __name__ == "__main__":
    main()
