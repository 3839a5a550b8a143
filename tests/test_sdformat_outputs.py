"""Every SDF the test fixtures hold and `new-package` writes, judged by libsdformat (through
Drake's parser, tests/sdformat_oracle.py), not by reedtool's own reader.

* A fixture libsdformat loads is loadable; one it refuses must be one validate refuses too
  (an error, or exit 2 for an include it cannot read). Two refusals depend on the
  libsdformat release rather than on the file's SDF version, and validate warns there by
  design (docs/rules.md): S124 (a comment before the XML declaration: TinyXML2, so
  libsdformat 10+, refuses; Gazebo classic's TinyXML reads it) and S125 (a 3-number pose:
  libsdformat 12+ refuses, 9 reads a position). Drake-only refusals are told apart by
  `sdformat_oracle.drake_only_reason`. A material `<script>` without `<uri>` is refused
  by the libsdformat DOM gz-sim loads and not by Gazebo classic; validate reports it
  (S170) for models with gz-sim systems, so a fixture made for Classic may be refused
  here while validate is silent (PX4's Classic models name their materials so).
* Every `.sdf`/`.world` that `new-package` writes, for every simulator, ROS version and
  autopilot it accepts, loads, with the package's `models/` folders as model paths. The
  robot itself is a URDF/xacro spawned into the world (check_urdf judges it in
  test_new_package*.py); what is SDF here is the world.

Stripped before loading, and only here: a world's `<include>` of a Fuel URL (https://):
there is no network in the tests, and Fuel models are Gazebo's, not reedtool's.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from cli_helpers import run_cli
from lxml import etree

from reedtool.checks.runner import run_checks
from reedtool.errors import ReedtoolError
from reedtool.io.loader import load_robots

FIXTURES = Path(__file__).parent / "fixtures"
SDF_FIXTURES = sorted(p for p in FIXTURES.rglob("*") if p.suffix in (".sdf", ".world"))
# Refused by libsdformat 10+/12+ only, where validate warns (see the module docstring).
RELEASE_DEPENDENT = {"S124", "S125"}
# The libsdformat DOM's refusal of a Classic named material, which Gazebo classic (the
# model's simulator) does not load through the DOM; S170 reports it for gz-sim models.
CLASSIC_MATERIAL = r"A <script> element is missing a child <uri> element"
# libsdformat 12+ (gz-sim) refuses a joint naming its own model's link by the scoped name
# `model::link` in a file before SDF 1.8; Gazebo classic resolves it (World::BaseByName).
# validate is silent on a Classic model and warns (S191) where the model targets gz-sim.
CLASSIC_SCOPED_NAME = r"frame with name\[[^\]]*::[^\]]*\] specified by joint"


def _model_dirs(path: Path) -> list[Path]:
    """Folders of model folders a fixture's `model://` URIs name: its model's parent (PX4
    layout, models/NAME/model.sdf) and the PX4-shaped models of px4_gz."""
    dirs = [path.parent.parent, FIXTURES / "px4_gz" / "models"]
    return [d for d in dirs if d.is_dir()]


def _fuel_stripped(path: Path) -> str | None:
    """The file's text without Fuel includes, or None when it has none."""
    text = path.read_text()
    if "https://" not in text and "http://" not in text:
        return None
    root = etree.fromstring(text.encode())
    for include in list(root.iter("include")):
        if (include.findtext("uri") or "").strip().startswith(("http://", "https://")):
            include.getparent().remove(include)
    return etree.tostring(root, encoding="unicode")


def _libsdformat_error(path: Path) -> str | None:
    import sdformat_oracle

    stripped = _fuel_stripped(path)
    if stripped is not None:
        return sdformat_oracle.libsdformat_error_text(stripped, _model_dirs(path))
    return sdformat_oracle.libsdformat_error(path, _model_dirs(path))


def _declared_version(path: Path) -> str | None:
    try:
        return etree.parse(str(path)).getroot().get("version")
    except etree.XMLSyntaxError:
        return None


def _validate(path: Path) -> tuple[set[str], set[str]]:
    """(error codes, warning codes) validate reports; an exit-2 refusal is an error."""
    try:
        findings = [f for robot in load_robots(path) for f in run_checks(robot)]
    except ReedtoolError as exc:
        return {f"refused: {exc.message}"}, set()
    return ({f.code for f in findings if f.severity == "error"},
            {f.code for f in findings if f.severity == "warning"})


@pytest.mark.parametrize("path", SDF_FIXTURES, ids=[str(p.relative_to(FIXTURES))
                                                    for p in SDF_FIXTURES])
def test_fixture_loads_in_libsdformat_or_validate_refuses_it(path):
    import sdformat_oracle

    error = _libsdformat_error(path)
    if error is None:
        return
    reason = sdformat_oracle.drake_only_reason(error, _declared_version(path))
    if reason:
        return   # Drake refuses what libsdformat, as Gazebo runs it, accepts (`reason`)
    errors, warnings = _validate(path)
    if not errors and re.search(CLASSIC_MATERIAL, error):
        return   # a Classic model's named material: S170 reports it in gz models only
    version = _declared_version(path) or "1.0"
    if not errors and re.search(CLASSIC_SCOPED_NAME, error) \
            and tuple(int(v) for v in version.split(".")) < (1, 8):
        from reedtool.checks.context import CheckContext

        classic = all(CheckContext(robot).simulator == "classic" for robot in load_robots(path))
        if "S191" in warnings or classic:
            return   # Classic's scoped name: fine in Classic, S191 where gz-sim is meant
    assert errors or warnings & RELEASE_DEPENDENT, \
        f"libsdformat refuses {path.name} and validate calls it clean: {error[:300]}"


def test_the_structural_fixtures_are_what_libsdformat_says():
    """Each S160-S168, S170 and S171 bad fixture is refused by libsdformat, each good one
    accepted (or refused by Drake alone, for the reason named)."""
    import sdformat_oracle

    checked = 0
    for path in sorted([*(FIXTURES / "validate").glob("S16*.sdf"),
                        *(FIXTURES / "validate").glob("S17[01]_*.sdf")]):
        error = _libsdformat_error(path)
        refused = error is not None and not sdformat_oracle.drake_only_reason(
            error, _declared_version(path))
        assert refused == ("_bad_" in path.name), (path.name, error)
        checked += 1
    assert checked >= 16


# new-package's accepted combinations: gz needs ROS 2 and a multirotor; --autopilot a
# multirotor. Classic packages write URDF/xacro only: none of them may write a refused SDF.
NEW_PACKAGE_CASES = [
    *[("2", "gz", autopilot, frame) for autopilot in (None, "px4", "ardupilot")
      for frame in ("quad-x", "hex-plus", "octo-x", "y6")],
    # (--autopilot ardupilot on Classic is refused: ardupilot_gazebo needs Gazebo Sim)
    *[(ros, "classic", autopilot, "quad-x") for ros in ("1", "2")
      for autopilot in (None, "px4")],
    ("1", "classic", None, "car-4w"),
    ("2", "classic", None, "diff-drive"),
]


@pytest.mark.parametrize("ros, sim, autopilot, frame", NEW_PACKAGE_CASES)
def test_every_sdf_new_package_writes_loads_in_libsdformat(tmp_path, ros, sim, autopilot,
                                                          frame):
    import sdformat_oracle

    args = ["new-package", "pkg", "--ros", ros, "--sim", sim, "--frame", frame,
            "-o", tmp_path, "--mass", "1.5"]
    if frame not in ("car-4w", "diff-drive"):
        args += ["--arm-length", "0.3"]
    if autopilot:
        args += ["--autopilot", autopilot]
    code, output = run_cli(*args)
    assert code == 0, output
    package = tmp_path / "pkg"
    written = sorted(p for p in package.rglob("*") if p.suffix in (".sdf", ".world"))
    if sim == "gz":
        assert written, "a gz package writes its world as SDF"
    model_dirs = [p for p in package.rglob("models") if p.is_dir()]
    for path in written:
        error = sdformat_oracle.libsdformat_error(path, model_dirs)
        # Drake's own refusals (an element libsdformat copies with a warning, such as
        # PX4's <gz_frame_id>) are Drake's: drake_only_reason names them.
        assert error is None or sdformat_oracle.drake_only_reason(
            error, _declared_version(path)), f"{path.relative_to(tmp_path)}: {error}"
