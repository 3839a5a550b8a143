"""Mass properties: primitives, triangle meshes, links and whole robots.

A `MassProperties` is mass, centre of mass and the inertia tensor ABOUT THAT CENTRE OF
MASS, all expressed in one frame's axes. Moving it between frames (`transformed`) only
moves the COM and rotates the tensor; the parallel-axis theorem appears in exactly one
place, `combine`, where parts are summed about their common COM.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Iterable, Iterator

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.model import Box, Cylinder, Link, Mesh, Robot, Sphere

# ------------------------------------------------------------ the value object


@dataclass(frozen=True)
class MassProperties:
    mass_kg: float
    com_m: np.ndarray              # (3,) centre of mass in the frame
    inertia_kg_m2: np.ndarray      # (3, 3) about com_m, in the frame's axes
    volume_m3: float | None = None
    # True when a mesh was open (or inconsistently wound) so the properties are those of
    # its convex hull; anything combined from such a part inherits the flag.
    from_hull: bool = False

    def transformed(self, T_a_b) -> "MassProperties":
        """Self is given in frame b; return the same body's properties in frame a."""
        T_a_b = np.asarray(T_a_b, dtype=float)
        R_a_b = T_a_b[:3, :3]
        return MassProperties(
            mass_kg=self.mass_kg,
            com_m=R_a_b @ np.asarray(self.com_m, dtype=float) + T_a_b[:3, 3],
            inertia_kg_m2=R_a_b @ np.asarray(self.inertia_kg_m2, dtype=float) @ R_a_b.T,
            volume_m3=self.volume_m3,
            from_hull=self.from_hull,
        )

    def scaled_to_mass(self, mass_kg: float) -> "MassProperties":
        """Same shape, uniform density chosen so the mass is `mass_kg`."""
        if self.mass_kg <= 0.0:
            raise ValueError("cannot rescale a massless body")
        factor = mass_kg / self.mass_kg
        return MassProperties(mass_kg, np.array(self.com_m, dtype=float),
                              np.asarray(self.inertia_kg_m2) * factor,
                              self.volume_m3, self.from_hull)

    def inertia_about(self, point_m) -> np.ndarray:
        """Tensor about another point (same axes): the parallel-axis theorem."""
        offset_m = np.asarray(point_m, dtype=float) - self.com_m
        return self.inertia_kg_m2 + parallel_axis_term(self.mass_kg, offset_m)

    @staticmethod
    def combine(parts: Iterable["MassProperties"]) -> "MassProperties":
        return combine(parts)


def parallel_axis_term(mass_kg: float, d_m: np.ndarray) -> np.ndarray:
    """m (|d|^2 E - d d^T): the parallel-axis (Steiner) term.

    The tensor about a point at offset d from the COM is I_com + this; every conversion
    between "about the COM" and "about another point" in reedtool goes through here.
    """
    d_m = np.asarray(d_m, dtype=float)
    return mass_kg * (float(d_m @ d_m) * np.eye(3) - np.outer(d_m, d_m))


def combine(parts: Iterable[MassProperties]) -> MassProperties:
    """Sum rigidly attached parts, all given in the same frame, about their common COM.

    Massless parts contribute nothing. With no mass at all the result is zero mass, COM
    at the origin and a zero tensor.
    """
    parts = list(parts)
    massive = [p for p in parts if p.mass_kg > 0.0]
    volumes = [p.volume_m3 for p in parts]
    volume = None if (not parts or any(v is None for v in volumes)) else float(sum(volumes))
    from_hull = any(p.from_hull for p in parts)
    total_kg = float(sum(p.mass_kg for p in massive))
    if total_kg <= 0.0:
        return MassProperties(0.0, np.zeros(3), np.zeros((3, 3)), volume, from_hull)
    com_m = sum(p.mass_kg * np.asarray(p.com_m, dtype=float) for p in massive) / total_kg
    inertia = np.zeros((3, 3))
    for p in massive:
        inertia += (np.asarray(p.inertia_kg_m2, dtype=float)
                    + parallel_axis_term(p.mass_kg, p.com_m - com_m))
    return MassProperties(total_kg, com_m, inertia, volume, from_hull)


# ---------------------------------------------------------------- primitives

def box_inertia(mass_kg: float, size_m) -> np.ndarray:
    """Solid box with full edge lengths size_m = (x, y, z), about its centre."""
    x, y, z = (float(s) for s in size_m)
    return mass_kg / 12.0 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])


def cylinder_inertia(mass_kg: float, radius_m: float, length_m: float,
                     axis: str = "z") -> np.ndarray:
    """Solid cylinder about its centre; `axis` (x|y|z) is the axis of symmetry."""
    if axis not in ("x", "y", "z"):
        raise ValueError(f"cylinder axis must be x, y or z, not {axis!r}")
    axial = 0.5 * mass_kg * radius_m ** 2
    transverse = mass_kg * (3.0 * radius_m ** 2 + length_m ** 2) / 12.0
    diag = [transverse, transverse, transverse]
    diag["xyz".index(axis)] = axial
    return np.diag(diag)


def sphere_inertia(mass_kg: float, radius_m: float) -> np.ndarray:
    """Solid sphere about its centre."""
    return np.eye(3) * (0.4 * mass_kg * radius_m ** 2)


def box_volume(size_m) -> float:
    return float(np.prod(np.asarray(size_m, dtype=float)))


def cylinder_volume(radius_m: float, length_m: float) -> float:
    return float(np.pi * radius_m ** 2 * length_m)


def sphere_volume(radius_m: float) -> float:
    return float(4.0 / 3.0 * np.pi * radius_m ** 3)


# ------------------------------------------------------------- triangle meshes

def solid_mass_properties(triangles_m: np.ndarray, density_kg_m3: float = 1.0) -> MassProperties:
    """Mass properties of the solid bounded by a closed, outward-wound triangle mesh.

    Volume integrals by the divergence theorem over signed tetrahedra (Eberly, "Polyhedral
    Mass Properties (Revisited)", 2002 — the same integrals trimesh uses), vectorised over
    all triangles. The mesh is shifted to its bounding-box centre first: CAD parts often sit
    far from their origin, and integrating x^2 about a distant origin cancels away digits.
    A negative volume means inside-out winding; the caller decides what to do with it.
    """
    tri = np.asarray(triangles_m, dtype=np.float64)
    flat = tri.reshape(-1, 3)
    shift = (flat.min(axis=0) + flat.max(axis=0)) / 2.0
    # One contiguous 1-D array per (coordinate, corner): fast, cache-friendly arithmetic.
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2) = (
        np.ascontiguousarray(tri[:, :, axis].T) - shift[axis] for axis in range(3))
    # d = (p1 - p0) x (p2 - p0): twice the area times the normal.
    ex1, ey1, ez1 = x1 - x0, y1 - y0, z1 - z0
    ex2, ey2, ez2 = x2 - x0, y2 - y0, z2 - z0
    dx = ey1 * ez2 - ez1 * ey2
    dy = ez1 * ex2 - ex1 * ez2
    dz = ex1 * ey2 - ey1 * ex2

    def subexpressions(w0, w1, w2):
        """Eberly's f1, f2, f3, g0, g1, g2 for one coordinate."""
        t0 = w0 + w1
        f1 = t0 + w2
        t1 = w0 * w0
        t2 = t1 + w1 * t0
        f2 = t2 + w2 * f1
        f3 = w0 * t1 + w1 * t2 + w2 * f2
        return f1, f2, f3, f2 + w0 * (f1 + w0), f2 + w1 * (f1 + w1), f2 + w2 * (f1 + w2)

    f1x, f2x, f3x, g0x, g1x, g2x = subexpressions(x0, x1, x2)
    _, f2y, f3y, g0y, g1y, g2y = subexpressions(y0, y1, y2)
    _, f2z, f3z, g0z, g1z, g2z = subexpressions(z0, z1, z2)

    volume = float(dx @ f1x) / 6.0
    first = np.array([dx @ f2x, dy @ f2y, dz @ f2z]) / 24.0      # integrals of x, y, z
    second = np.array([dx @ f3x, dy @ f3y, dz @ f3z]) / 60.0     # of x^2, y^2, z^2
    xy = float(dx @ (y0 * g0x + y1 * g1x + y2 * g2x)) / 120.0    # of xy, yz, zx
    yz = float(dy @ (z0 * g0y + z1 * g1y + z2 * g2y)) / 120.0
    zx = float(dz @ (x0 * g0z + x1 * g1z + x2 * g2z)) / 120.0

    if volume == 0.0:
        return MassProperties(0.0, shift, np.zeros((3, 3)), 0.0)
    com = first / volume                                  # relative to `shift`
    # Second moments about the COM (shift-invariant), then the inertia tensor.
    sxx = second[0] - volume * com[0] ** 2
    syy = second[1] - volume * com[1] ** 2
    szz = second[2] - volume * com[2] ** 2
    sxy = xy - volume * com[0] * com[1]
    syz = yz - volume * com[1] * com[2]
    szx = zx - volume * com[2] * com[0]
    inertia = density_kg_m3 * np.array([
        [syy + szz, -sxy, -szx],
        [-sxy, sxx + szz, -syz],
        [-szx, -syz, sxx + syy],
    ])
    return MassProperties(density_kg_m3 * volume, com + shift, inertia, volume)


def mesh_mass_properties(triangles_m: np.ndarray, density_kg_m3: float = 1.0,
                         *, closed: bool | None = None) -> MassProperties:
    """Mass properties of a mesh as a uniform solid; open meshes use their convex hull.

    `closed` is the caller's topology verdict (watertight and consistently wound); when
    None it is computed here. Raises ReedtoolError when there is no volume to speak of.
    """
    # Imported here: a model of primitives (validate's seed) never measures a mesh.
    from reedtool.physics.mesh_topology import convex_hull_triangles, topology

    if closed is None:
        closed = topology(triangles_m).closed
    from_hull = not closed
    solid = convex_hull_triangles(triangles_m) if from_hull else triangles_m
    props = solid_mass_properties(solid, density_kg_m3)
    if props.volume_m3 is not None and props.volume_m3 < 0.0:
        # Closed but wound inside-out: the same solid with every normal flipped.
        props = solid_mass_properties(np.asarray(solid)[:, ::-1], density_kg_m3)
    if not props.volume_m3 or props.volume_m3 <= 0.0 or not np.isfinite(props.volume_m3):
        raise ReedtoolError("mesh encloses no volume (flat or degenerate), so it has no mass "
                            "properties", hint="check the export, or use a primitive shape")
    return MassProperties(props.mass_kg, props.com_m, props.inertia_kg_m2, props.volume_m3,
                          from_hull)


@lru_cache(maxsize=64)
def _unit_density_mesh_properties(path: str, mtime_ns: int, scale: tuple[float, float, float]
                                  ) -> MassProperties:
    from reedtool.io.meshes import load_triangles

    triangles = load_triangles(path) * np.asarray(scale)
    try:
        return mesh_mass_properties(triangles)
    except ReedtoolError as exc:
        raise ReedtoolError(exc.message, file=path, hint=exc.hint) from exc


# ------------------------------------------------------------ URDF geometry

def geometry_mass_properties(geometry, T_link_geom, mass_kg: float) -> MassProperties:
    """Uniform-density mass properties of a URDF geometry with the given mass, in the link frame.

    Box, Cylinder (axis z) and Sphere are analytic. A Mesh is read from its resolved path
    and scaled by its `scale`; an open mesh gives its convex hull's properties and sets
    `from_hull`. Unresolvable, unreadable or empty meshes raise ReedtoolError.
    """
    if isinstance(geometry, Box):
        size = np.asarray(geometry.size_m, dtype=float)
        local = MassProperties(mass_kg, np.zeros(3), box_inertia(mass_kg, size), box_volume(size))
    elif isinstance(geometry, Cylinder):
        local = MassProperties(mass_kg, np.zeros(3),
                               cylinder_inertia(mass_kg, geometry.radius_m, geometry.length_m, "z"),
                               cylinder_volume(geometry.radius_m, geometry.length_m))
    elif isinstance(geometry, Sphere):
        local = MassProperties(mass_kg, np.zeros(3), sphere_inertia(mass_kg, geometry.radius_m),
                               sphere_volume(geometry.radius_m))
    elif isinstance(geometry, Mesh):
        if geometry.path is None:
            raise ReedtoolError(f"mesh '{geometry.uri}' could not be resolved"
                                + (f": {geometry.resolve_error}" if geometry.resolve_error else ""),
                                hint="pass --package-path for package:// URIs")
        path = str(geometry.path)
        try:
            mtime_ns = geometry.path.stat().st_mtime_ns
        except OSError as exc:
            raise ReedtoolError(f"cannot read mesh: {exc.strerror}", file=path) from exc
        scale = tuple(float(s) for s in np.broadcast_to(np.asarray(geometry.scale, float), (3,)))
        unit = _unit_density_mesh_properties(path, mtime_ns, scale)
        local = unit.scaled_to_mass(mass_kg)
    else:
        raise ReedtoolError(f"unsupported geometry type {type(geometry).__name__}")
    return local.transformed(T_link_geom)


def geometry_volume(geometry) -> tuple[float, bool]:
    """(volume in m³, from_hull) of one URDF/SDF geometry as the simulator sizes it.

    Primitives are exact. A mesh is read from its resolved path with its `scale`
    applied; a closed mesh gives the volume it encloses, an open one its convex hull's
    (from_hull True): a solid the open surface stands for lies inside that hull, so the
    hull never under-states it. Raises ReedtoolError like geometry_mass_properties."""
    if isinstance(geometry, Box):
        return box_volume(geometry.size_m), False
    if isinstance(geometry, Cylinder):
        return cylinder_volume(geometry.radius_m, geometry.length_m), False
    if isinstance(geometry, Sphere):
        return sphere_volume(geometry.radius_m), False
    props = geometry_mass_properties(geometry, np.eye(4), 1.0)
    return float(props.volume_m3 or 0.0), props.from_hull


@dataclass(frozen=True)
class LinkVolume:
    volume_m3: float
    source: str          # "collision" or "visual": the group the volume is of
    count: int           # geometries summed
    from_hull: bool      # some mesh was open: its convex hull was measured


def link_volumes(link: Link) -> Iterator[LinkVolume]:
    """The volume the link's geometry gives it, per group: the sum over its collision
    geometries, then over its visual ones, each group only when all of it can be measured
    (an unresolved or unreadable mesh leaves its group out). Lazy: a caller bounding a
    density stops at the first group that is plausible, and reads no more meshes.

    Summing is the cautious side for a density bound: overlapping shapes count their
    overlap twice, which only lowers mass / volume, never raises it."""
    for source, shapes in (("collision", link.collisions), ("visual", link.visuals)):
        geometries = [shape.geometry for shape in shapes if shape.geometry is not None]
        if not geometries:
            continue
        total, hull = 0.0, False
        try:
            for geometry in geometries:
                volume, from_hull = geometry_volume(geometry)
                total += volume
                hull = hull or from_hull
        except ReedtoolError:
            continue
        if math.isfinite(total) and total > 0:
            yield LinkVolume(total, source, len(geometries), hull)


# No material is denser than osmium (22,590 kg/m³): a geometry whose volume would need a
# denser one to hold the declared mass is not the body but a placeholder standing for it
# (RotorS omav's 0.28 kg tilt units on 5 mm boxes: 2.2e6 kg/m³), and says nothing about
# the tensor.
DENSEST_MATERIAL_KG_M3 = 22590.0


@dataclass
class LinkGeometry:
    """What a link's declared inertial is compared with: its collision shapes (else its
    visual shapes) filled with the declared mass at one uniform density."""

    body: MassProperties            # the shapes together, in the link frame
    kind: str                       # "collision" | "visual"
    shapes: list                    # the geometries, in document order
    alone: list[MassProperties]     # each shape holding all the mass (where it may sit)

    @property
    def density_kg_m3(self) -> float | None:
        volume = self.body.volume_m3
        return self.body.mass_kg / volume if volume and volume > 0 else None


def link_geometry(link: Link, mass_kg: float) -> LinkGeometry | None:
    """The link's geometry at `mass_kg`: every collision shape (a motor can and its prop
    disc are one link's body together), else every visual shape; None when it has none.

    Several shapes share the mass by volume (uniform density). A shape that cannot be
    measured (an unresolved mesh: S115 says so) is left out; ReedtoolError when none can.
    """
    for kind, shapes in (("collision", link.collisions), ("visual", link.visuals)):
        shapes = [s for s in shapes if s.geometry is not None]
        if not shapes:
            continue
        alone, errors = [], []
        for shape in shapes:
            try:
                alone.append((shape.geometry,
                              geometry_mass_properties(shape.geometry, shape.T_link_geom,
                                                       mass_kg)))
            except ReedtoolError as exc:
                errors.append(exc)
        if not alone:
            raise errors[0]
        volumes = [props.volume_m3 for _g, props in alone]
        if len(alone) == 1 or any(not v or v <= 0 for v in volumes):
            body = alone[0][1]
        else:
            total = float(sum(volumes))
            body = combine([props.scaled_to_mass(mass_kg * v / total)
                            for (_g, props), v in zip(alone, volumes)])
        return LinkGeometry(body, kind, [g for g, _p in alone], [p for _g, p in alone])
    return None


def declared_mass_properties(link: Link) -> MassProperties | None:
    """The link's <inertial> in the link frame (tensor rotated into link axes), or None."""
    inertial = link.inertial
    if inertial is None:
        return None
    return MassProperties(float(inertial.mass_kg), np.array(inertial.com_m, dtype=float),
                          inertial.inertia_in_link_axes())


def combine_inertials(T_link_part_inertials) -> MassProperties:
    """Mass properties in one link's frame of (T_link_part, Inertial) parts: the
    <inertial>s of links folded into it, each posed in it by T_link_part."""
    parts = []
    for T_link_part, inertial in T_link_part_inertials:
        T_link_com = T_link_part @ inertial.T_link_com
        R_link_com = T_link_com[:3, :3]
        parts.append(MassProperties(inertial.mass_kg, T_link_com[:3, 3],
                                    R_link_com @ inertial.inertia_kg_m2 @ R_link_com.T))
    return combine(parts)


def whole_robot(robot: Robot) -> MassProperties:
    """reedtool's own sum over links, in the root link's frame, at zero joint positions.

    Links not reachable from the root (a broken tree) are left out, as a simulator would.
    A number that could not be read (NaN/inf in a reached link's pose, mass, COM or
    inertia; S101/S102 report it) makes the sum unknown: NaN mass, COM and tensor, so
    nothing downstream judges a robot without that link.
    """
    from reedtool.physics.kinematics import link_poses

    parts = []
    # inf/NaN in a link are expected here and judged below, not warned about
    with np.errstate(invalid="ignore", over="ignore"):
        for name, T_base_link in link_poses(robot).items():
            declared = declared_mass_properties(robot.link_map[name])
            if declared is not None:
                parts.append(declared.transformed(T_base_link))

    def finite(p: MassProperties) -> bool:
        return bool(np.isfinite(p.mass_kg) and np.all(np.isfinite(p.com_m))
                    and np.all(np.isfinite(p.inertia_kg_m2)))

    if all(finite(p) for p in parts):
        total = combine(parts)
        if finite(total):           # 1e300 kg parts overflow the sum: unknown as well
            return total
    return MassProperties(math.nan, np.full(3, math.nan), np.full((3, 3), math.nan))


# --------------------------------------------------------------- checks

def principal_moments(inertia_kg_m2) -> np.ndarray:
    """Eigenvalues of the (symmetrised) tensor, ascending."""
    I = np.asarray(inertia_kg_m2, dtype=float)
    return np.linalg.eigvalsh((I + I.T) / 2.0)


# Principal moments may break A + B >= C by this fraction of the largest moment: hand-rounded
# values of a thin plate (where A + B = C exactly) stay quiet, real mistakes do not.
TRIANGLE_REL_TOL = 1e-3


def tensor_problem(inertia_kg_m2) -> str | None:
    """What makes a declared tensor physically impossible, or None.

    "non-finite", "not-positive-definite" (asymmetric, or a principal moment <= 0, I202) or
    "triangle" (A + B < C beyond TRIANGLE_REL_TOL, I203). `validate` and `inertia` both
    decide here.
    """
    I = np.asarray(inertia_kg_m2, dtype=float)
    if not np.all(np.isfinite(I)):
        return "non-finite"
    scale = max(float(np.max(np.abs(I))), 1e-300)
    moments = np.linalg.eigvalsh((I + I.T) / 2.0)
    if not np.allclose(I, I.T, rtol=0, atol=1e-12 * scale) or moments[0] <= 0 \
            or moments[0] <= 1e-12 * max(float(moments[2]), 1e-300):
        return "not-positive-definite"
    a, b, c = moments
    if a + b < c - TRIANGLE_REL_TOL * c:
        return "triangle"
    return None


# Eigenvalues of a tensor with zero moments come out as +-1e-25 of its largest moment:
# below this fraction of the largest, a moment is zero, not negative.
MOMENT_NOISE_REL = 1e-9


def degenerate_but_accepted(inertia_kg_m2, *, moving: bool, lumped: bool) -> bool:
    """A tensor with zero (not negative) principal moments that the simulator accepts: a
    point mass (all zero) on a fixed joint, which gz-math calls valid, or any such tensor
    of a URDF link merged into its parent, where it only adds to the parent's sum."""
    I = np.asarray(inertia_kg_m2, dtype=float)
    if moving or not np.all(np.isfinite(I)):
        return False
    moments = np.linalg.eigvalsh((I + I.T) / 2.0)
    largest = float(np.max(np.abs(moments)))
    if moments[0] < -MOMENT_NOISE_REL * max(largest, 1e-300):
        return False
    return lumped or largest == 0.0


def physically_valid(inertia_kg_m2) -> bool:
    """Positive principal moments obeying the triangle inequality (A + B >= C)."""
    return tensor_problem(inertia_kg_m2) is None


def relative_difference(declared, reference) -> float:
    """||declared - reference||_F / ||reference||_F (inf when the reference is zero)."""
    reference = np.asarray(reference, dtype=float)
    norm = float(np.linalg.norm(reference))
    diff = float(np.linalg.norm(np.asarray(declared, dtype=float) - reference))
    if norm == 0.0:
        return 0.0 if diff == 0.0 else float("inf")
    return diff / norm


# ------------------------------------------------------------- URDF text
# The numbers and <inertial> a person reads or pastes: written by io/urdf_write.py.

def inertial_xml(props: MassProperties, indent: str = "  ") -> str:
    """An <inertial> element: mass, COM origin and the tensor about the COM in link axes."""
    from reedtool.io.urdf_write import inertial_text

    return inertial_text(props.mass_kg, props.com_m, props.inertia_kg_m2, indent=indent)


def inertia_element(inertia_kg_m2) -> str:
    """An <inertia .../> element for a tensor (in the link axes), as inertial_xml writes it."""
    from reedtool.io.urdf_write import inertia_text

    return inertia_text(inertia_kg_m2)


# ------------------------------------------------- declared vs geometry, per link
#
# ONE verdict per link, shared by `reedtool inertia` and the I2xx rules of `validate`, so the
# same link gets the same verdict in both and `inertia` fails exactly when `validate` reports
# an inertia error. Severity of each verdict:
#   error:   invalid (I202/I203), way-off (I209), massless-inertia (I208), negative-mass and
#            massless-moving (I201)
#   warning: implausible (I204)
#   note:    differs, com-off (within what a real part can be), slowdown-scaled (RotorS
#            convention), and the verdicts that have nothing to compare.

# A real part is not a uniform solid of its collision shape, so only a large difference
# means a wrong tensor: within 50 % is "ok". The trace (twice the mass times the squared
# radius of gyration) decides plausibility: all mass in the corners of a box gives only 3x
# the solid box's inertia, so beyond 10x (below, only at 1/100: see _plausible) no real
# mass distribution fits
# (implausible, warning), and beyond 100x the tensor is a placeholder or a unit mistake
# (1.0 everywhere, mm^2 for m^2) that certainly changes how the body flies (way-off, error).
OK_REL_DIFF = 0.5
PLAUSIBLE_TRACE_RATIO = 10.0
ORDERS_OFF_TRACE_RATIO = 100.0
# The declared COM may sit anywhere inside the part; farther from the geometry's COM than
# this many radii of gyration, it is probably outside it.
COM_OFF_GYRATION_RADII = 1.0

FIXABLE_VERDICTS = ("invalid", "way-off", "implausible", "differs", "com-off")


@dataclass
class LinkComparison:
    link: str
    loc: object                        # SourceLoc of the <inertial> (else of the <link>)
    declared: MassProperties | None
    derived: MassProperties | None     # geometry's, with the declared mass, in link frame
    geometry: str | None               # e.g. "collision cylinder", "visual mesh body.stl"
    inertia_rel_diff: float | None
    trace_ratio: float | None          # trace(declared) / trace(derived)
    com_offset_m: float | None
    verdict: str                       # invalid | way-off | implausible | negative-mass |
    #   massless-moving | massless-inertia | placeholder | point-mass | ok | differs |
    #   com-off | slowdown-scaled | massless | no-geometry | no-inertial | geometry-error |
    #   unjudged (a number it needs is not a number: the reader's finding speaks) |
    #   static (scenery: its mass properties are never used) | placeholder-geometry (no
    #   material is dense enough for the geometry to be the body)
    message: str
    slowdown: float | None = None      # rotorVelocitySlowdownSim of the rotor on this link
    tensor_problem: str | None = None  # see tensor_problem()
    # How much the verdict matters is policy, not physics: the rule registry decides, with
    # the user's configuration (workflows.validation.judge_links fills this in).
    severity: str | None = None

    @property
    def failing(self) -> bool:
        return self.severity == "error"

    def corrected(self) -> MassProperties | None:
        """The <inertial> --fix writes: declared mass, geometry tensor; the declared COM
        unless it is implausibly far from the geometry's."""
        if self.derived is None or self.declared is None or self.verdict not in FIXABLE_VERDICTS:
            return None
        com = self.derived.com_m if self.verdict == "com-off" else self.declared.com_m
        return MassProperties(self.declared.mass_kg, np.array(com), self.derived.inertia_kg_m2)


def _geometry_label(kind: str, geometry) -> str:
    if isinstance(geometry, Mesh):
        return f"{kind} mesh {geometry.uri.rsplit('/', 1)[-1]}"
    return f"{kind} {type(geometry).__name__.lower()}"


def rotor_slowdown_by_link(robot: Robot) -> dict[str, float]:
    """rotorVelocitySlowdownSim of each rotor link's motor plugin (RotorS, PX4 classic, gz).

    RotorS simulates rotors `s` times slower than they spin and multiplies the rotor link's
    inertia by `s` to keep its angular momentum (multirotor_base.xacro: the rotor's box
    inertia with mass * rotor_velocity_slowdown_sim). Only motor plugins (those that name a
    jointName) count: the multirotor base plugin carries the same element for the body.
    """
    found: dict[str, float] = {}
    for _block, plugin in robot.plugins():
        text = plugin.param("rotorVelocitySlowdownSim")
        joint = plugin.param("jointName")
        if text is None or joint is None:
            continue
        try:
            slowdown = float(text)
        except ValueError:
            continue
        link = plugin.param("linkName")
        if link is None and joint in robot.joint_map:
            link = robot.joint_map[joint].child
        if link and math.isfinite(slowdown) and slowdown > 1.0:
            found[link] = slowdown
    return found


def unreadable_masses(robot: Robot) -> set[str]:
    """Links whose <mass> could not be read (S101 reports it; the 0 there is a default)."""
    bad_locs = {issue.loc for issue in robot.parse_issues}
    return {link.name for link in robot.links
            if link.inertial is not None and link.inertial.mass_loc in bad_locs}


def compare_link(link: Link, *, moving: bool = False, slowdown: float | None = None,
                 mass_unreadable: bool = False) -> LinkComparison:
    """Declared inertial beside the one its geometry implies at the same mass, with a verdict.

    `moving`: the link is the child of a non-fixed joint (a massless one is an error there).
    `slowdown`: rotorVelocitySlowdownSim of a motor plugin driving this link.
    """
    declared = declared_mass_properties(link)
    loc = link.inertial.loc if link.inertial is not None else link.loc
    found = link.geometry_for_mass()
    label = None
    if found is not None:
        kind = "collision" if any(c.geometry is found[0] for c in link.collisions) else "visual"
        label = _geometry_label(kind, found[0])
        count = sum(s.geometry is not None
                    for s in (link.collisions if kind == "collision" else link.visuals))
        if count > 1:
            label = f"{count} {kind} shapes"

    def result(verdict, message, derived=None, rel=None, ratio=None, offset=None, problem=None):
        return LinkComparison(link.name, loc, declared, derived, label, rel, ratio, offset,
                              verdict, message, slowdown, problem)

    if declared is None:
        if found is None:
            return result("no-inertial", "no <inertial> and no geometry (a frame-only link)")
        return result("no-inertial", f"has a {label} but no <inertial>: Gazebo ignores its mass")
    mass = declared.mass_kg
    if not np.isfinite(mass) or mass_unreadable:
        return result("massless", "the mass is not a number: nothing to compare")
    if mass < 0.0:
        return result("negative-mass", f"mass {mass:g} kg is negative")
    if mass == 0.0:
        I = np.asarray(declared.inertia_kg_m2, dtype=float)
        if np.any(I != 0.0):
            return result("massless-inertia", "mass 0 kg with a non-zero inertia: a body "
                                              "cannot have one without the other")
        if moving:
            return result("massless-moving", "mass 0 kg on a link that moves on its own joint")
        return result("massless", "mass 0 kg (a frame merged into its parent): nothing to compare")
    problem = tensor_problem(declared.inertia_kg_m2)
    if problem == "non-finite" or not np.all(np.isfinite(declared.com_m)):
        # The reader reported the number (S101/S102); nothing here can be judged from it.
        return result("unjudged", "the declared inertial has a number that is not a "
                                  "number (the reader's finding names it): not compared",
                      problem=problem)
    shapes = link.collisions if any(c.geometry is not None for c in link.collisions) \
        else link.visuals
    if any(s.geometry is not None and not np.all(np.isfinite(s.T_link_geom)) for s in shapes):
        return result("unjudged", f"the {label}'s pose is not a number (the reader's "
                                  "finding names it): not compared")
    if found is None:
        if problem:
            return result("invalid", "declared tensor is not physically possible "
                                     "(non-positive or A + B < C principal moments); no geometry "
                                     "to derive one from", problem=problem)
        return result("no-geometry", "no collision or visual geometry to compare with")
    try:
        geometry = link_geometry(link, mass)
    except ReedtoolError as exc:
        if problem:
            return result("invalid", "declared tensor is not physically possible; "
                                     f"{label}: {exc.one_line()}", problem=problem)
        return result("geometry-error", f"{label}: {exc.one_line()}")
    derived = geometry.body
    density = geometry.density_kg_m3
    trace_geom = float(np.trace(derived.inertia_kg_m2))
    ratio = float(np.trace(declared.inertia_kg_m2)) / trace_geom if trace_geom > 0 else float("inf")
    if not problem and density is not None and density > DENSEST_MATERIAL_KG_M3:
        # not judged, but the ratio stays the evidence of a stand-in for a larger part (I221)
        return result("placeholder-geometry",
                      f"the {label} would need {density:,.0f} kg/m³ to hold {mass:g} kg "
                      f"(no material is denser than {DENSEST_MATERIAL_KG_M3:,.0f}): a "
                      "placeholder, not the body, so the tensor is not compared with it",
                      derived, ratio=ratio)
    rel = relative_difference(declared.inertia_kg_m2, derived.inertia_kg_m2)
    # With several shapes the mass may sit in any of them (a motor can heavier than its
    # prop disc): the declared tensor is judged against whichever distribution fits it
    # best, the uniform one or all of the mass in one shape.
    trace_declared = float(np.trace(declared.inertia_kg_m2))
    for alone in geometry.alone if len(geometry.alone) > 1 else ():
        trace_alone = float(np.trace(alone.inertia_kg_m2))
        if trace_alone > 0 and ratio > 0 and np.isfinite(ratio) and abs(
                math.log(trace_declared / trace_alone)) < abs(math.log(ratio)):
            ratio = trace_declared / trace_alone
    offset = float(np.linalg.norm(declared.com_m - derived.com_m))
    gyration_m = np.sqrt(trace_geom / (2.0 * mass)) if trace_geom > 0 else 0.0
    hull = " (of its convex hull: the mesh is open)" if derived.from_hull else ""
    args = (derived, rel, ratio, offset, problem)
    if problem:
        return result("invalid", "declared tensor is not physically possible (non-positive or "
                                 f"A + B < C principal moments); the {label}{hull} gives one",
                      *args)
    if rel > OK_REL_DIFF and slowdown and _plausible(ratio / slowdown):
        return result("slowdown-scaled", f"declared inertia is {_times(ratio)} the {label}'s, "
                                         "plausible once divided by the motor's "
                                         f"rotorVelocitySlowdownSim {slowdown:g} (RotorS "
                                         "convention, not a mistake)", *args)
    # A rotor with a slowdown is expected anywhere between its geometry and s times it:
    # judge it against whichever of the two it is closer to.
    judged = ratio
    if slowdown and np.isfinite(ratio) and ratio > 0 \
            and abs(math.log(ratio / slowdown)) < abs(math.log(ratio)):
        judged = ratio / slowdown
    # Only a tensor too large for its geometry can be certainly wrong: no mass inside a
    # shape turns it 100x harder than the solid shape; mass gathered inside it turns it
    # easier down to any share, so a small tensor stays "implausible" (a warning).
    if not _plausible(judged, ORDERS_OFF_TRACE_RATIO) and judged > 1.0:
        return result("way-off", f"declared inertia is {_times(ratio)} the {label}'s{hull}",
                      *args)
    if not _plausible(judged, PLAUSIBLE_TRACE_RATIO):
        return result("implausible", f"declared inertia is {_times(ratio)} the {label}'s{hull}",
                      *args)
    if rel > OK_REL_DIFF:
        return result("differs", f"declared inertia differs from the {label}'s{hull} by "
                                 f"{rel:.0%}", *args)
    if offset > COM_OFF_GYRATION_RADII * gyration_m:
        return result("com-off", f"declared COM is {offset * 1000:.3g} mm from the {label}'s "
                                 f"centre{hull}", *args)
    return result("ok", f"within {OK_REL_DIFF:.0%} of the {label}'s{hull}", *args)


def _plausible(ratio: float, factor: float = PLAUSIBLE_TRACE_RATIO) -> bool:
    """Within `factor` of the geometry's trace: above it, or below by ORDERS_OFF at least.

    Asymmetric on purpose: a body inside its geometry has at most ~3x the uniform solid's
    trace (all mass in the corners), so 10x more is no mass distribution; but any share
    down to zero is one (a motor or a hub inside a large collision cylinder, a contact
    sensor box around a light frame: PX4's bumper at 1/84), so smaller is judged only at
    the orders-off bound, 1/100 (radius of gyration a tenth of the uniform body's)."""
    return 1.0 / max(factor, ORDERS_OFF_TRACE_RATIO) < ratio < factor


def _times(ratio: float) -> str:
    def number(x: float) -> str:
        return f"{x:,.0f}" if x >= 100 else f"{x:.3g}"
    if not np.isfinite(ratio) or ratio <= 0:
        return f"{ratio:g}x"
    return f"{number(ratio)}x" if ratio >= 1.0 else f"1/{number(1.0 / ratio)} of"


def moving_links(robot: Robot) -> set[str]:
    """Links that are the child of a non-fixed joint (their own body in the simulator)."""
    return {joint.child for joint in robot.joints if joint.moves}


def compare_links(robot: Robot) -> list[LinkComparison]:
    """compare_link for every link of the robot, in document order, then judged in the
    robot (judge_in_robot): a placeholder link, or a tensor whose error does not change
    how the robot flies, is not an error."""
    if robot.static:
        # Scenery: Gazebo never moves a static model, so no mass property of it is used.
        return [LinkComparison(link.name, link.loc, declared_mass_properties(link), None,
                               None, None, None, None, "static",
                               "a static model: Gazebo never moves it, its mass and "
                               "inertia are not used") for link in robot.links]
    moving = moving_links(robot)
    slowdowns = rotor_slowdown_by_link(robot)
    unreadable = unreadable_masses(robot)
    # An SDF link without <inertial> carries sdformat's 1 kg and unit tensor (S120 says so):
    # nothing the author wrote to compare with its geometry.
    defaulted = {issue.subject for issue in robot.parse_issues
                 if issue.kind == "sdf-default-inertial"}
    comparisons = [compare_link(link, moving=link.name in moving,
                                slowdown=slowdowns.get(link.name),
                                mass_unreadable=link.name in unreadable)
                   if link.name not in defaulted else
                   LinkComparison(link.name, link.loc, declared_mass_properties(link), None,
                                  None, None, None, None, "no-inertial",
                                  "no <inertial>: sdformat's default 1 kg and unit inertia")
                   for link in robot.links]
    lumped = lumped_urdf_links(robot)
    comparisons = [replace(c, verdict="point-mass", message="zero moments: a point mass on a "
                           "fixed joint (or merged into its parent), which Gazebo accepts")
                   if c.verdict == "invalid" and c.tensor_problem == "not-positive-definite"
                   and degenerate_but_accepted(c.declared.inertia_kg_m2,
                                               moving=c.link in moving,
                                               lumped=c.link in lumped) else c
                   for c in comparisons]
    return judge_in_robot(robot, comparisons)


def lumped_urdf_links(robot: Robot) -> set[str]:
    """URDF links that Gazebo's URDF->SDF conversion merges into their parent: children of
    fixed joints without preserveFixedJoint/disableFixedJointLumping (parser_urdf.cc)."""
    if robot.source_format != "urdf":
        return set()
    kept = {block.reference for block in robot.gazebo for node in block.elements
            if node.tag in ("disableFixedJointLumping", "preserveFixedJoint")
            and (node.text or "").strip().lower() == "true"}
    return {joint.child for joint in robot.joints
            if joint.type == "fixed" and joint.name not in kept}


# A link is a placeholder when its mass and its inertia about the robot's COM are both
# below this fraction of the robot's. Derivation: hover thrust is proportional to the
# mass, attitude response to the inverse inertia, so such a link changes either by less
# than 0.1 %: ten times below the finest figure a flight stack is tuned to (PX4's
# MPC_THR_HOVER resolution is 0.01 of full thrust; rate gains keep a 2x gain margin) and
# below what a scale (1 g on 2 kg) or a pendulum test (1-5 %) measures. Control surfaces
# of 1e-8 kg and sensor frames of 1e-15 kg are this: whatever their tensor, it cannot
# change how the vehicle flies, so it is not compared.
PLACEHOLDER_FRACTION = 1e-3
# A way-off tensor (100x its geometry's) is an error when it changes how the robot flies:
# swapping it for its geometry's changes a principal moment of the whole robot by this
# factor or more. Attitude controllers keep about a 2x (6 dB) gain margin, so beyond it
# the vehicle tuned on the real inertia is at the edge of stability, and a robot
# dominated by one wrong tensor (a 0.1 kg wheel with 1.0 kg·m²) moves like another body.
# Below it reedtool cannot tell a wrong tensor from a placeholder geometry (a 5 mm box
# standing for a 0.28 kg tilt unit): a warning that says so.
ROBOT_INERTIA_FACTOR = 2.0


def _robot_frame(robot: Robot):
    """(link poses in the base frame, whole-robot MassProperties) or None when the tree or
    the masses leave them undefined."""
    from reedtool.physics.kinematics import link_poses

    try:
        poses = link_poses(robot)
    except (ReedtoolError, KeyError, ValueError):
        return None
    if not all(np.all(np.isfinite(T)) for T in poses.values()):
        return None     # a pose the reader could not read: no whole robot to judge in
    parts = []
    for name, T_base_link in poses.items():
        declared = declared_mass_properties(robot.link_map[name])
        if declared is None:
            continue
        if not (np.isfinite(declared.mass_kg) and np.all(np.isfinite(declared.com_m))
                and np.all(np.isfinite(declared.inertia_kg_m2))) or declared.mass_kg < 0:
            return None
        parts.append(declared.transformed(T_base_link))
    whole = combine(parts)
    if whole.mass_kg <= 0 or not np.all(np.isfinite(whole.inertia_kg_m2)):
        return None
    return poses, whole


def _about_robot_com(part: MassProperties, T_base_link, com_m) -> np.ndarray:
    return part.transformed(T_base_link).inertia_about(com_m)


def _placeholder_shares(declared: MassProperties, T_base_link, whole: MassProperties,
                        smallest_moment: float) -> tuple[float, float]:
    """(mass share, inertia share) of a link in the robot; see PLACEHOLDER_FRACTION."""
    J = _about_robot_com(declared, T_base_link, whole.com_m)
    return (declared.mass_kg / whole.mass_kg,
            float(np.max(principal_moments(J))) / smallest_moment)


def placeholder_links(robot: Robot) -> set[str]:
    """Links whose mass and inertia about the robot's COM are both under
    PLACEHOLDER_FRACTION of the robot's: nothing about them can change how it flies."""
    frame = _robot_frame(robot)
    if frame is None:
        return set()
    poses, whole = frame
    smallest = float(principal_moments(whole.inertia_kg_m2)[0])
    if smallest <= 0:
        return set()
    out = set()
    for name, T in poses.items():
        declared = declared_mass_properties(robot.link_map[name])
        if declared is None or not declared.mass_kg > 0:
            continue
        mass_share, inertia_share = _placeholder_shares(declared, T, whole, smallest)
        if mass_share < PLACEHOLDER_FRACTION and inertia_share < PLACEHOLDER_FRACTION:
            out.add(name)
    return out


def own_tensor_share(robot: Robot, link_name: str) -> float | None:
    """The link's own tensor (about its COM: what an I202/I203 error is about; its mass
    and position are judged elsewhere) as a fraction of the whole robot's smallest
    principal moment; None when the robot's mass properties are undefined.

    Any tensor of that size or smaller in its place changes each whole-robot principal
    moment by at most this fraction."""
    frame = _robot_frame(robot)
    link = robot.link_map.get(link_name)
    if frame is None or link is None or link.inertial is None:
        return None
    _poses, whole = frame
    smallest = float(principal_moments(whole.inertia_kg_m2)[0])
    I = np.asarray(link.inertial.inertia_kg_m2, dtype=float)
    if smallest <= 0 or not np.all(np.isfinite(I)):
        return None
    return float(np.max(np.abs(np.linalg.eigvalsh((I + I.T) / 2.0)))) / smallest


def judge_in_robot(robot: Robot, comparisons: list[LinkComparison]) -> list[LinkComparison]:
    """Lower way-off and implausible verdicts that cannot matter to the robot; the others
    are returned unchanged.

    A placeholder (PLACEHOLDER_FRACTION) is not compared. A way-off tensor stays an error
    when swapping every way-off tensor of the robot for its geometry's changes a principal
    moment of the whole robot by ROBOT_INERTIA_FACTOR or more (several links may share one
    copied value: the smartcar's 1.0 everywhere), and this link's own swap is a tenth or
    more of that change; otherwise it is implausible (a warning saying why).
    """
    if not any(c.verdict in ("way-off", "implausible") for c in comparisons):
        return comparisons
    frame = _robot_frame(robot)
    if frame is None:
        return comparisons
    poses, whole = frame
    J_robot = whole.inertia_kg_m2
    moments = principal_moments(J_robot)
    if moments[0] <= 0:
        return comparisons

    judged: dict[str, tuple[str, str]] = {}        # link -> (verdict, message)
    changes: dict[str, np.ndarray] = {}            # way-off link -> J_geometry - J_declared
    for c in comparisons:
        T = poses.get(c.link)
        if c.verdict not in ("way-off", "implausible") or T is None or c.derived is None:
            continue
        J_declared = _about_robot_com(c.declared, T, whole.com_m)
        mass_share, inertia_share = _placeholder_shares(c.declared, T, whole, float(moments[0]))
        if mass_share < PLACEHOLDER_FRACTION and inertia_share < PLACEHOLDER_FRACTION:
            judged[c.link] = ("placeholder", (
                f"{c.message}; a placeholder: {mass_share:.1e} of the whole-robot mass and "
                f"{inertia_share:.1e} of its smallest moment cannot change how it flies"))
        elif c.verdict == "way-off":
            changes[c.link] = _about_robot_com(c.derived, T, whole.com_m) - J_declared
    if changes:
        total = sum(changes.values())
        swapped = principal_moments(J_robot + total)
        factor = float(np.max(np.maximum(swapped / moments,
                                         moments / np.maximum(swapped, 1e-300))))
        largest = float(np.max(np.abs(np.linalg.eigvalsh(total))))
        for name, change in changes.items():
            own = float(np.max(np.abs(np.linalg.eigvalsh(change))))
            c = next(c for c in comparisons if c.link == name)
            if factor >= ROBOT_INERTIA_FACTOR and own >= 0.1 * largest:
                others = len(changes) - 1
                together = (f"with the {others} other way-off tensor{'s' * (others > 1)} "
                            "it changes" if others else "it changes")
                judged[name] = ("way-off", f"{c.message}; {together} the whole-robot "
                                           f"inertia {factor:.3g}x")
            else:
                change = (f"{factor:.3g}x" if factor >= 1.1
                          else f"{100 * (factor - 1):.2g} %")
                judged[name] = ("implausible", (
                    f"{c.message}; swapping it for its geometry's changes the whole-robot "
                    f"inertia by {change} at most, so a wrong tensor and a placeholder "
                    "geometry fly alike"))
    return [replace(c, verdict=judged[c.link][0], message=judged[c.link][1])
            if c.link in judged else c for c in comparisons]


def robot_mass_problem(robot: Robot) -> str | None:
    """Why the whole robot cannot be simulated for its mass (sum <= 0 kg), or None.

    The plain sum over links with a finite declared mass: Gazebo needs a positive total.
    """
    if unreadable_masses(robot):
        return None          # a mass that is not a number: S101 says so, the sum is unknown
    masses = [link.inertial.mass_kg for link in robot.links
              if link.inertial is not None and math.isfinite(link.inertial.mass_kg)]
    if not masses:
        return None          # nothing declared: S117/I201 speak about the links
    total = float(sum(masses))
    if total <= 0.0:
        return f"the whole robot's mass is {total:g} kg (sum over {len(masses)} links)"
    return None
