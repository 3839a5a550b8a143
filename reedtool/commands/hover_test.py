"""`reedtool hover-test`: static trim, then a headless closed-loop hover, then (optionally)
a robustness batch of perturbed vehicles.

Exit 0 when the model hovers (and the batch meets --min-pass-rate), 1 when it does not
(no trim, or the simulation ends in anything but `passed`), 2 on unreadable input.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import sys
from pathlib import Path

import click

from reedtool.commands.params import FiniteFloatRange, model_arguments
from reedtool.errors import ReedtoolError

SPREAD_HELP = "Half-width of the uniform perturbation"
# A COM shifted by a metre is another vehicle, not a perturbation of this one.
MAX_COM_SPREAD_M = 1.0
# 10^7 fixed steps is 10,000 s at 1 kHz, far beyond any hover test; more is a typo
# (`--duration 1e9`) that would keep the machine busy for days.
MAX_STEPS = 10_000_000
SCHEMA = "reedtool.hover-test/1"


def _validation_json(errors, refused: bool) -> dict:
    return {"errors": [f.to_dict() for f in errors], "refused": refused}


# The robustness batch flies all vehicles at once as (k, N) float64 arrays: about 200 state,
# command and bookkeeping values per vehicle plus ~20 per rotor (measured: 10^7 quads took
# 22 GB). Estimated before allocating, against --max-memory.
BATCH_BYTES_PER_VEHICLE = 8 * 200
BATCH_BYTES_PER_VEHICLE_ROTOR = 8 * 20
DEFAULT_MAX_MEMORY_MB = 2048
# Real multirotors have 3 to 16 rotors; a model with hundreds is generated wrongly, and its
# (rotors x rotors) allocation work is what ran out of memory at 2000.
MAX_ROTORS = 64
# A run longer than this on a terminal shows that it is still working.
PROGRESS_AFTER_S = 2.0


def batch_memory_bytes(samples: int, n_rotors: int) -> int:
    """Estimated peak memory of flying `samples` perturbed vehicles together."""
    return samples * (BATCH_BYTES_PER_VEHICLE + n_rotors * BATCH_BYTES_PER_VEHICLE_ROTOR)


def check_batch_resources(every_rotor, samples: int | None, max_memory_bytes: int) -> None:
    """Refuse, before anything is allocated, a model or batch this machine cannot fly."""
    from reedtool.physics.rotors import lift_rotors

    if len(every_rotor) > MAX_ROTORS:
        source = every_rotor[0].loc.file if every_rotor else None
        raise ReedtoolError(f"{len(every_rotor)} rotors: more than the {MAX_ROTORS} a multirotor "
                            "hover test handles", file=source,
                            hint="is the model generated wrongly? real multirotors have 3 to "
                                 "16 rotors")
    n_lift = len(lift_rotors(every_rotor))
    if samples:
        need = batch_memory_bytes(samples, n_lift)
        if need > max_memory_bytes:
            fit = max_memory_bytes // batch_memory_bytes(1, n_lift)
            raise ReedtoolError(f"--samples {samples} needs about {need / 2**20:,.0f} MB for "
                                f"{n_lift} rotors, more than --max-memory "
                                f"{max_memory_bytes // 2**20} MB",
                                hint=f"use --samples {fit} or fewer (a few hundred give the "
                                     "pass rate to a few percent), or raise --max-memory")


@click.command(name="hover-test")
@model_arguments
@click.option("--duration", "duration_s", type=float, default=10.0, show_default=True,
              help="Simulated time [s].")
@click.option("--rate", "rate_hz", type=float, default=1000.0, show_default=True,
              help="Integration and control rate [Hz] (fixed step).")
@click.option("--offset", "offset_m", type=float, nargs=3, default=(0.5, 0.0, 0.0),
              show_default=True, metavar="X Y Z", help="Start position minus setpoint [m].")
@click.option("--roll", "roll_rad", type=float, default=0.2, show_default=True,
              help="Initial roll [rad].")
@click.option("--pitch", "pitch_rad", type=float, default=0.0, show_default=True,
              help="Initial pitch [rad].")
@click.option("--yaw", "yaw_rad", type=float, default=0.0, show_default=True,
              help="Initial yaw [rad] (the setpoint heading is 0).")
@click.option("--plot", "plot_path", type=click.Path(path_type=Path, dir_okay=False),
              help="Write a PNG of position, attitude and rotor speeds.")
@click.option("--csv", "csv_path", type=click.Path(path_type=Path, dir_okay=False),
              help="Write the sampled time series (100 Hz) as CSV ('-': standard output).")
@click.option("--force", is_flag=True, help="Overwrite existing --plot/--csv files.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
@click.option("--samples", type=click.IntRange(min=1), default=None,
              help="Also fly N perturbed vehicles (robustness batch).")
@click.option("--max-memory", "max_memory_mb", type=click.IntRange(min=16),
              default=DEFAULT_MAX_MEMORY_MB, show_default=True, metavar="MB",
              help="Refuse a robustness batch estimated to need more memory than this.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Random seed of the robustness batch.")
@click.option("--mass-spread", type=FiniteFloatRange(0.0, 0.9), default=0.10,
              show_default=True, help=f"{SPREAD_HELP} of the mass (fraction).")
@click.option("--com-spread", "com_spread_m", type=FiniteFloatRange(0.0, MAX_COM_SPREAD_M), default=0.01,
              show_default=True, help=f"{SPREAD_HELP} of the COM on each axis [m].")
@click.option("--inertia-spread", type=FiniteFloatRange(0.0, 0.9), default=0.10,
              show_default=True, help=f"{SPREAD_HELP} of each principal moment (fraction).")
@click.option("--motor-spread", type=FiniteFloatRange(0.0, 0.9), default=0.05,
              show_default=True, help=f"{SPREAD_HELP} of each motor constant (fraction).")
@click.option("--engine", type=click.Choice(["numpy", "numba"]), default="numpy",
              show_default=True,
              help="Simulator engine: numpy (the reference) or numba (compiled, all cores; "
                   "needs pip install 'reedtool[fast]').")
@click.option("--min-pass-rate", type=FiniteFloatRange(0.0, 1.0), default=0.95,
              show_default=True, help="Batch pass rate needed to exit 0.")
@click.option("--require", "require", default="stable", show_default=True,
              metavar="hover|stable|margin:DEG",
              help="What exit 0 needs: a hover trim (hover); and a vehicle some controller "
                   "can stabilise (stable); and recovery from a start tilted DEG degrees "
                   "(margin:DEG).")
@click.option("--ignore-validation", is_flag=True,
              help="Fly a model that `validate` reports errors for (by default it is "
                   "refused: exit 1 without flying).")
def command(model: Path, mappings: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None,
            duration_s: float, rate_hz: float, offset_m: tuple[float, float, float],
            roll_rad: float, pitch_rad: float, yaw_rad: float, plot_path: Path | None,
            csv_path: Path | None, force: bool, fmt: str, samples: int | None,
            max_memory_mb: int, seed: int,
            mass_spread: float, com_spread_m: float, inertia_spread: float,
            motor_spread: float, engine: str, min_pass_rate: float,
            require: str = "stable", ignore_validation: bool = False) -> int:
    """Trim MODEL (.urdf or .xacro, with xacro NAME:=VALUE arguments) for hover and fly it.

    Starts from a disturbance (default 0.5 m off the setpoint, rolled 0.2 rad) and passes
    when it settles within 5 cm and 2 deg and stays there. A model `validate` reports
    errors for is not flown (exit 1) unless --ignore-validation is given: a hover of a
    model Gazebo would simulate differently is not a pass.
    """
    from reedtool.errors import check_plausible
    from reedtool.sim import HoverConfig
    from reedtool.sim.verdict import Requirement

    try:
        requirement = Requirement.parse(require)
    except ValueError as exc:
        raise ReedtoolError(f"bad option: {exc}",
                            hint="e.g. --require stable, or --require margin:10") from exc

    check_plausible("rate", rate_hz, "--rate")
    check_plausible("duration", duration_s, "--duration")
    for axis, value in zip("xyz", offset_m):
        check_plausible("offset", value, f"--offset {axis}", magnitude=True)
    for option, value in (("--roll", roll_rad), ("--pitch", pitch_rad), ("--yaw", yaw_rad)):
        check_plausible("angle", value, option, magnitude=True)
    config = HoverConfig(duration_s=duration_s, rate_hz=rate_hz, offset_m=tuple(offset_m),
                         roll_rad=roll_rad, pitch_rad=pitch_rad, yaw_rad=yaw_rad)
    try:
        config.validate()
    except ValueError as exc:
        raise ReedtoolError(f"bad option: {exc}", hint="see reedtool hover-test --help") from exc
    steps = duration_s * rate_hz
    if steps > MAX_STEPS:
        raise ReedtoolError(f"bad option: --duration {duration_s:g} s at --rate {rate_hz:g} Hz "
                            f"is {steps:.3g} steps, more than {MAX_STEPS:.0e}",
                            hint="a hover test settles in seconds; the defaults are 10 s at "
                                 "1000 Hz")
    if engine == "numba":
        from reedtool.sim.compiled import available, unavailable_reason

        if not available():
            raise ReedtoolError(f"bad option: --engine numba: {unavailable_reason()}",
                                hint="or use --engine numpy (the default)")
    from reedtool.io.fileio import check_writable, note_input

    note_input(model)           # the model is never an output of its own test
    if plot_path is not None:   # fail before flying, not after
        check_writable(plot_path, force)
    if csv_path is not None:
        check_writable(csv_path, force, stdout_ok=True)
    # What the path is comes first (a FIFO is refused as such), then its format.
    if plot_path is not None and plot_path.suffix.lower() not in (".png", ".svg"):
        raise ReedtoolError(f"cannot tell the plot format from '{plot_path.suffix or plot_path.name}'",
                            file=plot_path, hint="name the --plot file .png or .svg")
    if not model.is_file():
        raise ReedtoolError("model file not found", file=model,
                            hint="pass the path of a .urdf or .xacro file")

    from reedtool.checks.preflight import require_sound_model
    from reedtool.commands.validate import validation_errors
    from reedtool.io.loader import load_robot
    from reedtool.io.mappings import parse_mappings

    robot = load_robot(model, parse_mappings(mappings), list(package_paths),
                       model_name=model_name)
    require_sound_model(robot)
    from reedtool.physics.rotors import discover_rotors

    # A model or batch too large for the machine is refused before any rule runs on it.
    every_rotor = discover_rotors(robot)
    check_batch_resources(every_rotor, samples, max_memory_mb * 1024 * 1024)
    errors = validation_errors(model, robot)
    if errors and not ignore_validation:
        # Bad input (exit 2) comes before what validate finds (exit 1): unreadable rotor
        # parameters.
        from reedtool.sim.params import check_rotor_dynamics

        # ArduPilotPlugin rotors carry no time constants: hover_test derives them from
        # the joint's velocity PID (or refuses with the reason) only when it flies.
        check_rotor_dynamics([r for r in every_rotor if r.kind != "ardupilot"])
    if errors:
        from reedtool.report import ModelResult, render

        refused = not ignore_validation
        why = (f"validate reports {len(errors)} error{'s' if len(errors) != 1 else ''} for "
               f"this model; " + ("not flying it (--ignore-validation flies it anyway)"
                                  if refused else "flying it anyway (--ignore-validation)"))
        if fmt == "text":
            click.echo(render([ModelResult(str(model), errors)], "text"), nl=False)
            click.echo(why if not refused else f"FAILED: {why}")
        if refused:
            if fmt == "json":
                from reedtool.report.json_format import envelope

                click.echo(json.dumps({**envelope(SCHEMA), "model": {"file": str(model)},
                                       "validation": _validation_json(errors, True),
                                       "passed": False, "status": "refused",
                                       "message": why}, indent=2))
            return 1
    report = hover_test(robot, config, samples=samples, seed=seed,
                        spreads=(mass_spread, com_spread_m, inertia_spread, motor_spread),
                        record=bool(plot_path or csv_path), show_progress=fmt == "text",
                        engine=engine, envelope=plot_path is not None,
                        max_memory_bytes=max_memory_mb * 1024 * 1024,
                        requirement=requirement)
    batch = report.get("batch")
    if batch is not None:
        batch["min_pass_rate"] = min_pass_rate
        if report["passed"] and batch["pass_rate"] < min_pass_rate:
            report["passed"] = False
            report["message"] = (f"only {100 * batch['pass_rate']:.1f}% of the perturbed "
                                 f"vehicles hover, {100 * min_pass_rate:.0f}% required")

    run, omega_max = report.pop("_run", None), report.pop("_omega_max")
    envelope = report.pop("_envelope", None)
    if run is not None and csv_path is not None:
        _write_csv(csv_path, run.series, force)
    if run is not None and plot_path is not None:
        from reedtool.io.fileio import atomic_write_bytes
        from reedtool.sim.plot import failure_marks, render

        figure = render(run.series, omega_max, run.initial_omega_rad_s,
                        f"{robot.name}: {run.status.value}"
                        + (f" ({batch['passed']}/{batch['samples']} of the batch passed)"
                           if batch is not None else ""),
                        fmt=plot_path.suffix.lower()[1:],
                        position_tol_m=config.position_tol_m,
                        attitude_tol_deg=config.attitude_tol_deg,
                        settle_time_s=run.settle_time_s, failures=failure_marks(run),
                        envelope=envelope)
        atomic_write_bytes(plot_path, figure, force=force)

    if fmt == "json":
        from reedtool.report.json_format import envelope

        document = {**envelope(SCHEMA), **report,
                    "validation": _validation_json(errors, False)}
        click.echo(json.dumps(_finite(document), indent=2, allow_nan=False))
    else:
        click.echo(render_text(report))
    return 0 if report["passed"] else 1


def hover_test(robot, config, *, samples: int | None = None, seed: int = 0,
               spreads: tuple[float, float, float, float] = (0.1, 0.01, 0.1, 0.05),
               record: bool = False, show_progress: bool = False,
               engine: str = "numpy", envelope: bool = False,
               max_memory_bytes: int = DEFAULT_MAX_MEMORY_MB * 1024 * 1024,
               requirement=None) -> dict:
    """Trim, simulate and (optionally) batch one robot; the JSON-ready report.

    Keys: "model", "trim", "sim" (None when not flown), "batch" (None without samples),
    "verdict" (sim.verdict: what the vehicle can do, with its cause), "status" (the
    verdict's), "message", "passed" (the verdict against `requirement`); plus "_run" (the
    HoverRun, for CSV/plot) and "_omega_max".
    """
    import numpy as np

    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import (
        discover_rotors,
        is_omnidirectional,
        lift_rotors,
        rotor_table,
    )
    from reedtool.physics.trim import solve_trim, solve_trim_6dof
    from reedtool.sim import verdict as judge
    from reedtool.sim.params import VehicleParams, check_rotor_dynamics

    requirement = requirement or judge.Requirement()

    def conclude(found) -> dict:
        report["verdict"] = found.to_dict()
        report["status"] = found.verdict.value
        report["message"] = found.message
        report["passed"] = found.passes(requirement)
        report["require"] = str(requirement)
        return report

    # Hover is held by the lift rotors: a VTOL's pusher or a plane's puller stays off.
    every_rotor = discover_rotors(robot)
    rotors = lift_rotors(every_rotor)
    check_batch_resources(every_rotor, samples, max_memory_bytes)
    props = whole_robot_pinocchio(robot)
    # The trim validate judges by (checks.context): the 6-DoF allocation for an
    # omnidirectional frame, whose reversible rotors may push down.
    omni = is_omnidirectional(rotors)
    trim = (solve_trim_6dof if omni else solve_trim)(props.mass_kg, props.com_m, rotors)
    if every_rotor and not rotors:
        # A fixed-wing's puller (or a glider with a pusher): motors exist, none lifts.
        import dataclasses

        roles = ", ".join(f"{r.name} is {r.role}" for r in every_rotor)
        trim = dataclasses.replace(trim, message=(
            f"the model has no lift rotors ({roles}: its thrust axis is horizontal); "
            "a fixed-wing cannot hover"))
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
        return conclude(judge.HoverVerdict(judge.Verdict.CANNOT_HOVER,
                                           f"no hover trim: {trim.message}"))
    if omni:
        return conclude(judge.omnidirectional(trim.message))
    rotors, derived = _ardupilot_motor_response(robot, rotors)
    report["model"]["derived"] = derived
    check_rotor_dynamics(rotors)
    if props.mass_kg <= 0 or not np.all(np.linalg.eigvalsh(props.inertia_kg_m2) > 0):
        raise ReedtoolError("the whole-robot inertia is not positive definite, nothing can "
                            "be simulated", file=robot.source_file,
                            hint="run `reedtool inertia` on the model")
    params = VehicleParams.from_rotors(props.mass_kg, props.com_m, props.inertia_kg_m2, rotors)
    from reedtool.sim.rigid import locked_joints

    report["model"]["locked_joints"] = [
        lj.to_dict() for lj in locked_joints(robot, every_rotor, props.com_m)]
    controllable, acai = judge.stabilisable(params)
    if not controllable:
        return conclude(judge.uncontrollable(acai))

    from reedtool.sim.controller import ControllerGains
    from reedtool.sim.run import simulate_hover

    gains = ControllerGains.from_params(params)
    with _still_working(f"flying {config.duration_s:g} s at {config.rate_hz:g} Hz",
                        show_progress):
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

        # The batch flies from the start the nominal vehicle recovers from: the start
        # itself when it flies, its recoverable margin when it is marginal.
        scale = 1.0
        if found.verdict is judge.Verdict.MARGINAL and found.start_tilt_deg:
            scale = (found.recoverable_tilt_deg or 0.0) / found.start_tilt_deg
        elif found.verdict is judge.Verdict.MARGINAL and found.start_offset_m:
            scale = (found.recoverable_offset_m or 0.0) / found.start_offset_m
        batch_config = judge.scaled_start(config, scale)
        mass_rel, com_m, inertia_rel, motor_rel = spreads
        spread = Spreads(mass_rel=mass_rel, com_m=com_m, inertia_rel=inertia_rel,
                         motor_constant_rel=motor_rel)
        if show_progress:
            with click.progressbar(length=config.n_steps, file=sys.stderr,
                                   label=f"flying {samples} vehicles") as bar:
                batch = robustness_batch(params, samples, batch_config, spread, seed,
                                         progress=bar.update, engine=engine, record=envelope)
        else:
            batch = robustness_batch(params, samples, batch_config, spread, seed,
                                     engine=engine, record=envelope)
        report["batch"] = batch.to_dict()
        report["batch"]["start_scale"] = scale
        report["_envelope"] = batch.envelope
    return report


def _ardupilot_motor_response(robot, rotors):
    """ArduPilotPlugin rotors carry no time constants: derive them from the joint's
    velocity PID and the rotor's inertia, or refuse with the reason (one line)."""
    import dataclasses

    from reedtool.physics.rotors import ardupilot_time_constant

    out, derived = [], []
    for rotor in rotors:
        if rotor.kind != "ardupilot":
            out.append(rotor)
            continue
        found = ardupilot_time_constant(robot, rotor)
        if not found.time_constant_s > 0:
            raise ReedtoolError(
                f"rotor {rotor.name}: the ArduPilotPlugin gives no motor time constant "
                f"({found.explanation}), and hover-test simulates the motor response",
                file=rotor.loc.file, line=rotor.loc.line,
                hint="`reedtool validate` checks their hover trim from the LiftDrag estimate")
        out.append(dataclasses.replace(rotor, time_constant_up_s=found.time_constant_s,
                                       time_constant_down_s=found.time_constant_s))
        derived.append(f"{rotor.name}: {found.explanation}")
    return out, derived


@contextlib.contextmanager
def _still_working(label: str, enabled: bool):
    """On a terminal, after PROGRESS_AFTER_S, say on stderr every second that work goes on.

    The single flight runs inside one compiled call that reports nothing; a thread prints
    the elapsed time so a long run (--duration 10000) is not mistaken for a hang.
    """
    if not (enabled and sys.stderr.isatty()):
        yield
        return
    import threading
    import time

    done = threading.Event()
    start = time.monotonic()

    def tick() -> None:
        if done.wait(PROGRESS_AFTER_S):
            return
        while not done.wait(1.0):
            sys.stderr.write(f"\r{label}: {time.monotonic() - start:.0f} s elapsed")
            sys.stderr.flush()
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()


# ------------------------------------------------------------------ output

def render_text(report: dict) -> str:
    model, trim, sim, batch = report["model"], report["trim"], report["sim"], report["batch"]
    lines = [f"hover-test {model['name']}: {model['rotors']} rotors, "
             f"mass {model['mass_kg']:.4g} kg, COM ({', '.join(f'{v:.4g}' for v in model['com_m'])}) m"]
    others = [r for r in model.get("rotor_table", ()) if r["role"] != "lift"]
    if others:
        lines.append("not used for hover: " + ", ".join(f"{r['name']} ({r['role']})"
                                                         for r in others))
    for line in model.get("derived", ()):
        lines.append(f"derived: {line}")
    for lj in model.get("locked_joints", ()):
        # Passive joints (no plugin drives them) are flown rigid: say so, with what the
        # mass beyond them adds to the inertia about the COM.
        added = [lj["inertia_about_com_kg_m2"][i][i] for i in range(3)]
        total = [model["inertia_kg_m2"][i][i] for i in range(3)]
        share = ", ".join(f"{axis} {a:.3g} kg*m^2 ({100 * a / t:.0f}%)" if t > 0 else
                          f"{axis} {a:.3g} kg*m^2" for axis, a, t in zip("xyz", added, total))
        lines.append(f"locked rigid: {lj['joint']} ({lj['type']}, no plugin drives it; "
                     f"{lj['mass_kg']:.3g} kg beyond it adds {share} about the COM)")
    if trim["feasible"]:
        lines.append(f"trim: {trim['message']}")
    else:
        lines.append(f"trim: INFEASIBLE ({trim['cause']}): {trim['message']}")
    if trim["rotors"]:
        width = max(len(r["name"]) for r in trim["rotors"])
        lines.append(f"  {'rotor':<{width}}  {'thrust N':>9}  {'omega rad/s':>11}  {'throttle':>8}")
        for r in trim["rotors"]:
            lines.append(f"  {r['name']:<{width}}  {_num(r['thrust_N'], '9.4f')}  "
                         f"{_num(r['omega_rad_s'], '11.2f')}  {_pct(r['throttle']):>8}")
    if trim["feasible"]:
        a = trim["torque_authority_N_m"]
        lines.append(f"  thrust-to-weight {trim['thrust_to_weight']:.3f}; torque authority at "
                     f"hover: roll {a['roll']:.3g}, pitch {a['pitch']:.3g}, "
                     f"yaw {a['yaw']:.3g} N*m")
    if sim is not None:
        from reedtool.sim.verdict import tuning_line

        c = sim["config"]
        lines.append(f"tuning: {tuning_line(sim['gains'])}")
        lines.append(f"sim: {sim['status'].upper()}: {sim['message']}")
        lines.append(f"  start {c['offset_m']} m off, roll {c['roll_rad']:g} pitch "
                     f"{c['pitch_rad']:g} yaw {c['yaw_rad']:g} rad; {c['duration_s']:g} s at "
                     f"{c['rate_hz']:g} Hz ({c['integrator']}; engine {sim['engine']})")
        lines.append(f"  max error {sim['max_position_error_m']:.3f} m, "
                     f"{sim['max_attitude_error_deg']:.1f} deg; final "
                     f"{100 * sim['final_position_error_m']:.2f} cm, "
                     f"{sim['final_attitude_error_deg']:.2f} deg; max throttle "
                     f"{_pct(sim['max_throttle'])}")
        if sim["passed"]:
            speeds = ", ".join(f"{w:.2f}" for w in sim["final_omega_rad_s"].values())
            lines.append(f"  final rotor speeds {speeds} rad/s")
    if batch is not None:
        s = batch["spreads"]
        counts = ", ".join(f"{k} {v}" for k, v in sorted(batch["counts"].items()))
        lines.append(f"batch: {batch['passed']}/{batch['samples']} passed "
                     f"({100 * batch['pass_rate']:.1f}%, need "
                     f"{100 * batch['min_pass_rate']:.0f}%): {counts}")
        lines.append(f"  spreads: mass +-{100 * s['mass_rel']:g}%, COM +-{1000 * s['com_m']:g} mm, "
                     f"inertia +-{100 * s['inertia_rel']:g}%, motor constant "
                     f"+-{100 * s['motor_constant_rel']:g}%; seed {batch['seed']}")
        for w in batch["worst"]:
            lines.append(f"  #{w['index']}: {w['status']}: {w['message']} "
                         f"(mass {w['mass_kg']:.4g} kg, COM shift "
                         f"{', '.join(f'{1000 * v:.1f}' for v in w['com_shift_m'])} mm)")
    verdict = report.get("verdict")
    if verdict is not None:
        lines.append(f"verdict: {verdict['status'].upper()}: {verdict['message']}")
    lines.append("PASSED" if report["passed"] else f"FAILED: {report.get('message', '')}")
    return "\n".join(lines)


def _write_csv(path: Path, series: dict, force: bool) -> None:
    from reedtool.io.fileio import atomic_write_text, is_stdout, write_stdout

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    keys = list(series)
    writer.writerow(keys)
    for row in zip(*(series[k] for k in keys)):
        writer.writerow([f"{float(v):.9g}" for v in row])
    if is_stdout(path):
        write_stdout(buffer.getvalue())
    else:
        atomic_write_text(path, buffer.getvalue(), force=force)


def _num(value, spec: str) -> str:
    return format(value, spec) if value is not None and math.isfinite(value) else "n/a".rjust(
        int(spec.split(".")[0]))


def _pct(value) -> str:
    return f"{100 * value:.1f}%" if value is not None and math.isfinite(value) else "n/a"


def _finite(value):
    """JSON has no NaN or infinity: those become null (e.g. the speeds of an invalid trim)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
