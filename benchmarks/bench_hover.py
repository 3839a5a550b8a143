"""Hover-simulation speed: each engine against a yardstick measured in the same run.

Run on demand: python benchmarks/bench_hover.py [--vehicles 10000] [--repeats 5] [--no-command]

The machine is shared, so an absolute time says more about the other users than about
the code. Every figure here is measured next to a yardstick, repeat by repeat, and its
target is scaled by the yardstick's rate in that repeat:

- the yardstick (`yardstick`) is a fixed pure-Python float loop written like the
  traced single-vehicle step, timed in CPU seconds right before each repeat;
- YARDSTICK_REF_M is its rate where the issue-29 targets held; "target here" is the
  target scaled by (yardstick now / YARDSTICK_REF_M), a duration inversely, and "ratio"
  compares the figure with it (>= 1: met), median and spread over the repeats.

Figures are per CPU second (process time), which a loaded machine inflates far less than
wall time; the batch's is per CPU second of each of numba's threads (its wall-clock rate
is printed too).

Targets (issue 29): the numpy engine's single vehicle >= 320x real time; the numba batch
>= 47 M vehicle-steps/s; the whole `hover-test --engine numba` command on one vehicle,
warm cache, <= 0.6 s, timed as processes (CPU seconds of each child) with
`--engine numpy` and an empty `python -c pass` beside it.

YARDSTICK_REF_M = 1.43 is the yardstick rate at which the numpy engine's single vehicle
read 332x (the middle of the 320-344x measured before issue 29), the median over 12
interleaved pairs, with the step a hand-written generator wrote then (commit 0ae1443):
it calibrates the yardstick, and every figure is held to it.

Whole-process pairs before the equations became one source (A B A B, median of the pair
ratios A/B and their spread): the "slip" of issue 29 (162x, 25 M) was load, not code
(numpy single vehicle CPU 1.09 (0.96-1.15) against commit 0ae1443; numba batch 1.06
(0.87-1.16)); the block kernel's per-rotor stages then vectorised (numba batch of
10,000 x 5 s: 0.51 of the wall time).

After issue 29 item 1 (sim/equations.py the one source; the float step and the numpy
batch traced from it, numba compiling it), this script, 5 repeats each, at load ~2.6
(and ~5 in a first run):
- numpy single vehicle 198x real time, ratio 0.98 (0.97-1.00) to the scaled 320x (1.01,
  0.84-2.24, at load ~5); in pairs against the hand-written generator of before, about
  1.1x its CPU time (the trace computes the rolling moments and yaw reactions rotor by
  rotor, where the generator had factored them by hand);
- numba batch of 10,000 x 10 s: 40.1 M vehicle-steps per thread's CPU second (19.8 M on
  the wall clock), ratio 1.59 (1.26-2.03) to the scaled 47 M (1.62 at load ~5); the
  hand-laid block kernel it replaces read 38-39 M beside it in pairs;
- numpy batch of 1,000 x 1.5 s: 1.19 M vehicle-steps/s;
- the whole `hover-test --engine numba` command, one vehicle: 1.00 s CPU, ratio 1.01
  (0.77-1.07) to the scaled 0.6 s (0.86 at load ~5), 0.36 s more than `--engine numpy`
  (0.63 s): numba's import (~0.3 s) and cache load (~0.25 s) are most of it, so one
  vehicle flies on numpy by default (sim.choose_engine). As whole processes in pairs
  (median wall): one vehicle 2.10 s numba against 1.05 s numpy (load ~5); `--samples 2`
  1.29 s numba against 4.77 s numpy (load ~1.6).

After the judge became one source too (equations.judge_sample, verdict, settle_time),
5 repeats at load ~0.3-0.6, before / after, yardstick-scaled ratios: numpy single vehicle
0.83 / 0.84; numba batch of 4,000 x 5 s 1.71 / 1.60 (30.0 / 28.5 M vehicle-steps per
thread's CPU second); whole numba command 1.12 / 1.10; in pairs (CPU new / old, median
of 5) the numba batch 1.02, the numpy batch of 1,000 1.00. `--numpy-vehicles N` (N up to
4 x batch.FLOAT_ENGINE_MAX_VEHICLES) also flies that batch both ways the numpy engine
can, columns and one by one on the float step, and prints the median CPU ratio: 8
vehicles 5.4, 16 2.2, 24 1.76, 32 1.45, 40 0.93, 48 0.82, 64 0.52 (robustness_batch flies up to
32 one by one).
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
from reedtool.sim.batch import (FLOAT_ENGINE_MAX_VEHICLES, Spreads, perturbed_plant,
                                robustness_batch, sample_perturbations, simulate_batch,
                                simulate_one_by_one)
from reedtool.sim.controller import ControllerDesign
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.run import simulate_hover

NUMPY_SINGLE_TARGET_X = 320.0
NUMBA_BATCH_TARGET_VS_S = 47e6
NUMBA_COMMAND_TARGET_S = 0.6
YARDSTICK_N = 20_000
YARDSTICK_REF_M = 1.43      # M it/s per CPU second where the targets held (see above)
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "reed_quad_x"


def yardstick(n: int = YARDSTICK_N) -> float:
    """M iterations/s per CPU second of a fixed pure-Python float loop: a rotation from a
    quaternion, a body-rate update and the quaternion step, written as the generated
    single-vehicle step writes them (locals, sqrt and tan), so a loaded machine slows it
    as it slows the engines (ratio to the numpy engine within -25%/+15% of its median over
    12 interleaved pairs at load 3, against -40%/+60% for a four-line loop)."""
    sqrt, tan = math.sqrt, math.tan
    start = time.process_time()
    qw, qx, qy, qz = 1.0, 0.01, 0.02, 0.0
    wx, wy, wz = 0.3, -0.2, 0.1
    for _ in range(n):
        x2 = qx + qx
        y2 = qy + qy
        z2 = qz + qz
        xx, yy, zz = qx * x2, qy * y2, qz * z2
        xy, xz, yz = qx * y2, qx * z2, qy * z2
        xw, yw, zw = qw * x2, qw * y2, qw * z2
        R00, R01, R02 = 1.0 - (yy + zz), xy - zw, xz + yw
        R10, R11, R12 = xy + zw, 1.0 - (xx + zz), yz - xw
        R20, R21, R22 = xz - yw, yz + xw, 1.0 - (xx + yy)
        wx -= 1e-3 * (R01 * wy + R02 * wz)
        wy -= 1e-3 * (R10 * wx + R12 * wz)
        wz -= 1e-3 * (R20 * wx + R21 * wy) + 1e-4 * (R00 + R11 + R22)
        rate = sqrt(wx * wx + wy * wy + wz * wz)
        tan_h = tan(0.0005 * rate)
        a = rate / tan_h if tan_h != 0.0 else 1.0
        qw, qx, qy, qz = (qw * a - qx * wx - qy * wy - qz * wz,
                          qx * a + qw * wx + qy * wz - qz * wy,
                          qy * a + qw * wy + qz * wx - qx * wz,
                          qz * a + qw * wz + qx * wy - qy * wx)
        inv_q = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        qw, qx, qy, qz = qw * inv_q, qx * inv_q, qy * inv_q, qz * inv_q
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
    def scaled(stick: float) -> float:
        # a rate scales with the machine's speed, a duration inversely
        speed = stick / YARDSTICK_REF_M
        return target * speed if higher_is_better else target / speed

    ratios = [fig / scaled(stick) if higher_is_better else scaled(stick) / fig
              for fig, stick in zip(figures, sticks)]
    m = statistics.median(figures)
    here = scaled(statistics.median(sticks))
    return (f"{m:10.3g} {unit} ({min(figures):.3g}-{max(figures):.3g}); target here "
            f"{here:.3g} {unit}: ratio {statistics.median(ratios):.2f} "
            f"({min(ratios):.2f}-{max(ratios):.2f})")


def command_cpu_s(args: list[str]) -> float:
    """CPU seconds (user + sys) of one child process running args, which must run through
    (hover-test exits 0 or 1 with its report). Bytecode is written and read as an
    installed package's would be (a sandbox's PYTHONDONTWRITEBYTECODE would recompile
    every module at each run)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                          check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1) or (len(args) > 3 and not done.stdout):
        raise SystemExit(f"{' '.join(args)} failed ({done.returncode}): "
                         f"{done.stderr.decode(errors='replace')[-400:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def commands(repeats: int) -> None:
    base = [sys.executable, "-c", "import sys; from reedtool.cli import main; sys.exit(main())",
            "hover-test", str(EXAMPLE)]
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
    parser.add_argument("--numpy-vehicles", type=int, default=1000,
                        help="vehicles of the numpy batch (its rate hardly depends on the "
                             "count beyond a thousand, its run time does)")
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

    steps = args.numpy_vehicles * short.n_steps
    times, _, _ = paired(1, lambda: robustness_batch(params, args.numpy_vehicles, short,
                                                     Spreads(), seed=0, engine="numpy"))
    numpy_rate = steps / times[0]
    print(f"batch of {args.numpy_vehicles}, numpy ({short.duration_s:g} s): "
          f"{numpy_rate / 1e6:10.3g} M vehicle-steps/s")
    if args.numpy_vehicles <= 4 * FLOAT_ENGINE_MAX_VEHICLES:
        # the two ways the numpy engine can fly a small batch (robustness_batch picks one
        # by FLOAT_ENGINE_MAX_VEHICLES), interleaved, each on the same perturbed plant
        plant = perturbed_plant(params, sample_perturbations(
            args.numpy_vehicles, params.n_rotors, Spreads(), 0))
        ways = {"columns": lambda: simulate_batch(params, short, plant),
                "one by one": lambda: simulate_one_by_one(params, short, plant,
                                                          ControllerDesign(), None, False)}
        cpu = {name: [] for name in ways}
        for _ in range(args.repeats):
            for name, fly in ways.items():
                cpu[name].append(paired(1, fly)[0][0])
        ratio = statistics.median(a / b for a, b in zip(cpu["columns"], cpu["one by one"]))
        picked = ("one by one" if args.numpy_vehicles <= FLOAT_ENGINE_MAX_VEHICLES
                  else "columns")
        print("  columns / one by one: " + ", ".join(
            f"{name} {steps / statistics.median(t) / 1e6:.3g} M vehicle-steps/s "
            f"({steps / max(t) / 1e6:.3g}-{steps / min(t) / 1e6:.3g})"
            for name, t in cpu.items())
            + f"; CPU ratio {ratio:.2f} (robustness_batch picks: {picked})")
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
