"""The one reading of a CAD mesh's units and axes, for every command that takes a mesh.

STL and OBJ carry no unit and no "up". A CAD tool writes numbers in its document unit
(SolidWorks: mm or inch; Onshape: m; Fusion: cm or mm) and in its own axes (SolidWorks
and glTF: Y up; PX4 and aerospace: NED/FRD, Z down). Guessing from the size alone takes a
15-inch frame exported in inches for a 15 mm body. So each unit is judged by every cue the
command has:

- size: the mesh's largest extent must be that of a multirotor part (or body);
- density: the declared mass over the mesh's volume must be one a drone body can have;
- arm length: the rotor circle must be of the body's size, within the factors below.

Exactly one unit passing every cue is taken, and the reasons are printed. None, or more
than one, is a refusal that names the choices and the flag that settles it. Axes: a body
is thinnest in height and is drawn upward from its CAD origin; a mesh read in the assumed
axes that says otherwise is refused, naming the conventions its extents fit.

`import-stl` and `new-package --mesh` call `choose_units` and `choose_axes` (through
physics.mesh_import.import_mesh); nothing else guesses a mesh's units or axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.frames import ALIASES, RIGHT_HANDED_CODES, AxisConvention, axis_convention

UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}

# Largest extent a mesh can have, per role.
# - part (import-stl on its own): from a 1 cm screw to a 5 m airframe.
# - body (the vehicle's body, new-package --mesh): from a 65 mm tiny-whoop frame's
#   body (3 cm) to the largest multirotors that exist (DJI Agras T50: 2.8 m across the
#   unfolded arms): 0.03 .. 3 m.
# - link (a mesh in a model validate reads): a part's sizes.
SIZE_M = {"part": (0.01, 5.0), "body": (0.03, 3.0), "link": (0.01, 5.0)}

# Mean density of a mesh filled uniformly with the declared mass [kg/m^3].
# Lower: a closed shell filled uniformly counts the air inside as body. A DJI Phantom 4
#   (1.38 kg, shell about 0.29 x 0.29 x 0.19 m, half of it air around the shell: ~8 L)
#   averages ~170 kg/m^3; a Matrice 300 body (3.6 kg without battery, ~0.43 x 0.43 x 0.2 m,
#   half filled: ~18 L) ~200. Ten times emptier than those is 17; the bound is 10, still
#   above expanded-polystyrene foam's 10-30 for the shell alone.
# Upper, a part (its own mass): osmium, the densest matter at room conditions (22,590).
# Upper, a body: the mesh may be the frame alone while the mass is the whole body's
#   (battery, motors, electronics on it). A 450-class frame's two 2 mm carbon plates are
#   about 40 cm^3 under a 1.5 kg body: 37,500 kg/m^3; 1e5 leaves room for lighter frames
#   under heavier bodies. The window is still 1e4 wide, less than the 16,387 between mm
#   and inch: density alone always tells those two apart.
#   A link's mesh in a model is judged as a body: its <mass> may be more than the mesh's own.
DENSITY_KG_M3 = {"part": (10.0, 22_590.0), "body": (10.0, 1e5), "link": (10.0, 1e5)}

# Motor mounts found in the mesh (physics.motor_mounts) against the arm length given: the
# unit that puts the mounts under the rotors. Units differ by 2.54x at least; a rotor
# circle within 15 % of the mounts' is the same circle, not another unit's.
MOUNTS_TO_ARM = 0.15

# Rotor circle radius (centre to rotor axis) over the body's half-span (largest extent / 2).
# Lower: a body may reach past its rotors (a VTOL's wing spans 2 m over rotors 0.5 m out:
#   1/2); no multirotor body is 5 times wider than its rotor circle: 1/5.
# Upper: a body mesh of the hub alone (arms drawn separately): a 450 mm frame's 60 mm hub
#   gives 0.225 / 0.03 = 7.5; 12 leaves room for smaller hubs, not for a unit slip of 10
#   on top of it.
ARM_OVER_HALF_SPAN = (1.0 / 5.0, 12.0)

UNIT_ORDER = ("mm", "in", "cm", "m")     # how the choices are listed


@dataclass(frozen=True)
class UnitChoice:
    unit: str
    metres_per_unit: float
    reason: str
    guessed: bool
    note: str | None = None          # a given unit the cues disagree with


@dataclass(frozen=True)
class UnitCues:
    """What a mesh offers to judge its unit by, in its own (file) units."""

    largest_extent: float            # file units
    volume: float | None             # file units cubed (convex hull's when open)
    mass_kg: float | None = None
    arm_radial_m: float | None = None
    role: str = "part"               # "part" | "body"
    mount_radial: float | None = None  # motor mounts' distance from their centre, file units


def _fmt(value: float) -> str:
    return f"{value:.3g}"


def judge_unit(unit: str, cues: UnitCues) -> tuple[bool, str, str]:
    """(plausible, what this unit makes of the mesh, the first cue it fails or "")."""
    s = UNITS_M[unit]
    low, high = SIZE_M[cues.role]
    size_m = cues.largest_extent * s
    parts, failures = [f"{_fmt(size_m)} m across"], []
    if not low <= size_m <= high:
        failures.append(f"{_fmt(size_m)} m across, a {cues.role} is {low:g}-{high:g} m")
    if cues.mass_kg is not None and cues.volume and cues.volume > 0:
        density = cues.mass_kg / (cues.volume * s ** 3)
        dlow, dhigh = DENSITY_KG_M3[cues.role]
        parts.append(f"{_fmt(density)} kg/m^3 at {cues.mass_kg:g} kg")
        if not dlow <= density <= dhigh:
            failures.append(f"{_fmt(density)} kg/m^3, a {cues.role} averages "
                            f"{dlow:g}-{dhigh:g}")
    if cues.arm_radial_m is not None and size_m > 0:
        ratio = cues.arm_radial_m / (size_m / 2.0)
        alow, ahigh = ARM_OVER_HALF_SPAN
        parts.append(f"rotors {_fmt(cues.arm_radial_m)} m out = {_fmt(ratio)} half-spans")
        if not alow <= ratio <= ahigh:
            failures.append(f"rotors {_fmt(ratio)} half-spans out, where a body puts "
                            f"them {alow:g}-{ahigh:g}")
    if cues.mount_radial is not None and cues.arm_radial_m:
        mounts_m = cues.mount_radial * s
        parts.append(f"motor mounts {_fmt(mounts_m)} m out")
        if abs(mounts_m / cues.arm_radial_m - 1.0) > MOUNTS_TO_ARM:
            failures.append(f"motor mounts {_fmt(mounts_m)} m out, the rotors "
                            f"{_fmt(cues.arm_radial_m)} m")
    return not failures, ", ".join(parts), failures[0] if failures else ""


def choose_units(given: str, cues: UnitCues, *, declared_m: float | None = None,
                 flag: str = "--units", file=None) -> UnitChoice:
    """The mesh's unit: `given` (a UNITS_M key), the file's own (COLLADA <unit>, as Gazebo
    reads it) under "auto", else the one unit every cue finds plausible."""
    if given == "auto" and declared_m is not None:
        return UnitChoice(_unit_name(declared_m), declared_m,
                          f"declared by the file (<unit meter=\"{declared_m:g}\">), as "
                          "Gazebo reads it", False)
    if given != "auto" and given not in UNITS_M:
        raise ReedtoolError(f"unknown unit '{given}'", hint="use one of: auto, "
                            + ", ".join(UNITS_M))
    verdicts = {unit: judge_unit(unit, cues) for unit in UNIT_ORDER}
    if given != "auto":
        ok, text, failure = verdicts[given]
        note = None if ok else f"as {given} the mesh is implausible ({failure}): check {flag}"
        return UnitChoice(given, UNITS_M[given], f"given with {flag}; {text}", False, note)
    fits = [unit for unit in UNIT_ORDER if verdicts[unit][0]]
    said = f"largest extent {cues.largest_extent:g} units"
    if len(fits) == 1:
        unit = fits[0]
        others = ", ".join(f"{u} ({verdicts[u][2]})" for u in UNIT_ORDER if u != unit)
        return UnitChoice(unit, UNITS_M[unit],
                          f"{said}; as {unit}: {verdicts[unit][1]}; not {others}", True)
    listed = fits or list(UNIT_ORDER)
    missing = [name for name, value in (("the mass", cues.mass_kg),
                                        ("the arm length", cues.arm_radial_m)) if value is None]
    more = f"; giving {' or '.join(missing)} may settle it" if missing and fits else ""
    if not fits and cues.arm_radial_m is not None:
        from dataclasses import replace

        armless = replace(cues, arm_radial_m=None, mount_radial=None)
        body_fits = [u for u in UNIT_ORDER if judge_unit(u, armless)[0]]
        if body_fits:
            # The mesh is a body in some unit; the rotors are what no unit can hold.
            said_units = " or ".join(body_fits)
            raise ReedtoolError(
                f"the arm length puts the rotors {cues.arm_radial_m:g} m out, which fits "
                f"this body in no unit: as {said_units} (what its size and mass allow) "
                f"{'; '.join(verdicts[u][2] for u in body_fits)}", file=file,
                hint="check --arm-length and its unit (e.g. '176.8 mm'), or name the "
                     f"mesh's unit with {flag}")
    if fits:
        choices = "; ".join(f"as {u}: {verdicts[u][1]}" for u in fits)
        message = f"which unit? {said} fit {' and '.join(fits)} ({choices}){more}"
    else:
        choices = "; ".join(f"{u}: {verdicts[u][2]}" for u in listed)
        message = f"which unit? {said} fit no unit ({choices})"
    raise ReedtoolError(message, file=file,
                        hint="pass " + " or ".join(f"{flag} {u}" for u in listed))


UNIT_WORDS = {"mm": "millimetres", "cm": "centimetres", "in": "inches", "m": "metres"}


def units_read_as_metres(largest_extent_m: float, volume_m3: float | None,
                         mass_kg: float | None) -> list[str]:
    """The units (mm, in, cm) a mesh Gazebo reads as metres was most likely written in:
    those that make it a plausible link (size, and density at its link's mass), in
    UNIT_ORDER; [] when none does. validate's mesh-unit rules name them (I206, I210)."""
    cues = UnitCues(largest_extent_m, volume_m3, mass_kg, None, "link")
    return [unit for unit in UNIT_ORDER if unit != "m" and judge_unit(unit, cues)[0]]


def signed_volume(triangles: np.ndarray) -> float:
    """|Volume| enclosed by a closed triangle mesh (divergence theorem), in its units^3."""
    t = np.asarray(triangles, dtype=float)
    return abs(float(np.einsum("ij,ij->", t[:, 0], np.cross(t[:, 1], t[:, 2]))) / 6.0)


def _unit_name(metres_per_unit: float) -> str:
    for unit, metres in UNITS_M.items():
        if np.isclose(metres, metres_per_unit, rtol=1e-9):
            return unit
    return f"{metres_per_unit:g} m"


# ------------------------------------------------------------------ axes

# A vehicle body is flatter than it is wide: its height is its thinnest extent. Another
# axis this much thinner than the assumed height says the mesh stands on another axis
# (a 300 x 60 x 350 mm Y-up body read as Z-up is 35 cm tall and 6 cm wide: ratio 5.8).
TALLER_THAN_THINNEST = 1.5
# A part drawn upward from its CAD origin on a Z-down (NED/FRD) export lies wholly on the
# negative side of the assumed up axis; allow this fraction of its height as round-off.
ORIGIN_SLACK = 0.01


@dataclass(frozen=True)
class AxisReading:
    """What a mesh's extents say about its axes, against the convention assumed."""

    suggested: tuple[str, ...]     # conventions the extents fit better; () = the assumed fits
    reason: str


def _conventions_with(source_axis: int, letter: str, assumed: str) -> tuple[str, ...]:
    """Named conventions, then the letter code closest to the `assumed` code, whose
    source axis `source_axis` points `letter` (u or d)."""
    named = [name for name, (code, _) in ALIASES.items() if code[source_axis] == letter]
    # Closest first; on a tie, x forward (FLU, FRD, NED all keep it) before the rest.
    codes = sorted((code for code in RIGHT_HANDED_CODES if code[source_axis] == letter),
                   key=lambda code: (-sum(a == b for a, b in zip(code, assumed)),
                                     code[0] != "f"))
    return tuple(dict.fromkeys(named + codes[:1]))


def read_axes(vertices_flu_m: np.ndarray, frame: AxisConvention,
              shown_unit: tuple[float, str] = (1000.0, "mm")) -> AxisReading:
    """Does the mesh (vertices already turned to FLU by `frame`, in metres, CAD origin kept)
    sit as a body does: thinnest extent up, not hanging wholly below its origin? Otherwise,
    the conventions that fit its extents. Sizes are shown times shown_unit[0], named
    shown_unit[1]. The verdict does not depend on the unit."""
    factor, mm = shown_unit
    vertices = np.asarray(vertices_flu_m, dtype=float).reshape(-1, 3)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    size = high - low
    R = frame.R_flu_src
    names = "xyz"
    thinnest = int(np.argmin(size))
    shown = " x ".join(f"{s * factor:.4g}" for s in size)
    label = frame.name.upper()
    if thinnest != 2 and size[2] > TALLER_THAN_THINNEST * size[thinnest]:
        source_axis = int(np.argmax(np.abs(R[thinnest])))   # the source axis on FLU `thinnest`
        return AxisReading(
            _conventions_with(source_axis, "u", frame.code),
            f"read as {label} the body is {shown} {mm} (x, y, z in FLU): "
            f"{size[2] * factor:.4g} {mm} tall and {size[thinnest] * factor:.4g} {mm} along "
            f"{names[thinnest]}; a body is thinnest in height, so its source "
            f"{names[source_axis]} axis is most likely up")
    if low[2] < 0 and high[2] <= ORIGIN_SLACK * size[2]:
        source_axis = int(np.argmax(np.abs(R[2])))
        return AxisReading(
            _conventions_with(source_axis, "d", frame.code),
            f"read as {label} the body lies wholly below its origin "
            f"(z from {low[2] * factor:.4g} to {high[2] * factor:.4g} {mm}): a part drawn upward "
            f"from its CAD origin in a {names[source_axis]}-down export")
    where = ("above its origin" if low[2] >= -ORIGIN_SLACK * size[2] else
             "across its origin in height (no sign of which way is up: the convention "
             "given or assumed decides)")
    return AxisReading((), f"read as {label} the body is {shown} {mm} (x, y, z in FLU), "
                           f"thinnest in height, as a body is, and lies {where}")


def choose_axes(given: str, vertices_src: np.ndarray, *, flag: str = "--from-frame",
                file=None, shown_unit: tuple[float, str] = (1000.0, "mm")
                ) -> tuple[AxisConvention, AxisReading]:
    """The mesh's axis convention: `given`, or under "auto" FLU unless the extents say the
    mesh stands on another axis (then refused, naming the conventions that fit)."""
    auto = given.strip().lower() == "auto"
    frame = axis_convention("flu" if auto else given)
    vertices = np.asarray(vertices_src, dtype=float).reshape(-1, 3) @ frame.R_flu_src.T
    reading = read_axes(vertices, frame, shown_unit)
    if not auto and reading.suggested:
        # The user's word is taken; what the extents say is kept beside it.
        reading = AxisReading(reading.suggested,
                              f"{reading.reason} (taken as given with {flag} {given})")
    if auto and reading.suggested:
        choices = " or ".join(f"{flag} {name}" for name in reading.suggested)
        raise ReedtoolError(
            f"which way is up? {reading.reason}", file=file,
            hint=f"pass {choices} if it was exported so, or {flag} flu to keep its "
                 "axes (`reedtool import-stl --help` lists every convention)")
    return frame, reading
