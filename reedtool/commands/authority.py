"""`reedtool authority`: the rotors' control authority, intact and after each rotor failure.

A static analysis of the model (no simulation): the Available Control Authority Index of
Du et al. (2015) for the intact vehicle and for every single rotor failure, whether each
case stays controllable with yaw and without it, and the thrust-to-weight ratio that would
make it so. `hover-test --fail-rotor` flies a failure; this command says which ones to fly.
"""

from __future__ import annotations

import json
from pathlib import Path

import click

from reedtool.commands.params import FiniteFloatRange, model_option
from reedtool.errors import ReedtoolError

SCHEMA = "reedtool.authority/1"
# --require: which cases must be controllable for exit 0.
POLICIES = {
    "none": "nothing (always exit 0 on a readable model)",
    "intact": "the intact vehicle",
    "any-single": "the intact vehicle and every single rotor failure, with yaw",
    "any-single-without-yaw": "the intact vehicle, and every single failure at least with "
                              "yaw given up",
}


def policy_met(report, policy: str) -> bool:
    if policy == "none":
        return True
    if not report.intact.controllable:
        return False
    if policy == "any-single":
        return all(case.controllable for case in report.failures)
    if policy == "any-single-without-yaw":
        return all(case.controllable_without_yaw for case in report.failures)
    return True


def _ratio(value: float | None) -> str:
    return "none" if value is None else f"{value:.2f}"


def format_text(model: Path, report, policy: str) -> str:
    intact = report.intact
    lines = [f"authority {model}: {len(report.thrust_max_N)} lift rotors, mass "
             f"{report.mass_kg:.4g} kg, thrust-to-weight {report.thrust_to_weight:.2f}",
             f"intact: ACAI {intact.acai:.4f} ({'controllable' if intact.controllable else 'NOT controllable'})",
             ""]
    label = "stopped" if report.failures and report.failures[0].efficiency == 0 else \
        f"at {report.failures[0].efficiency:.0%}" if report.failures else ""
    lines.append(f"  {'rotor':<16} {'number':>6}  {'ACAI':>8}  {'with yaw':<12} "
                 f"{'ACAI no yaw':>11}  {'without yaw':<12} {'needs T/W':>9}")
    for case in report.failures:
        lines.append(
            f"  {case.failed_name:<16} {'-' if case.failed_number is None else case.failed_number:>6}  "
            f"{case.acai:8.4f}  {'controllable' if case.controllable else 'lost':<12} "
            f"{case.acai_without_yaw:11.4f}  "
            f"{'controllable' if case.controllable_without_yaw else 'lost':<12} "
            f"{_ratio(case.min_thrust_to_weight):>9}")
    survivable = len(report.survivable())
    without_yaw = sum(case.controllable_without_yaw for case in report.failures)
    lines += ["", f"one rotor {label}: {survivable} of {len(report.failures)} failures keep full "
                  f"control; {without_yaw} keep hover with yaw given up",
              f"require {policy} ({POLICIES[policy]}): "
              f"{'met' if policy_met(report, policy) else 'NOT met'}"]
    return "\n".join(lines) + "\n"


def format_json(model: Path, report, policy: str) -> str:
    from reedtool.report.json_format import envelope

    doc = {**envelope(SCHEMA), "model": str(model), "mass_kg": report.mass_kg,
           "weight_N": report.weight_N, "thrust_to_weight": report.thrust_to_weight,
           "thrust_max_N": [float(k) for k in report.thrust_max_N],
           "intact": report.intact.to_dict(),
           "failures": [case.to_dict() for case in report.failures],
           "require": policy, "passed": policy_met(report, policy)}
    return json.dumps(doc, indent=2) + "\n"


@click.command("authority")
@click.argument("model", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("mappings", nargs=-1)
@click.option("--package-path", "package_paths", multiple=True, metavar="DIR",
              type=click.Path(path_type=Path, file_okay=False),
              help="Directory to search for ROS packages first (repeatable).")
@model_option
@click.option("--efficiency", type=FiniteFloatRange(0.0, 1.0, max_open=True), default=0.0,
              show_default=True,
              help="What each failing rotor keeps of its thrust: 0 is a stopped rotor, "
                   "0.5 a damaged one.")
@click.option("--require", "policy", type=click.Choice(list(POLICIES)), default="intact",
              show_default=True, help="Which cases must stay controllable for exit 0.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
def command(model: Path, mappings: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, efficiency: float, policy: str, fmt: str) -> int:
    """Control authority of MODEL's lift rotors, intact and with each one failed.

    Exit 0 when the --require policy is met, 1 when it is not, 2 on unreadable input.
    """
    from reedtool.checks.preflight import require_sound_model
    from reedtool.io.loader import load_robot
    from reedtool.io.mappings import parse_mappings
    from reedtool.physics.authority import analyse_rotors
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, lift_rotors

    robot = load_robot(model, parse_mappings(mappings), list(package_paths),
                       model_name=model_name)
    require_sound_model(robot)
    rotors = lift_rotors(discover_rotors(robot))
    if len(rotors) < 2:
        raise ReedtoolError(f"the model has {len(rotors)} lift rotor(s); control authority "
                            "needs a multirotor", file=model,
                            hint="`reedtool validate` lists the rotors it found")
    for rotor in rotors:
        if not (rotor.max_thrust_N > 0 and rotor.max_thrust_N < float("inf")):
            raise ReedtoolError(f"rotor {rotor.name}: no usable maximum thrust (motorConstant "
                                f"{rotor.motor_constant:g}, maxRotVelocity "
                                f"{rotor.max_rot_velocity_rad_s:g})", file=rotor.loc.file,
                                line=rotor.loc.line, hint="`reedtool validate` names the value")
    props = whole_robot_pinocchio(robot)
    if not props.mass_kg > 0:
        raise ReedtoolError("the model has no mass", file=model,
                            hint="`reedtool validate` shows the links' <inertial>")
    report = analyse_rotors(rotors, props.mass_kg, props.com_m, efficiency)
    render = format_json if fmt == "json" else format_text
    click.echo(render(model, report, policy), nl=False)
    return 0 if policy_met(report, policy) else 1
