"""`authority` as one call: the options checked, the model assembled and judged by
validate's refusal policy, its lift rotors' ACAI intact and per single failure
(workflows.failures), each failure flown on request and the chosen flight drawn, and
whether the result meets `--require`. The caller formats the report (report.authority_text,
JSON); nothing here prints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from reedtool.errors import ReedtoolError
from reedtool.workflows.robots import ModelRequest

# --require policies: what must hold for exit 0.
POLICIES = {
    "none": "report only",
    "hover": "the intact vehicle is controllable about hover",
    "any-single": "every single rotor failure leaves full control (thrust, roll, pitch, yaw)",
    "any-single-without-yaw": "every single rotor failure leaves thrust, roll and pitch "
                              "(the vehicle may spin down)",
}
# The validate rules whose errors explain an intact vehicle that cannot be controlled.
CAUSE_RULES = ("R303", "R304", "R305", "R307", "R308")


@dataclass
class AuthorityOptions:
    """What the command line asks of one `authority` run."""

    efficiency_items: tuple[str, ...] = ()
    degrade: float = 0.0
    policy: str = "hover"
    fly: bool = False
    fail_at_s: float = 1.0
    duration_s: float = 6.0
    plot_path: Path | None = None
    force: bool = False
    ignore_validation: bool = False


@dataclass
class AuthorityReport:
    """One run's outcome: `document` is the JSON report (without the envelope); a refused
    model has status "refused" there and no analysis."""

    name: str                       # the robot's name
    policy: str
    document: dict
    refused: bool = False
    policy_text: str = field(init=False)

    def __post_init__(self) -> None:
        self.policy_text = POLICIES[self.policy]

    @property
    def passed(self) -> bool:
        return bool(self.document["passed"])


def parse_efficiency(items: tuple[str, ...], names: list[str]) -> list[float]:
    """--efficiency ROTOR=ETA items -> one ETA per rotor (1.0 where none is given)."""
    eta = [1.0] * len(names)
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or name not in names:
            raise ReedtoolError(f"bad --efficiency '{item}': expected ROTOR=ETA with ROTOR one "
                                f"of {', '.join(names)}", hint="e.g. --efficiency rotor_0=0.5")
        try:
            eta_i = float(value)
        except ValueError:
            eta_i = math.nan
        if not 0.0 <= eta_i <= 1.0:
            raise ReedtoolError(f"bad --efficiency '{item}': ETA must be a number in [0, 1]",
                                hint="1 is a healthy rotor, 0 a failed one")
        eta[names.index(name)] = eta_i
    return eta


def meets(report: dict, policy: str) -> bool:
    """Does the analysis (workflows.failures.analyse) hold what `policy` requires?"""
    failures = report["failures"]
    if policy == "none":
        return True
    if policy == "hover":
        return report["intact"]["controllable"]
    if policy == "any-single":
        return report["intact"]["controllable"] and all(f["controllable"] for f in failures)
    return report["intact"]["controllable"] and all(f["controllable_without_yaw"]
                                                    for f in failures)


def uncontrollable_causes(robot) -> list[dict]:
    """The findings behind "not controllable" (e.g. R304), as validate reports them."""
    from reedtool.checks.runner import Selection, run_checks

    return [{"code": f.code, "slug": f.slug, "message": f.message}
            for f in run_checks(robot, Selection(select=CAUSE_RULES)) if f.severity == "error"]


def check_options(options: AuthorityOptions) -> None:
    """Refuse contradictory options and an unwritable --plot before anything is loaded."""
    from reedtool.sim import HoverConfig

    hold_s = HoverConfig().hold_s
    if options.fly and options.degrade > 0:
        raise ReedtoolError("--fly stops the rotor; --degrade applies to the table only",
                            hint="run the table with --degrade and the flights without it")
    if options.fly and options.fail_at_s >= options.duration_s - hold_s:
        raise ReedtoolError(f"--fail-at {options.fail_at_s:g} s leaves less than the "
                            f"{hold_s:g} s hold time before --duration {options.duration_s:g} s",
                            hint=f"fail earlier or fly longer (--duration above "
                                 f"{options.fail_at_s + hold_s:g})")
    plot_path = options.plot_path
    if plot_path is not None and not options.fly:
        raise ReedtoolError("--plot needs --fly", hint="add --fly to fly the failures")
    if plot_path is not None:          # refused before anything is flown
        from reedtool.io.fileio import check_writable

        check_writable(plot_path, options.force)
        if plot_path.suffix.lower() not in (".png", ".svg"):
            raise ReedtoolError(f"cannot tell the plot format from '{plot_path.name}'",
                                file=plot_path, hint="name the --plot file .png or .svg")


def check_vehicle(model: Path, robot, vehicle) -> None:
    """A vehicle the ACAI says something about: lift rotors that push one way, usable
    constants and a mass (one line, exit 2, otherwise)."""
    # A VTOL's pusher or a plane's puller holds no hover: the lift rotors are analysed.
    rotors = vehicle.rotors
    if len(rotors) < 1 and vehicle.every_rotor:
        # A fixed-wing: motors exist, none lifts ("no motor plugins" would be untrue).
        raise ReedtoolError(f"{vehicle.trim.message}: no hover to analyse", file=model,
                            hint="authority analyses the lift rotors of a multirotor or VTOL")
    if len(rotors) < 1:
        raise ReedtoolError("no motor plugins found: nothing to analyse", file=model,
                            hint="authority needs RotorS, PX4 or gz-sim motor plugins")
    if vehicle.omnidirectional:
        # The ACAI here is the 4-D zonotope of rotors that push one way along body z: on
        # reversible or many-direction rotors it reports a hovering frame as uncontrollable.
        raise ReedtoolError(
            f"{robot.name}: an omnidirectional frame (reversible or many-direction rotors); "
            "authority's ACAI assumes rotors that push one way (thrust and three torques), "
            "which does not apply to it", file=model,
            hint="`reedtool validate` and `reedtool hover-test` check its 6-DoF hover trim")


def check_rotors(model: Path, vehicle) -> None:
    """Rotors with a position, a turning direction and finite constants, and a mass."""
    bad = [r.name for r in vehicle.rotors
           if not (math.isfinite(r.max_thrust_N) and r.max_thrust_N > 0 and r.turning_sign != 0
                   and all(math.isfinite(v) for v in r.position_m)
                   and math.isfinite(r.moment_constant))]
    if bad:
        raise ReedtoolError(f"rotor(s) {', '.join(bad)} lack a position, a turning direction "
                            f"or usable constants", file=model,
                            hint="`reedtool validate MODEL` names the problem")
    if not vehicle.props.mass_kg > 0:
        raise ReedtoolError("the robot has no mass", file=model,
                            hint="run `reedtool inertia` on the model")


def plot_failure(robot, chosen, params, config, plot_path: Path, force: bool) -> None:
    """The chosen failure flight as a picture, the failure time marked."""
    import numpy as np

    from reedtool.io.fileio import atomic_write_bytes
    from reedtool.sim.plot import render

    keep = [i for i in range(params.n_rotors) if i != chosen.schedule.rotor_index]
    figure = render(chosen.series(), np.asarray(params.omega_max_rad_s)[keep],
                    chosen.after.initial_omega_rad_s,
                    f"{robot.name}: {chosen.status.value}",
                    fmt=plot_path.suffix.lower().lstrip(".") or "png",
                    position_tol_m=config.position_tol_m,
                    attitude_tol_deg=config.attitude_tol_deg,
                    failures=((chosen.schedule.time_s, f"{chosen.rotor_name} fails"),))
    atomic_write_bytes(plot_path, figure, force=force)


def run_authority(model: Path, request: ModelRequest, options: AuthorityOptions,
                  on_validation: Callable[[object, bool], None] | None = None
                  ) -> AuthorityReport:
    """The whole `authority` run on one model. `on_validation(verdict, refused)` is called
    once validate's errors are judged, before any analysis (for the caller to show them
    first); a refused model returns at once."""
    from reedtool.report.validation_note import validation_json, why_line
    from reedtool.workflows.assemble import assemble
    from reedtool.workflows.failures import analyse, fly_failures

    check_options(options)
    assembled = assemble(model, request, "authority")
    robot, vehicle, verdict = assembled.robot, assembled.vehicle, assembled.verdict
    check_vehicle(model, robot, vehicle)
    refused = bool(verdict.refusing) and not options.ignore_validation
    if on_validation is not None:
        on_validation(verdict, refused)
    if refused:
        return AuthorityReport(robot.name, options.policy, {
            "model": robot.name, "require": options.policy, "passed": False,
            "status": "refused",
            "message": why_line(verdict.refusing, verdict.reported, True, "analysing it"),
            "validation": validation_json(verdict.refusing, verdict.reported, True)},
            refused=True)
    check_rotors(model, vehicle)
    rotors, props = vehicle.rotors, vehicle.props
    report = analyse(rotors, props.mass_kg, props.com_m,
                     parse_efficiency(options.efficiency_items, [r.name for r in rotors]),
                     options.degrade)
    if not report["intact"]["controllable"]:
        report["intact"]["causes"] = uncontrollable_causes(robot)
    if options.fly:
        chosen, params, config = fly_failures(rotors, props, report,
                                              fail_at_s=options.fail_at_s,
                                              duration_s=options.duration_s,
                                              record=options.plot_path is not None)
        if options.plot_path is not None and chosen is not None:
            plot_failure(robot, chosen, params, config, options.plot_path, options.force)
    document = {"model": robot.name, "require": options.policy,
                "passed": meets(report, options.policy), **report,
                "validation": validation_json(verdict.refusing, verdict.reported, False)}
    return AuthorityReport(robot.name, options.policy, document)
