"""Hover-simulation speed, numpy engine and compiled (numba) engine side by side.

Run on demand: python benchmarks/bench_hover.py [--vehicles 10000] [--repeats 3]
Targets (issue 15): single vehicle 10 s at 1 kHz >= 1000x real time; a batch of 10,000
vehicles >= 30 M vehicle-steps/s on a 2-core machine, both on the compiled engine. The
numpy engine is the yardstick measured in the same run (issue 6 targets: 200x, 3 M/s).
Prints the median of the repeats with its spread, the ratio to each target, the load
average before and after (the machine may be shared), and the compiled engine's first-call
time (compiling, or loading numba's on-disk cache) separately.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from reedtool.sim import HoverConfig, compiled
from reedtool.sim.batch import Spreads, robustness_batch
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.run import simulate_hover

SINGLE_TARGET_X = 1000.0
BATCH_TARGET_VS_S = 30e6


def timings(repeats: int, fn) -> list[float]:
    out = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return out


def single(engine: str, params, config, repeats: int) -> str:
    times = timings(repeats, lambda: simulate_hover(params, config, record=False,
                                                    engine=engine))
    x = [config.duration_s / t for t in times]
    m = statistics.median(x)
    return (f"{m:8.0f}x real time ({min(x):.0f}-{max(x):.0f}x; "
            f"target {SINGLE_TARGET_X:.0f}x: {m / SINGLE_TARGET_X:.2f})")


def batch(engine: str, params, config, vehicles: int, repeats: int) -> str:
    times = timings(repeats, lambda: robustness_batch(params, vehicles, config, Spreads(),
                                                      seed=0, engine=engine))
    rates = [vehicles * config.n_steps / t for t in times]
    r = statistics.median(rates)
    return (f"{r / 1e6:8.2f} M vehicle-steps/s ({min(rates) / 1e6:.2f}-"
            f"{max(rates) / 1e6:.2f}; {statistics.median(times):.2f} s; "
            f"target {BATCH_TARGET_VS_S / 1e6:.0f} M: {r / BATCH_TARGET_VS_S:.2f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", type=int, default=10000)
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--numpy-batch-duration", type=float, default=1.0,
                        help="simulated seconds of the numpy batch (the yardstick; its rate "
                             "hardly depends on the duration, its run time does)")
    args = parser.parse_args()
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=args.duration)
    short = HoverConfig(duration_s=max(args.numpy_batch_duration, 1.5), hold_s=0.5)
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cpus, "
          f"{args.repeats} repeats (median, min-max)")
    if compiled.available():
        import numba

        print(f"compiled engine: numba {numba.__version__}, {numba.get_num_threads()} threads; "
              f"first call (compile or load cache) {compiled.warm_up():.2f} s")
    else:
        print(f"compiled engine: unavailable ({compiled.unavailable_reason()})")

    label = f"single vehicle, {args.duration:g} s at {config.rate_hz:g} Hz"
    simulate_hover(params, config, record=False)          # generate + compile its step
    print(f"{label}, numpy: {single('numpy', params, config, args.repeats)}")
    if compiled.available():
        print(f"{label}, numba: {single('numba', params, config, args.repeats)}")

    print(f"batch of {args.vehicles}, numpy ({short.duration_s:g} s): "
          f"{batch('numpy', params, short, args.vehicles, 1)}")
    if compiled.available():
        print(f"batch of {args.vehicles}, numba ({args.duration:g} s): "
              f"{batch('numba', params, config, args.vehicles, args.repeats)}")
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
