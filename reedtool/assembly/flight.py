"""A vehicle -> its hover test: trim, one closed-loop flight from a disturbance, and
(optionally) a robustness batch of perturbed vehicles, as one JSON-ready report.

Progress is shown through a `Progress` the caller hands in, so this stage never prints.
"""

from __future__ import annotations

import contextlib
from typing import Callable, ContextManager

from reedtool.assembly.vehicle import (
    DEFAULT_MAX_MEMORY_MB,
    Vehicle,
    check_batch_resources,
    prepare_flight,
)


class Progress:
    """How a long computation says it is still working. The default says nothing."""

    def flying(self, label: str) -> ContextManager[None]:
        """Around one flight (a single compiled call that reports nothing itself)."""
        return contextlib.nullcontext()

    def steps(self, label: str, n_steps: int) -> ContextManager[Callable[[int], None] | None]:
        """Around a batch: yields a callable taking the number of steps done since the
        last call, or None for no reporting."""
        return contextlib.nullcontext()


def hover_test(robot, config, *, samples: int | None = None, seed: int = 0,
               spreads: tuple[float, float, float, float] = (0.1, 0.01, 0.1, 0.05),
               record: bool = False, progress: Progress | None = None,
               engine: str = "numpy", envelope: bool = False,
               max_memory_bytes: int = DEFAULT_MAX_MEMORY_MB * 1024 * 1024,
               vehicle: Vehicle | None = None) -> dict:
    """Trim, simulate and (optionally) batch one robot; the JSON-ready report.

    Keys: "model", "trim", "sim" (None when the trim failed), "batch" (None without
    samples), "passed"; plus "_run" (the HoverRun, for CSV/plot), "_omega_max" and
    "_envelope" (the batch's, with `envelope`).
    """
    import numpy as np

    from reedtool.physics.rotors import rotor_table
    from reedtool.sim import ExitStatus

    progress = progress or Progress()
    vehicle = vehicle or Vehicle.of(robot)
    every_rotor, rotors = vehicle.every_rotor, vehicle.rotors
    check_batch_resources(every_rotor, samples, max_memory_bytes)
    props, trim = vehicle.props, vehicle.trim
    report: dict = {
        "model": {"name": robot.name, "file": str(robot.source_file or ""),
                  "mass_kg": props.mass_kg, "com_m": [float(v) for v in props.com_m],
                  "inertia_kg_m2": [[float(v) for v in row] for row in props.inertia_kg_m2],
                  "rotors": len(rotors), "rotor_table": rotor_table(every_rotor)},
        "trim": trim.to_dict(),
        "sim": None,
        "batch": None,
        "passed": False,
        "_omega_max": np.array([r.max_rot_velocity_rad_s for r in rotors], dtype=float),
    }
    if not trim.feasible:
        report["status"] = ExitStatus.TRIM_INFEASIBLE.value
        report["message"] = f"no hover trim: {trim.message}"
        return report

    flying = prepare_flight(vehicle)
    report["model"]["derived"] = flying.derived
    params = flying.params

    from reedtool.sim.run import simulate_hover

    with progress.flying(f"flying {config.duration_s:g} s at {config.rate_hz:g} Hz"):
        run = simulate_hover(params, config, record=record, engine=engine)
    sim = run.to_dict()
    sim["trim_omega_rad_s"] = dict(zip(params.rotor_names,
                                       (float(w) for w in trim.omega_rad_s)))
    report["sim"] = sim
    report["_run"] = run
    report["status"] = run.status.value
    report["message"] = run.message
    report["passed"] = run.passed

    if samples:
        from reedtool.sim.batch import Spreads, robustness_batch

        mass_rel, com_m, inertia_rel, motor_rel = spreads
        spread = Spreads(mass_rel=mass_rel, com_m=com_m, inertia_rel=inertia_rel,
                         motor_constant_rel=motor_rel)
        with progress.steps(f"flying {samples} vehicles", config.n_steps) as update:
            batch = robustness_batch(params, samples, config, spread, seed, progress=update,
                                     engine=engine, record=envelope)
        report["batch"] = batch.to_dict()
        report["_envelope"] = batch.envelope
    return report
