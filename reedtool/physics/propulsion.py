"""Motor, propeller and battery -> the RotorS motor constants, each with where it came from.

RotorS' motor model (and PX4's and gz-sim's MulticopterMotorModel) pushes
T = motorConstant * omega^2 along the rotor axis and turns the body by
Q = momentConstant * T about it, omega capped at maxRotVelocity [rad/s]. From a propeller's
static coefficients (UIUC: T = CT rho n^2 D^4, P = CP rho n^3 D^5, n = omega / 2 pi):

    motorConstant  k_f = CT rho D^4 / (4 pi^2)            [N / (rad/s)^2]
    momentConstant k_m = Q / T = CP D / (2 pi CT)         [m]   (Q = P / omega)

CT and CP are read at the full-throttle speed (interpolated between the measured rows,
the last row held beyond them): one constant cannot follow CT's rise with speed, and the
top of the range is where thrust-to-weight, the number the hover checks judge, is set.

The full-throttle speed: a brushless motor turns at KV x (back-EMF), and the back-EMF is
the supply voltage less the I R drop in winding, ESC, wiring and the pack itself, so
omega_max = eta KV V with eta = 1 - I R / V, the back-EMF share of the supply. At a
2212-class motor's rated 20-28 A its 0.05-0.10 ohm winding alone drops 1-3 V of 11.1 V
(eta 0.75-0.90); ESC, connectors and the pack's sag under four motors' current take it
down to ~0.6 for a motor at or past its rating. LOADED_SPEED_FACTOR takes 0.80, and the
band is printed with it (thrust goes with its square).
V is the pack's nominal voltage, 3.7 V per LiPo cell
(4.2 V full, ~3.5 V near empty under load).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from reedtool.errors import ReedtoolError
from reedtool.physics.propeller_data import MOTORS, PROPELLERS, MotorData, PropellerData

# ISA sea-level density, the one UIUC reduces its coefficients with.
AIR_DENSITY_KG_M3 = 1.225
INCH_M = 0.0254
LIPO_NOMINAL_V_PER_CELL = 3.7
LOADED_SPEED_FACTOR = 0.80
LOADED_SPEED_BAND = (0.60, 0.90)
RPM_TO_RAD_S = 2.0 * math.pi / 60.0
# A propeller is "the same" as a tabulated one when its diameter is within this fraction
# and its pitch-to-diameter ratio within PITCH_RATIO_TOL: the static coefficients of APC's
# slow-flyer family at P/D 0.43-0.52 (the three files) differ by less than their own
# 2,000-6,500 rpm spread (CT 0.106-0.130), so a prop inside that neighbourhood is
# represented within that spread; farther, another blade shape is guessed.
DIAMETER_TOL = 0.10
PITCH_RATIO_TOL = 0.05
# RotorS firefly's motor model, new-package's defaults without --motor/--prop/--battery.
FIREFLY = {"motor_constant": 8.54858e-06, "moment_constant": 0.016, "max_rot_velocity": 838.0,
           "time_constant_up": 0.0125, "time_constant_down": 0.025}


@dataclass(frozen=True)
class Derived:
    """One constant, its unit and how it was obtained."""

    value: float
    unit: str
    source: str


@dataclass(frozen=True)
class Propulsion:
    motor: MotorData
    propeller: PropellerData
    diameter_in: float                # what the user named (may differ from the table's)
    pitch_in: float
    cells: int
    voltage_V: float
    match: str                        # how the user's propeller maps onto the table
    constants: dict[str, Derived]     # package_spec keys -> value with its source

    @property
    def radius_m(self) -> float:
        return self.diameter_in * INCH_M / 2.0

    def max_thrust_N(self) -> float:
        return self.constants["motor_constant"].value * self.constants["max_rot_velocity"].value ** 2


# ------------------------------------------------------------------ reading the options

_PROP = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*[x×*]\s*(\d+(?:\.\d+)?)\s*(?:in)?\s*$", re.I)
_APC_CODE = re.compile(r"^\s*(\d{2})(\d{2})\s*$")        # 1047 -> 10 x 4.7 (APC naming)
_CELLS = re.compile(r"^\s*(\d+)\s*s(?:\s*\d+\s*p)?\s*$", re.I)
_KV = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(?:kv)?\s*$", re.I)


def parse_propeller(text: str) -> tuple[float, float]:
    """'10x4.7' (inches, diameter x pitch), '10x4.7in' or APC's '1047' -> (10.0, 4.7)."""
    match = _PROP.match(str(text))
    if match:
        diameter, pitch = float(match.group(1)), float(match.group(2))
    elif _APC_CODE.match(str(text)):
        code = _APC_CODE.match(str(text))
        diameter, pitch = float(code.group(1)), float(code.group(2)) / 10.0
    else:
        raise ReedtoolError(f"--prop '{text}': expected DIAMETERxPITCH in inches, e.g. 10x4.7")
    if not (1.0 <= diameter <= 80.0 and 0.5 <= pitch <= diameter):
        raise ReedtoolError(f"--prop '{text}': a {diameter:g} in propeller of {pitch:g} in "
                            "pitch is no multirotor propeller",
                            hint="diameter x pitch in inches, e.g. 10x4.7")
    return diameter, pitch


def parse_battery(text: str) -> int:
    """'4S', '4s', '4S2P' or '4' -> 4 LiPo cells in series."""
    text = str(text)
    match = _CELLS.match(text) or re.match(r"^\s*(\d+)\s*$", text)
    cells = int(match.group(1)) if match else 0
    if not 1 <= cells <= 24:
        raise ReedtoolError(f"--battery '{text}': expected LiPo cells in series, 1S to 24S, "
                            "e.g. 4S")
    return cells


def parse_motor(text: str) -> MotorData:
    """A KV ('920', '920kv') or a named motor of MOTORS."""
    text = str(text).strip()
    named = {m.key: m for m in MOTORS}
    if text.lower() in named:
        return named[text.lower()]
    match = _KV.match(text)
    if match:
        kv = float(match.group(1))
        if not 50.0 <= kv <= 20_000.0:
            raise ReedtoolError(f"--motor {text}: KV {kv:g} rpm/V is outside brushless "
                                "multirotor motors (50-20,000)")
        return MotorData(f"{kv:g}kv", f"a {kv:g} KV motor", kv, "--motor")
    import difflib

    close = difflib.get_close_matches(text.lower(), list(named), n=1)
    raise ReedtoolError(f"--motor '{text}': not a KV nor a motor reedtool knows",
                        hint=(f"did you mean '{close[0]}'? " if close else "")
                        + "give the KV (e.g. --motor 920) or one of: " + ", ".join(named))


# ------------------------------------------------------------------ the derivation

def find_propeller(diameter_in: float, pitch_in: float) -> tuple[PropellerData, str]:
    """The tabulated propeller the user's stands for, and how close it is."""
    ratio = pitch_in / diameter_in

    def distance(p: PropellerData) -> float:
        return abs(p.diameter_in / diameter_in - 1.0) + abs(p.pitch_in / p.diameter_in - ratio)

    best = min(PROPELLERS, key=distance)
    if best.diameter_in == diameter_in and best.pitch_in == pitch_in:
        return best, "measured"
    if abs(best.diameter_in / diameter_in - 1.0) <= DIAMETER_TOL \
            and abs(best.pitch_in / best.diameter_in - ratio) <= PITCH_RATIO_TOL:
        return best, (f"the nearest measured propeller, {best.diameter_in:g}x{best.pitch_in:g} "
                      f"(pitch/diameter {best.pitch_in / best.diameter_in:.2f} vs {ratio:.2f}); "
                      "coefficients are dimensionless, so its CT and CP are used with your "
                      f"{diameter_in:g} in diameter")
    known = ", ".join(f"{p.diameter_in:g}x{p.pitch_in:g}" for p in PROPELLERS)
    raise ReedtoolError(
        f"--prop {diameter_in:g}x{pitch_in:g}: no published static data near it in reedtool's "
        f"table (UIUC-measured APC Slow Flyer {known})",
        hint="give the constants from your own thrust-stand data instead: motor_constant, "
             "moment_constant and max_rot_velocity in a --spec file")


def coefficients_at(prop: PropellerData, rpm: float) -> tuple[float, float, str]:
    """(CT, CP, where) at `rpm`: linear between measured rows, the end row beyond them."""
    rows = prop.rows
    if rpm <= rows[0].rpm:
        return rows[0].ct, rows[0].cp, f"the lowest measured row, {rows[0].rpm:g} rpm"
    if rpm >= rows[-1].rpm:
        return rows[-1].ct, rows[-1].cp, f"the highest measured row, {rows[-1].rpm:g} rpm"
    for lo, hi in zip(rows, rows[1:]):
        if lo.rpm <= rpm <= hi.rpm:
            t = (rpm - lo.rpm) / (hi.rpm - lo.rpm)
            return (lo.ct + t * (hi.ct - lo.ct), lo.cp + t * (hi.cp - lo.cp),
                    f"interpolated at {rpm:.0f} rpm")
    raise AssertionError("rows are sorted by rpm")


def thrust_N(ct: float, rpm: float, diameter_m: float) -> float:
    n = rpm / 60.0
    return ct * AIR_DENSITY_KG_M3 * n * n * diameter_m ** 4


def derive(motor: MotorData, diameter_in: float, pitch_in: float, cells: int) -> Propulsion:
    """The constants RotorS needs for this motor, propeller and LiPo pack."""
    prop, match = find_propeller(diameter_in, pitch_in)
    voltage = cells * LIPO_NOMINAL_V_PER_CELL
    rpm_max = LOADED_SPEED_FACTOR * motor.kv_rpm_per_v * voltage
    ct, cp, where = coefficients_at(prop, rpm_max)
    D = diameter_in * INCH_M
    k_f = ct * AIR_DENSITY_KG_M3 * D ** 4 / (4.0 * math.pi ** 2)
    k_m = cp * D / (2.0 * math.pi * ct)
    low, high = LOADED_SPEED_BAND
    coeffs = f"CT {ct:.4f}, CP {cp:.4f} of the {prop.name} ({prop.source}, {where})"
    constants = {
        "motor_constant": Derived(k_f, "N/(rad/s)^2",
                                  f"CT rho D^4 / 4 pi^2 with {coeffs}, rho "
                                  f"{AIR_DENSITY_KG_M3} kg/m^3, D {D:.4g} m"),
        "moment_constant": Derived(k_m, "m", f"CP D / (2 pi CT) with the same CT and CP"),
        "max_rot_velocity": Derived(
            rpm_max * RPM_TO_RAD_S, "rad/s",
            f"{LOADED_SPEED_FACTOR:g} x KV {motor.kv_rpm_per_v:g} ({motor.source}) x "
            f"{voltage:.3g} V ({cells}S LiPo at {LIPO_NOMINAL_V_PER_CELL} V/cell) = "
            f"{rpm_max:.0f} rpm; {LOADED_SPEED_FACTOR:g} is the back-EMF share of the "
            f"supply at full throttle ({low:g} for a motor past its rated current to "
            f"{high:g} lightly loaded: "
            f"{low * motor.kv_rpm_per_v * voltage * RPM_TO_RAD_S:.0f}-"
            f"{high * motor.kv_rpm_per_v * voltage * RPM_TO_RAD_S:.0f} rad/s)"),
        "time_constant_up": Derived(FIREFLY["time_constant_up"], "s",
                                    "RotorS firefly's (not derived: set by the ESC's speed "
                                    "loop and the rotor's inertia, which reedtool is not told)"),
        "time_constant_down": Derived(FIREFLY["time_constant_down"], "s",
                                      "RotorS firefly's (as time_constant_up)"),
    }
    if rpm_max > prop.max_rpm:
        match += (f"; {rpm_max:.0f} rpm is above APC's {prop.max_rpm:.0f} rpm limit for "
                  "this slow-flyer size (65,000 / D[in]): a lower KV, fewer cells or a "
                  "stiffer propeller")
    return Propulsion(motor, prop, diameter_in, pitch_in, cells, voltage, match, constants)
