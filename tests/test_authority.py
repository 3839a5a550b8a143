"""Available control authority (Du, Quan, Yang & Cai 2015, arXiv 1403.5986).

References are the paper's published numbers and qualitative results, hand-derived
hover limits, and a second ACAI computation by the support function.
"""

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from cli_helpers import run_cli

from reedtool.physics.allocation import allocation_matrix
from reedtool.physics.authority import (
    acai_support,
    authority,
    failure_cases,
    full_control_after_failures,
)

# The paper's hexacopter (Sec. V, Table): mass 1.535 kg, g 9.80, arm 0.275 m,
# K 6.125 N per rotor, k_mu 0.1; rotor i at 60*i degrees, rotor 1 at the nose.
HEX_WEIGHT_N = 1.535 * 9.80
HEX_K_N = 6.125


def paper_hexacopter(spins: str, arm_m: float = 0.275, k_mu: float = 0.1) -> np.ndarray:
    """B_f of the paper's hexacopter; spins 'P' (+k_mu) / 'N' (-k_mu) per rotor."""
    phi = np.radians(60.0 * np.arange(6))
    sigma = np.array([1.0 if s == "P" else -1.0 for s in spins])
    return np.array([np.ones(6), -arm_m * np.sin(phi), arm_m * np.cos(phi), k_mu * sigma])


def rotor(x, y, sign, k_mu=0.1):
    """Just the attributes allocation_matrix reads, as a Rotor carries them."""
    return SimpleNamespace(position_m=np.array([x, y, 0.0]), axis=np.array([0.0, 0.0, 1.0]),
                           turning_sign=sign, moment_constant=k_mu)


def ring(n, arm_m, signs, k_mu=0.1):
    angles = 2 * np.pi * np.arange(n) / n
    return [rotor(arm_m * math.cos(a), arm_m * math.sin(a), s, k_mu)
            for a, s in zip(angles, signs)]


def test_plus_quadrotor_matches_the_published_acai():
    # The paper's anchor: d = 0.28 m, k_mu = 0.1, K = 6 N, G = 15 N -> ACAI 0.7299. Our
    # allocation (physical thrust [N] and torques [N*m], yaw = k_mu * thrust) reproduces it.
    B = allocation_matrix(ring(4, 0.28, [1, -1, 1, -1]), np.zeros(3))
    a = authority(B, [6.0] * 4, 15.0)
    assert a.acai == pytest.approx(0.7299, abs=1e-4)
    assert a.controllable and a.rank == 4
    # Hover needs 15/4 = 3.75 N per rotor, so K may shrink to 3.75/6 of itself.
    assert a.min_thrust_scale == pytest.approx(3.75 / 6.0, rel=1e-12)


def test_paper_hexacopter_pnpnpn_loses_control_with_any_rotor():
    intact, failed = failure_cases(paper_hexacopter("PNPNPN"), [HEX_K_N] * 6, HEX_WEIGHT_N)
    assert intact.controllable
    G = [HEX_WEIGHT_N, 0, 0, 0]
    # Facet enumeration (exact up to rounding) vs acai_support, an iterative descent of
    # 400 subgradient steps: its convergence, not rounding, sets abs 1e-6 (in N and N*m).
    assert intact.acai == pytest.approx(acai_support(paper_hexacopter("PNPNPN"),
                                                     [HEX_K_N] * 6, G), abs=1e-6)
    assert [f.controllable for f in failed] == [False] * 6
    assert all(f.acai == 0.0 for f in failed)                       # G on the boundary
    assert all(math.isinf(f.min_thrust_scale) for f in failed)      # no motor fixes that
    # Yaw given up, thrust/roll/pitch are still held: the degraded strategy of the paper.
    assert all(f.controllable_without_yaw for f in failed)


def test_paper_hexacopter_ppnnpn_keeps_four_of_six():
    intact, failed = failure_cases(paper_hexacopter("PPNNPN"), [HEX_K_N] * 6, HEX_WEIGHT_N)
    assert intact.controllable
    assert [f.controllable for f in failed] == [True, True, True, True, False, False]
    # The layout is mirror-symmetric about the axis between rotors 2 and 3 (0-based 1, 2)
    # with opposite spins swapped, so failures 0/3 and 1/2 leave congruent sets.
    assert failed[0].acai == pytest.approx(failed[3].acai, abs=1e-12)
    assert failed[1].acai == pytest.approx(failed[2].acai, abs=1e-12)
    assert failed[4].acai < 0 and failed[5].acai < 0


def test_quadrotor_survives_no_single_failure_with_full_control():
    B = allocation_matrix(ring(4, 0.2, [1, -1, 1, -1]), np.zeros(3))
    intact, failed = failure_cases(B, [8.0] * 4, 14.0)
    assert intact.controllable
    assert [f.controllable for f in failed] == [False] * 4
    assert all(f.rank == 3 for f in failed)      # three rotors cannot span four axes


def test_symmetric_octocopter_with_thrust_to_weight_two_survives_each():
    B = allocation_matrix(ring(8, 0.3, [1, -1] * 4), np.zeros(3))
    weight_N = 20.0
    intact, failed = failure_cases(B, [2 * weight_N / 8] * 8, weight_N)
    assert intact.controllable
    assert [f.controllable for f in failed] == [True] * 8
    assert all(f.acai > 0 for f in failed)


def test_min_thrust_scale_is_the_threshold():
    # Independent of the gauge formula: just below the scale the failure is not
    # survivable, just above it is.
    B = paper_hexacopter("PPNNPN")
    K = np.full(6, HEX_K_N)
    for i in range(4):
        eta = np.ones(6)
        eta[i] = 0.0
        s = authority(B, K, HEX_WEIGHT_N, eta).min_thrust_scale
        assert 0 < s < 1
        assert not authority(B, K * s * 0.999, HEX_WEIGHT_N, eta).controllable
        assert authority(B, K * s * 1.001, HEX_WEIGHT_N, eta).controllable


def test_efficiency_is_a_scaled_maximum_thrust():
    B = paper_hexacopter("PPNNPN")
    eta = np.array([1.0, 0.4, 1.0, 1.0, 0.7, 1.0])
    a = authority(B, [HEX_K_N] * 6, HEX_WEIGHT_N, eta)
    b = authority(B, HEX_K_N * eta, HEX_WEIGHT_N)
    # eta*K computed before or inside: a few ulps of ~10 N facet distances (~1e-14).
    assert a.acai == pytest.approx(b.acai, abs=1e-12)


def test_facets_agree_with_the_support_function_on_random_layouts():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(12):
        n = int(rng.integers(4, 9))
        B = rng.normal(size=(4, n))
        B[0] = np.abs(B[0]) + 0.5
        K = rng.uniform(2.0, 8.0, n)
        G = np.array([rng.uniform(0.2, 0.6) * (B[0] @ K), 0.0, 0.0, 0.0])
        facets = authority(B, K, G[0]).acai
        if facets <= 0:
            continue             # the support-function minimum is the ACAI only inside
        assert acai_support(B, K, G) == pytest.approx(facets, abs=1e-6)
        checked += 1
    assert checked >= 3


def test_without_yaw_is_the_projection():
    # A coaxial pair at the centre has no lever arm: thrust only. Two such pairs plus
    # nothing else cannot hold roll or pitch -> rank 1, controllable in neither sense.
    B = allocation_matrix([rotor(0, 0, 1), rotor(0, 0, -1)], np.zeros(3))
    a = authority(B, [10.0, 10.0], 5.0)
    assert a.rank == 2 and not a.controllable and not a.controllable_without_yaw


@pytest.mark.parametrize("frame", ["quad-x", "quad-plus", "hex-x", "hex-plus", "octo-x", "y6"])
def test_every_generated_frame_gets_a_table(tmp_path, frame):
    from reedtool.generate.airframes import MULTIROTOR_FRAMES

    assert frame in MULTIROTOR_FRAMES
    name = "t_" + frame.replace("-", "_")
    code, out = run_cli("new-package", name, "--frame", frame, "-o", tmp_path)
    assert code == 0, out
    model = tmp_path / name / "urdf" / f"{name}.xacro"
    code, out = run_cli("authority", model, "namespace:=t", "--package-path", tmp_path,
                        "--format", "json", "--require", "any-single")
    report = json.loads(out)
    n = len(report["failures"])
    assert n == {"quad": 4, "hex": 6, "octo": 8, "y6": 6}[frame.split("-")[0]]
    assert report["intact"]["controllable"]
    assert {"rotor", "index", "motor_number", "acai", "controllable",
            "controllable_without_yaw", "min_thrust_to_weight"} <= set(report["failures"][0])
    # Whether every single failure is survivable, by the support function (acai_support, a
    # second method beside the facet enumeration) on the generated geometry: G = [m g, 0,
    # 0, 0] inside the failed set by more than the method's 1e-6 convergence.
    from reedtool.io.loader import load_robot
    from reedtool.physics.inertia import whole_robot
    from reedtool.physics.rotors import discover_rotors, lift_rotors

    robot = load_robot(model, {"namespace": "t"}, [tmp_path])
    rotors = lift_rotors(discover_rotors(robot))
    whole = whole_robot(robot)
    B = allocation_matrix(rotors, whole.com_m)
    K = np.array([r.max_thrust_N for r in rotors])
    G = [whole.mass_kg * 9.80665, 0.0, 0.0, 0.0]
    survives = [acai_support(B, np.where(np.arange(len(K)) == i, 0.0, K), G) > 1e-6
                for i in range(len(K))]
    assert [f["controllable"] for f in report["failures"]] == survives
    # What the frames are known to give: three rotors cannot span four axes (quad); the
    # alternating hexacopter loses full control with any rotor (Du et al. 2015); the
    # alternating octocopter and a Y6's coaxial partners keep it.
    exit_code = {"quad-x": 1, "quad-plus": 1, "hex-x": 1, "hex-plus": 1, "octo-x": 0,
                 "y6": 0}[frame]
    assert code == exit_code == (0 if all(survives) else 1)


def test_efficiency_option_and_bad_input(tmp_path):
    code, out = run_cli("new-package", "t_hex", "--frame", "hex-x", "-o", tmp_path)
    assert code == 0, out
    model = tmp_path / "t_hex" / "urdf" / "t_hex.xacro"
    base = [model, "namespace:=t", "--package-path", tmp_path, "--format", "json"]
    _, out = run_cli("authority", *base)
    _, degraded = run_cli("authority", *base, "--efficiency", "t/rotor_0=0.5")
    assert json.loads(degraded)["intact"]["acai"] < json.loads(out)["intact"]["acai"]
    code, out = run_cli("authority", *base, "--efficiency", "nope=0.5")
    assert code == 2 and "bad --efficiency" in out
    code, out = run_cli("authority", *base, "--efficiency", "t/rotor_0=2")
    assert code == 2 and "[0, 1]" in out


def test_r350_names_an_order_that_really_keeps_control():
    # Second opinion on the rule's suggestion: rebuild the hexacopter with the order it
    # names and count the survivable failures with the paper's matrix.
    import re

    from rule_helpers import FIXTURES

    from reedtool.checks.runner import Selection, run_checks
    from reedtool.io.loader import load_robot

    (finding,) = run_checks(load_robot(FIXTURES / "R350_bad_alternating_hex.urdf"),
                            Selection(select=("R350",)))
    spins = re.findall(r"rotor_\d+ (ccw|cw)", finding.message)
    assert len(spins) == 6 and spins.count("ccw") == 3
    count = int(re.search(r"after (\d) of 6", finding.message).group(1))
    order = "".join("P" if s == "ccw" else "N" for s in spins)
    _, failed = failure_cases(paper_hexacopter(order, arm_m=0.3, k_mu=0.016),
                              [8.54858e-06 * 838.0 ** 2] * 6, 2.03 * 9.80665)
    assert sum(f.controllable for f in failed) == count >= 1


def test_fly_reports_a_flight_per_failure_and_plots_the_failure(tmp_path):
    code, out = run_cli("new-package", "t_quad", "--frame", "quad-x", "-o", tmp_path)
    assert code == 0, out
    model = tmp_path / "t_quad" / "urdf" / "t_quad.xacro"
    png = tmp_path / "fail.png"
    code, out = run_cli("authority", model, "namespace:=t", "--package-path", tmp_path,
                        "--format", "json", "--fly", "--plot", png)
    report = json.loads(out)
    assert code == 0                        # --require hover: the intact quad is fine
    # The analysis says no quad failure is survivable; no flight may claim otherwise.
    assert [f["flight"]["passed"] for f in report["failures"]] == [False] * 4
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out = run_cli("authority", model, "namespace:=t", "--package-path", tmp_path,
                        "--fly", "--plot", png)
    assert code == 2 and "refusing to overwrite" in out


@pytest.mark.parametrize("K_N", [5.5, HEX_K_N, 7.0])
@pytest.mark.parametrize("arm_m,k_mu", [(0.2, 0.05), (0.275, 0.1), (0.35, 0.2)])
def test_hexacopter_verdicts_do_not_hang_on_the_exact_parameters(K_N, arm_m, k_mu):
    # The paper's qualitative result holds around its parameters, not just at them.
    _, alternating = failure_cases(paper_hexacopter("PNPNPN", arm_m, k_mu), [K_N] * 6,
                                   HEX_WEIGHT_N)
    _, paired = failure_cases(paper_hexacopter("PPNNPN", arm_m, k_mu), [K_N] * 6, HEX_WEIGHT_N)
    assert sum(f.controllable for f in alternating) == 0
    assert sum(f.controllable for f in paired) == 4


def test_bad_input_is_one_line_and_exit_2(tmp_path):
    from rule_helpers import FIXTURES

    code, out = run_cli("authority", tmp_path / "missing.urdf")
    assert code == 2 and "model file not found" in out
    code, out = run_cli("authority", FIXTURES / "clean_arm.urdf")
    assert code == 2 and "no motor plugins" in out
    code, out = run_cli("authority", FIXTURES / "clean_hex.urdf", "--plot", tmp_path / "x.png")
    assert code == 2 and "--plot needs --fly" in out


def test_require_policies_on_the_paper_hexacopter_fixtures():
    from rule_helpers import FIXTURES

    alternating = FIXTURES / "R350_bad_alternating_hex.urdf"
    paired = FIXTURES / "R350_good_ppnnpn_hex.urdf"
    assert run_cli("authority", alternating, "--require", "any-single")[0] == 1
    assert run_cli("authority", alternating, "--require", "any-single-without-yaw")[0] == 0
    code, out = run_cli("authority", paired, "--format", "json", "--require", "none")
    assert code == 0
    assert sum(f["controllable"] for f in json.loads(out)["failures"]) == 4


def test_the_search_verdict_is_the_tables_verdict():
    """R350's fast per-failure verdict (column removed) equals failure_cases' (thrust zeroed)."""
    rng = np.random.default_rng(7)
    for _ in range(25):
        n = int(rng.integers(6, 9))
        angles = np.sort(rng.uniform(0, 2 * np.pi, n))
        arm = rng.uniform(0.2, 0.4)
        k_mu = rng.uniform(0.01, 0.1)
        signs = rng.choice([-1.0, 1.0], n)
        B = np.vstack([np.ones(n), -arm * np.sin(angles), arm * np.cos(angles), k_mu * signs])
        K = rng.uniform(4.0, 8.0, n)
        weight = rng.uniform(0.3, 0.6) * K.sum()
        _, failed = failure_cases(B, K, weight)
        fast = full_control_after_failures(B, K, weight)
        assert [a is not None for a in fast] == [f.controllable for f in failed]
        for a, f in zip(fast, failed):
            if a is not None:
                # Two algorithms (failure verdict alone vs the full table) over the same facets:
                # rounding of 4x4 solves with cond ~1e2-1e4: < 1e-11 relative; 1e-9 holds, abs for 0.
                assert a == pytest.approx(f.acai, rel=1e-9, abs=1e-12)


def test_degraded_rotor_needs_the_hand_derived_thrust():
    """A quad-X holds hover with zero torque only with four equal thrusts m g / 4, so a rotor
    left with half its thrust needs 0.5 K >= m g / 4: thrust-to-weight 4 K / (m g) >= 2."""
    a = 0.2
    B = allocation_matrix([rotor(a, -a, 1), rotor(-a, a, 1), rotor(a, a, -1), rotor(-a, -a, -1)],
                          np.zeros(3))
    K = np.full(4, 6.0)
    weight = 15.0
    _, degraded = failure_cases(B, K, weight, failed_efficiency=0.5)
    _, stopped = failure_cases(B, K, weight)
    for half, none in zip(degraded, stopped):
        assert half.min_thrust_scale * K.sum() / weight == pytest.approx(2.0, rel=1e-9)
        assert math.isinf(none.min_thrust_scale)       # stopped: no thrust is enough
        assert not half.controllable                   # this quad has 4 x 6 / 15 = 1.6
