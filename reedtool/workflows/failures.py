"""A vehicle's control authority about hover: the ACAI intact and after each single rotor
failure (or degradation), and, on request, each failure flown closed-loop.
See docs/fault-tolerance.md.
"""

from __future__ import annotations

from reedtool.io.json_values import finite_or_none


def analyse(rotors, mass_kg: float, com_m, efficiency=None, degrade: float = 0.0) -> dict:
    """The JSON-ready report: the intact case and one entry per single-rotor failure (or,
    with `degrade` > 0, per rotor left with that fraction of its thrust)."""
    import numpy as np

    from reedtool.physics.allocation import allocation_matrix
    from reedtool.physics.authority import failure_cases
    from reedtool.physics.trim import STANDARD_GRAVITY_M_S2

    B = allocation_matrix(rotors, np.asarray(com_m, dtype=float))
    K = np.array([r.max_thrust_N for r in rotors], dtype=float)
    eta = np.ones(len(rotors)) if efficiency is None else np.asarray(efficiency, dtype=float)
    weight_N = mass_kg * STANDARD_GRAVITY_M_S2
    # The designer's thrust-to-weight: every rotor healthy, at full speed, along body z.
    thrust_to_weight = float(B[0] @ K) / weight_N

    def entry(a) -> dict:
        return {"acai": float(a.acai), "rank": a.rank, "controllable": a.controllable,
                "acai_without_yaw": float(a.acai_without_yaw),
                "controllable_without_yaw": a.controllable_without_yaw,
                "min_thrust_to_weight": finite_or_none(a.min_thrust_scale * thrust_to_weight),
                "min_thrust_to_weight_without_yaw":
                    finite_or_none(a.min_thrust_scale_without_yaw * thrust_to_weight)}

    intact, failed = failure_cases(B, K, weight_N, eta, failed_efficiency=degrade)
    failures = []
    for i, (rotor, a) in enumerate(zip(rotors, failed)):
        failures.append({"rotor": rotor.name, "index": i, "motor_number": rotor.motor_number,
                         "direction": rotor.direction, **entry(a)})
    return {"mass_kg": mass_kg, "weight_N": weight_N, "thrust_to_weight": thrust_to_weight,
            "efficiency": {r.name: float(e) for r, e in zip(rotors, eta)},
            "failed_rotor_efficiency": degrade,
            "intact": entry(intact), "failures": failures}


def fly_failures(rotors, props, report: dict, *, fail_at_s: float = 1.0,
                 duration_s: float = 6.0, record: bool = False):
    """Fly every single failure of `report` (from `analyse`), adding each one's "flight";
    the controller keeps yaw only where the analysis says it can.

    Returns (the first failure flight that does not hold, else the first; the vehicle
    parameters; the HoverConfig flown), for a plot.
    """
    from reedtool.sim import HoverConfig
    from reedtool.sim.failure import FailureSchedule, simulate_rotor_failure
    from reedtool.sim.params import VehicleParams, check_rotor_dynamics

    check_rotor_dynamics(rotors)
    params = VehicleParams.from_rotors(props.mass_kg, props.com_m, props.inertia_kg_m2, rotors)
    config = HoverConfig(duration_s=duration_s)
    chosen = None
    for f in report["failures"]:
        yaw = f["controllable"] or not f["controllable_without_yaw"]
        run = simulate_rotor_failure(params, FailureSchedule(f["index"], fail_at_s), config,
                                     yaw_controlled=yaw, record=record)
        f["flight"] = {"status": run.status.value, "passed": run.passed,
                       "yaw_controlled": yaw, "message": run.message}
        if chosen is None or (chosen.passed and not run.passed):
            chosen = run
    return chosen, params, config
