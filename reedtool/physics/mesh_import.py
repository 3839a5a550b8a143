"""The pipeline behind `reedtool import-stl`.

read -> check -> units -> axes to FLU -> recentre -> mass properties -> collision mesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.frames import AxisConvention, axis_convention
from reedtool.io.meshes import MeshCheck, check_triangles, read_mesh
from reedtool.physics.inertia import MassProperties, mesh_mass_properties
from reedtool.physics.mesh_topology import (
    Topology,
    cluster_decimate,
    convex_hull_triangles,
    topology,
)

UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}


# A part of a multirotor is between a screw and a large airframe.
PLAUSIBLE_SIZE_M = (0.01, 5.0)


@dataclass(frozen=True)
class UnitChoice:
    unit: str
    metres_per_unit: float
    reason: str
    guessed: bool


def guess_units(extent: np.ndarray) -> UnitChoice:
    """Pick the unit that makes the part's largest extent a plausible multirotor part size."""
    largest = float(np.max(extent))
    low, high = PLAUSIBLE_SIZE_M
    for unit in ("m", "mm", "cm", "in"):
        size_m = largest * UNITS_M[unit]
        if low <= size_m <= high:
            return UnitChoice(unit, UNITS_M[unit],
                              f"largest extent {largest:g} units; as {unit} that is "
                              f"{size_m:g} m, within the plausible {low:g}-{high:g} m", True)
    unit = "mm" if largest > high else "m"
    return UnitChoice(unit, UNITS_M[unit],
                      f"largest extent {largest:g} units fits no unit's plausible "
                      f"{low:g}-{high:g} m; assuming {unit} — pass --units to be sure", True)


def _unit_name(metres_per_unit: float) -> str:
    for unit, metres in UNITS_M.items():
        if np.isclose(metres, metres_per_unit, rtol=1e-9):
            return unit
    return f"{metres_per_unit:g} m"


def choose_units(name: str, extent: np.ndarray, declared_m: float | None = None) -> UnitChoice:
    """--units NAME; "auto" takes the unit the file declares (COLLADA <unit>), as Gazebo
    does, and guesses from the size only for formats without one (STL, OBJ)."""
    if name == "auto" and declared_m is not None:
        return UnitChoice(_unit_name(declared_m), declared_m,
                          f"declared by the file (<unit meter=\"{declared_m:g}\">), as "
                          "Gazebo reads it", False)
    if name == "auto":
        return guess_units(extent)
    if name not in UNITS_M:
        raise ReedtoolError(f"unknown unit '{name}'", hint="use one of: auto, "
                            + ", ".join(UNITS_M))
    return UnitChoice(name, UNITS_M[name], "given with --units", False)


@dataclass(frozen=True)
class CollisionSpec:
    kind: str                        # "same" | "hull" | "simplify"
    max_faces: int | None = None

    @classmethod
    def parse(cls, text: str) -> "CollisionSpec":
        text = text.strip().lower()
        if text in ("same", "hull"):
            return cls(text)
        if text.startswith("simplify:"):
            number = text.split(":", 1)[1]
            if number.isdigit() and int(number) >= 4:
                return cls("simplify", int(number))
        raise ReedtoolError(f"bad --collision value '{text}'",
                            hint="use hull, same, or simplify:N with N >= 4 faces")


def collision_triangles(triangles: np.ndarray, spec: CollisionSpec) -> np.ndarray | None:
    """The collision mesh to write, or None when collision uses the visual mesh."""
    if spec.kind == "same":
        return None
    if spec.kind == "hull":
        return convex_hull_triangles(triangles)
    return cluster_decimate(triangles, spec.max_faces)


@dataclass
class ImportedMesh:
    source: Path
    file_format: str                 # binary STL | ASCII STL | COLLADA | OBJ
    triangles_m: np.ndarray          # (n, 3, 3), metres, FLU, recentred
    units: UnitChoice
    frame: AxisConvention
    offset_m: np.ndarray             # translation applied after rotation (recentring)
    recenter: str
    check: MeshCheck
    topology: Topology
    mass: MassProperties             # in the written mesh's frame
    mass_source: str                 # "given mass", "density ... x volume", "DEFAULT density ..."
    collision_m: np.ndarray | None   # collision triangles, None = use the visual mesh
    collision: CollisionSpec
    notes: list[str] = field(default_factory=list)

    @property
    def size_m(self) -> np.ndarray:
        vertices = self.triangles_m.reshape(-1, 3)
        return vertices.max(axis=0) - vertices.min(axis=0)


DEFAULT_DENSITY_KG_M3 = 1000.0


def import_mesh(path: str | Path, *, units: str = "auto", from_frame: str = "flu",
                mass_kg: float | None = None, density_kg_m3: float | None = None,
                recenter: str = "none", collision: str = "same", progress=None) -> ImportedMesh:
    """Read a CAD mesh (STL, COLLADA .dae, OBJ) and return it in metres and FLU with its
    mass properties. A .dae's <unit> is honoured (COLLADA node transforms applied).

    `progress(stage_name)` is called before each stage, for a progress bar.
    """
    step = progress or (lambda _stage: None)
    path = Path(path)
    frame = axis_convention(from_frame)
    spec = CollisionSpec.parse(collision)
    if recenter not in ("none", "com", "bbox"):
        raise ReedtoolError(f"bad --recenter value '{recenter}'", hint="use none, com or bbox")
    if mass_kg is not None and density_kg_m3 is not None:
        raise ReedtoolError("give --mass or --density, not both")
    for value, flag in ((mass_kg, "--mass"), (density_kg_m3, "--density")):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise ReedtoolError(f"{flag} must be a positive number, not {value}")

    step("reading")
    read = read_mesh(path)
    step("checking")
    check = check_triangles(read.triangles, path)
    topo = topology(read.triangles)
    choice = choose_units(units, check.extent,
                          read.metres_per_unit if read.unit_declared else None)

    step("transforming")
    # Uniform scale and a rotation commute; one matrix does both.
    M = frame.R_flu_src * choice.metres_per_unit
    triangles = read.triangles @ M.T

    step("mass properties")
    try:
        unit_props = mesh_mass_properties(triangles, 1.0, closed=topo.closed)
    except ReedtoolError as exc:
        raise ReedtoolError(exc.message, file=path, hint=exc.hint) from exc
    volume = float(unit_props.volume_m3)
    if mass_kg is not None:
        props, mass_source = unit_props.scaled_to_mass(mass_kg), "given mass"
    else:
        density = density_kg_m3 if density_kg_m3 is not None else DEFAULT_DENSITY_KG_M3
        props = unit_props.scaled_to_mass(density * volume)
        mass_source = (f"density {density:g} kg/m^3 x volume" if density_kg_m3 is not None
                       else f"DEFAULT density {density:g} kg/m^3 x volume")

    if recenter == "com":
        offset = -props.com_m
    elif recenter == "bbox":
        vertices = triangles.reshape(-1, 3)
        offset = -(vertices.min(axis=0) + vertices.max(axis=0)) / 2.0
    else:
        offset = np.zeros(3)
    if recenter != "none":
        triangles = triangles + offset
        props = MassProperties(props.mass_kg, props.com_m + offset, props.inertia_kg_m2,
                               props.volume_m3, props.from_hull)

    step("collision mesh")
    collision_m = collision_triangles(triangles, spec)

    notes = list(read.notes)
    if check.zero_area_triangles:
        notes.append(f"{check.zero_area_triangles} zero-area triangles (kept; they add nothing)")
    if props.from_hull:
        why = "not watertight" if not topo.watertight else "inconsistently wound"
        notes.append(f"mesh is {why}: mass properties are those of its convex hull")
    file_format = {"stl-binary": "binary STL", "stl-ascii": "ASCII STL", "dae": "COLLADA",
                   "obj": "OBJ"}.get(read.format, read.format)
    return ImportedMesh(path, file_format, triangles, choice, frame, offset, recenter, check,
                        topo, props, mass_source, collision_m, spec, notes)


# ------------------------------------------------------------------ what was assumed

def assumption_lines(imported: ImportedMesh) -> list[str]:
    """The unit and axis reasoning `import-stl` and `new-package --mesh` both print."""
    return [f"units: {imported.units.unit} ({imported.units.reason})",
            f"frame: {imported.frame.description}"]


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
    """Named conventions, then the letter codes closest to the `assumed` code, whose
    source axis `source_axis` points `letter` (u or d)."""
    from reedtool.frames import ALIASES, RIGHT_HANDED_CODES

    named = [name for name, (code, _) in ALIASES.items() if code[source_axis] == letter]
    # Closest first; on a tie, x forward (FLU, FRD, NED all keep it) before the rest.
    codes = sorted((code for code in RIGHT_HANDED_CODES if code[source_axis] == letter),
                   key=lambda code: (-sum(a == b for a, b in zip(code, assumed)),
                                     code[0] != "f"))
    return tuple(dict.fromkeys(named + codes[:1]))


def read_axes(imported: ImportedMesh) -> AxisReading:
    """Does the mesh sit as a body does in the assumed convention (thinnest extent up, not
    hanging wholly below its origin)? Otherwise, the conventions that fit its extents."""
    vertices = imported.triangles_m.reshape(-1, 3) - imported.offset_m   # before recentring
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    size = high - low
    R = imported.frame.R_flu_src
    names = "xyz"
    thinnest = int(np.argmin(size))
    shown = " x ".join(f"{s * 1000:.4g}" for s in size)
    if thinnest != 2 and size[2] > TALLER_THAN_THINNEST * size[thinnest]:
        source_axis = int(np.argmax(np.abs(R[thinnest])))   # the source axis on FLU `thinnest`
        return AxisReading(
            _conventions_with(source_axis, "u", imported.frame.code),
            f"read as {imported.frame.name.upper()} the body is {shown} mm (x, y, z in FLU): "
            f"{size[2] * 1000:.4g} mm tall and {size[thinnest] * 1000:.4g} mm along "
            f"{names[thinnest]}; a body is thinnest in height, so its source "
            f"{names[source_axis]} axis is most likely up")
    if low[2] < 0 and high[2] <= ORIGIN_SLACK * size[2]:
        source_axis = int(np.argmax(np.abs(R[2])))
        return AxisReading(
            _conventions_with(source_axis, "d", imported.frame.code),
            f"read as {imported.frame.name.upper()} the body lies wholly below its origin "
            f"(z from {low[2] * 1000:.4g} to {high[2] * 1000:.4g} mm): a part drawn upward "
            f"from its CAD origin in a {names[source_axis]}-down export")
    return AxisReading((), f"read as {imported.frame.name.upper()} the body is {shown} mm "
                           "(x, y, z in FLU), thinnest in height, as a body is")
