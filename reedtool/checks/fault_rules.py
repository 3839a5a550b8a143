"""Fault-tolerance rules (R350-R359): what a single rotor failure leaves of the control.

The analysis is `physics.authority` (the ACAI of Du et al. 2015); `reedtool authority`
prints the whole table. These rules only point at a design choice the model file makes
and could make better.
"""

from __future__ import annotations

from typing import Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.checks.rotor_rules import _lift, _physics_ready

# Below this many rotors no spin order survives a failure with full control (a quadrotor
# never does; the paper's results start at six).
MIN_ROTORS = 6
# The search tries every order with the same count of cw and ccw rotors: C(8, 4) = 70 orders
# of 8 failures each at most, a few milliseconds. Larger frames are left to `authority`.
MAX_ROTORS = 8


def _spin_name(sign: int) -> str:
    return "ccw" if sign > 0 else "cw"


@rule("R350", "spin-order-not-fault-tolerant", "info",
      "No single rotor failure is survivable with this spin order, but another order would "
      "survive some.")
def spin_order_not_fault_tolerant(ctx: CheckContext) -> Iterator[Issue]:
    """With the usual alternating spins (ccw, cw, ccw, ...) a hexacopter loses full control
    after any single rotor failure: five rotors remain and the allocation keeps full rank,
    yet the hover point sits on the boundary of what they can produce (ACAI = 0; Du, Quan,
    Yang and Cai 2015). The same rotors with another spin order (the paper's PPNNPN) keep
    full control for four of the six failures. The choice is made in the model file, one
    `turningDirection` per motor.

    Reported as information on vehicles with six to eight lift rotors when every single
    failure is uncontrollable with the spins as written but some order of the same number
    of cw and ccw rotors survives at least one, naming the best such order (most
    survivable failures). `reedtool authority MODEL` prints the full table. The autopilot's
    mixer must know the spins too: change both or neither.
    """
    from reedtool.physics.authority import acai, full_rank, spin_orders, survivable_failures

    if not _physics_ready(ctx) or ctx.omnidirectional:
        return
    rotors = _lift(ctx)
    if not MIN_ROTORS <= len(rotors) <= MAX_ROTORS:
        return
    B = ctx.allocation
    K_N = np.array([r.max_thrust_N for r in rotors], dtype=float)
    weight_N = ctx.whole_robot.mass_kg * 9.80665
    if not (full_rank(B) and acai(B, K_N, np.array([weight_N, 0.0, 0.0, 0.0])) > 0):
        return                                       # intact not controllable: R307 and co.
    signs = [r.turning_sign for r in rotors]
    # Each rotor's drag reaction per unit of turning sign (the only thing a spin changes).
    reaction = np.array([-r.moment_constant * r.axis / np.linalg.norm(r.axis)
                         for r in rotors]).T

    def B_of(order):
        changed = B.copy()
        changed[1:] += reaction * (np.asarray(order) - np.asarray(signs))
        return changed

    if survivable_failures(B_of, K_N, weight_N, signs) > 0:
        return
    best_order, best = None, 0
    for order in spin_orders(signs):
        count = survivable_failures(B_of, K_N, weight_N, order)
        if count > best:
            best_order, best = order, count
    if best_order is None:
        return
    numbered = sorted(range(len(rotors)), key=lambda i: (rotors[i].motor_number is None,
                                                         rotors[i].motor_number, i))
    written = ", ".join(f"{rotors[i].name} {_spin_name(signs[i])}" for i in numbered)
    better = ", ".join(f"{rotors[i].name} {_spin_name(best_order[i])}" for i in numbered)
    first = rotors[numbered[0]]
    yield Issue(f"with the spins as written ({written}) no single rotor failure leaves full "
                f"control; {better} keeps it for {best} of {len(rotors)} failures",
                first.loc, first.name,
                hint="`reedtool authority MODEL` shows every case; change the autopilot's "
                     "mixer with the turningDirection values")
