"""Closed-loop rotor failure (sim.failure): who stays up, judged by ExitStatus.

The verdicts are cross-checked against the static analysis (physics.authority): a
vehicle the ACAI calls uncontrollable must not pass, one it calls controllable flies.
"""

import numpy as np
import pytest

from reedtool.physics.authority import failure_cases
from reedtool.sim import ExitStatus, HoverConfig
from reedtool.sim.failure import FailureSchedule, simulate_rotor_failure, without_rotor
from reedtool.sim.params import symmetric_multirotor

CONFIG = HoverConfig(duration_s=5.0)


def _static(params):
    return failure_cases(params.allocation(), params.thrust_max_N, params.weight_N)


def test_octocopter_loses_a_rotor_and_stays_within_bounds():
    octo = symmetric_multirotor(8, mass_kg=1.5)
    _, failed = _static(octo)
    assert failed[0].controllable            # what the analysis predicts
    run = simulate_rotor_failure(octo, FailureSchedule(rotor_index=0, time_s=1.0), CONFIG)
    assert run.status is ExitStatus.PASSED, run.message
    # The failed rotor is gone from the flight after t_fail; the others picked up its load.
    assert len(run.after.final_omega_rad_s) == 7
    assert run.series()["t_s"][0] >= 1.0


def test_quadrotor_loses_a_rotor_and_does_not_survive():
    quad = symmetric_multirotor(4, mass_kg=1.5)
    _, failed = _static(quad)
    assert not failed[2].controllable and not failed[2].controllable_without_yaw
    for yaw in (True, False):
        run = simulate_rotor_failure(quad, FailureSchedule(rotor_index=2, time_s=0.5), CONFIG,
                                     yaw_controlled=yaw, record=False)
        assert run.status in (ExitStatus.CRASHED, ExitStatus.DIVERGED), run.message
        assert not run.passed


def test_hexacopter_without_yaw_holds_while_spinning():
    # The alternating hexacopter: no full control after a failure (ACAI 0), but thrust,
    # roll and pitch remain; the yaw-less controller holds position while it spins.
    hexa = symmetric_multirotor(6, mass_kg=1.5)
    _, failed = _static(hexa)
    assert not failed[0].controllable and failed[0].controllable_without_yaw
    full = simulate_rotor_failure(hexa, FailureSchedule(0, 1.0), CONFIG, record=False)
    assert not full.passed, full.message
    spin = simulate_rotor_failure(hexa, FailureSchedule(0, 1.0), CONFIG, yaw_controlled=False)
    assert spin.status is ExitStatus.SPINNING_HOLD, spin.message
    yaw = np.unwrap(spin.series()["yaw_rad"])
    assert abs(yaw[-1] - yaw[0]) > np.pi        # it really turned round


def test_without_rotor_drops_exactly_that_rotor():
    octo = symmetric_multirotor(8)
    reduced = without_rotor(octo, 3)
    assert reduced.n_rotors == 7
    # The same column products recomputed for 7 rotors: identical arithmetic per column
    # (bit-equal in practice); allclose's default (rtol 1e-5) is only a ceiling.
    assert np.allclose(np.delete(octo.allocation(), 3, axis=1), reduced.allocation())
    assert "rotor_3" not in reduced.rotor_names


def test_bad_schedule_is_refused():
    with pytest.raises(ValueError):
        simulate_rotor_failure(symmetric_multirotor(4), FailureSchedule(4, 1.0), CONFIG)
    with pytest.raises(ValueError):
        simulate_rotor_failure(symmetric_multirotor(4), FailureSchedule(0, 4.5), CONFIG)


@pytest.mark.parametrize("n,index,yaw", [(8, 0, True), (4, 2, True), (6, 0, False)])
def test_batch_engine_gives_the_same_verdict_after_a_failure(n, index, yaw):
    from reedtool.sim.batch import simulate_batch
    from reedtool.sim.controller import ControllerDesign
    from reedtool.sim.failure import after_failure

    params = symmetric_multirotor(n, mass_kg=1.5)
    schedule = FailureSchedule(index, 1.0)
    scalar = simulate_rotor_failure(params, schedule, CONFIG, yaw_controlled=yaw, record=False)
    reduced, gains, config, omega0 = after_failure(params, schedule, CONFIG, ControllerDesign(),
                                                   yaw)
    batch = simulate_batch(reduced, config, gains=gains, initial_omega_rad_s=omega0)
    assert batch.status(0) is scalar.after.status
