"""RotorS Lee controller rules (C450-C454): the gains and vehicle parameters RotorS'
`lee_position_controller_node` reads, against the model they will fly.

The controller files come from `hover-test --controller` and `validate --controller`
(reedtool.flightstack.rotors_lee, reedtool.flightstack.controller_tables). The rotor
table itself (count, angles, directions, constants, mass, inertia within tolerance) is
C401-C411's; these rules catch what makes the Lee controller itself fail: a gain of the
wrong sign, a loop the 100 Hz controller and the motors cannot hold (a unit slip in a
gain), a loop that rings, and a vehicle mass or inertia in another unit.

Physics (sim/lee_rotors.py has the equations): RotorS divides the attitude and rate gains
by the YAML inertia and multiplies the angular acceleration by it again, so about one axis
the torque is -k_R theta - k_w theta' and the loop is J theta'' = -k_R theta - k_w theta'
with the true J; the thrust is m_yaml g - k_x z - k_v z', so m x'' = -k_x x - k_v x'.
"""

from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule

# RotorS' basic.world steps at 100 Hz and the node commands once per odometry message.
CONTROL_PERIOD_S = 0.01
# A gain this many times the Firefly's scaled to the vehicle (or this fraction of it) is
# named as a likely unit slip: tuned gains stay within a factor of a few of it (the
# rotors_gazebo vehicles' gains, scaled to their own inertia, span 0.3x-3x the Firefly's).
UNIT_SLIP_FACTOR = 30.0
# A vehicle mass or inertia moment 10x off the model's is no estimate error; these are
# the unit factors an inertia is then named after (ratio within 30 % of one).
INERTIA_UNITS = {1e3: "g*m^2", 1e4: "kg*cm^2", 1e6: "kg*mm^2", 1e7: "g*cm^2", 1e9: "g*mm^2"}
AXES = "xyz"


def _lee_tables(ctx: CheckContext) -> list:
    if not ctx.tree_ok:
        return []
    return [t for t in ctx.controller_tables if getattr(t, "lee_gains", None) is not None]


def _flyable_inertia(ctx: CheckContext) -> np.ndarray | None:
    """The whole robot's inertia (kg*m^2) where the loops can be judged on it: mass and
    finite, positive principal moments; else None (other rules report why)."""
    whole = ctx.whole_robot
    J = np.asarray(whole.inertia_kg_m2, dtype=float)
    if whole.mass_kg <= 0 or not np.all(np.isfinite(J)) or np.any(np.diag(J) <= 0):
        return None
    return J


def _motor_lag_s(ctx: CheckContext) -> float:
    """The slowest rotor's mean of its spin-up and spin-down time constants (the torque
    lags the speed command about hover with that time constant, linearised)."""
    lags = [0.5 * (r.time_constant_up_s + r.time_constant_down_s) for r in ctx.lift_rotors
            if math.isfinite(r.time_constant_up_s) and math.isfinite(r.time_constant_down_s)]
    return max(lags) if lags else 0.0


@rule("C450", "lee-gain-not-positive", "error",
      "A RotorS Lee controller gain is zero or negative.", clause="cannot-fly")
def lee_gain_not_positive(ctx: CheckContext) -> Iterator[Issue]:
    """RotorS' Lee controller applies -k o error for every gain (position, velocity,
    attitude, angular rate): a negative gain pushes the vehicle further from where it
    should be, so it flips (attitude, rate) or runs away (position, velocity) on take-off;
    a zero gain leaves that axis without a spring or damper.

    Severity (error, cannot-fly): the loop is unstable or undamped.
    """
    for table in _lee_tables(ctx):
        gains = table.lee_gains
        for key in ("position_gain", "velocity_gain", "attitude_gain", "angular_rate_gain"):
            for i, axis in enumerate(AXES):
                value = float(gains.gain(key)[i])
                if value > 0.0:
                    continue
                what = ("pushes the vehicle further from the setpoint" if value < 0
                        else "leaves that axis without feedback")
                yield Issue(f"{key}/{axis} is {value:g}: the RotorS Lee controller applies "
                            f"-{key.replace('_gain', '')} gain x error, so this {what}; "
                            "the vehicle flips or drifts away on take-off",
                            gains.loc_of(key, axis), f"{key}/{axis}",
                            hint=f"a positive gain (the RotorS Firefly uses "
                                 f"{_firefly(key, i)}); a sign flipped for another axis "
                                 "convention is not needed: RotorS uses the body frame FLU")


def _firefly(key: str, i: int) -> str:
    from reedtool.flightstack.rotors_lee import FIREFLY_GAINS

    return f"{FIREFLY_GAINS[key][i]:g}"


@rule("C451", "lee-loop-unstable", "error",
      "A RotorS Lee controller loop is unstable at 100 Hz with the model's motors.",
      clause="cannot-fly")
def lee_loop_unstable(ctx: CheckContext) -> Iterator[Issue]:
    """About each body axis the attitude and angular-rate gains make the loop
    J theta'' = -k_R theta - k_w theta' (RotorS normalises by the YAML inertia and
    multiplies by it again), with J the model's principal moment; the position and
    velocity gains make m x'' = -k_x x - k_v x'. The node computes its command once per
    odometry message, 100 Hz in RotorS' worlds, and holds it; the motors follow with
    their time constants. The rule discretises each loop exactly (zero-order hold, the
    motor lag as a first-order lag of the torque) and reports a loop whose sampled
    closed loop has a pole outside the unit circle: a gain too large for 100 Hz, most
    often a unit slip (it names the factor against the Firefly's gains scaled to this
    vehicle).

    Severity (error, cannot-fly): the controller oscillates with growing amplitude.
    """
    whole = ctx.whole_robot
    J = _flyable_inertia(ctx)
    if J is None:
        return
    lag_s = _motor_lag_s(ctx)
    for table in _lee_tables(ctx):
        # Here, not at the top: a model without Lee gain files never loads the node's model.
        from reedtool.flightstack.rotors_lee import (
            firefly_scaled,
            largest_stable_scale,
            loop_spectral_radius,
        )

        gains = table.lee_gains
        loops = [("attitude_gain", "angular_rate_gain", J[i, i], lag_s, i,
                  f"J{AXES[i] * 2} = {J[i, i]:.4g} kg*m^2") for i in range(3)]
        loops += [("position_gain", "velocity_gain", whole.mass_kg, 0.0, i,
                   f"mass {whole.mass_kg:.4g} kg") for i in range(3)]
        for k_key, d_key, inertia, lag, i, plant in loops:
            k, d = float(gains.gain(k_key)[i]), float(gains.gain(d_key)[i])
            if not (k > 0 and d > 0):
                continue          # C450's
            radius = loop_spectral_radius(k, d, inertia, lag, CONTROL_PERIOD_S)
            if radius < 1.0:
                continue
            scale = largest_stable_scale(k, d, inertia, lag, CONTROL_PERIOD_S)
            # The gain furthest from the Firefly gain scaled to this vehicle is the cause
            # named (messages avoid apostrophes: quoted names are shortened).
            ratios = [(value / firefly_scaled(key, i, whole.mass_kg, J), key, value)
                      for key, value in ((k_key, k), (d_key, d))]
            ratio, key, value = max(ratios, key=lambda r: abs(math.log(r[0])))
            usual = value / ratio
            slip = (f"{key}/{AXES[i]} {value:g} is {ratio:.0f}x the Firefly gain scaled to "
                    f"this vehicle ({usual:.3g}): a unit slip? "
                    if ratio >= UNIT_SLIP_FACTOR else "")
            lagged = f" with motor lag {lag:.3g} s" if lag > 0 else ""
            loop_name = "attitude" if k_key == "attitude_gain" else "position"
            yield Issue(
                f"{loop_name} loop about {AXES[i]} unstable at the {1 / CONTROL_PERIOD_S:g} Hz "
                f"of RotorS worlds{lagged}: {slip}{k_key}/{AXES[i]} {k:g} and "
                f"{d_key}/{AXES[i]} {d:g} on {plant} give a sampled pole of magnitude "
                f"{radius:.3g} (> 1); stable only up to {scale:.3g}x these gains",
                gains.loc_of(key if slip else k_key, AXES[i]), f"{k_key}/{AXES[i]}",
                hint=f"set {k_key}/{AXES[i]}: "
                     f"{firefly_scaled(k_key, i, whole.mass_kg, J):.3g} and {d_key}/{AXES[i]}: "
                     f"{firefly_scaled(d_key, i, whole.mass_kg, J):.3g} (the Firefly gains "
                     "scaled to this vehicle) and tune from there")


def _unit_named(ratio: float, units: dict[float, str]) -> str | None:
    for factor, name in units.items():
        if 0.7 <= ratio / factor <= 1.0 / 0.7:
            return name
    return None


@rule("C452", "lee-mass-unit-slip", "error",
      "A RotorS vehicle file's mass is 10x or more off the model's.", clause="cannot-fly")
def lee_mass_unit_slip(ctx: CheckContext) -> Iterator[Issue]:
    """RotorS' Lee controller feeds forward the hover thrust m g with the vehicle file's
    `mass` and has no integral term: with the mass 10x off, the thrust it commands at the
    setpoint is 10x off the weight, and the vehicle climbs away at full throttle or never
    leaves the ground. C409 reports smaller differences (an altitude offset of
    (m_model - m_file) g / k_z).

    Severity (error, cannot-fly): the controller cannot hold the vehicle's weight.
    """
    if not ctx.tree_ok:
        return
    whole = ctx.whole_robot.mass_kg
    for table in ctx.controller_tables:
        if table.source != "yaml" or table.mass_kg is None or not math.isfinite(table.mass_kg):
            continue
        if whole <= 0 or table.mass_kg <= 0:
            continue
        ratio = table.mass_kg / whole
        if 0.1 < ratio < 10.0:
            continue
        unit = _unit_named(ratio, {1e3: "grams written as kg", 1e-3: "the file in kg, the "
                                   "model in grams"})
        yield Issue(f"{table.label}: mass {table.mass_kg:.6g} kg is {ratio:.3g}x the "
                    f"{whole:.6g} kg of the model '{ctx.robot.name}'; the hover thrust the Lee "
                    f"controller feeds forward, {table.mass_kg * 9.81:.4g} N, is that far off "
                    "the weight"
                    + (f" ({unit}?)" if unit else ""), table.loc_of("mass"), ctx.robot.name,
                    hint=f"set mass: {whole:.6g} (kg, the whole vehicle)")


@rule("C453", "lee-inertia-unit-slip", "warning",
      "A RotorS vehicle file's inertia is 10x or more off the model's.", clause="suspicious")
def lee_inertia_unit_slip(ctx: CheckContext) -> Iterator[Issue]:
    """RotorS' controllers read `inertia` in kg*m^2. A moment 10x or more off the model's
    is another unit (g*cm^2 is 10^7 kg*m^2, kg*mm^2 10^6) or another vehicle's file.
    RotorS' Lee and roll-pitch-yawrate controllers divide the attitude gains by this
    inertia and multiply the angular acceleration by it again, so a uniform factor
    cancels and their flight is unchanged (hover-test --controller flies the same); the
    numbers are still wrong for anything else that reads the file.

    Severity (warning, suspicious): the file is wrong, but RotorS' controllers fly the
    same with it.
    """
    if not ctx.tree_ok:
        return
    I_m = np.asarray(ctx.whole_robot.inertia_kg_m2, dtype=float)
    for table in ctx.controller_tables:
        I_c = table.inertia_kg_m2
        if table.source != "yaml" or I_c is None or not np.all(np.isfinite(I_c)):
            continue
        ratios = [I_c[i, i] / I_m[i, i] for i in range(3) if I_m[i, i] > 0 and I_c[i, i] > 0]
        off = [r for r in ratios if not 0.1 < r < 10.0]
        if not off:
            continue
        ratio = float(np.exp(np.mean(np.log(off))))
        unit = _unit_named(ratio, INERTIA_UNITS)
        yield Issue(f"{table.label}: inertia is {ratio:.3g}x the whole-robot inertia about "
                    f"the COM of the model '{ctx.robot.name}'"
                    + (f": {unit} written where kg*m^2 is read?" if unit else "")
                    + "; the RotorS Lee controller flies the same (the factor cancels), anything "
                      "else reading the file does not", table.loc_of("inertia"),
                    ctx.robot.name,
                    hint="write the inertia in kg*m^2 (`reedtool inertia` prints the model's)")


# A loop damped below this rings: its step response overshoots by more than 37 %
# (exp(-pi 0.3 / sqrt(1 - 0.09))) and each swing is at least 0.15 of the one before.
MIN_DAMPING = 0.3


@rule("C454", "lee-loop-underdamped", "warning",
      "A RotorS Lee controller loop is damped below 0.3 on the model.", clause="suspicious")
def lee_loop_underdamped(ctx: CheckContext) -> Iterator[Issue]:
    """With the gains as forces and torques per unit error (RotorS' normalisation), each
    loop on the model is second order: damping k_w / (2 sqrt(k_R J)) about each body axis
    and k_v / (2 sqrt(k_x m)) per position axis, with the model's principal moment J and
    mass m. Below 0.3 a disturbance rings: more than 37 % overshoot, settling in
    4 / (zeta w_n). RotorS' compiled-in yaw gains (0.035, 0.025) give the Firefly 0.21.

    Severity (warning, suspicious): it flies, but it rings; hover-test --controller shows
    how long it takes to settle.
    """
    whole = ctx.whole_robot
    J = _flyable_inertia(ctx)
    if J is None:
        return
    for table in _lee_tables(ctx):
        gains = table.lee_gains
        for k_key, d_key, inertia, plant in (
                *(("attitude_gain", "angular_rate_gain", J[i, i], i) for i in range(3)),
                *(("position_gain", "velocity_gain", whole.mass_kg, i) for i in range(3))):
            i = plant
            k, d = float(gains.gain(k_key)[i]), float(gains.gain(d_key)[i])
            if not (k > 0 and d > 0):
                continue
            zeta = d / (2.0 * math.sqrt(k * inertia))
            wn = math.sqrt(k / inertia)
            if zeta >= MIN_DAMPING:
                continue
            want = 2.0 * 0.7 * math.sqrt(k * inertia)
            yield Issue(f"{d_key}/{AXES[i]} {d:g} with {k_key}/{AXES[i]} {k:g} damps the loop "
                        f"about {AXES[i]} at {zeta:.2g} on this model (natural frequency "
                        f"{wn:.3g} rad/s): it rings, settling in about {4 / (zeta * wn):.3g} s",
                        gains.loc_of(d_key, AXES[i]), f"{d_key}/{AXES[i]}",
                        hint=f"{d_key}/{AXES[i]}: {want:.3g} gives damping 0.7")
