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

from reedtool.workflows.flight import Progress
from reedtool.workflows.vehicle import DEFAULT_MAX_MEMORY_MB
from reedtool.commands.params import (
    FiniteFloatRange,
    model_inputs,
    note_model_files,
    one_model_request,
    validation_options,
)
from reedtool.errors import ReedtoolError
from reedtool.io.json_values import finite_tree

SPREAD_HELP = "Half-width of the uniform perturbation"
# A COM shifted by a metre is another vehicle, not a perturbation of this one.
MAX_COM_SPREAD_M = 1.0
# 10^7 fixed steps is 10,000 s at 1 kHz, far beyond any hover test; more is a typo
# (`--duration 1e9`) that would keep the machine busy for days.
MAX_STEPS = 10_000_000
SCHEMA = "reedtool.hover-test/1"
DEFAULT_DURATION_S = 10.0


# A run longer than this on a terminal shows that it is still working.
PROGRESS_AFTER_S = 2.0


@click.command(name="hover-test")
@model_inputs()
@click.option("--duration", "duration_s", type=float, default=None,
              help="Simulated time [s]. Default 10 s, longer when the vehicle's tuned "
                   "position loop needs more to settle (the text and JSON say how long).")
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
@click.option("--replay", "replay_path", type=click.Path(path_type=Path, dir_okay=False),
              default=None, help="Write the flight as an HTML page that plays it back "
              "(offline, any browser): pose, rotor speeds as colour, settle band.")
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
@click.option("--engine", type=click.Choice(["auto", "numpy", "numba"]), default="auto",
              show_default=True,
              help="Simulator engine: numpy (the reference) or numba (compiled, all cores; "
                   "needs numba: pip install numba); auto: numba for a --samples batch "
                   "when it is installed, numpy for one vehicle (faster as a whole).")
@click.option("--min-pass-rate", type=FiniteFloatRange(0.0, 1.0), default=0.95,
              show_default=True, help="Batch pass rate needed to exit 0.")
@click.option("--require", "require", default="flies", show_default=True,
              metavar="flies|hover|stable|margin:DEG",
              help="What exit 0 needs: the verdict flies (flies); or only a hover trim "
                   "(hover); a vehicle some controller can stabilise (stable); recovery "
                   "from a start tilted DEG degrees (margin:DEG). A verdict other than "
                   "flies is then ACCEPTED, never PASSED.")
@click.option("--controller", "controller_files", multiple=True,
              type=click.Path(path_type=Path, dir_okay=False), metavar="FILE.yaml",
              help="Fly RotorS' Lee position controller with these files instead of "
                   "reedtool's controller: the gains (lee_controller_NAME.yaml) and the "
                   "vehicle parameters (NAME.yaml; found beside the gains when not given). "
                   "Repeatable. numpy engine only.")
@click.option("--controller-rate", "controller_rate_hz", type=float, default=100.0,
              show_default=True, help="Rate of the --controller node [Hz] (RotorS' worlds "
                                      "step at 100 Hz; the node runs once per odometry "
                                      "message).")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None,
            duration_s: float, rate_hz: float, offset_m: tuple[float, float, float],
            roll_rad: float, pitch_rad: float, yaw_rad: float, plot_path: Path | None,
            replay_path: Path | None,
            csv_path: Path | None, force: bool, fmt: str, samples: int | None,
            max_memory_mb: int, seed: int,
            mass_spread: float, com_spread_m: float, inertia_spread: float,
            motor_spread: float, engine: str, min_pass_rate: float,
            require: str = "flies", controller_files: tuple[Path, ...] = (),
            controller_rate_hz: float = 100.0,
            ignore: tuple[str, ...] = (), ignore_validation: bool = False) -> int:
    """Trim MODEL for hover and fly it.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.

    Starts from a disturbance (default 0.5 m off the setpoint, rolled 0.2 rad) and passes
    when it settles within 5 cm and 2 deg and stays there. validate's rules run first: a
    model with a structure, mass or rotor error (the flight would be another vehicle's) is
    not flown (exit 1) unless --ignore CODE or --ignore-validation is given; other errors
    are listed and the model flown.
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
    auto_duration = duration_s is None
    duration_s = DEFAULT_DURATION_S if auto_duration else duration_s
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
    if controller_files:
        check_plausible("rate", controller_rate_hz, "--controller-rate")
        if controller_rate_hz > rate_hz:
            raise ReedtoolError(f"bad option: --controller-rate {controller_rate_hz:g} Hz is "
                                f"faster than the simulation's --rate {rate_hz:g} Hz",
                                hint="keep --controller-rate at or below --rate")
        for option, given in (("--samples", samples is not None),
                              ("--engine numba", engine == "numba")):
            if given:
                raise ReedtoolError(f"bad option: {option} with --controller: the Lee "
                                    "controller flies one vehicle on the numpy engine",
                                    hint=f"drop {option}, or drop --controller to fly "
                                         "reedtool's own controller")
    from reedtool.sim import choose_engine

    engine = choose_engine(engine, batch=samples is not None and not controller_files)
    if engine == "numba":
        from reedtool.sim.compiled import available, unavailable_reason

        if not available():
            raise ReedtoolError(f"bad option: --engine numba: {unavailable_reason()}",
                                hint="or use --engine numpy")
    from reedtool.io.fileio import check_writable, note_input

    note_model_files(inputs)          # the model is never an output of its own run
    for path in controller_files:
        note_input(path)
    if plot_path is not None:   # fail before flying, not after
        check_writable(plot_path, force)
    if replay_path is not None:
        if replay_path.suffix.lower() != ".html":
            raise ReedtoolError(f"--replay writes an HTML page, not '{replay_path.suffix or replay_path.name}'",
                                file=replay_path, hint="name the --replay file .html")
        check_writable(replay_path, force)
    if csv_path is not None:
        check_writable(csv_path, force, stdout_ok=True)
    # What the path is comes first (a FIFO is refused as such), then its format.
    if plot_path is not None and plot_path.suffix.lower() not in (".png", ".svg"):
        raise ReedtoolError(f"cannot tell the plot format from '{plot_path.suffix or plot_path.name}'",
                            file=plot_path, hint="name the --plot file .png or .svg")
    model, request = one_model_request("hover-test", inputs, package_paths, model_name,
                                       launch_file, ignore)
    note_input(model)

    from reedtool.workflows.assemble import assemble

    # A model or batch too large for the machine is refused before any rule runs on it.
    assembled = assemble(model, request, "hover-test", samples=samples,
                         max_memory_bytes=max_memory_mb * 1024 * 1024)
    robot, verdict = assembled.robot, assembled.verdict
    every_rotor = assembled.vehicle.every_rotor
    refused = bool(verdict.refusing) and not ignore_validation
    if refused:
        # Bad input (exit 2) comes before what validate finds (exit 1): unreadable rotor
        # parameters.
        from reedtool.sim.params import check_rotor_dynamics

        # ArduPilotPlugin rotors carry no time constants: hover_test derives them from
        # the joint's velocity PID (or refuses with the reason) only when it flies.
        check_rotor_dynamics([r for r in every_rotor if r.kind != "ardupilot"])
    from reedtool.report.validation_note import validation_json, validation_text, why_line

    if fmt == "text":
        click.echo(validation_text(str(model), verdict.refusing, verdict.reported, refused,
                                   "flying it", ignore_validation), nl=False)
    if refused:
        if fmt == "json":
            from reedtool.report.json_format import envelope

            click.echo(json.dumps({**envelope(SCHEMA), "model": {"file": str(model)},
                                   "validation": validation_json(verdict.refusing,
                                                                 verdict.reported, True),
                                   "passed": False, "status": "refused",
                                   "message": why_line(verdict.refusing, verdict.reported,
                                                       True, "flying it")}, indent=2))
        return 1
    from reedtool.workflows.flight import hover_test

    report = hover_test(robot, config, samples=samples, seed=seed,
                        spreads=(mass_spread, com_spread_m, inertia_spread, motor_spread),
                        record=bool(plot_path or csv_path or replay_path),
                        progress=TerminalProgress() if fmt == "text" else None,
                        engine=engine, envelope=plot_path is not None,
                        max_memory_bytes=max_memory_mb * 1024 * 1024,
                        vehicle=assembled.vehicle, requirement=requirement,
                        auto_duration=auto_duration, controller_files=controller_files,
                        control_rate_hz=controller_rate_hz)
    batch = report.get("batch")
    if batch is not None:
        batch["min_pass_rate"] = min_pass_rate
        if report["passed"] and batch["pass_rate"] < min_pass_rate:
            report["passed"] = False
            report["message"] = (f"only {100 * batch['pass_rate']:.1f}% of the perturbed "
                                 f"vehicles hover, {100 * min_pass_rate:.0f}% required")

    from reedtool.sim.verdict import outcome

    report["outcome"] = outcome(report.get("status", ""), report["passed"])
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

    if run is not None and replay_path is not None:
        from reedtool.workflows.flight import replay_page
        from reedtool.io.fileio import atomic_write_text

        atomic_write_text(replay_path, replay_page(assembled.vehicle, run, config,
                                                   robot.name, f"verdict: {report['status']}: "
                                                   f"{report['message']}"),
                          force=force)

    if fmt == "json":
        from reedtool.report.json_format import envelope

        document = {**envelope(SCHEMA), **report,
                    "validation": validation_json(verdict.refusing, verdict.reported, False)}
        click.echo(json.dumps(finite_tree(document), indent=2, allow_nan=False))
    else:
        click.echo(render_text(report))
    return 0 if report["passed"] else 1


class TerminalProgress(Progress):
    """Progress on stderr: a bar for a batch, elapsed seconds for a long flight."""

    def flying(self, label: str):
        return _still_working(label, True)

    @contextlib.contextmanager
    def steps(self, label: str, n_steps: int):
        with click.progressbar(length=n_steps, file=sys.stderr, label=label) as bar:
            yield bar.update


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
            # A saturated rotor shows what it can give, and what the allocation asked.
            limit = {"max": "  at max, needs {:.4g} N", "min": "  at 0, needs {:.4g} N"
                     }.get(r.get("limit") or "", "").format(r.get("demand_N"))
            lines.append(f"  {r['name']:<{width}}  {_num(r['thrust_N'], '9.4f')}  "
                         f"{_num(r['omega_rad_s'], '11.2f')}  {_pct(r['throttle']):>8}{limit}")
    if trim["feasible"]:
        a = trim["torque_authority_N_m"]
        authority = ("" if not all(math.isfinite(v) for v in a.values()) else
                     f"; torque authority at hover: roll {a['roll']:.3g}, "
                     f"pitch {a['pitch']:.3g}, yaw {a['yaw']:.3g} N*m")
        lines.append(f"  thrust-to-weight {trim['thrust_to_weight']:.3f}{authority}")
    if report.get("controller") is not None:
        from reedtool.report.lee_text import controller_lines

        lines += controller_lines(report["controller"])
    if sim is not None:
        from reedtool.sim.verdict import tuning_line

        c = sim["config"]
        if sim["gains"].get("controller") != "rotors-lee":
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
                     f"+-{100 * s['motor_constant_rel']:g}%; seed {batch['seed']}"
                     + (f"; from {batch['start_scale']:.3g} of the start (the recoverable margin)"
                        if batch.get("start_scale", 1.0) != 1.0 else ""))
        for w in batch["worst"]:
            lines.append(f"  #{w['index']}: {w['status']}: {w['message']} "
                         f"(mass {w['mass_kg']:.4g} kg, COM shift "
                         f"{', '.join(f'{1000 * v:.1f}' for v in w['com_shift_m'])} mm)")
    verdict = report.get("verdict")
    if verdict is not None:
        lines.append(f"verdict: {verdict['status'].upper()}: {verdict['message']}")
    from reedtool.sim.verdict import final_line

    lines.append(final_line(report.get("status", ""), report["passed"],
                            report.get("require", "flies"), report.get("message", "")))
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
