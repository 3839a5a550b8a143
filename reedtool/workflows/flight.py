"""A vehicle -> its hover test: trim, one closed-loop flight from a disturbance, and
(optionally) a robustness batch of perturbed vehicles, as one JSON-ready report.

Progress is shown through a `Progress` the caller hands in, so this stage never prints.
"""

from __future__ import annotations

import contextlib
from typing import Callable, ContextManager

from reedtool.workflows.vehicle import (
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
               vehicle: Vehicle | None = None, requirement=None,
               auto_duration: bool = False, controller_files=(),
               control_rate_hz: float | None = None) -> dict:
    """Trim, simulate and (optionally) batch one robot; the JSON-ready report.

    Keys: "model", "trim", "sim" (None when not flown), "batch" (None without samples),
    "verdict" (sim.verdict: what the vehicle can do, with its cause), "status" (the
    verdict's), "message", "passed" (the verdict against `requirement`, default
    --require flies); plus "_run" (the HoverRun, for CSV/plot), "_omega_max" and
    "_envelope" (the batch's, with `envelope`). With `controller_files` (RotorS Lee
    gains and vehicle YAML) the flight is that controller's (workflows.lee_flight) and
    "controller" reports its checks; it passes only when it flies.
    """
    import numpy as np

    from reedtool.physics.rotors import rotor_table
    from reedtool.sim import verdict as judge

    requirement = requirement or judge.Requirement()
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

    def conclude(found) -> dict:
        report["verdict"] = found.to_dict()
        report["status"] = found.verdict.value
        report["message"] = found.message
        report["passed"] = found.passes(requirement)
        report["require"] = str(requirement)
        return report

    if not trim.feasible:
        from reedtool.sim.params import STANDARD_GRAVITY_M_S2
        from reedtool.sim.rigid import tilting_joints

        # Rotors on driven tilt joints get roll/pitch/yaw from the tilt: a fixed-axis
        # trim that finds no torque balance says nothing about such a frame.
        tilting = tilting_joints(robot, every_rotor)
        # Their tilt can also turn the thrust upward: only all of it at full speed falling
        # short of the weight (thrust-to-weight < 1 along any axis) still fails.
        lift_N = sum(r.max_thrust_N for r in every_rotor)
        if tilting and trim.cause is not None and (
                trim.cause.value in judge.TILT_CAUSES
                or (trim.cause.value == "insufficient-thrust" and lift_N >= props.mass_kg * STANDARD_GRAVITY_M_S2)):
            return conclude(judge.tilt_rotor(trim.message, tilting))
        return conclude(judge.HoverVerdict(judge.Verdict.CANNOT_HOVER,
                                           f"no hover trim: {trim.message}"))
    if vehicle.omnidirectional:
        return conclude(judge.omnidirectional(trim.message))

    flying = prepare_flight(vehicle)
    report["model"]["derived"] = flying.derived
    params = flying.params
    from reedtool.sim.rigid import locked_joints

    # Passive joints (no plugin drives them) are flown rigid: which, and what they add.
    report["model"]["locked_joints"] = [
        lj.to_dict() for lj in locked_joints(robot, every_rotor, props.com_m)]
    controllable, acai = judge.stabilisable(params)
    if not controllable:
        return conclude(judge.uncontrollable(acai))

    if controller_files:
        from reedtool.workflows.lee_flight import fly_controller
        from reedtool.sim.lee_rotors import ROTORS_CONTROL_RATE_HZ

        lee = fly_controller(robot, vehicle, flying, config, controller_files,
                             control_rate_hz=control_rate_hz or ROTORS_CONTROL_RATE_HZ,
                             requirement=requirement, record=record,
                             auto_duration=auto_duration, progress=progress)
        sim = lee["sim"]
        sim["trim_omega_rad_s"] = dict(zip(params.rotor_names,
                                           (float(w) for w in trim.omega_rad_s)))
        report["sim"], report["_run"], report["controller"] = sim, lee["_run"], lee["controller"]
        conclude(lee["found"])
        report["passed"], report["message"] = lee["passed"], lee["message"]
        return report

    from reedtool.sim.controller import ControllerGains
    from reedtool.sim.run import simulate_hover

    gains = ControllerGains.from_params(params)
    if auto_duration:
        # A slowly tuned vehicle (a heavy one, little authority) gets the time its
        # position loop needs to settle, not a fixed 10 s.
        config = judge.with_time_to_settle(config, gains)
    with progress.flying(f"flying {config.duration_s:g} s at {config.rate_hz:g} Hz"):
        run = simulate_hover(params, config, record=record, engine=engine, gains=gains)
        found = judge.judge_flight(
            params, config, run,
            lambda start: simulate_hover(params, start, record=False, engine=engine,
                                         gains=gains), requirement)
    sim = run.to_dict()
    sim["trim_omega_rad_s"] = dict(zip(params.rotor_names,
                                       (float(w) for w in trim.omega_rad_s)))
    report["sim"] = sim
    report["_run"] = run
    conclude(found)

    if samples:
        from reedtool.sim.batch import Spreads, robustness_batch

        # The batch flies the nominal tuning from the start the nominal vehicle recovers
        # from: the start itself when it flies, its recoverable margin when marginal.
        scale = judge.batch_start_scale(found)
        batch_config = judge.scaled_start(config, scale)
        mass_rel, com_m, inertia_rel, motor_rel = spreads
        spread = Spreads(mass_rel=mass_rel, com_m=com_m, inertia_rel=inertia_rel,
                         motor_constant_rel=motor_rel)
        with progress.steps(f"flying {samples} vehicles", config.n_steps) as update:
            batch = robustness_batch(params, samples, batch_config, spread, seed,
                                     progress=update, engine=engine, record=envelope)
        report["batch"] = batch.to_dict()
        report["batch"]["start_scale"] = scale
        report["_envelope"] = batch.envelope
    return report


def replay_page(vehicle: Vehicle, run, config, name: str, verdict: str) -> str:
    """One flight (a recorded HoverRun) as the page report/replay_page.py draws."""
    import numpy as np

    from reedtool.report.replay_page import render_replay, replay_document

    com_m = np.asarray(vehicle.props.com_m, dtype=float)
    by_name = {rotor.name: rotor for rotor in vehicle.rotors}
    rotors = [by_name[name] for name in run.rotor_names if name in by_name] or vehicle.rotors
    document = replay_document(
        run.series,
        rotor_positions_m=np.array([np.asarray(r.position_m, dtype=float) - com_m
                                    for r in rotors]),
        turning_signs=[r.turning_sign for r in rotors],
        omega_max_rad_s=np.array([r.max_rot_velocity_rad_s for r in rotors], dtype=float),
        rotor_names=[r.name for r in rotors],
        setpoint_m=(0.0, 0.0, config.hover_altitude_m),
        position_tol_m=config.position_tol_m, attitude_tol_deg=config.attitude_tol_deg,
        settle_time_s=run.settle_time_s, title=f"{name}: hover-test flight",
        verdict=verdict)
    return render_replay(document)
