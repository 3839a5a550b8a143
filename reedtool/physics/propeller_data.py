"""Published propeller and motor data `new-package --prop/--motor` derives from, with sources.

Propellers: static (zero airspeed) thrust and power coefficients measured in the UIUC
Propeller Data Site, Volume 1 (J.B. Brandt, R.W. Deters, G.K. Ananda, O.D. Dantsker and
M.S. Selig, University of Illinois at Urbana-Champaign; Brandt & Selig, "Propeller
Performance Data at Low Reynolds Numbers", AIAA 2011-1255), rows transcribed from the
static files named below (columns RPM, CT, CP; CT = T / (rho n^2 D^4), CP = P / (rho n^3 D^5),
n in rev/s). Only two-blade APC Slow Flyer propellers of multirotor size are tabulated:
the coefficients are dimensionless, so another propeller of the same shape and
pitch-to-diameter ratio keeps them (up to Reynolds-number effects: CT rises ~20 % from
2,400 to 6,500 rpm in the 10x4.7 file below), but a propeller of another family does not.

Motors: a named motor is its product name and the KV rating in it (rpm per volt, no load),
from the manufacturer's product page named in `source`.
"""

from __future__ import annotations

from dataclasses import dataclass

UIUC_VOLUME_1 = "https://m-selig.ae.illinois.edu/props/volume-1/data/"


@dataclass(frozen=True)
class StaticRow:
    rpm: float
    ct: float
    cp: float


@dataclass(frozen=True)
class PropellerData:
    name: str
    diameter_in: float
    pitch_in: float
    file: str                          # the UIUC data file the rows are from
    rows: tuple[StaticRow, ...]
    # APC's published maximum speed for its Slow Flyer line: 65,000 / D[in] rpm
    # (apcprop.com, "RPM limits"); thin blades flex beyond it.
    max_rpm: float

    @property
    def source(self) -> str:
        return f"UIUC Propeller Data Site vol. 1, {self.file}"

    @property
    def url(self) -> str:
        return UIUC_VOLUME_1 + self.file


def _rows(*values: tuple[float, float, float]) -> tuple[StaticRow, ...]:
    return tuple(StaticRow(*v) for v in values)


APC_SF_LIMIT_RPM_IN = 65_000.0

PROPELLERS: tuple[PropellerData, ...] = (
    PropellerData("APC Slow Flyer 9x4.7", 9.0, 4.7, "apcsf_9x4.7_static_kt1032.txt", _rows(
        (2763, 0.1137, 0.0481), (3062, 0.1152, 0.0482), (3310, 0.1152, 0.0481),
        (3622, 0.1158, 0.0480), (3874, 0.1159, 0.0480), (4153, 0.1163, 0.0480),
        (4422, 0.1170, 0.0481), (4687, 0.1176, 0.0482), (4942, 0.1175, 0.0481),
        (5226, 0.1184, 0.0484), (5473, 0.1189, 0.0484), (5736, 0.1190, 0.0484),
        (6026, 0.1192, 0.0484), (6285, 0.1192, 0.0483), (6554, 0.1195, 0.0483),
        (6768, 0.1199, 0.0483)), APC_SF_LIMIT_RPM_IN / 9.0),
    PropellerData("APC Slow Flyer 10x4.7", 10.0, 4.7, "apcsf_10x4.7_static_kt0835.txt", _rows(
        (2377, 0.1059, 0.0431), (2676, 0.1079, 0.0437), (2947, 0.1079, 0.0437),
        (3234, 0.1104, 0.0444), (3494, 0.1117, 0.0450), (3762, 0.1143, 0.0460),
        (4029, 0.1158, 0.0466), (4319, 0.1177, 0.0474), (4590, 0.1200, 0.0484),
        (4880, 0.1223, 0.0494), (5147, 0.1237, 0.0500), (5417, 0.1252, 0.0508),
        (5715, 0.1263, 0.0513), (5960, 0.1278, 0.0520), (6226, 0.1286, 0.0524),
        (6528, 0.1299, 0.0531)), APC_SF_LIMIT_RPM_IN / 10.0),
    PropellerData("APC Slow Flyer 11x4.7", 11.0, 4.7, "apcsf_11x4.7_static_pg0526.txt", _rows(
        (1666, 0.0986, 0.0392), (2018, 0.1005, 0.0391), (2271, 0.1022, 0.0396),
        (2556, 0.1042, 0.0401), (2875, 0.1059, 0.0407), (3144, 0.1074, 0.0411),
        (3423, 0.1091, 0.0418), (3728, 0.1114, 0.0426), (3994, 0.1128, 0.0432),
        (4290, 0.1151, 0.0442), (4585, 0.1174, 0.0452), (4853, 0.1191, 0.0460),
        (5175, 0.1209, 0.0468), (5450, 0.1230, 0.0477), (5710, 0.1249, 0.0486),
        (6021, 0.1259, 0.0493)), APC_SF_LIMIT_RPM_IN / 11.0),
)


@dataclass(frozen=True)
class MotorData:
    key: str             # what --motor takes
    name: str
    kv_rpm_per_v: float
    source: str


# Common multirotor motors; the KV is part of each product's name and datasheet.
MOTORS: tuple[MotorData, ...] = (
    MotorData("dji-2212-920", "DJI 2212 920KV (F450/F550 E300 system)", 920.0,
              "DJI E300 propulsion system specifications"),
    MotorData("sunnysky-x2212-980", "SunnySky X2212 KV980", 980.0,
              "SunnySky X2212 product page"),
    MotorData("tmotor-mn2212-920", "T-Motor MN2212 KV920", 920.0,
              "T-Motor MN2212 product page"),
    MotorData("tmotor-mn3110-700", "T-Motor MN3110 KV700", 700.0,
              "T-Motor MN3110 product page"),
    MotorData("emax-mt2213-935", "EMAX MT2213 935KV", 935.0, "EMAX MT2213 product page"),
)
