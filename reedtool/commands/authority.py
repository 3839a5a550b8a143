"""`reedtool authority`: can this multirotor lose a rotor and still be flown down?

A static analysis (no simulation): the available control authority index (ACAI) of the
intact vehicle and of every single-rotor failure, with and without yaw control, and the
thrust-to-weight at which each failure becomes survivable. See docs/fault-tolerance.md.

Exit 0 when the model meets --require, 1 when it does not, 2 on unreadable input.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import click

from reedtool.commands.params import (
    FiniteFloatRange,
    model_inputs,
    one_model_request,
    validation_options,
)
from reedtool.errors import ReedtoolError

SCHEMA = "reedtool.authority/1"

# --require policies: what must hold for exit 0.
POLICIES = {
    "none": "report only",
    "hover": "the intact vehicle is controllable about hover",
    "any-single": "every single rotor failure leaves full control (thrust, roll, pitch, yaw)",
    "any-single-without-yaw": "every single rotor failure leaves thrust, roll and pitch "
                              "(the vehicle may spin down)",
}


def _efficiency(items: tuple[str, ...], names: list[str]) -> list[float]:
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


def _plot(robot, chosen, params, config, plot_path: Path, force: bool) -> None:
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


def meets(report: dict, policy: str) -> bool:
    failures = report["failures"]
    if policy == "none":
        return True
    if policy == "hover":
        return report["intact"]["controllable"]
    if policy == "any-single":
        return report["intact"]["controllable"] and all(f["controllable"] for f in failures)
    return report["intact"]["controllable"] and all(f["controllable_without_yaw"]
                                                    for f in failures)


def _ttw(value: float | None) -> str:
    return "never" if value is None else f"{value:.3g}"


# The validate rules whose errors explain an intact vehicle that cannot be controlled.
CAUSE_RULES = ("R303", "R304", "R305", "R307", "R308")


def uncontrollable_causes(robot) -> list[dict]:
    """The findings behind "not controllable" (e.g. R304), as validate reports them."""
    from reedtool.checks.runner import Selection, run_checks

    return [{"code": f.code, "slug": f.slug, "message": f.message}
            for f in run_checks(robot, Selection(select=CAUSE_RULES)) if f.severity == "error"]


def _intact_line(intact: dict) -> str:
    need = intact["min_thrust_to_weight"]
    if intact["controllable"]:
        return (f"intact: ACAI {intact['acai']:.4g} (controllable), needs thrust-to-weight > "
                f"{_ttw(need)}")
    if need is None:
        return (f"intact: ACAI {intact['acai']:.4g}: not controllable about hover at any "
                "thrust-to-weight")
    return (f"intact: ACAI {intact['acai']:.4g}: not controllable about hover; it would be "
            f"with thrust-to-weight > {need:.3g}")


def _verdict(report: dict, policy: str) -> str:
    """The --require line: what was required and, when it failed, what is not so."""
    if meets(report, policy):
        return f"PASSED --require {policy}: {POLICIES[policy]}"
    causes = report["intact"].get("causes") or []
    because = f" ({', '.join(c['code'] for c in causes)})" if causes else ""
    if not report["intact"]["controllable"]:
        what = f"the intact vehicle is not controllable about hover{because}"
    else:
        key = "controllable" if policy == "any-single" else "controllable_without_yaw"
        lost = [f["rotor"] for f in report["failures"] if not f[key]]
        what = f"losing {', '.join(lost)} leaves " + (
            "less than full control" if policy == "any-single"
            else "no thrust, roll and pitch control")
    return f"FAILED --require {policy}: {what} (required: {POLICIES[policy]})"


def render_text(name: str, report: dict, policy: str) -> str:
    intact = report["intact"]
    lines = [(f"authority {name}: {len(report['failures'])} rotors, mass "
              f"{report['mass_kg']:.4g} kg, thrust-to-weight {report['thrust_to_weight']:.3g}"),
             _intact_line(intact)]
    for cause in intact.get("causes") or ():
        lines.append(f"  because {cause['code']} ({cause['slug']}): {cause['message']}")
    degraded = {k: v for k, v in report["efficiency"].items() if v != 1.0}
    if degraded:
        lines.append("efficiency: " + ", ".join(f"{k} {v:g}" for k, v in degraded.items()))
    if report["failed_rotor_efficiency"] > 0:
        lines.append(f"each case below: that rotor keeps {report['failed_rotor_efficiency']:g} "
                     "of its thrust (--degrade) instead of stopping")
    rows = [("#", "failed rotor", "dir", "ACAI", "full control", "ACAI no yaw",
             "no yaw", "min T/W", "min T/W no yaw")]
    for f in report["failures"]:
        number = "-" if f["motor_number"] is None else str(f["motor_number"])
        rows.append((number, f["rotor"], f["direction"], f"{f['acai']:.4g}",
                     "yes" if f["controllable"] else "no", f"{f['acai_without_yaw']:.4g}",
                     "yes" if f["controllable_without_yaw"] else "no",
                     _ttw(f["min_thrust_to_weight"]), _ttw(f["min_thrust_to_weight_without_yaw"])))
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    for r in rows:
        lines.append("  " + "  ".join(cell.ljust(w) if c < 3 else cell.rjust(w)
                                      for c, (cell, w) in enumerate(zip(r, widths))).rstrip())
    for f in report["failures"]:
        if "flight" in f:
            mode = "" if f["flight"]["yaw_controlled"] else " (yaw dropped)"
            lines.append(f"  flight{mode}: {f['flight']['status'].upper()}: {f['flight']['message']}")
    full = sum(f["controllable"] for f in report["failures"])
    no_yaw = sum(f["controllable_without_yaw"] for f in report["failures"])
    lines.append(f"single failures: {full}/{len(report['failures'])} keep full control, "
                 f"{no_yaw}/{len(report['failures'])} keep thrust, roll and pitch "
                 f"(ACAI in mixed units: N and N*m)")
    lines.append(_verdict(report, policy))
    return "\n".join(lines)


@click.command(name="authority")
@model_inputs()
@click.option("--efficiency", "efficiency_items", multiple=True, metavar="ROTOR=ETA",
              help="Degrade a rotor: its maximum thrust times ETA in [0, 1] (repeatable).")
@click.option("--degrade", "degrade", type=FiniteFloatRange(0.0, 1.0, max_open=True),
              default=0.0, show_default=True, metavar="ETA",
              help="Each case leaves its rotor ETA of its thrust instead of stopping it "
                   "(0: a failure; 0.5: a damaged propeller).")
@click.option("--require", "policy", type=click.Choice(list(POLICIES)), default="hover",
              show_default=True, help="What must hold for exit 0.")
@click.option("--fly", is_flag=True,
              help="Also fly each failure closed-loop: hover, lose the rotor at --fail-at, "
                   "fly on until --duration.")
@click.option("--fail-at", "fail_at_s", type=FiniteFloatRange(0.0, 600.0), default=1.0,
              show_default=True, metavar="S", help="With --fly: when the rotor stops [s].")
@click.option("--duration", "duration_s", type=FiniteFloatRange(0.5, 600.0), default=6.0,
              show_default=True, metavar="S", help="With --fly: length of each flight [s].")
@click.option("--plot", "plot_path", type=click.Path(path_type=Path, dir_okay=False),
              help="With --fly: the first failure flight that does not hold (else the first) "
                   "as .png or .svg, the failure time marked.")
@click.option("--force", is_flag=True, help="Overwrite an existing --plot file.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, efficiency_items: tuple[str, ...], degrade: float,
            policy: str, fly: bool,
            fail_at_s: float, duration_s: float, plot_path: Path | None, force: bool,
            fmt: str, ignore: tuple[str, ...] = (), ignore_validation: bool = False) -> int:
    """Control authority of MODEL about hover, intact and after each single rotor failure.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file with motor
    plugins, or a directory, glob or ROS package holding one such model; NAME:=VALUE words
    are its xacro arguments. validate's rules run first: a structure, mass or rotor error
    refuses the model (exit 1) unless --ignore CODE or --ignore-validation is given; other
    errors are listed beside the analysis.
    """
    model, request = one_model_request("authority", inputs, package_paths, model_name,
                                       launch_file, ignore)
    from reedtool.sim import HoverConfig

    hold_s = HoverConfig().hold_s
    if fly and degrade > 0:
        raise ReedtoolError("--fly stops the rotor; --degrade applies to the table only",
                            hint="run the table with --degrade and the flights without it")
    if fly and fail_at_s >= duration_s - hold_s:
        raise ReedtoolError(f"--fail-at {fail_at_s:g} s leaves less than the {hold_s:g} s hold "
                            f"time before --duration {duration_s:g} s",
                            hint=f"fail earlier or fly longer (--duration above "
                                 f"{fail_at_s + hold_s:g})")
    if plot_path is not None and not fly:
        raise ReedtoolError("--plot needs --fly", hint="add --fly to fly the failures")
    if plot_path is not None:          # refused before anything is flown
        from reedtool.io.fileio import check_writable

        check_writable(plot_path, force)
        if plot_path.suffix.lower() not in (".png", ".svg"):
            raise ReedtoolError(f"cannot tell the plot format from '{plot_path.name}'",
                                file=plot_path, hint="name the --plot file .png or .svg")
    from reedtool.workflows.assemble import assemble
    from reedtool.report.validation_note import validation_json, validation_text, why_line

    assembled = assemble(model, request, "authority")
    robot, vehicle, verdict = assembled.robot, assembled.vehicle, assembled.verdict
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
    refused = bool(verdict.refusing) and not ignore_validation
    if fmt == "text":
        click.echo(validation_text(str(model), verdict.refusing, verdict.reported, refused,
                                   "analysing it", ignore_validation), nl=False)
    if refused:
        if fmt == "json":
            from reedtool.report.json_format import envelope

            click.echo(json.dumps({**envelope(SCHEMA), "model": robot.name, "require": policy,
                                   "passed": False, "status": "refused",
                                   "message": why_line(verdict.refusing, verdict.reported,
                                                       True, "analysing it"),
                                   "validation": validation_json(verdict.refusing,
                                                                 verdict.reported, True)},
                                  indent=2))
        return 1
    bad = [r.name for r in rotors
           if not (math.isfinite(r.max_thrust_N) and r.max_thrust_N > 0 and r.turning_sign != 0
                   and all(math.isfinite(v) for v in r.position_m)
                   and math.isfinite(r.moment_constant))]
    if bad:
        raise ReedtoolError(f"rotor(s) {', '.join(bad)} lack a position, a turning direction "
                            f"or usable constants", file=model,
                            hint="`reedtool validate MODEL` names the problem")
    props = vehicle.props
    if not props.mass_kg > 0:
        raise ReedtoolError("the robot has no mass", file=model,
                            hint="run `reedtool inertia` on the model")
    from reedtool.workflows.failures import analyse, fly_failures

    report = analyse(rotors, props.mass_kg, props.com_m,
                     _efficiency(efficiency_items, [r.name for r in rotors]), degrade)
    if not report["intact"]["controllable"]:
        report["intact"]["causes"] = uncontrollable_causes(robot)
    if fly:
        chosen, params, config = fly_failures(rotors, props, report, fail_at_s=fail_at_s,
                                              duration_s=duration_s,
                                              record=plot_path is not None)
        if plot_path is not None and chosen is not None:
            _plot(robot, chosen, params, config, plot_path, force)
    report = {"model": robot.name, "require": policy, "passed": meets(report, policy), **report,
              "validation": validation_json(verdict.refusing, verdict.reported, False)}
    if fmt == "json":
        from reedtool.report.json_format import envelope

        click.echo(json.dumps({**envelope(SCHEMA), **report}, indent=2, allow_nan=False))
    else:
        click.echo(render_text(robot.name, report, policy))
    return 0 if report["passed"] else 1
