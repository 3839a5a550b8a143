"""Hover-test speed: single vehicle (x real time) and the 1000-vehicle batch (vehicle-steps/s).

Run on demand: /work/venv/bin/python benchmarks/bench_hover.py [--vehicles 1000]
Targets (issue 6): single vehicle 10 s at 1 kHz >= 200x real time; batch >= 3 M
vehicle-steps/s. Prints the figures and the ratio to each target.
"""

from __future__ import annotations

import argparse
import time

from reedtool.sim import HoverConfig
from reedtool.sim.batch import Spreads, robustness_batch, simulate_batch
from reedtool.sim.params import symmetric_multirotor

SINGLE_TARGET_X = 200.0
BATCH_TARGET_VS_S = 3e6


def best_of(repeats: int, fn) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", type=int, default=1000)
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=args.duration)

    try:
        from reedtool.sim.run import simulate_hover
        single = best_of(args.repeats, lambda: simulate_hover(params, config))
        x_real_time = args.duration / single
        print(f"single vehicle (plain-float engine): {args.duration:g} s at "
              f"{config.rate_hz:g} Hz in {1e3 * single:.1f} ms = {x_real_time:.0f}x real time "
              f"(target {SINGLE_TARGET_X:.0f}x: {x_real_time / SINGLE_TARGET_X:.2f})")
    except ImportError:
        pass
    engine_one = best_of(1, lambda: simulate_batch(params, config))
    print(f"single vehicle (array engine, N=1): {args.duration / engine_one:.0f}x real time")

    batch = best_of(args.repeats, lambda: robustness_batch(
        params, args.vehicles, config, Spreads(), seed=0))
    rate = args.vehicles * config.n_steps / batch
    print(f"batch: {args.vehicles} vehicles x {args.duration:g} s at {config.rate_hz:g} Hz in "
          f"{batch:.2f} s = {rate / 1e6:.2f} M vehicle-steps/s "
          f"(target {BATCH_TARGET_VS_S / 1e6:.0f} M: {rate / BATCH_TARGET_VS_S:.2f})")


if __name__ == "__main__":
    main()
