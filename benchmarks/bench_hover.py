"""Hover-simulation speed: each engine against a yardstick measured in the same run.

Run on demand: python benchmarks/bench_hover.py [--vehicles 10000] [--repeats 5] [--no-command]

The machine is shared, so an absolute time says more about the other users than about
the code. Every figure here is therefore measured next to a yardstick, repeat by repeat,
and its target is scaled by the yardstick's rate in this run:

- the yardstick is a fixed pure-Python float loop (`yardstick`: the kind of work the
  generated single-vehicle step does), timed right before each repeat of each measure;
- YARDSTICK_REF_M is its rate (M iterations/s) on the machine and at the load where
  the issue-29 targets were measured; a target printed "here" is target * (yardstick
  now / YARDSTICK_REF_M), and "ratio" is figure / scaled target (>= 1: met).

Targets (issue 29): the numpy engine's single vehicle >= 320x real time; the numba batch
>= 47 M vehicle-steps/s; the whole `hover-test --engine numba` command on one vehicle,
warm cache, <= 0.6 s. The command is timed as processes (CPU seconds of each child,
which a loaded machine inflates far less than wall time), with `--engine numpy` and an
empty `python -c pass` beside it.

YARDSTICK_REF_M was set so that the numpy engine's single vehicle reads 332x (the middle
of the 320-344x measured before issue 29) in the runs below: the generated step is
byte-identical to the one measured then (sim/scalar.py's source for the benchmark's
quad diffs empty against commit 0ae1443), so the numpy figure calibrates the yardstick
and the other two are held to it.

Whole-process pairs on this machine (5 runs each, A B A B, load ~5 on 2 cores; median
of the pair ratios A/B, CPU seconds), before and after issue 29's work on sim/:
- numpy single vehicle, 8 flights of 10 s, HEAD before this work / commit 0ae1443
  (the 320-344x era): 1.09 (0.96-1.15): the engine had not slowed; the "162x" was load;
- numba batch, 10,000 vehicles x 5 s, same pair: 1.06 (0.87-1.16): not slowed either;
- `hover-test examples/reed_quad_x --engine numba` / `--engine numpy`, before: 1.92
  (1.80-2.64), +0.93 s CPU; after (scipy.linalg no longer imported by numba's start-up):
  see the commit message of that change and the figures printed by this script.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from reedtool.sim import HoverConfig, compiled
from reedtool.sim.batch import Spreads, robustness_batch
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.run import simulate_hover

NUMPY_SINGLE_TARGET_X = 320.0
NUMBA_BATCH_TARGET_VS_S = 47e6
NUMBA_COMMAND_TARGET_S = 0.6
YARDSTICK_N = 200_000
YARDSTICK_REF_M = 12.0      # M iterations/s per CPU second where the targets were measured (see above)
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "reed_quad_x"


def yardstick(n: int = YARDSTICK_N) -> float:
    """M iterations/s of a fixed float loop (a damped oscillator, one sqrt a step)."""
    sqrt = math.sqrt
    start = time.process_time()
    x, v, s = 1.0, 0.0, 0.0
    for _ in range(n):
        a = -4.0 * x - 0.1 * v
        v += 1e-3 * a
        x += 1e-3 * v
        s += sqrt(x * x + v * v)
    return n / (time.process_time() - start) / 1e6


def paired(repeats: int, fn) -> tuple[list[float], list[float], list[float]]:
    """(CPU seconds of fn, wall seconds of fn, yardstick rate just before it) per repeat."""
    cpu, wall, sticks = [], [], []
    for _ in range(repeats):
        sticks.append(yardstick())
        start, start_wall = time.process_time(), time.perf_counter()
        fn()
        cpu.append(time.process_time() - start)
        wall.append(time.perf_counter() - start_wall)
    return cpu, wall, sticks


def scaled_line(figures: list[float], sticks: list[float], target: float, unit: str,
                higher_is_better: bool = True) -> str:
    """Median figure, and the median over repeats of figure / (target scaled by that
    repeat's yardstick)."""
    ratios = []
    for fig, stick in zip(figures, sticks):
        here = target * stick / YARDSTICK_REF_M
        ratios.append(fig / here if higher_is_better else here / fig)
    m = statistics.median(figures)
    here = target * statistics.median(sticks) / YARDSTICK_REF_M
    return (f"{m:10.3g} {unit} ({min(figures):.3g}-{max(figures):.3g}); target here "
            f"{here:.3g} {unit}: ratio {statistics.median(ratios):.2f} "
            f"({min(ratios):.2f}-{max(ratios):.2f})")


def command_cpu_s(args: list[str]) -> float:
    """CPU seconds (user + sys) of one child process running args."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def commands(repeats: int) -> None:
    base = [sys.executable, "-m", "reedtool.cli", "hover-test", str(EXAMPLE)]
    runs = {"python -c pass": [sys.executable, "-c", "pass"],
            "hover-test --engine numpy": base + ["--engine", "numpy"],
            "hover-test --engine numba": base + ["--engine", "numba"]}
    for args in runs.values():          # warm-up: page cache, numba's on-disk cache
        command_cpu_s(args)
    cpu: dict[str, list[float]] = {name: [] for name in runs}
    sticks = []
    for _ in range(repeats):            # interleaved, as pairs
        sticks.append(yardstick())
        for name, args in runs.items():
            cpu[name].append(command_cpu_s(args))
    for name, values in cpu.items():
        print(f"  {name}: {statistics.median(values):.3f} s CPU "
              f"({min(values):.3f}-{max(values):.3f})")
    numba_cmd, numpy_cmd = cpu["hover-test --engine numba"], cpu["hover-test --engine numpy"]
    pair = [a / b for a, b in zip(numba_cmd, numpy_cmd)]
    print(f"  numba / numpy command: {statistics.median(pair):.2f} "
          f"({min(pair):.2f}-{max(pair):.2f}); numba - numpy: "
          f"{statistics.median(a - b for a, b in zip(numba_cmd, numpy_cmd)):+.3f} s CPU")
    print("  numba command (whole process, CPU): "
          + scaled_line(numba_cmd, sticks, NUMBA_COMMAND_TARGET_S, "s",
                        higher_is_better=False))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", type=int, default=10000)
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--numpy-batch-duration", type=float, default=1.0,
                        help="simulated seconds of the numpy batch (its rate hardly depends "
                             "on the duration, its run time does)")
    parser.add_argument("--no-command", action="store_true",
                        help="skip timing the whole hover-test command")
    args = parser.parse_args()
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=args.duration)
    short = HoverConfig(duration_s=max(args.numpy_batch_duration, 1.5), hold_s=0.5)
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cpus, "
          f"{args.repeats} repeats (median, min-max); yardstick {yardstick():.2f} M it/s "
          f"(reference {YARDSTICK_REF_M} M it/s)")
    numba = None
    if compiled.available():
        import numba

        print(f"compiled engine: numba {numba.__version__}, {numba.get_num_threads()} threads; "
              f"first call (compile or load cache) {compiled.warm_up():.2f} s")
    else:
        print(f"compiled engine: unavailable ({compiled.unavailable_reason()})")

    label = f"single vehicle, {args.duration:g} s at {config.rate_hz:g} Hz"
    simulate_hover(params, config, record=False)          # generate + compile its step
    times, _, sticks = paired(args.repeats, lambda: simulate_hover(
        params, config, record=False, engine="numpy"))
    numpy_x = [config.duration_s / t for t in times]
    print(f"{label}, numpy: "
          + scaled_line(numpy_x, sticks, NUMPY_SINGLE_TARGET_X, "x real time"))
    if compiled.available():
        times, _, _ = paired(args.repeats, lambda: simulate_hover(
            params, config, record=False, engine="numba"))
        numba_x = [config.duration_s / t for t in times]
        print(f"{label}, numba: {statistics.median(numba_x):10.3g} x real time; "
              f"numba / numpy {statistics.median(numba_x) / statistics.median(numpy_x):.1f}")

    steps = args.vehicles * short.n_steps
    times, _, _ = paired(1, lambda: robustness_batch(params, args.vehicles, short, Spreads(),
                                                     seed=0, engine="numpy"))
    numpy_rate = steps / times[0]
    print(f"batch of {args.vehicles}, numpy ({short.duration_s:g} s): "
          f"{numpy_rate / 1e6:10.3g} M vehicle-steps/s")
    if compiled.available():
        steps = args.vehicles * config.n_steps
        threads = numba.get_num_threads()
        times, wall, sticks = paired(args.repeats, lambda: robustness_batch(
            params, args.vehicles, config, Spreads(), seed=0, engine="numba"))
        # CPU seconds over the threads' count: the rate with the cores to itself
        rates = [steps / (t / threads) / 1e6 for t in times]
        print(f"batch of {args.vehicles}, numba, wall clock: "
              f"{statistics.median(steps / t / 1e6 for t in wall):.3g} M vehicle-steps/s")
        print(f"batch of {args.vehicles}, numba ({args.duration:g} s): "
              + scaled_line(rates, sticks, NUMBA_BATCH_TARGET_VS_S / 1e6,
                            "M vehicle-steps/s")
              + f"; numba / numpy {statistics.median(rates) * 1e6 / numpy_rate:.1f}")
        if not args.no_command:
            print(f"whole command, one vehicle ({EXAMPLE.name}), "
                  f"{args.repeats} interleaved runs each:")
            commands(args.repeats)
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
