"""The pipeline behind `reedtool import-stl` and `new-package --mesh`.

read -> check -> units and axes (physics.mesh_units) -> to metres and FLU -> mass properties
-> recentre (only when asked) -> collision mesh. The CAD origin is kept unless the user
asks to recentre; the COM is reported, never moved to.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.frames import AxisConvention
from reedtool.io.meshes import MeshCheck, check_triangles, read_mesh
from reedtool.physics import mesh_units
from reedtool.physics.mesh_units import AxisReading, UnitChoice, UnitCues
from reedtool.physics.inertia import MassProperties, mesh_mass_properties
from reedtool.physics.mesh_topology import (
    Topology,
    cluster_decimate,
    convex_hull_triangles,
    topology,
)

# Units and axes are read by physics.mesh_units, the one detector every command uses.
UNITS_M = mesh_units.UNITS_M


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
    axes: AxisReading                # what the extents say about the axes
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


def import_mesh(path: str | Path, *, units: str = "auto", from_frame: str = "auto",
                mass_kg: float | None = None, density_kg_m3: float | None = None,
                recenter: str = "none", collision: str = "same", progress=None,
                arm_radial_m: float | None = None, role: str = "part",
                mount_count: int | None = None,
                flags: tuple[str, str] = ("--units", "--from-frame")) -> ImportedMesh:
    """Read a CAD mesh (STL, COLLADA .dae, OBJ) and return it in metres and FLU with its
    mass properties. A .dae's <unit> is honoured (COLLADA node transforms applied).

    `units` and `from_frame` may be "auto": physics.mesh_units decides from the size, the
    mass (density) and `arm_radial_m` (centre to rotor axis), or refuses naming the
    choices and `flags` (the command's own option names). `role` is "body" for a
    vehicle's body (tighter size bounds), else "part". `mount_count` motor mounts, when
    the mesh has them where the arm length puts rotors, settle a unit size and density
    leave open.
    `progress(stage_name)` is called before each stage, for a progress bar.
    """
    step = progress or (lambda _stage: None)
    path = Path(path)
    if from_frame.strip().lower() != "auto":
        from reedtool.frames import axis_convention

        axis_convention(from_frame)      # an unknown name is the error, before any reading
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
    # Volume in file units: a rotation does not change it, a unit scales it by s^3.
    try:
        raw = mesh_mass_properties(read.triangles, 1.0, closed=topo.closed)
    except ReedtoolError as exc:
        raise ReedtoolError(exc.message, file=path, hint=exc.hint) from exc
    cues = UnitCues(float(np.max(check.extent)), float(raw.volume_m3), mass_kg,
                    arm_radial_m, role)
    declared = read.metres_per_unit if read.unit_declared else None
    try:
        choice = mesh_units.choose_units(units, cues, declared_m=declared, flag=flags[0],
                                         file=path)
    except ReedtoolError:
        if not (mount_count and arm_radial_m and units == "auto"):
            raise
        # Sizes and density leave more than one unit: the motor mounts settle it, if the
        # mesh has them, as the unit that puts them under the rotors of the arm length.
        frame, _ = mesh_units.choose_axes(from_frame, read.triangles, flag=flags[1],
                                          file=path, shown_unit=(1.0, "file units"))
        from reedtool.physics.motor_mounts import find_mounts

        found = find_mounts(read.triangles @ frame.R_flu_src.T, mount_count).mounts
        if not found:
            raise
        centre = np.mean([m.xy_m for m in found], axis=0)
        radial = float(np.mean([np.linalg.norm(m.xy_m - centre) for m in found]))
        cues = UnitCues(cues.largest_extent, cues.volume, mass_kg, arm_radial_m, role, radial)
        choice = mesh_units.choose_units(units, cues, declared_m=declared, flag=flags[0],
                                         file=path)
    frame, axes = mesh_units.choose_axes(from_frame, read.triangles * choice.metres_per_unit,
                                         flag=flags[1], file=path)

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
    if choice.note:
        notes.insert(0, choice.note)
    return ImportedMesh(path, file_format, triangles, choice, frame, axes, offset, recenter,
                        check, topo, props, mass_source, collision_m, spec, notes)


# ------------------------------------------------------------------ what was assumed

def assumption_lines(imported: ImportedMesh) -> list[str]:
    """The unit and axis reasoning every command that reads a mesh prints."""
    return [f"units: {imported.units.unit} ({imported.units.reason})",
            f"frame: {imported.frame.description}",
            f"axes: {imported.axes.reason}"]
