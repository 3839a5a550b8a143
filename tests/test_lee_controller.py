"""`hover-test --controller`: RotorS' Lee position controller flown with a package's own
files.

- The gains `new-package` ships fly every multirotor frame to the verdict "flies".
- Broken files fail with the cause named: the pre-flight rule for what can be known from
  the files and the model (a sign, a unit slip, degrees for radians, a flipped direction),
  the flight for the rest.
- The simulation of the controller is held to second-order responses derived by hand
  from RotorS' equations (the references below are closed-form, not the code's output).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml
from cli_helpers import run_cli

from reedtool.sim import HoverConfig
from reedtool.sim.lee_rotors import RotorsLee, simulate_lee
from reedtool.sim.params import symmetric_multirotor

FRAMES = ("quad-x", "quad-plus", "hex-x", "octo-x", "y6")


@pytest.fixture(scope="module")
def packages(tmp_path_factory):
    out = tmp_path_factory.mktemp("lee_pkgs")
    made = {}
    for frame in FRAMES:
        name = "l_" + frame.replace("-", "_")
        code, output = run_cli("new-package", name, "--frame", frame, "-o", out)
        assert code == 0, output
        made[frame] = out / name
    return made


def model_of(pkg):
    return pkg / "urdf" / "mav_generic_odometry_sensor.gazebo"


def fly(pkg, *files, extra=()):
    code, output = run_cli("hover-test", model_of(pkg), *(a for f in files
                                                         for a in ("--controller", f)),
                           "--format", "json", *extra)
    assert code in (0, 1), output
    return code, json.loads(output)


# ------------------------------------------------------------------ shipped gains fly

@pytest.mark.parametrize("frame", FRAMES)
def test_shipped_gains_fly(packages, frame):
    """The package's lee_controller_NAME.yaml (with NAME.yaml found beside it) flies the
    package's model from the default start plus a 0.3 rad yaw, within the default 10 s,
    to "flies", and the pre-flight finds nothing wrong in the files."""
    pkg = packages[frame]
    code, report = fly(pkg, pkg / "config" / f"lee_controller_{pkg.name}.yaml",
                       extra=("--yaw", "0.3", "--duration", "10"))
    c = report["controller"]
    assert [f["code"] for f in c["preflight"] if f["severity"] != "info"] == []
    assert report["verdict"]["status"] == "flies", report["message"]
    assert code == 0 and report["passed"]
    assert c["files"][-1].endswith(f"config/{pkg.name}.yaml")
    # The shipped mass is the model's: no altitude offset left by the missing integrator
    # beyond the controller's g = 9.81 against the world's 9.80665 (m * 0.00335 / k_z,
    # k_z = 6 m / 1.56779: 0.9 mm).
    assert abs(c["predicted_altitude_offset_m"]) < 1.5e-3


def test_generated_yaw_loop_is_damped(packages):
    """Derivation in package_spec: the shipped yaw gains are lee_controller_firefly.yaml's
    scaled by J_z, so on the model the yaw loop has the Firefly's w_n = sqrt(0.15 /
    0.0977) = 1.239 rad/s and zeta = 0.18 / (2 sqrt(0.15 * 0.0977)) = 0.744 (not 0.21).
    Tolerance: the gains are printed to 4 digits and scaled with the generator's inertia
    estimate, which differs from the model's (rotor inertia) by < 3 %: w_n and zeta
    within 2 % (half of it, square roots)."""
    pkg = packages["quad-x"]
    _, report = fly(pkg, pkg / "config" / f"lee_controller_{pkg.name}.yaml",
                    extra=("--duration", "3"))
    loops = report["controller"]["loops"]
    assert loops["attitude_natural_rad_s"][2] == pytest.approx(math.sqrt(0.15 / 0.0977), rel=0.02)
    assert loops["attitude_damping"][2] == pytest.approx(
        0.18 / (2 * math.sqrt(0.15 * 0.0977)), rel=0.02)


# ------------------------------------------------------------------ broken files fail

def broken_copy(pkg, tmp_path, *, gains=None, vehicle=None):
    """The package's two files, changed by `gains(d)` / `vehicle(d)`, written to tmp."""
    name = pkg.name
    g = yaml.safe_load((pkg / "config" / f"lee_controller_{name}.yaml").read_text())
    v = yaml.safe_load((pkg / "config" / f"{name}.yaml").read_text())
    if gains:
        gains(g)
    if vehicle:
        vehicle(v)
    gpath, vpath = tmp_path / f"lee_controller_{name}.yaml", tmp_path / f"{name}.yaml"
    gpath.write_text(yaml.safe_dump(g))
    vpath.write_text(yaml.safe_dump(v))
    return gpath, vpath


def codes(report, severity="error"):
    return {f["code"] for f in report["controller"]["preflight"] if f["severity"] == severity}


def message_of(report, code):
    return next(f["message"] + " " + (f["hint"] or "")
                for f in report["controller"]["preflight"] if f["code"] == code)


def test_negative_attitude_gain_fails_named(packages, tmp_path):
    def flip(g):
        g["attitude_gain"]["x"] = -g["attitude_gain"]["x"]

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path, gains=flip))
    assert code == 1 and not report["passed"]
    assert "C450" in codes(report)
    assert "attitude_gain/x" in message_of(report, "C450")
    # The flight itself: positive feedback in roll flips it (the start is rolled 0.2 rad).
    assert report["sim"]["status"] == "crashed"


def test_angular_rate_gain_1000x_fails_named(packages, tmp_path):
    def slip(g):
        for axis in "xyz":
            g["angular_rate_gain"][axis] *= 1000

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path, gains=slip))
    assert code == 1 and report["verdict"]["status"] != "flies"
    assert "C451" in codes(report)
    text = message_of(report, "C451")
    # 1000x the shipped gain, which is the Firefly's scaled (4 digits): named as ~1000x.
    assert "unit slip" in text
    import re
    factor = float(re.search(r"angular_rate_gain/\w [\d.e+-]+ is (\d+)x", text).group(1))
    assert factor == pytest.approx(1000, rel=0.03)


def test_mass_in_grams_fails_named(packages, tmp_path):
    def grams(v):
        v["mass"] = v["mass"] * 1000

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path,
                                                         vehicle=grams))
    assert code == 1
    assert "C452" in codes(report)
    assert "grams written as kg" in message_of(report, "C452")
    # 1000x the hover thrust: every rotor is asked beyond its maximum, RotorS clamps each
    # on its own and the attitude is lost on the way up.
    assert report["verdict"]["status"] != "flies" and report["sim"]["max_throttle"] == 1.0


def test_angle_in_degrees_fails_named(packages, tmp_path):
    def degrees(v):
        for entry in v["rotor_configuration"].values():
            entry["angle"] = math.degrees(entry["angle"])

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path,
                                                         vehicle=degrees))
    assert code == 1 and report["verdict"]["status"] != "flies"
    assert "C405" in codes(report)
    assert "degrees" in message_of(report, "C405")


def test_wrong_rotor_direction_fails_named(packages, tmp_path):
    def flip(v):
        for entry in v["rotor_configuration"].values():
            entry["direction"] = -entry["direction"]

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path,
                                                         vehicle=flip), extra=("--duration", "10"))
    assert code == 1 and report["verdict"]["status"] != "flies"
    assert "C404" in codes(report)
    # Yaw feedback of the wrong sign: it spins up about the vertical (0.3 rad start).
    _, yawed = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path, vehicle=flip),
                   extra=("--yaw", "0.3"))
    assert yawed["sim"]["status"] == "yaw-spin"


def test_inertia_in_g_cm2_is_named_and_flies_the_same(packages, tmp_path):
    """RotorS divides the attitude gains by the YAML inertia and multiplies the angular
    acceleration by it again: a factor of 10^7 (g*cm^2 for kg*m^2) cancels exactly, so
    the flight is the same to rounding. The file is still wrong: C453 names the unit."""
    pkg = packages["quad-x"]

    def g_cm2(v):
        for key in v["inertia"]:
            v["inertia"][key] = v["inertia"][key] * 1e7

    (tmp_path / "good").mkdir()
    _, good = fly(pkg, *broken_copy(pkg, tmp_path / "good"))
    _, slipped = fly(pkg, *broken_copy(pkg, tmp_path, vehicle=g_cm2))
    assert "C453" in codes(slipped, "warning")
    assert "g*cm^2" in message_of(slipped, "C453")
    # Same flight: final rotor speeds equal to 1e-6 relative (the inverse of a 1e7-scaled
    # matrix times the matrix again costs a few ulps per step).
    a = np.array(list(good["sim"]["final_omega_rad_s"].values()))
    b = np.array(list(slipped["sim"]["final_omega_rad_s"].values()))
    np.testing.assert_allclose(a, b, rtol=1e-6)


# ------------------------------------------------------------------ against the analytic loop

def _vehicle():
    """A symmetric hexacopter without rotor drag and with motors 100x faster than
    RotorS' (tau 1.25e-4 s): the closed loops are then RotorS' equations alone."""
    p = symmetric_multirotor(6, arm_m=0.215, mass_kg=1.5, inertia_diag_kg_m2=(0.03, 0.04, 0.07),
                             time_constant_up_s=1.25e-4, time_constant_down_s=1.25e-4,
                             rotor_drag_coefficient=0.0, rolling_moment_coefficient=0.0)
    return p


def _lee(p, **gains):
    angles = (np.arange(6) + 0.5) * 2 * math.pi / 6
    return RotorsLee(mass_kg=p.mass_kg, inertia_kg_m2=p.inertia_kg_m2, angle_rad=angles,
                     arm_length_m=np.full(6, 0.215), force_constant=p.motor_constant,
                     moment_constant=p.moment_constant, direction=p.turning_sign, **gains)


def _extrema(t, x):
    """(times, values) of the local extrema of a sampled signal (sign changes of the
    difference), refined by a parabola through the three samples around each."""
    d = np.diff(x)
    idx = np.flatnonzero(np.sign(d[1:]) != np.sign(d[:-1])) + 1
    times, values = [], []
    for i in idx:
        y0, y1, y2 = x[i - 1], x[i], x[i + 1]
        den = y0 - 2 * y1 + y2
        s = 0.5 * (y0 - y2) / den if den != 0 else 0.0
        times.append(t[i] + s * (t[1] - t[0]))
        values.append(y1 - 0.25 * (y0 - y2) * s)
    return np.array(times), np.array(values)


def _second_order(t, x0, wn, zeta):
    """x'' + 2 zeta wn x' + wn^2 x = 0 from x(0) = x0, x'(0) = 0 (zeta < 1)."""
    wd = wn * math.sqrt(1 - zeta ** 2)
    return x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta ** 2)
                                           * np.sin(wd * t))


# The delays the loops see beyond the continuous model: the 1 ms zero-order hold of the
# 1 kHz command (T/2 on average), one step of semi-implicit Euler (the torque of step k
# moves the attitude at step k+1: dt) and the motors' 0.125 ms: delta <= 1.7 ms. A delay
# delta in J s^2 + (k_w s + k_R) e^{-s delta} shifts w_n by about delta zeta w_n^2 and
# zeta by about -delta w_n / 2 (first order in delta); at w_n = 10 rad/s, zeta = 0.25:
# 0.4 % in w_n and 0.0085 in zeta, which moves the overshoot exp(-pi zeta / sqrt(1 -
# zeta^2)) by 0.0085 * pi / (1 - zeta^2)^1.5 * 0.444 = 0.013 absolute.
WN_REL_TOL = 0.01           # 2.5x the w_n shift
ZETA_ABS_TOL = 0.02         # 2.4x the zeta shift
OVERSHOOT_ABS_TOL = 0.03    # 2.3x the overshoot shift
PEAK_TIME_REL_TOL = 0.02    # t_p = pi / w_d: the w_n shift plus 1 ms of 0.31 s


def test_roll_step_matches_the_second_order_loop():
    """A 0.02 rad roll start with the position gains on x and y near zero (the desired
    attitude stays level) is J theta'' = -k_R sin(theta) - k_w theta' (RotorS'
    normalisation cancels the YAML inertia): a second-order loop with w_n = sqrt(k_R / J)
    and zeta = k_w / (2 sqrt(k_R J)). sin(0.02) differs from 0.02 by 7e-5 relative."""
    p = _vehicle()
    J, wn, zeta, theta0 = 0.03, 10.0, 0.25, 0.02
    lee = _lee(p, position_gain=[1e-9, 1e-9, 6.0], velocity_gain=[1e-9, 1e-9, 4.7],
               attitude_gain=[J * wn ** 2, 0.04 * wn ** 2, 0.07 * 4.0],
               angular_rate_gain=[2 * zeta * wn * J, 2 * zeta * wn * 0.04, 2 * 0.8 * 2 * 0.07])
    config = HoverConfig(duration_s=3.0, offset_m=(0.0, 0.0, 0.0), roll_rad=theta0,
                         sample_hz=1000.0)
    run = simulate_lee(p, lee, config, control_rate_hz=1000.0, record=True)
    t, roll = run.series["t_s"], run.series["roll_rad"]
    times, values = _extrema(t, roll)
    times, values = times[times > 0.01], values[times > 0.01]
    wd = wn * math.sqrt(1 - zeta ** 2)
    # overshoot (the first extremum past zero) and peak time
    assert -values[0] / theta0 == pytest.approx(math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2)),
                                                abs=OVERSHOOT_ABS_TOL)
    assert times[0] == pytest.approx(math.pi / wd, rel=PEAK_TIME_REL_TOL)
    # damping from the logarithmic decrement of successive extrema, w_n from their spacing
    dec = math.log(abs(values[0] / values[1]))
    zeta_sim = dec / math.sqrt(math.pi ** 2 + dec ** 2)
    wn_sim = math.pi / (times[1] - times[0]) / math.sqrt(1 - zeta_sim ** 2)
    assert zeta_sim == pytest.approx(zeta, abs=ZETA_ABS_TOL)
    assert wn_sim == pytest.approx(wn, rel=WN_REL_TOL)
    # settling into 5 %: the analytic curve's last exit (its 4th extremum, 0.039 theta0,
    # stays 22 % inside the band, so the exit is the 3rd one's descent, not a jump)
    fine = np.linspace(0, 3, 300001)
    ref = _second_order(fine, theta0, wn, zeta)
    settle_ref = fine[np.flatnonzero(np.abs(ref) > 0.05 * theta0)[-1]]
    settle_sim = t[np.flatnonzero(np.abs(roll) > 0.05 * theta0)[-1]]
    # the crossing moves with w_n (1 %) and zeta (0.02 of 0.25: 8 % in the decay rate,
    # applied over the ~1 / (zeta w_n) it takes): 1 % + 8 % of 0.4 s ~ 0.04 s
    assert settle_sim == pytest.approx(settle_ref, abs=0.04)


def test_altitude_step_matches_the_second_order_loop():
    """A 0.1 m altitude start, level: the thrust along body z is m_yaml g_c - k_z e_z -
    k_v z' exactly (R = I), so m z'' = -k_z e_z - k_v z' + m_yaml g_c - m g: a second-order
    loop about the offset e_ss = (m_yaml g_c - m g) / k_z (g_c = 9.81 is RotorS', g =
    9.80665 the plant's; no integral term removes it)."""
    p = _vehicle()
    m, wn, zeta, z0 = p.mass_kg, 2.0, 0.25, 0.1
    kz, kv = m * wn ** 2, 2 * zeta * wn * m
    lee = _lee(p, position_gain=[6.0, 6.0, kz], velocity_gain=[4.7, 4.7, kv],
               attitude_gain=[0.03 * 100, 0.04 * 100, 0.07 * 4.0],
               angular_rate_gain=[0.03 * 2 * 0.8 * 10, 0.04 * 2 * 0.8 * 10, 0.07 * 2 * 0.8 * 2])
    config = HoverConfig(duration_s=8.0, offset_m=(0.0, 0.0, z0), roll_rad=0.0,
                         sample_hz=1000.0)
    run = simulate_lee(p, lee, config, control_rate_hz=1000.0, record=True)
    t, z = run.series["t_s"], run.series["z_m"] - config.hover_altitude_m
    e_ss = (m * 9.81 - m * p.g_m_s2) / kz
    assert e_ss == pytest.approx(m * 0.00335 / kz)              # 1.3 mm, by hand
    # final value: the offset, to the decayed transient (z0 e^{-zeta wn 8} = 1.8e-3 m) plus
    # 0.1 mm
    assert z[-1] == pytest.approx(e_ss, abs=0.1 * math.exp(-zeta * wn * 8) + 1e-4)
    x = z - e_ss
    times, values = _extrema(t, x)
    times, values = times[times > 0.01], values[times > 0.01]
    x0 = z0 - e_ss
    wd = wn * math.sqrt(1 - zeta ** 2)
    # At w_n = 2 rad/s the 1.7 ms delay shifts zeta by 0.0017 and w_n by 0.09 %: half the
    # roll loop's tolerances still hold them 10x.
    assert -values[0] / x0 == pytest.approx(math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2)),
                                            abs=OVERSHOOT_ABS_TOL / 2)
    assert times[0] == pytest.approx(math.pi / wd, rel=PEAK_TIME_REL_TOL / 2)
    dec = math.log(abs(values[0] / values[1]))
    zeta_sim = dec / math.sqrt(math.pi ** 2 + dec ** 2)
    assert zeta_sim == pytest.approx(zeta, abs=ZETA_ABS_TOL / 2)
    assert math.pi / (times[1] - times[0]) / math.sqrt(1 - zeta_sim ** 2) == pytest.approx(
        wn, rel=WN_REL_TOL / 2)


# ------------------------------------------------------------------ validate --controller

GZ = __import__("pathlib").Path(__file__).parent / "fixtures" / "gz"
X3_GAINS = (GZ / "x3_lee_controller.yaml").read_text()
X3_VEHICLE = (GZ / "x3_rotors.yaml").read_text()


def validate_codes(tmp_path, gains=X3_GAINS, vehicle=X3_VEHICLE):
    (tmp_path / "lee_controller_x3.yaml").write_text(gains)
    (tmp_path / "x3.yaml").write_text(vehicle)
    code, output = run_cli("validate", GZ / "x3_quad.sdf", "--format", "json", "--controller",
                           tmp_path / "lee_controller_x3.yaml", "--controller",
                           tmp_path / "x3.yaml")
    report = json.loads(output)
    return code, report["findings"]


def test_validate_x3_gains_clean(tmp_path):
    code, findings = validate_codes(tmp_path)
    assert (code, findings) == (0, [])


@pytest.mark.parametrize("case,edit,expected", [
    ("negative", lambda g, v: (g.replace("attitude_gain: {x: 2.603", "attitude_gain: {x: -2.603"), v),
     ["C450"]),
    ("rate-1000x", lambda g, v: (g.replace("{x: 0.4511, y: 0.3345, z: 0.1043}",
                                           "{x: 451.1, y: 334.5, z: 104.3}"), v),
     ["C451", "C451", "C451"]),
    ("grams", lambda g, v: (g, v.replace("mass: 1.52", "mass: 1520")), ["C409", "C452"]),
    ("yaw-underdamped", lambda g, v: (g.replace("z: 0.1043", "z: 0.025"), v), ["C454"]),
    ("g-cm2", lambda g, v: (g, v.replace("xx: 0.0301535", "xx: 301535").replace(
        "yy: 0.0295235", "yy: 295235").replace("zz: 0.056631", "zz: 566310")), ["C410", "C453"]),
])
def test_validate_x3_broken(tmp_path, case, edit, expected):
    gains, vehicle = edit(X3_GAINS, X3_VEHICLE)
    assert (gains, vehicle) != (X3_GAINS, X3_VEHICLE)
    code, findings = validate_codes(tmp_path, gains, vehicle)
    assert sorted(f["code"] for f in findings) == expected
    # every finding is located in the file it is about, on the line of the value (found
    # by text here, like grep -n)
    key = {"C450": "attitude_gain", "C451": "angular_rate_gain", "C452": "mass:",
           "C454": "angular_rate_gain",
           "C409": "mass:", "C453": "inertia:", "C410": "inertia:"}
    for f in findings:
        lines = (tmp_path / __import__("pathlib").Path(f["file"]).name).read_text().splitlines()
        assert lines[f["line"] - 1].startswith(key[f["code"]])


def test_validate_names_degrees(tmp_path):
    import re

    vehicle = re.sub(r"angle: (-?[\d.]+)",
                     lambda m: f"angle: {math.degrees(float(m.group(1))):.4f}", X3_VEHICLE)
    code, findings = validate_codes(tmp_path, vehicle=vehicle)
    assert code == 1 and [f["code"] for f in findings] == ["C405"] * 4
    assert all("in degrees; RotorS reads radians" in f["hint"] for f in findings)


# ------------------------------------------------------------------ COM off the base origin

BATTERY_KG, BATTERY_X_M = 0.3, 0.08      # a battery strapped 8 cm forward, as users do
BATTERY_I = 1e-5                        # its own inertia, each axis [kg m^2]


def _with_battery(pkg, tmp_path):
    """A copy of the package with a battery link fixed to the base link, 8 cm forward."""
    import shutil

    copy = tmp_path / pkg.name
    shutil.copytree(pkg, copy)
    xacro = copy / "urdf" / f"{pkg.name}.xacro"
    battery = f"""
  <link name="${{namespace}}/battery">
    <inertial><origin xyz="0 0 0"/><mass value="{BATTERY_KG}"/>
      <inertia ixx="{BATTERY_I}" ixy="0" ixz="0" iyy="{BATTERY_I}" iyz="0" izz="{BATTERY_I}"/>
    </inertial>
  </link>
  <joint name="${{namespace}}/battery_joint" type="fixed">
    <parent link="${{namespace}}/base_link"/><child link="${{namespace}}/battery"/>
    <origin xyz="{BATTERY_X_M} 0 0" rpy="0 0 0"/>
  </joint>
</robot>"""
    text = xacro.read_text()
    xacro.write_text(text[:text.rindex("</robot>")] + battery.lstrip("\n") + "\n")
    return copy


def test_com_off_the_base_origin(packages, tmp_path):
    """With the COM 13 mm forward of the base origin, RotorS' allocation must measure the
    rotors from the COM: its torques are about that point, and the body turns about the
    COM. The vehicle file is rewritten by hand here for the new mass and inertia (parallel
    axis theorem) and with the rotors (a) from the base origin, (b) from the COM. (a) is
    named (C405, C406) and does not fly: no integral term, so the attitude loop holds the
    tilt error m g d / k_R that balances the COM's lever, and the position loop sits
    m g theta / k_x off (about 0.3 m here); (b) is clean and flies."""
    pkg = _with_battery(packages["quad-x"], tmp_path)
    v = yaml.safe_load((pkg / "config" / f"{pkg.name}.yaml").read_text())
    m0 = v["mass"]
    m = m0 + BATTERY_KG
    com_x = BATTERY_KG * BATTERY_X_M / m                       # 13.1 mm for the quad-x
    I = v["inertia"]
    # parallel axis: each part about the new COM (the old COM sits at -com_x, the battery
    # at BATTERY_X_M - com_x, both on the x axis)
    shift = m0 * com_x ** 2 + BATTERY_KG * (BATTERY_X_M - com_x) ** 2
    v["mass"] = m
    v["inertia"] = {**I, "xx": I["xx"] + BATTERY_I, "yy": I["yy"] + BATTERY_I + shift,
                    "zz": I["zz"] + BATTERY_I + shift}
    from_base = {k: dict(e) for k, e in v["rotor_configuration"].items()}
    from_com = {}
    for k, e in from_base.items():
        x = e["arm_length"] * math.cos(e["angle"]) - com_x
        y = e["arm_length"] * math.sin(e["angle"])
        from_com[k] = {**e, "angle": math.atan2(y, x), "arm_length": math.hypot(x, y)}
    g = (pkg / "config" / f"lee_controller_{pkg.name}.yaml").read_text()
    results = {}
    for label, rotors in (("base", from_base), ("com", from_com)):
        d = tmp_path / label
        d.mkdir()
        (d / f"lee_controller_{pkg.name}.yaml").write_text(g)
        (d / f"{pkg.name}.yaml").write_text(yaml.safe_dump({**v, "rotor_configuration": rotors}))
        results[label] = fly(pkg, d / f"lee_controller_{pkg.name}.yaml",
                             extra=("--duration", "10"))
    code, report = results["base"]
    assert code == 1 and report["verdict"]["status"] != "flies"
    assert sorted(codes(report) | codes(report, "warning")) == ["C405", "C406"]
    # C405 proposes, for each entry, the angle this test derived by hand about the COM
    import re
    for f in report["controller"]["preflight"]:
        if f["code"] == "C405":
            entry = re.search(r"rotor_configuration/(\d+)", f["message"]).group(1)
            proposed = float(re.search(r"set angle: (-?[\d.]+)", f["hint"]).group(1))
            assert proposed == pytest.approx(from_com[entry]["angle"], abs=1e-5)
    code, report = results["com"]
    assert [f["code"] for f in report["controller"]["preflight"]] == []
    assert code == 0 and report["verdict"]["status"] == "flies", report["message"]


def test_mass_5_percent_low_hovers_low_and_says_so(packages, tmp_path):
    """RotorS' pelican.yaml shape: the file's mass 5 % below the model's. No integral term,
    so it hovers (m_file 9.81 - m 9.80665) / k_z off the height it is sent (by hand below);
    hover-test names C409, reports that offset, and judges the flight about it."""
    pkg = packages["quad-x"]

    def light(v):
        v["mass"] = round(v["mass"] * 0.95, 6)

    gpath, vpath = broken_copy(pkg, tmp_path, vehicle=light)
    code, report = fly(pkg, gpath)
    c = report["controller"]
    m, m_file = c["model_mass_kg"], yaml.safe_load(vpath.read_text())["mass"]
    k_z = yaml.safe_load(gpath.read_text())["position_gain"]["z"]
    by_hand = (m_file * 9.81 - m * 9.80665) / k_z          # about -12 cm
    assert c["predicted_altitude_offset_m"] == pytest.approx(by_hand, rel=1e-3)
    assert c["judged_about_offset"] and "C409" in codes(report, "warning")
    assert code == 0 and report["verdict"]["status"] == "flies"
    # it settled where the formula says: judged about that height, within the 5 cm band
    assert report["sim"]["final_position_error_m"] < 0.05


def test_bad_controller_input_is_one_line_exit_2(packages, tmp_path):
    pkg = packages["quad-x"]
    gains = pkg / "config" / f"lee_controller_{pkg.name}.yaml"
    lonely = tmp_path / "lee_controller_other.yaml"          # no other.yaml beside it
    lonely.write_text(gains.read_text())
    for args, fragment in (
            (("--controller", tmp_path / "missing.yaml"), "controller file not found"),
            (("--controller", lonely), "no rotor_configuration"),
            (("--controller", gains, "--samples", "3"), "--samples with --controller"),
            (("--controller", gains, "--engine", "numba"), "--engine numba with --controller"),
            (("--controller", gains, "--controller-rate", "5000"), "faster than"),
    ):
        code, output = run_cli("hover-test", model_of(pkg), *args)
        assert code == 2 and fragment in output, output
        assert "Traceback" not in output


def test_rotors_own_firefly_files_fly_the_firefly():
    """RotorS' authors tuned lee_controller_firefly.yaml on their Firefly in Gazebo; the
    same files (fixtures in their shape) fly the Firefly-shaped model (tests/fixtures/
    migrate/firefly_hex.xacro; its base inertia breaks the triangle inequality as
    RotorS' does, hence --ignore I203). RotorS' file says 1.56779 kg, the model weighs
    1.53 kg (body 1.5 + six 5 g rotors): by hand it hovers (1.56779 * 9.81 - 1.53 *
    9.80665) / 6 = 6.3 cm high, which the report says and C409 names."""
    fixtures = __import__("pathlib").Path(__file__).parent / "fixtures"
    model = fixtures / "migrate" / "firefly_hex.xacro"
    code, output = run_cli("hover-test", model, "--ignore", "I203", "--format", "json",
                           "--controller", fixtures / "rotors_lee" / "lee_controller_firefly.yaml",
                           "--yaw", "0.3")
    report = json.loads(output)
    c = report["controller"]
    assert c["files"][-1].endswith("rotors_lee/firefly.yaml")   # found beside the gains
    m = c["model_mass_kg"]
    assert m == pytest.approx(1.5 + 6 * 0.005)
    assert c["predicted_altitude_offset_m"] == pytest.approx(
        (1.56779 * 9.81 - m * 9.80665) / 6, rel=1e-6)
    assert [f["code"] for f in c["preflight"]] == ["C409"]
    assert code == 0 and report["verdict"]["status"] == "flies", report["message"]


@pytest.mark.parametrize("frame", FRAMES)
def test_shipped_allocation_is_the_models(packages, frame):
    """common.h's allocation from the shipped NAME.yaml (per rotor speed squared, divided
    by k_F: torque per newton of thrust) against reedtool.physics.allocation's from the
    model's motor plugins (lever about the COM, drag reaction -turning_sign k_M T): a
    second derivation of the same matrix from the other file, so a sign convention
    (angle, direction) read wrong in either shows. Equal to 1e-9 m (the YAML's 10
    significant digits)."""
    from reedtool.workflows.lee_flight import entry_of_rotor, rotors_lee_of
    from reedtool.workflows.vehicle import Vehicle
    from reedtool.flightstack.rotors_lee import load_lee_parameters
    from reedtool.io.loader import load_robot
    from reedtool.physics.allocation import allocation_matrix

    pkg = packages[frame]
    vehicle = Vehicle.of(load_robot(model_of(pkg)))
    lee = rotors_lee_of(load_lee_parameters([pkg / "config" / f"lee_controller_{pkg.name}.yaml"]))
    B = allocation_matrix(vehicle.rotors, vehicle.props.com_m)       # rotor order
    A = lee.allocation() / lee.force_constant                        # entry order
    entries = entry_of_rotor(vehicle.rotors)
    # rows: RotorS [roll, pitch, yaw, thrust], physics [thrust, roll, pitch, yaw]
    np.testing.assert_allclose(A[[3, 0, 1, 2]][:, entries], B, atol=1e-9)


def test_unset_gains_take_rotors_defaults_and_say_so(packages, tmp_path):
    """The node keeps its compiled-in default (lee_position_controller.h: attitude 3, 3,
    0.035) for a gain the files do not set; the report lists it."""
    def drop(g):
        del g["attitude_gain"]

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path, gains=drop),
                       extra=("--duration", "10"))
    notes = " ".join(report["controller"]["notes"])
    assert "attitude_gain/x, attitude_gain/y, attitude_gain/z" in notes
    assert report["sim"]["gains"]["attitude_gain"] == [3.0, 3.0, 0.035]


def test_a_missing_entry_leaves_its_motor_stopped(packages, tmp_path):
    """Three entries for four motors: RotorS publishes three speeds and motor 3's plugin
    refuses the index, so that motor gets nothing; C401 names it and it cannot hover."""
    def drop(v):
        del v["rotor_configuration"]["3"]

    code, report = fly(packages["quad-x"], *broken_copy(packages["quad-x"], tmp_path, vehicle=drop),
                       extra=("--duration", "10"))
    assert code == 1 and "C401" in codes(report)
    assert report["sim"]["status"] == "crashed"
