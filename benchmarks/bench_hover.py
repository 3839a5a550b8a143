"""Hover-test speed: single vehicle (x real time) and the 1000-vehicle batch (vehicle-steps/s).

Run on demand: python benchmarks/bench_hover.py [--vehicles 1000] [--repeats 5]
Targets (issue 6): single vehicle 10 s at 1 kHz >= 200x real time; batch >= 3 M
vehicle-steps/s. Prints the median of the repeats and its ratio to each target, plus the
spread, the load average (before and after) and, for the single vehicle, the first (cold) run, which also
generates and compiles the vehicle's step (later runs of the same vehicle reuse it).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from reedtool.sim import HoverConfig
from reedtool.sim.batch import Spreads, robustness_batch, simulate_batch
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.run import simulate_hover

SINGLE_TARGET_X = 200.0
BATCH_TARGET_VS_S = 3e6


def timings(repeats: int, fn) -> list[float]:
    out = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", type=int, default=1000)
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=args.duration)
    print(f"load average {os.getloadavg()[0]:.2f}, {args.repeats} repeats (median, min-max)")

    cold = timings(1, lambda: simulate_hover(params, config))[0]
    single = timings(args.repeats, lambda: simulate_hover(params, config))
    x = [args.duration / t for t in single]
    x_median = statistics.median(x)
    print(f"single vehicle (plain-float engine): {args.duration:g} s at {config.rate_hz:g} Hz "
          f"in {1e3 * statistics.median(single):.1f} ms = {x_median:.0f}x real time "
          f"({min(x):.0f}-{max(x):.0f}x; first run {args.duration / cold:.0f}x) "
          f"(target {SINGLE_TARGET_X:.0f}x: {x_median / SINGLE_TARGET_X:.2f})")

    engine_one = timings(1, lambda: simulate_batch(params, config))[0]
    print(f"single vehicle (array engine, N=1): {args.duration / engine_one:.0f}x real time")

    batch = timings(args.repeats, lambda: robustness_batch(
        params, args.vehicles, config, Spreads(), seed=0))
    rates = [args.vehicles * config.n_steps / t for t in batch]
    rate = statistics.median(rates)
    print(f"batch: {args.vehicles} vehicles x {args.duration:g} s at {config.rate_hz:g} Hz in "
          f"{statistics.median(batch):.2f} s = {rate / 1e6:.2f} M vehicle-steps/s "
          f"({min(rates) / 1e6:.2f}-{max(rates) / 1e6:.2f}) "
          f"(target {BATCH_TARGET_VS_S / 1e6:.0f} M: {rate / BATCH_TARGET_VS_S:.2f})")
    # The machine may be shared: a load that rose during the run explains a slow figure.
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
