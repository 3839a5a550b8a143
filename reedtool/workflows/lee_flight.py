"""`hover-test --controller`: the package's own RotorS Lee controller files, checked against
the model and flown on it.

The files are read as RotorS' node reads them (flightstack.rotors_lee), checked against
the model by validate's controller rules (C401-C411: rotor count, order, angles,
directions, constants, mass, inertia; C450-C454: the gains and units), then flown
(sim.lee_rotors) on the model's true mass, inertia and rotors. The verdict is the
flight's (sim.verdict); the test passes only when the controller flies the vehicle and no
rule finds an error in the files.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math

import numpy as np

from reedtool.flightstack.rotors_lee import LeeParameters, load_lee_parameters

# rotors_control parameters.h Rotor(): what a rotor entry's missing value becomes.
ROTORS_ROTOR_DEFAULTS = {"angle_rad": 0.0, "arm_length_m": 0.215,
                         "force_constant": 8.54858e-6, "moment_constant": 1.6e-2,
                         "direction": 1.0}
MAX_AUTO_DURATION_S = 60.0
# An altitude offset the files predict (no integral term) up to this is judged about; a
# larger one is the vehicle failing to hold its setpoint (a quarter of the 2 m setpoint
# height: beyond it the offset is no longer a detail of the files but a lost hover).
MAX_JUDGED_OFFSET_M = 0.5
SETTLE_MARGIN = 1.5


def rotors_lee_of(parameters: LeeParameters):
    """sim.lee_rotors.RotorsLee from the files' values, RotorS' defaults where unset."""
    from reedtool.sim.lee_rotors import RotorsLee

    table, gains = parameters.vehicle, parameters.gains

    def column(attr: str) -> np.ndarray:
        values = [getattr(e, attr) for e in table.rotors]
        return np.array([v if v is not None and math.isfinite(v) else ROTORS_ROTOR_DEFAULTS[attr]
                         for v in values], dtype=float)

    inertia = table.inertia_kg_m2
    if inertia is None or not np.all(np.isfinite(inertia)):
        from reedtool.flightstack.rotors_lee import ROTORS_DEFAULT_INERTIA_KG_M2

        inertia = np.diag(ROTORS_DEFAULT_INERTIA_KG_M2)
    return RotorsLee(position_gain=gains.position_gain, velocity_gain=gains.velocity_gain,
                     attitude_gain=gains.attitude_gain,
                     angular_rate_gain=gains.angular_rate_gain, mass_kg=table.mass_kg,
                     inertia_kg_m2=inertia, angle_rad=column("angle_rad"),
                     arm_length_m=column("arm_length_m"),
                     force_constant=column("force_constant"),
                     moment_constant=column("moment_constant"), direction=column("direction"))


def entry_of_rotor(rotors) -> np.ndarray:
    """The controller entry (motor speed index) each rotor obeys: its motor number when the
    numbers are 0..n-1 (RotorS' motor plugin reads index motorNumber), else its order."""
    numbers = [r.motor_number for r in rotors]
    if None not in numbers and sorted(numbers) == list(range(len(rotors))):
        return np.array(numbers, dtype=int)
    return np.arange(len(rotors))


def preflight(robot, parameters: LeeParameters) -> list:
    """validate's controller rules (C4xx) on the files, the findings located in them."""
    from reedtool.checks.runner import Selection, run_checks

    findings = run_checks(robot, Selection(select=("C4",)), controllers=[parameters.vehicle])
    files = set(parameters.files)
    return [f for f in findings if f.file in files]


def fly_controller(robot, vehicle, flying, config, files, *, control_rate_hz: float,
                   requirement, record: bool = False, auto_duration: bool = False,
                   progress=None) -> dict:
    """Check and fly the package's Lee controller; the report's "controller", "sim",
    "verdict" parts and "_run"."""
    from reedtool.sim import verdict as judge
    from reedtool.sim.lee_rotors import (
        equilibrium_altitude_offset_m,
        loops,
        settle_time_s,
        simulate_lee,
    )

    parameters = load_lee_parameters(files)
    found_static = preflight(robot, parameters)
    lee = rotors_lee_of(parameters)
    params = flying.params
    props = vehicle.props
    entries = entry_of_rotor(flying.rotors)
    # The odometry frame is the base link (RotorS mounts the odometry sensor there); its
    # origin seen from the COM, base axes.
    odometry_from_com_m = -np.asarray(props.com_m, dtype=float)
    loop = loops(lee, params.mass_kg, params.inertia_kg_m2)
    if auto_duration:
        need = SETTLE_MARGIN * settle_time_s(loop) + config.hold_s
        need = min(float(math.ceil(need)) if math.isfinite(need) else MAX_AUTO_DURATION_S,
                   MAX_AUTO_DURATION_S)
        if need > config.duration_s:
            config = dataclasses.replace(config, duration_s=need)

    # No integral term: a file whose mass (or force constants) differ from the model's
    # hovers level at another height than it is sent. Up to MAX_JUDGED_OFFSET_M that is
    # reported (C409, C407 name the cause) and the flight judged about that height; beyond
    # it the flight is judged at the setpoint and fails.
    offset_m = equilibrium_altitude_offset_m(params, lee, entries)
    judged_offset_m = offset_m if math.isfinite(offset_m) and abs(offset_m) <= \
        MAX_JUDGED_OFFSET_M else 0.0

    def fly(start, rec: bool = False):
        return simulate_lee(params, lee, start, entry_of_rotor=entries,
                            odometry_from_com_m=odometry_from_com_m,
                            control_rate_hz=control_rate_hz, record=rec,
                            reference_offset_m=judged_offset_m)

    flying_label = f"flying the Lee controller {config.duration_s:g} s"
    context = (progress.flying(flying_label) if progress is not None
               else contextlib.nullcontext())
    with context:
        run = fly(config, record)
        found = judge.judge_flight(params, config, run, fly, requirement)
    sim = run.to_dict()
    errors = [f for f in found_static if f.severity == "error"]
    controller = {
        "files": parameters.files,
        "notes": parameters.notes,
        "control_rate_hz": control_rate_hz,
        "yaml_mass_kg": lee.mass_kg, "model_mass_kg": params.mass_kg,
        "yaml_inertia_kg_m2": lee.inertia_kg_m2.tolist(),
        "model_inertia_kg_m2": np.asarray(params.inertia_kg_m2).tolist(),
        "predicted_altitude_offset_m": offset_m if math.isfinite(offset_m) else None,
        "judged_about_offset": judged_offset_m != 0.0,
        "entries": len(lee.angle_rad), "rotors": params.n_rotors,
        "loops": loop.to_dict(),
        "preflight": [f.to_dict() for f in found_static],
        "preflight_errors": len(errors),
    }
    passed = found.verdict is judge.Verdict.FLIES and not errors
    if errors:
        first = errors[0]
        message = (f"the controller files have {len(errors)} error(s), first {first.code} "
                   f"({first.file}:{first.line}): {first.message}; the flight: "
                   f"{found.verdict.value}: {found.message}")
    elif not passed:
        message = f"RotorS' Lee controller with these files: {found.verdict.value}: {found.message}"
    else:
        message = found.message
    return {"controller": controller, "sim": sim, "_run": run, "found": found,
            "passed": passed, "message": message, "config": config}

