"""The compiled engine (reedtool[fast]) against the numpy engines.

Both fly equations.py's functions (compiled.jitted is equations' code compiled; the numpy
engines are traced from it), so the outcome is the same arithmetic; compilers may still
contract or reorder a few operations (LLVM's fused multiply-adds, the block's lanes), so
results are held to test_sim.ENGINE_RTOL relative, derived there from what these flights
make of a few-ulp change of their inputs. Relative to a quantity's scale: a value that settles near 0 (a
position error of 1e-5 m, the difference of two ~2 m coordinates; a crash depth of 2 cm
after a 2 m fall) keeps only the digits the flight left it in either engine, so the
absolute tolerance is ENGINE_RTOL times the largest magnitude of that quantity in the run or
batch.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_sim import ENGINE_RTOL, tilted_hex

from reedtool.sim import STATUS_CODES, ExitStatus, HoverConfig, compiled
from reedtool.sim.batch import Spreads, perturbed_plant, sample_perturbations, simulate_batch
from reedtool.sim.dynamics import Plant
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.run import simulate_hover

pytestmark = pytest.mark.skipif(
    not compiled.available(),
    reason="numba is not installed (pip install '.[fast]'): no compiled engine to test")

RTOL = ENGINE_RTOL   # see test_sim.test_engine_tolerance_stands_far_above_the_ulp_floor
FIELDS = ("status_code", "reason", "reason_value", "end_time_s", "settle_time_s",
          "max_position_error_m", "max_attitude_error_deg", "final_position_error_m",
          "final_attitude_error_deg", "max_throttle", "longest_saturation_s",
          "final_omega_rad_s")


def assert_close(got, ref, name):
    got, ref = np.asarray(got, dtype=float), np.asarray(ref, dtype=float)
    scale = float(np.nanmax(np.abs(ref))) if np.isfinite(ref).any() else 0.0
    # RTOL: test_sim.ENGINE_RTOL, derived from the flights' measured ulp floor.
    np.testing.assert_allclose(got, ref, rtol=RTOL, atol=RTOL * scale, err_msg=name)


def assert_same_outcome(ref, got):
    for name in FIELDS[:-1]:
        assert_close(getattr(got, name), getattr(ref, name), name)
    # Final states only of the vehicles that flew to the end: the numpy batch keeps
    # stepping the ones it parked (their "final" state is the parked hover's, which its
    # docstring calls meaningless); the compiled one reports the park itself.
    flew = np.isin(ref.status_code, [STATUS_CODES[s] for s in (
        ExitStatus.PASSED, ExitStatus.NOT_SETTLED, ExitStatus.SATURATED)])
    assert_close(got.final_omega_rad_s[:, flew], ref.final_omega_rad_s[:, flew],
                 "final_omega_rad_s")
    for name in ("p", "v", "q", "w", "omega"):
        assert_close(getattr(got.final_state, name)[:, flew],
                     getattr(ref.final_state, name)[:, flew], f"final_state.{name}")


@pytest.mark.parametrize("make", [lambda: symmetric_multirotor(4), tilted_hex])
def test_single_vehicle_equals_the_reference(make):
    params = make()
    config = HoverConfig(duration_s=2.5, offset_m=(0.3, -0.2, 0.25), roll_rad=0.15,
                         pitch_rad=-0.1, yaw_rad=0.3)
    ref = simulate_hover(params, config)
    got = simulate_hover(params, config, engine="numba")
    assert (got.engine, ref.engine) == ("numba", "numpy")
    assert got.status is ref.status and got.reason == ref.reason
    for name in ("end_time_s", "settle_time_s", "max_position_error_m",
                 "max_attitude_error_deg", "final_position_error_m",
                 "final_attitude_error_deg", "max_throttle", "longest_saturation_s"):
        assert_close(getattr(got, name), getattr(ref, name), name)
    # Engines: RTOL (test_sim.ENGINE_RTOL, derived from the flights' ulp floor).
    np.testing.assert_allclose(got.final_omega_rad_s, ref.final_omega_rad_s, rtol=RTOL)
    assert got.series.keys() == ref.series.keys()
    for key in ref.series:
        assert_close(got.series[key], ref.series[key], key)


def test_perturbed_batch_equals_the_numpy_batch():
    # Spreads wide enough that some vehicles crash (parked early) and others saturate
    # for a while and recover. (Wider still, some fly at full throttle in a limit cycle
    # through the desaturation's switches, which magnifies rounding to ~1e-6: a property
    # of that flight, not of either engine.)
    # 150 vehicles: two full blocks of the compiled batch and a partial third.
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=3.0)
    assert 2 * compiled.BLOCK < 150 < 3 * compiled.BLOCK
    plant = perturbed_plant(params, sample_perturbations(
        150, 4, Spreads(mass_rel=0.3, com_m=0.03, inertia_rel=0.2, motor_constant_rel=0.15), 3))
    ref = simulate_batch(params, config, plant)
    got = simulate_batch(params, config, plant, engine="numba")
    assert len(set(ref.status_code.tolist())) >= 3        # not all alike
    assert ref.longest_saturation_s.max() > 0.5
    assert_same_outcome(ref, got)


def test_awkward_vehicle_batch_equals_the_numpy_batch():
    params = tilted_hex()
    config = HoverConfig(duration_s=2.0, yaw_rad=0.2)
    plant = perturbed_plant(params, sample_perturbations(16, 6, Spreads(), 5))
    assert_same_outcome(simulate_batch(params, config, plant),
                        simulate_batch(params, config, plant, engine="numba"))


def _one(params, config, change):
    plant = Plant.from_params(params)
    change(plant)
    return (simulate_batch(params, config, plant),
            simulate_batch(params, config, plant, engine="numba"))


@pytest.mark.parametrize("change,status", [
    (lambda plant: setattr(plant, "mass_kg", plant.mass_kg * 3.0), ExitStatus.CRASHED),
    (lambda plant: setattr(plant, "mass_kg", np.array([np.nan])), ExitStatus.DIVERGED),
    (lambda plant: setattr(plant, "torque_map", symmetric_multirotor(4).with_changes(
        turning_sign=[-1, -1, 1, -1]).allocation()[1:4].copy()), ExitStatus.YAW_SPIN),
])
def test_every_early_ending_is_the_same(change, status):
    ref, got = _one(symmetric_multirotor(4), HoverConfig(duration_s=4.0), change)
    assert ref.status(0) is status and got.status(0) is status
    assert_same_outcome(ref, got)


def test_saturated_climb_is_the_same():
    base = symmetric_multirotor(4)
    omega_max = np.sqrt(base.weight_N * 1.03 / (4 * base.motor_constant[0]))
    params = base.with_changes(omega_max_rad_s=omega_max)
    config = HoverConfig(duration_s=6.0, offset_m=(0.0, 0.0, -1.5), roll_rad=0.0)
    ref = simulate_hover(params, config)
    got = simulate_hover(params, config, engine="numba")
    assert ref.status is got.status is ExitStatus.SATURATED
    # Engines: RTOL (test_sim.ENGINE_RTOL, derived from the flights' ulp floor).
    assert got.longest_saturation_s == pytest.approx(ref.longest_saturation_s, rel=RTOL)
    np.testing.assert_allclose(got.series["z_m"], ref.series["z_m"], rtol=RTOL)


def test_hover_test_says_which_engine_ran():
    from cli_helpers import run_cli
    from test_hover_test_cli import ARGV, SEED_MODEL

    for engine in ("numpy", "numba"):
        code, out = run_cli("hover-test", SEED_MODEL, *ARGV, "--duration", "3", "--format",
                            "json", "--samples", "4", "--engine", engine)
        report = json.loads(out)
        assert report["sim"]["engine"] == engine and report["batch"]["engine"] == engine
    code, out = run_cli("hover-test", SEED_MODEL, *ARGV, "--duration", "3", "--engine", "numba")
    assert "engine numba" in out


def test_default_engine_is_numba_for_a_batch_numpy_for_one_vehicle(monkeypatch):
    from cli_helpers import run_cli
    from test_hover_test_cli import ARGV, SEED_MODEL

    from reedtool.sim import choose_engine

    _, out = run_cli("hover-test", SEED_MODEL, *ARGV, "--duration", "3", "--format", "json",
                     "--samples", "4")
    report = json.loads(out)
    assert report["sim"]["engine"] == "numba" and report["batch"]["engine"] == "numba"
    _, out = run_cli("hover-test", SEED_MODEL, *ARGV, "--duration", "3", "--format", "json")
    assert json.loads(out)["sim"]["engine"] == "numpy"
    # the command tells choose_engine the batch's size: 3 vehicles stay on numpy
    _, out = run_cli("hover-test", SEED_MODEL, *ARGV, "--duration", "3", "--format", "json",
                     "--samples", "3")
    assert json.loads(out)["batch"]["engine"] == "numpy"
    # an explicit choice is kept; without numba a batch falls back to the reference
    assert choose_engine("numpy", batch=True) == "numpy"
    assert choose_engine("numba", batch=False) == "numba"
    # told the batch's size, auto keeps numpy for a few vehicles (they fly one by one
    # faster than numba starts: sim.AUTO_NUMPY_MAX_VEHICLES's measurements)
    assert choose_engine("auto", batch=True, vehicles=2) == "numpy"
    assert choose_engine("auto", batch=True, vehicles=16) == "numba"
    assert choose_engine("numba", batch=True, vehicles=2) == "numba"
    monkeypatch.setattr(compiled, "available", lambda: False)
    assert choose_engine("auto", batch=True) == "numpy"


def test_every_compiled_equation_is_equations_own_code():
    """The compiled engine's equations are equations.py's functions compiled, not a
    transcription: each jitted function runs the very code object of its namesake, and
    every function of equations is compiled."""
    import types

    from reedtool.sim import equations

    functions = {name for name, f in vars(equations).items()
                 if isinstance(f, types.FunctionType) and f.__module__ == equations.__name__
                 and name not in ("select", "guarded_by")}
    assert set(compiled.jitted) == functions
    for name, jitted in compiled.jitted.items():
        assert jitted.py_func.__code__ is getattr(equations, name).__code__


def test_compiled_judge_is_equations_own_code():
    """The kernels judge a flight with equations' judge compiled: the functions _fly and
    _fly_block call are judge_sample, verdict, settle_time and judge_start's own code
    objects, and no kernel carries a judge of its own (no reason code is named in
    compiled.py's source)."""
    import inspect
    import re

    from reedtool.sim import equations

    for name in ("judge_start", "judge_sample", "verdict", "settle_time"):
        assert getattr(compiled, "_" + name).py_func.__code__ is \
            getattr(equations, name).__code__
    source = inspect.getsource(compiled)
    for code in ("NON_FINITE", "FLIPPED", "GROUND", "YAW_SPIN", "DRIFTED", "RATE"):
        assert not re.search(rf"\b_?{code}\b", source), code
    for kernel in (compiled._fly, compiled._fly_block):
        names = kernel.py_func.__code__.co_names
        assert "_judge_sample" in names and "_verdict" in names


def test_numba_loads_without_importing_scipy_linalg():
    """The compiled engine's start-up leaves scipy.linalg unimported (numba's BLAS probe
    would import it: ~0.3 s of a single-vehicle run) and numba's answer as it was."""
    import subprocess
    import sys

    code = ("import sys, importlib.util\n"
            "from reedtool.sim import HoverConfig\n"
            "from reedtool.sim.params import symmetric_multirotor\n"
            "from reedtool.sim.run import simulate_hover\n"
            "run = simulate_hover(symmetric_multirotor(4), HoverConfig(duration_s=0.02, "
            "hold_s=0.01), engine='numba')\n"
            "assert run.engine == 'numba'\n"
            "print('scipy.linalg' in sys.modules)\n"
            "import numba.np.arraymath as a\n"
            "print(a._HAVE_BLAS == (importlib.util.find_spec('scipy.linalg') is not None))\n"
            "import numba, numpy as np\n"
            "print(numba.njit(lambda x: np.dot(x, x))(np.arange(3.0)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "True", "5.0"]


def test_kernel_cache_is_stamped_with_the_equations_source():
    """numba keys a cached kernel to its own file; the kernels run equations.py's
    functions, so their cache stamp carries that file's digest too (an edit there
    recompiles them instead of flying old code)."""
    import hashlib
    import inspect

    from reedtool.sim import equations

    stamp = compiled._fly_block._cache._impl.locator.get_source_stamp()
    assert list(stamp[1:]) == [hashlib.sha256(open(inspect.getfile(equations), "rb")
                                              .read()).digest()]
    # numba's own locators still serve functions of other files
    assert not type(compiled.jitted["rotation"]._cache._impl.locator).__name__.startswith(
        "Shared")
