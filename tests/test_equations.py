"""The flight equations are one source: the generated engines compute what equations.py's
functions compute, bit for bit.

The reference is equations.py itself, run by the Python interpreter on floats, vehicle by
vehicle. The float engine's step (`scalar`) and the numpy batch's (`columns`) are traced
from it; the tracer folds constants and drops terms only where that is exact for finite
values (x * 0, x * 1, x + 0, x - x, a + (-b)), and numpy's and math's +, -, *, / and sqrt
are both IEEE correctly rounded, so the results must be equal, not close. A tracer that
dropped, reordered or re-associated a term would differ in the last bits.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_sim import tilted_hex

from reedtool.sim import HoverConfig, columns, equations, layout
from reedtool.sim.batch import Spreads, perturbed_plant, sample_perturbations
from reedtool.sim.controller import ControllerGains
from reedtool.sim.layout import ERROR, ROTATION, as_constants, state_names
from reedtool.sim.scalar import step_lines
from reedtool.sim.params import symmetric_multirotor

VEHICLES = {"quad": lambda: symmetric_multirotor(4), "tilted-hex": tilted_hex,
            "racing-lead": lambda: symmetric_multirotor(4, time_constant_up_s=0.08,
                                                        time_constant_down_s=0.12)}


def random_states(n_rotors: int, count: int, seed: int) -> np.ndarray:
    """States near a disturbed hover: metres off, tilted, turning (|w| below the series'
    range of equations.cot_ratio, as in flight), rotors around the trim; some saturate."""
    rng = np.random.default_rng(seed)
    x = np.zeros((count, 16 + n_rotors))
    x[:, 0:3] = rng.normal(scale=0.15, size=(count, 3)) + [0.0, 0.0, 2.0]
    x[:, 3:6] = rng.normal(scale=0.2, size=(count, 3))
    q = rng.normal(size=(count, 4)) * [0.0, 0.06, 0.06, 0.004] + [1.0, 0.0, 0.0, 0.0]
    x[:, 6:10] = q / np.linalg.norm(q, axis=1, keepdims=True)
    x[:, 10:13] = rng.normal(scale=[0.5, 0.5, 0.05], size=(count, 3))
    x[:, 13:16] = rng.normal(scale=0.1, size=(count, 3))
    x[:, 16:] = rng.uniform(300.0, 800.0, size=(count, n_rotors))
    return x


def by_the_equations(the, j: int, state: np.ndarray):
    """control_state then advance_state run by the interpreter on floats."""
    n = len(the.thrust_max)
    x = [float(v) for v in state]
    R, e, T = [0.0] * 9, [0.0] * 3, [0.0] * n
    saturated, worst = equations.control_state(as_constants(the.ctl), as_constants(the.pinv),
                                               as_constants(the.thrust_max), as_constants(the.setpoint),
                                               x, R, e, T)
    controlled = (*R, *e, *T, saturated, worst if saturated else 0)
    equations.advance_state(as_constants(the.vehicle(j)), x, T, R, e)
    return controlled, tuple(x)


@pytest.mark.parametrize("name", sorted(VEHICLES))
def test_traced_float_step_is_the_equations_bit_for_bit(name):
    params = VEHICLES[name]()
    gains = ControllerGains.from_params(params)
    config = HoverConfig()
    setpoint = (0.0, 0.0, config.hover_altitude_m)
    namespace: dict = {}
    before, after = step_lines(params, gains, config, setpoint, namespace)
    n = params.n_rotors
    names = state_names(n)
    controlled = [*ROTATION, *ERROR, *(f"T{i}" for i in range(n)), "saturated", "worst"]
    body = "\n".join("    " + line for line in [*before, f"c = ({', '.join(controlled)},)",
                                                 *after, f"return c, ({', '.join(names)},)"])
    exec(f"def step({', '.join(names)}):\n{body}\n", namespace)
    import math
    namespace.update(sqrt=math.sqrt, tan=math.tan)
    the = layout.inputs(params, gains, config, setpoint_m=setpoint)
    states = random_states(n, 200, seed=4)
    saturating = 0
    for state in states:
        got = namespace["step"](*state)
        want = by_the_equations(the, 0, state)
        assert got == want
        saturating += bool(want[0][-2])
    # the states exercise the desaturation as well as the plain allocation
    assert 10 < saturating < 190
    if name == "racing-lead":
        assert gains.has_motor_lead


@pytest.mark.parametrize("name", ["quad", "tilted-hex"])
def test_column_step_is_the_equations_bit_for_bit(name):
    """The numpy batch's step, on perturbed vehicles (mass, inertia, COM, motors per
    column), against each vehicle's equations run alone."""
    params = VEHICLES[name]()
    gains = ControllerGains.from_params(params)
    config = HoverConfig()
    N = 64
    plant = perturbed_plant(params, sample_perturbations(
        N, params.n_rotors, Spreads(mass_rel=0.3, com_m=0.03, inertia_rel=0.2,
                                    motor_constant_rel=0.15), 5))
    control, advance = columns.build(params, gains, config, plant)
    the = layout.inputs(params, gains, config, plant)
    states = random_states(params.n_rotors, N, seed=9)
    rows = list(states.T.copy())
    out = control(*rows)
    n = params.n_rotors
    saturated = out[12 + n]
    worst = out[13 + n]
    new = advance(*rows, *out[12:12 + n], *out[0:9], *out[9:12])
    for j in range(N):
        want_controlled, want_state = by_the_equations(the, j, states[j])
        got_controlled = (*(float(np.broadcast_to(v, (N,))[j]) for v in out[:12 + n]),
                          bool(saturated[j]) if saturated is not None else False,
                          int(worst[j]) if saturated is not None else 0)
        assert got_controlled == want_controlled
        assert tuple(float(np.broadcast_to(v, (N,))[j]) for v in new) == want_state
    assert saturated is not None and 0 < saturated.sum() < N
