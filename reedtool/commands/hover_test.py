"""`reedtool hover-test`: static trim, then a headless closed-loop hover, then (optionally)
a robustness batch of perturbed vehicles.

Exit 0 when the model hovers (and the batch meets --min-pass-rate), 1 when it does not
(no trim, or the simulation ends in anything but `passed`), 2 on unreadable input.
"""

from __future__ import annotations

import contextlib
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

SPREAD_HELP = "Half-width of the uniform perturbation"
# A COM shifted by a metre is another vehicle, not a perturbation of this one.
MAX_COM_SPREAD_M = 1.0


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
              help="Simulator engine: numpy (no compiler needed) or numba (compiled, all cores; "
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
    from reedtool.workflows.hover_test import HoverTestOptions, plan_hover_test, run_hover_test

    note_model_files(inputs)          # the model is never an output of its own run
    plan = plan_hover_test(HoverTestOptions(
        duration_s=duration_s, rate_hz=rate_hz, offset_m=tuple(offset_m), roll_rad=roll_rad,
        pitch_rad=pitch_rad, yaw_rad=yaw_rad, plot_path=plot_path, replay_path=replay_path,
        csv_path=csv_path, force=force, samples=samples, max_memory_mb=max_memory_mb,
        seed=seed, spreads=(mass_spread, com_spread_m, inertia_spread, motor_spread),
        engine=engine, min_pass_rate=min_pass_rate, require=require,
        controller_files=controller_files, controller_rate_hz=controller_rate_hz,
        ignore_validation=ignore_validation))
    model, request = one_model_request("hover-test", inputs, package_paths, model_name,
                                       launch_file, ignore)
    result = run_hover_test(model, request, plan,
                            progress=TerminalProgress() if fmt == "text" else None,
                            on_validation=_show_validation(model, fmt, ignore_validation))
    from reedtool.report.hover_text import render_json, render_text

    if fmt == "json":
        click.echo(render_json(result))
    elif not result.refused:     # a refusal's text is validate's errors, already shown
        click.echo(render_text(result.document))
    return 0 if result.passed else 1


def _show_validation(model: Path, fmt: str, ignore_validation: bool):
    """validate's errors, shown in the text report before the flight."""
    def show(verdict, refused: bool) -> None:
        if fmt == "text":
            from reedtool.report.validation_note import validation_text

            click.echo(validation_text(str(model), verdict.refusing, verdict.reported, refused,
                                       "flying it", ignore_validation), nl=False)
    return show


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
