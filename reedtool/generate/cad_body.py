"""`new-package --mesh`: a CAD body as the CAD drew it, with its rotors where it has them.

The mesh keeps its CAD frame: base_link is the CAD origin and the mesh is not moved. Its
centre of mass goes into the body's <inertial><origin> (as onshape-to-robot and the
SolidWorks URDF exporter write it). The rotors go either

- on the motor mounts found in the mesh (physics.motor_mounts), when no arm length is
  given, or
- at the frame's pattern for the arm length about the rotor centre the user names
  (`--center`: the CAD origin by default, the COM, the mounts' centre, or x,y,z).

Either way the output says where the COM is against the rotors and what that does to the
hover trim (per-rotor thrusts, physics.trim), so an off-centre COM is seen, not erased.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from reedtool.errors import ReedtoolError

CENTRE_WORDS = ("origin", "com", "mounts")
# A rotor is on its mount when its axis is within this of the mount's: an M3 screw in a
# 3.2-3.4 mm hole has 0.1-0.2 mm of play, so 2 mm off is a motor that does not bolt on.
ON_MOUNT_M = 0.002
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_CENTRE = re.compile(rf"^\s*({_NUMBER})\s*,\s*({_NUMBER})\s*,\s*({_NUMBER})\s*([a-z]*)\s*$")


def parse_centre(text: str | None):
    """--center: origin | com | mounts | X,Y,Z[unit] (FLU, CAD frame; unit m, cm, mm, in)."""
    from reedtool.physics.mesh_units import UNITS_M

    word = (text or "origin").strip().lower()
    if word in CENTRE_WORDS:
        return word
    match = _CENTRE.match(word)
    if match is None or (match.group(4) and match.group(4) not in UNITS_M):
        raise ReedtoolError(f"bad --center '{text}'",
                            hint="use origin, com, mounts, or x,y,z with an optional unit "
                                 "(m, cm, mm, in), e.g. '15.2,0,0 mm' (FLU, the CAD frame)")
    scale = UNITS_M[match.group(4) or "m"]
    return np.array([float(match.group(i)) for i in (1, 2, 3)]) * scale


@dataclass
class CadBody:
    imported: object                 # physics.mesh_import.ImportedMesh (CAD frame, metres)
    props: object                    # physics.inertia.MassProperties, COM in the CAD frame
    centre_m: np.ndarray
    centre_how: str
    mounts: object                   # physics.motor_mounts.MountReading
    on_mounts: bool                  # rotors placed on the mounts (else by the arm length)
    mount_offsets_m: list[float]     # each rotor's distance from its mount ([] without)
    layout_note: str                 # why the rotors are where they are
    trim: object = None              # physics.trim.TrimResult with the COM where it is
    total_com_m: np.ndarray | None = None


def _mount_slots(spec, mounts):
    """Mount index per rotor slot, or None when the mounts do not follow the frame."""
    from reedtool.physics.motor_mounts import match_bearings

    centre = np.mean([m.xy_m for m in mounts.mounts], axis=0)
    return match_bearings(mounts.mounts, [s.bearing_deg for s in spec.frame.rotors], centre)


def load_cad_body(spec, *, units: str = "auto", frame: str | None = None,
                  centre: str | None = None) -> CadBody:
    """Import spec.mesh in its CAD frame and place the rotors on it; sets spec.cad (and the
    arm length when the mounts give it)."""
    from reedtool.physics.mesh_import import import_mesh
    from reedtool.physics.motor_mounts import MountReading, find_mounts
    from reedtool.generate.package_spec import (
        CadPlacement,
        check_geometry,
        rotor_positions_m,
    )

    choice = parse_centre(centre)
    multirotor = spec.kind == "multirotor"
    arm_given = multirotor and spec.origin.get("arm_length") != "default"
    arm_radial = (spec["arm_length"] * spec.frame.radial_per_arm_length) if arm_given else None
    coaxial = multirotor and any(slot.level < 0 for slot in spec.frame.rotors)
    imported = import_mesh(spec.mesh, units=units, from_frame=frame or "auto",
                           mass_kg=spec["mass"], role="body" if multirotor else "part",
                           arm_radial_m=arm_radial, flags=("--mesh-units", "--mesh-frame"),
                           mount_count=spec.frame.rotor_count if multirotor and not coaxial
                           else None)
    props = imported.mass
    _size_body_box(spec, imported)
    vertices = imported.triangles_m.reshape(-1, 3)
    bottom = float(vertices[:, 2].min())
    if not multirotor:
        spec.cad = CadPlacement((0.0, 0.0, 0.0), tuple(props.com_m), bottom)
        return CadBody(imported, props, np.zeros(3), "the CAD origin", MountReading((), ""),
                       False, [], "")

    mounts = (MountReading((), "a coaxial frame: rotors are placed by the arm length")
              if coaxial else find_mounts(imported.triangles_m, spec.frame.rotor_count))
    slots = _mount_slots(spec, mounts) if mounts.mounts else None
    if mounts.mounts and slots is None:
        mounts = MountReading((), mounts.reason + ", but they do not follow the "
                              f"{spec.frame.title} layout: not used")

    top = spec["rotor_offset_top"]
    # Rotors go on the mounts unless the user placed them: an arm length or a centre.
    on_mounts = bool(mounts.mounts) and not arm_given and centre is None
    if mounts.mounts:
        on_slots = [mounts.mounts[i] for i in slots]
        mount_xyz = np.array([(m.xy_m[0], m.xy_m[1], m.top_z_m) for m in on_slots])
        mounts_centre = mount_xyz.mean(axis=0)
    if on_mounts:
        centre_m, centre_how = mounts_centre, "the motor mounts' centre"
        # Rounded to 0.1 um: a float32 STL carries about 7 digits.
        positions = tuple(tuple(round(float(v), 7) + 0.0 for v in (x, y, z + top))
                          for x, y, z in mount_xyz)
        measured = _arm_length_from(spec.frame, np.array(positions), centre_m)
        spec.values["arm_length"], spec.origin["arm_length"] = measured, "the motor mounts"
        note = (f"rotors on the motor mounts, rotor_offset_top {top:g} m above their tops; "
                f"arm_length {measured:.4g} m measured from their centre")
        spec.cad = CadPlacement(tuple(float(v) for v in centre_m), tuple(props.com_m), bottom,
                                positions)
    else:
        centre_m, centre_how = _resolve_centre(choice, props, mounts)
        if arm_given:
            source = "given"
        elif mounts.mounts:
            measured = _arm_length_from(spec.frame, mount_xyz, mounts_centre)
            spec.values["arm_length"], spec.origin["arm_length"] = measured, "the motor mounts"
            source = "measured from the motor mounts"
        else:
            source = "the default (pass --arm-length)"
        spec.cad = CadPlacement(tuple(float(v) for v in centre_m), tuple(props.com_m), bottom)
        note = f"rotors at arm_length {spec['arm_length']:.4g} m ({source}) about the rotor centre"
    offsets = []
    if mounts.mounts:
        positions_now = rotor_positions_m(spec)
        offsets = [float(np.linalg.norm(positions_now[k, :2] - mounts.mounts[i].xy_m))
                   for k, i in enumerate(slots)]
    check_geometry(spec)
    body = CadBody(imported, props, centre_m, centre_how, mounts, on_mounts, offsets, note)
    body.trim, body.total_com_m = hover_trim(spec, props)
    if not body.trim.feasible:
        # A model that cannot hover is not written: validate would refuse it (R307).
        raise ReedtoolError(
            f"the rotors about {centre_how.split(' (')[0].replace(chr(39), '')} cannot hold "
            "this body level: "
            f"its centre of mass is at {_mm(props.com_m)} in the CAD frame; "
            f"{body.trim.message}", file=spec.mesh,
            hint="pass --center com (rotors about the COM), --center x,y,z, or move the CAD "
                 "origin to the motor centre and export again")
    return body


def _size_body_box(spec, imported) -> None:
    """The body box parameters (still the template's fallback) follow the mesh unless set."""
    size_m = imported.size_m
    if spec.origin.get("body_width") == "default":
        wide = max(size_m[0], size_m[1]) if spec.kind == "multirotor" else size_m[1]
        spec.values["body_width"], spec.origin["body_width"] = float(wide), "the mesh"
    if spec.origin.get("body_height") == "default":
        spec.values["body_height"], spec.origin["body_height"] = float(size_m[2]), "the mesh"
    if spec.kind == "ground" and spec.origin.get("body_length") == "default":
        spec.values["body_length"], spec.origin["body_length"] = float(size_m[0]), "the mesh"


def _resolve_centre(choice, props, mounts) -> tuple[np.ndarray, str]:
    if isinstance(choice, np.ndarray):
        return choice, "given with --center"
    if choice == "com":
        return np.array(props.com_m, dtype=float), "the body COM (--center com)"
    if choice == "mounts":
        if not mounts.mounts:
            raise ReedtoolError(f"--center mounts: {mounts.reason}",
                                hint="use --center origin, com or x,y,z")
        xy = np.mean([m.xy_m for m in mounts.mounts], axis=0)
        z = float(np.mean([m.top_z_m for m in mounts.mounts]))
        return np.array([xy[0], xy[1], z]), "the motor mounts' centre (--center mounts)"
    return np.zeros(3), "the CAD origin (default; --center names another)"


def _arm_length_from(frame, positions: np.ndarray, centre_m: np.ndarray) -> float:
    """The frame's arm_length that best fits `positions` about `centre_m` (least squares
    over the rotors' x and y)."""
    unit = np.array([frame.unit_xy(slot) for slot in frame.rotors])
    offsets = positions[:, :2] - centre_m[:2]
    return float(np.sum(unit * offsets) / np.sum(unit * unit))


def hover_trim(spec, body_props):
    """Trim of the whole vehicle (body, rotors, sensors) as new-package writes it: the
    per-rotor thrusts its COM asks for. Returns (TrimResult, total COM)."""
    from reedtool.physics.allocation import allocation_from_geometry
    from reedtool.physics.inertia import MassProperties, combine
    from reedtool.physics.trim import trim_from_allocation
    from reedtool.generate.package_spec import (
        STANDARD_GRAVITY_M_S2,
        rotor_positions_m,
        sensor_mass_kg,
    )

    positions = rotor_positions_m(spec)
    parts = [body_props] + [MassProperties(spec["mass_rotor"], p, np.zeros((3, 3)))
                            for p in positions]
    if sensor_mass_kg(spec) > 0:
        parts.append(MassProperties(sensor_mass_kg(spec), np.zeros(3), np.zeros((3, 3))))
    total = combine(parts)
    n = len(positions)
    A = allocation_from_geometry(positions, [(0.0, 0.0, 1.0)] * n, spec.frame.turning_signs(),
                                 [spec["moment_constant"]] * n, total.com_m)
    names = [slot.suffix for slot in spec.frame.rotors]
    trim = trim_from_allocation(A, np.full(n, spec["motor_constant"]),
                                np.full(n, spec["max_rot_velocity"]),
                                total.mass_kg * STANDARD_GRAVITY_M_S2, names)
    return trim, np.asarray(total.com_m)


def _mm(v) -> str:
    # Below 0.1 um is round-off (a float32 STL), shown as 0.
    return "(" + ", ".join(f"{(0.0 if abs(x) < 1e-7 else float(x) * 1000) + 0.0:.4g}"
                           for x in v) + ") mm"


def cad_lines(body: CadBody, spec) -> list[str]:
    """What new-package did with the CAD body: frame, COM, centre, rotors, trim."""
    lines = ["  kept in its CAD frame: base_link is the CAD origin, the mesh is not moved",
             f"  centre of mass (body): {_mm(body.props.com_m)} from the CAD origin, "
             "in <inertial><origin>"]
    if spec.kind != "multirotor":
        return lines
    lines.append(f"  rotor centre: {_mm(body.centre_m)}, {body.centre_how}")
    lines.append(f"  motor mounts: {body.mounts.reason}")
    lines.append(f"  {body.layout_note}")
    if body.mount_offsets_m:
        worst = max(body.mount_offsets_m)
        if worst <= ON_MOUNT_M:
            lines.append(f"  every rotor is on its mount (within {worst * 1000:.3f} mm)")
        else:
            names = [slot.suffix for slot in spec.frame.rotors]
            off = ", ".join(f"{n} {d * 1000:.3g} mm" for n, d in zip(names, body.mount_offsets_m)
                            if d > ON_MOUNT_M)
            lines.append(f"  NOT over the mesh's motor mounts: {off} off "
                         f"(drop --arm-length to place them on the mounts, or check --center)")
    lines.extend(trim_lines(body, spec))
    return lines


def trim_lines(body: CadBody, spec) -> list[str]:
    trim = body.trim
    from reedtool.generate.package_spec import rotor_positions_m

    centroid = rotor_positions_m(spec).mean(axis=0)
    shift = (body.total_com_m - centroid)[:2]
    lines = [f"  whole-vehicle COM {_mm(body.total_com_m)}: "
             f"{np.hypot(*shift) * 1000:.3g} mm from the rotors' centroid "
             f"{_mm(shift)} in x, y"]
    if not trim.feasible:
        lines.append(f"  hover trim: NOT POSSIBLE: {trim.message}")
        return lines
    thrust = trim.thrust_N
    low, high = int(np.argmin(thrust)), int(np.argmax(thrust))
    names = trim.rotor_names
    lines.append(f"  hover trim: {thrust[low]:.3g} N ({names[low]}) to {thrust[high]:.3g} N "
                 f"({names[high]}), {100 * (thrust[high] / thrust[low] - 1):.0f} % apart; "
                 f"the busiest rotor at {100 * trim.throttle[high]:.0f} % speed")
    lines.append("  per rotor: " + ", ".join(f"{n} {t:.3g} N" for n, t in zip(names, thrust)))
    return lines
