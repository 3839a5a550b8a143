"""Fault-tolerance rules (R350-R359): what the spin order means for losing a rotor.

The control authority after a rotor failure comes from reedtool.physics.authority (ACAI,
Du et al. 2015); this module only compares spin orders of the same rotors.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.checks.rotor_rules import all_rotors, physics_ready
from reedtool.physics.allocation import allocation_matrix
from reedtool.physics.trim import STANDARD_GRAVITY_M_S2

# Fewer rotors cannot survive a failure with full control whatever the spin order
# (a quad keeps 3 rotors for 4 axes); more make the search (n choose n/2 orders) slow.
MIN_ROTORS = 6
MAX_ROTORS_SEARCHED = 8


def _survivors(rotors, com_m, sign_rows, weight_N) -> list[tuple[int, float]]:
    """Per spin order (a row of signs): (number of single failures that keep full
    control, their worst ACAI)."""
    # Only a vehicle of MIN_ROTORS or more gets here; validate of a quad does not load it.
    from reedtool.physics.authority import full_control_after_failures_many

    Bs = _allocations_with_signs(rotors, com_m, np.atleast_2d(sign_rows))
    K = np.array([r.max_thrust_N for r in rotors])
    out = []
    for acai in full_control_after_failures_many(Bs, K, weight_N):
        ok = acai[~np.isnan(acai)]
        out.append((len(ok), float(ok.min()) if len(ok) else -math.inf))
    return out


def _allocations_with_signs(rotors, com_m, sign_rows) -> np.ndarray:
    """(orders, 4, n): the allocation of each spin order of the same rotors."""
    B = allocation_matrix(rotors, com_m)
    # Only the drag term depends on the spin: flip it where the sign differs.
    axis = np.array([r.axis / np.linalg.norm(r.axis) for r in rotors])
    km = np.array([r.moment_constant for r in rotors])
    old = np.array([r.turning_sign for r in rotors], dtype=float)
    Bs = np.repeat(B[None], len(sign_rows), axis=0)
    Bs[:, 1:] += ((old[None] - np.asarray(sign_rows, dtype=float)) * km)[:, None, :] \
        * axis.T[None]
    return Bs


def _order(rotors, signs) -> str:
    return ", ".join(f"{r.name} {'ccw' if s > 0 else 'cw'}" for r, s in zip(rotors, signs))


@rule("R350", "spin-order-not-fault-tolerant", "info",
      "No single rotor failure leaves full control, but another spin order would.", clause="explains")
def spin_order_not_fault_tolerant(ctx: CheckContext) -> Iterator[Issue]:
    """A multirotor with six or more rotors has spare actuators, yet with the common
    alternating spin order (ccw, cw, ccw, ...) of a hexacopter, losing any one rotor
    leaves a vehicle that cannot hold thrust, roll, pitch and yaw at once: the hover
    point lands on the boundary of what the five others can produce (Du, Quan, Yang &
    Cai 2015, arXiv 1403.5986). It can still be flown down spinning (see
    `reedtool authority`), and PX4 and ArduPilot use this order, so it is only
    information.

    Another assignment of the same rotors (same positions, as many ccw and cw) can keep
    full control after some failures (the paper's PPNNPN hexacopter keeps it after four
    of six). The finding names the best such order found by trying every balanced
    assignment (up to eight rotors), ranked by how many failures it survives and then by
    its worst ACAI. Changing the spin order means changing the propellers and the
    flight stack's mixer together.

    Severity (info, explains): a spin order is a choice; it says which one would survive
    a motor failure.
    """
    rotors = all_rotors(ctx)
    if not MIN_ROTORS <= len(rotors) <= MAX_ROTORS_SEARCHED or not physics_ready(ctx):
        return
    if not all(r.max_thrust_N > 0 for r in rotors):
        return
    whole = ctx.whole_robot
    weight_N = whole.mass_kg * STANDARD_GRAVITY_M_S2
    com_m = np.asarray(whole.com_m, dtype=float)
    signs = np.array([r.turning_sign for r in rotors], dtype=float)
    (survived, _), = _survivors(rotors, com_m, signs, weight_N)
    if survived > 0:
        return
    n_ccw = int(np.sum(signs > 0))
    orders = []
    for ccw in itertools.combinations(range(len(rotors)), n_ccw):
        candidate = -np.ones(len(rotors))
        candidate[list(ccw)] = 1.0
        orders.append(candidate)
    best = None
    for score, candidate in zip(_survivors(rotors, com_m, np.array(orders), weight_N), orders):
        if score[0] > 0 and (best is None or score > best[0]):
            best = (score, candidate)
    if best is None:
        return
    (count, worst_acai), order = best
    where = rotors[0].plugin.param_loc("turningDirection")
    yield Issue(f"no single rotor failure leaves full control (thrust, roll, pitch and yaw) "
                f"with this spin order; the same rotors spun as {_order(rotors, order)} keep "
                f"it after {count} of {len(rotors)} failures (worst ACAI {worst_acai:.3g})",
                where, rotors[0].name,
                hint="run `reedtool authority MODEL` for the table; a spin-order change must "
                     "be mirrored in the propellers and the flight stack's mixer")
