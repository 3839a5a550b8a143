"""Control authority (ACAI) against the literature and against a second method.

References: Du, Quan, Yang and Cai, "Controllability Analysis for Multirotor Helicopter
Rotor Degradation and Failure", JGCD 2015 (arXiv 1403.5986). Their control-effectiveness
columns are b_i = [1, -d sin(phi_i), d cos(phi_i), k_mu w_i] for a rotor at bearing phi_i
on an arm d, spinning w_i = +1/-1, with per-rotor lift in [0, K_i].
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_helpers import run_cli

from reedtool.physics.authority import (acai, analyse_cases, full_rank, min_thrust_to_weight,
                                        survivable_failures)
from reedtool.sim.params import allocation_from_arrays

# The paper's hexacopter (Section V): mass 1.535 kg, arm 0.275 m, K 6.125 N, k_mu 0.1.
HEX_MASS_KG, HEX_G, HEX_ARM_M, HEX_K_N, HEX_K_MU = 1.535, 9.80, 0.275, 6.125, 0.1


def paper_B(bearings_deg, spins, d, k_mu) -> np.ndarray:
    phi = np.radians(bearings_deg)
    return np.vstack([np.ones(len(phi)), -d * np.sin(phi), d * np.cos(phi),
                      k_mu * np.asarray(spins, dtype=float)])


def hexacopter(spins):
    B = paper_B(np.arange(6) * 60.0, spins, HEX_ARM_M, HEX_K_MU)
    return B, np.full(6, HEX_K_N), HEX_MASS_KG * HEX_G


def support_acai(B, K, G, starts=60, seed=1) -> float:
    """ACAI by a second method: min over unit u of h(u) - u.G, h the zonotope's support
    function h(u) = sum_i K_i max(0, b_i . u). Nelder-Mead from many random starts."""
    from scipy.optimize import minimize

    B, K, G = (np.asarray(a, dtype=float) for a in (B, K, G))

    def gap(v):
        u = v / np.linalg.norm(v)
        return float(np.sum(K * np.maximum(0.0, u @ B)) - u @ G)

    rng = np.random.default_rng(seed)
    best = math.inf
    for _ in range(starts):
        result = minimize(gap, rng.normal(size=len(G)), method="Nelder-Mead",
                          options={"xatol": 1e-12, "fatol": 1e-13, "maxiter": 20000})
        best = min(best, result.fun)
    return best


def test_published_plus_quadrotor_anchor():
    """A plus quadrotor, d 0.28 m, k_mu 0.1, K 6 N, G 15 N: ACAI 0.7299 (published)."""
    B = paper_B([0, 90, 180, 270], [1, -1, 1, -1], 0.28, 0.1)
    assert acai(B, np.full(4, 6.0), [15.0, 0, 0, 0]) == pytest.approx(0.7299, abs=1e-4)


def test_anchor_through_reedtool_allocation():
    """The same vehicle through the allocation reedtool builds from rotor geometry."""
    d = 0.28
    positions = np.array([[d, 0, 0], [0, d, 0], [-d, 0, 0], [0, -d, 0]], dtype=float)
    axes = np.tile([0.0, 0.0, 1.0], (4, 1))
    B = allocation_from_arrays(positions, axes, np.array([1, -1, 1, -1]), np.full(4, 0.1))
    assert acai(B, np.full(4, 6.0), [15.0, 0, 0, 0]) == pytest.approx(0.7299, abs=1e-4)


def test_alternating_hexacopter_loses_full_control_with_any_rotor():
    B, K, weight = hexacopter([1, -1, 1, -1, 1, -1])
    report = analyse_cases(B, K, weight)
    assert report.intact.controllable
    assert [case.controllable for case in report.failures] == [False] * 6
    # The rank condition still holds: it is the ACAI that says no (the paper's point).
    assert all(case.rank_ok for case in report.failures)
    assert all(case.acai == 0.0 for case in report.failures)


def test_ppnnpn_hexacopter_survives_four_of_six_failures():
    B, K, weight = hexacopter([1, 1, -1, -1, 1, -1])
    report = analyse_cases(B, K, weight)
    assert [case.controllable for case in report.failures] == [True] * 4 + [False] * 2
    assert survivable_failures(lambda s: hexacopter(s)[0], K, weight, [1, 1, -1, -1, 1, -1]) == 4


def test_quadrotor_survives_no_single_failure():
    B = paper_B([45, 135, 225, 315], [1, -1, 1, -1], 0.25, 0.016)
    report = analyse_cases(B, np.full(4, 8.0), 15.0)
    assert report.intact.controllable
    assert not any(case.controllable for case in report.failures)
    # Three rotors left cannot span four directions: the rank condition fails too.
    assert not any(case.rank_ok for case in report.failures)


def test_symmetric_octocopter_with_thrust_to_weight_two_survives_each_failure():
    weight = 20.0
    B = paper_B(np.arange(8) * 45.0 + 22.5, [1, -1] * 4, 0.4, 0.05)
    report = analyse_cases(B, np.full(8, 2 * weight / 8), weight)
    assert report.thrust_to_weight == pytest.approx(2.0)
    assert all(case.controllable for case in report.failures)


@pytest.mark.parametrize("seed", range(6))
def test_facet_and_support_function_methods_agree(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 9))
    bearings = np.sort(rng.uniform(0, 360, n))
    B = paper_B(bearings, rng.choice([-1, 1], n), rng.uniform(0.2, 0.4), rng.uniform(0.02, 0.2))
    K = rng.uniform(4.0, 8.0, n)
    G = np.array([0.45 * K.sum(), 0, 0, 0])
    facet = acai(B, K, G)
    if facet <= 0:
        pytest.skip("hover point outside: the support-function form measures the inside only")
    assert support_acai(B, K, G) == pytest.approx(facet, abs=1e-6)


def test_yaw_given_up_leaves_a_controllable_hexacopter():
    """With yaw free to spin, five rotors of the alternating hexacopter still hold hover."""
    B, K, weight = hexacopter([1, -1, 1, -1, 1, -1])
    report = analyse_cases(B, K, weight)
    assert all(case.controllable_without_yaw for case in report.failures)


def test_min_thrust_to_weight_is_the_threshold():
    B, K, weight = hexacopter([1, 1, -1, -1, 1, -1])
    B1, K1 = np.delete(B, 0, axis=1), np.delete(K, 0)
    G = np.array([weight, 0, 0, 0])
    ratio = min_thrust_to_weight(B1, K1, G, weight, K.sum())
    scale = ratio * weight / K.sum()
    assert acai(B1, K1 * scale * 1.001, G) > 0
    assert acai(B1, K1 * scale * 0.999, G) <= 0
    # A lost direction is lost whatever the thrust.
    B_alt, _, _ = hexacopter([1, -1, 1, -1, 1, -1])
    assert min_thrust_to_weight(np.delete(B_alt, 0, axis=1), K1, G, weight, K.sum()) is None


def test_rank_deficient_set_has_no_authority():
    B = paper_B([0, 180], [1, -1], 0.3, 0.1)          # two rotors on the x axis: no roll torque
    assert not full_rank(B)
    assert acai(B, np.full(2, 10.0), [5.0, 0, 0, 0]) <= 0


def test_degraded_rotor_between_intact_and_stopped():
    B, K, weight = hexacopter([1, 1, -1, -1, 1, -1])
    stopped = analyse_cases(B, K, weight, efficiency=0.0).failures[4].acai
    half = analyse_cases(B, K, weight, efficiency=0.5).failures[4].acai
    intact = analyse_cases(B, K, weight).intact.acai
    assert stopped < half < intact


FRAMES = ["quad-x", "quad-plus", "hex-x", "hex-plus", "octo-x", "y6"]


@pytest.fixture(scope="module")
def packages(tmp_path_factory):
    root = tmp_path_factory.mktemp("authority")
    made = {}
    for frame in FRAMES:
        name = "a_" + frame.replace("-", "_")
        code, _ = run_cli("new-package", name, "--frame", frame, "--ros", "2", "-o", str(root))
        assert code == 0
        made[frame] = next((root / name / "urdf").glob("*.xacro"))
    return made


@pytest.mark.parametrize("frame", FRAMES)
def test_every_generated_frame_gets_a_table(packages, frame):
    code, output = run_cli("authority", str(packages[frame]), "--format", "json")
    assert code == 0
    doc = json.loads(output)
    assert doc["schema"] == "reedtool.authority/1" and doc["intact"]["controllable"]
    n = len(doc["thrust_max_N"])
    assert [f["failed_rotor"]["index"] for f in doc["failures"]] == list(range(n))
    for entry in doc["failures"]:
        assert set(entry) >= {"acai", "controllable", "controllable_without_yaw",
                              "min_thrust_to_weight"}
        assert entry["failed_rotor"]["name"] and entry["failed_rotor"]["number"] is not None
    if frame.startswith("quad"):
        assert not any(f["controllable"] for f in doc["failures"])
    if frame == "octo-x":
        assert all(f["controllable"] for f in doc["failures"])


def test_require_policy_sets_the_exit_code(packages):
    model = str(packages["quad-x"])
    assert run_cli("authority", model, "--require", "none")[0] == 0
    assert run_cli("authority", model, "--require", "intact")[0] == 0
    code, output = run_cli("authority", model, "--require", "any-single")
    assert code == 1 and "NOT met" in output
    assert run_cli("authority", str(packages["octo-x"]), "--require", "any-single")[0] == 0
