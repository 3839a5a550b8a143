"""`hover-test` as one call: the options checked (before the model is read), the model
assembled and judged by validate's refusal policy, flown (workflows.flight), the batch's
pass rate held to --min-pass-rate, and the plot, CSV and replay page written. The caller
formats the report (report.hover_text, JSON); nothing here prints.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from reedtool.errors import ReedtoolError
from reedtool.workflows.flight import Progress
from reedtool.workflows.robots import ModelRequest
from reedtool.workflows.vehicle import DEFAULT_MAX_MEMORY_MB

DEFAULT_DURATION_S = 10.0
# 10^7 fixed steps is 10,000 s at 1 kHz, far beyond any hover test; more is a typo
# (`--duration 1e9`) that would keep the machine busy for days.
MAX_STEPS = 10_000_000


@dataclass
class HoverTestOptions:
    """What the command line asks of one `hover-test` run (duration None: automatic)."""

    duration_s: float | None = None
    rate_hz: float = 1000.0
    offset_m: tuple[float, float, float] = (0.5, 0.0, 0.0)
    roll_rad: float = 0.2
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    plot_path: Path | None = None
    replay_path: Path | None = None
    csv_path: Path | None = None
    force: bool = False
    samples: int | None = None
    max_memory_mb: int = DEFAULT_MAX_MEMORY_MB
    seed: int = 0
    spreads: tuple[float, float, float, float] = (0.10, 0.01, 0.10, 0.05)
    engine: str = "auto"
    min_pass_rate: float = 0.95
    require: str = "flies"
    controller_files: tuple[Path, ...] = ()
    controller_rate_hz: float = 100.0
    ignore_validation: bool = False


@dataclass
class HoverPlan:
    """The options checked: what is flown, with which engine, judged against what."""

    options: HoverTestOptions
    config: object                  # sim.HoverConfig
    requirement: object             # sim.verdict.Requirement
    engine: str                     # "numpy" or "numba"
    auto_duration: bool


@dataclass
class HoverTestReport:
    """One run's outcome: `document` is the JSON report (without the envelope). A refused
    model has status "refused" there and was not flown."""

    document: dict
    refused: bool = False

    @property
    def passed(self) -> bool:
        return bool(self.document["passed"])


def _check_flight(options: HoverTestOptions, duration_s: float):
    from reedtool.errors import check_plausible
    from reedtool.sim import HoverConfig

    check_plausible("rate", options.rate_hz, "--rate")
    check_plausible("duration", duration_s, "--duration")
    for axis, value in zip("xyz", options.offset_m):
        check_plausible("offset", value, f"--offset {axis}", magnitude=True)
    for option, value in (("--roll", options.roll_rad), ("--pitch", options.pitch_rad),
                          ("--yaw", options.yaw_rad)):
        check_plausible("angle", value, option, magnitude=True)
    config = HoverConfig(duration_s=duration_s, rate_hz=options.rate_hz,
                         offset_m=tuple(options.offset_m), roll_rad=options.roll_rad,
                         pitch_rad=options.pitch_rad, yaw_rad=options.yaw_rad)
    try:
        config.validate()
    except ValueError as exc:
        raise ReedtoolError(f"bad option: {exc}", hint="see reedtool hover-test --help") from exc
    steps = duration_s * options.rate_hz
    if steps > MAX_STEPS:
        raise ReedtoolError(f"bad option: --duration {duration_s:g} s at --rate "
                            f"{options.rate_hz:g} Hz is {steps:.3g} steps, more than "
                            f"{MAX_STEPS:.0e}",
                            hint="a hover test settles in seconds; the defaults are 10 s at "
                                 "1000 Hz")
    return config


def _check_controller(options: HoverTestOptions) -> None:
    from reedtool.errors import check_plausible

    check_plausible("rate", options.controller_rate_hz, "--controller-rate")
    if options.controller_rate_hz > options.rate_hz:
        raise ReedtoolError(f"bad option: --controller-rate {options.controller_rate_hz:g} Hz "
                            f"is faster than the simulation's --rate {options.rate_hz:g} Hz",
                            hint="keep --controller-rate at or below --rate")
    for option, given in (("--samples", options.samples is not None),
                          ("--engine numba", options.engine == "numba")):
        if given:
            raise ReedtoolError(f"bad option: {option} with --controller: the Lee "
                                "controller flies one vehicle on the numpy engine",
                                hint=f"drop {option}, or drop --controller to fly "
                                     "reedtool's own controller")


def _check_outputs(options: HoverTestOptions) -> None:
    """The controller files are inputs; --plot, --replay and --csv writable, each in a
    format it can be written in (what the path is comes first: a FIFO is refused as such)."""
    from reedtool.io.fileio import check_writable, note_input

    for path in options.controller_files:
        note_input(path)
    plot_path, replay_path, force = options.plot_path, options.replay_path, options.force
    if plot_path is not None:   # fail before flying, not after
        check_writable(plot_path, force)
    if replay_path is not None:
        if replay_path.suffix.lower() != ".html":
            raise ReedtoolError(f"--replay writes an HTML page, not "
                                f"'{replay_path.suffix or replay_path.name}'",
                                file=replay_path, hint="name the --replay file .html")
        check_writable(replay_path, force)
    if options.csv_path is not None:
        check_writable(options.csv_path, force, stdout_ok=True)
    if plot_path is not None and plot_path.suffix.lower() not in (".png", ".svg"):
        raise ReedtoolError(f"cannot tell the plot format from "
                            f"'{plot_path.suffix or plot_path.name}'",
                            file=plot_path, hint="name the --plot file .png or .svg")


def plan_hover_test(options: HoverTestOptions) -> HoverPlan:
    """Every option checked before the model is read (one line, exit 2, on a bad one)."""
    from reedtool.sim import choose_engine
    from reedtool.sim.verdict import Requirement

    try:
        requirement = Requirement.parse(options.require)
    except ValueError as exc:
        raise ReedtoolError(f"bad option: {exc}",
                            hint="e.g. --require stable, or --require margin:10") from exc
    auto_duration = options.duration_s is None
    config = _check_flight(options, DEFAULT_DURATION_S if auto_duration else options.duration_s)
    if options.controller_files:
        _check_controller(options)
    engine = choose_engine(options.engine,
                           batch=options.samples is not None and not options.controller_files,
                           vehicles=options.samples)
    if engine == "numba":
        from reedtool.sim.compiled import available, unavailable_reason

        if not available():
            raise ReedtoolError(f"bad option: --engine numba: {unavailable_reason()}",
                                hint="or use --engine numpy")
    _check_outputs(options)
    return HoverPlan(options, config, requirement, engine, auto_duration)


def hold_pass_rate(report: dict, min_pass_rate: float) -> None:
    """A run passes only when its batch (if flown) meets `min_pass_rate`; the outcome word."""
    from reedtool.sim.verdict import outcome

    batch = report.get("batch")
    if batch is not None:
        batch["min_pass_rate"] = min_pass_rate
        if report["passed"] and batch["pass_rate"] < min_pass_rate:
            report["passed"] = False
            report["message"] = (f"only {100 * batch['pass_rate']:.1f}% of the perturbed "
                                 f"vehicles hover, {100 * min_pass_rate:.0f}% required")
    report["outcome"] = outcome(report.get("status", ""), report["passed"])


def write_outputs(plan: HoverPlan, report: dict, run, omega_max, envelope, assembled) -> None:
    """The recorded flight as --csv, --plot and --replay ask."""
    from reedtool.io.fileio import atomic_write_bytes, atomic_write_text, is_stdout, write_stdout
    from reedtool.report.hover_text import series_csv

    options, robot, batch = plan.options, assembled.robot, report.get("batch")
    if options.csv_path is not None:
        text = series_csv(run.series)
        if is_stdout(options.csv_path):
            write_stdout(text)
        else:
            atomic_write_text(options.csv_path, text, force=options.force)
    if options.plot_path is not None:
        from reedtool.sim.plot import failure_marks, render

        figure = render(run.series, omega_max, run.initial_omega_rad_s,
                        f"{robot.name}: {run.status.value}"
                        + (f" ({batch['passed']}/{batch['samples']} of the batch passed)"
                           if batch is not None else ""),
                        fmt=options.plot_path.suffix.lower()[1:],
                        position_tol_m=plan.config.position_tol_m,
                        attitude_tol_deg=plan.config.attitude_tol_deg,
                        settle_time_s=run.settle_time_s, failures=failure_marks(run),
                        envelope=envelope)
        atomic_write_bytes(options.plot_path, figure, force=options.force)
    if options.replay_path is not None:
        from reedtool.workflows.flight import replay_page

        atomic_write_text(options.replay_path,
                          replay_page(assembled.vehicle, run, plan.config, robot.name,
                                      f"verdict: {report['status']}: {report['message']}"),
                          force=options.force)


def _refused(model: Path, verdict) -> HoverTestReport:
    from reedtool.report.validation_note import validation_json, why_line

    return HoverTestReport({"model": {"file": str(model)},
                            "validation": validation_json(verdict.refusing, verdict.reported,
                                                          True),
                            "passed": False, "status": "refused",
                            "message": why_line(verdict.refusing, verdict.reported, True,
                                                "flying it")}, refused=True)


def run_hover_test(model: Path, request: ModelRequest, plan: HoverPlan, *,
                   progress: Progress | None = None,
                   on_validation: Callable[[object, bool], None] | None = None
                   ) -> HoverTestReport:
    """The whole `hover-test` run on one model. `on_validation(verdict, refused)` is called
    once validate's errors are judged, before anything is flown (for the caller to show
    them first); a refused model returns at once."""
    from reedtool.io.fileio import note_input
    from reedtool.report.validation_note import validation_json
    from reedtool.workflows.assemble import assemble
    from reedtool.workflows.flight import hover_test

    options = plan.options
    note_input(model)
    max_memory_bytes = options.max_memory_mb * 1024 * 1024
    # A model or batch too large for the machine is refused before any rule runs on it.
    assembled = assemble(model, request, "hover-test", samples=options.samples,
                         max_memory_bytes=max_memory_bytes)
    verdict = assembled.verdict
    refused = bool(verdict.refusing) and not options.ignore_validation
    if refused:
        # Bad input (exit 2) comes before what validate finds (exit 1): unreadable rotor
        # parameters.
        from reedtool.sim.params import check_rotor_dynamics

        # ArduPilotPlugin rotors carry no time constants: hover_test derives them from
        # the joint's velocity PID (or refuses with the reason) only when it flies.
        check_rotor_dynamics([r for r in assembled.vehicle.every_rotor
                              if r.kind != "ardupilot"])
    if on_validation is not None:
        on_validation(verdict, refused)
    if refused:
        return _refused(model, verdict)
    report = hover_test(assembled.robot, plan.config, samples=options.samples,
                        seed=options.seed, spreads=options.spreads,
                        record=bool(options.plot_path or options.csv_path
                                    or options.replay_path),
                        progress=progress, engine=plan.engine,
                        envelope=options.plot_path is not None,
                        max_memory_bytes=max_memory_bytes, vehicle=assembled.vehicle,
                        requirement=plan.requirement, auto_duration=plan.auto_duration,
                        controller_files=options.controller_files,
                        control_rate_hz=options.controller_rate_hz)
    hold_pass_rate(report, options.min_pass_rate)
    run, omega_max = report.pop("_run", None), report.pop("_omega_max")
    envelope = report.pop("_envelope", None)
    if run is not None:
        write_outputs(plan, report, run, omega_max, envelope, assembled)
    return HoverTestReport({**report, "validation": validation_json(verdict.refusing,
                                                                    verdict.reported, False)})
