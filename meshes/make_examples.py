"""Generate the bundled example meshes (run: python meshes/make_examples.py).

Both are prisms: a 2-D profile extruded along one axis, triangulated as a fan from a
vertex that sees the whole profile, so every edge is shared by exactly two triangles
(watertight, outward-wound). Written with trimesh's STL exporter, not reedtool's, so
reedtool's reader is tested against a writer it did not write.

- l_bracket_mm_ned.stl: an asymmetric L-bracket in MILLIMETRES and NED body axes
  (x forward, y right, z down), like the seed's SolidWorks export. Profile in (x, z):
  a 60 x 5 mm plate and a 5 mm thick upright reaching 30 mm "down" (NED z), 40 mm wide
  along y. Import with: reedtool import-stl meshes/l_bracket_mm_ned.stl --units mm --from-frame ned
- quad_body_mm.stl: a simple X-frame quad body in MILLIMETRES, FLU: four 20 mm wide arms
  reaching 125 mm from the centre along the diagonals, 10 mm thick.
- quadx_body_mm_ned.stl: the seed's story, a SolidWorks-style quad-X body in MILLIMETRES and
  NED, drawn upward from its CAD origin, which is the motor centre: four round motor mounts
  (radius 15 mm, 8 mm tall, 32-sided) at x, y = +-176.8 mm, arms 12 x 4 mm, a 140 x 140 x 4
  mm plate and a battery block 100 x 40 x 30 mm mounted forward, so the centre of mass
  is about 15 mm ahead of the motor centre. Separate closed shells that touch but do not
  overlap (QUADX_PARTS lists them, for analytic mass properties). Import with:
  reedtool new-package my_quad --mesh meshes/quadx_body_mm_ned.stl --mesh-frame ned --mass 1.2
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

# L profile in the (x, z) plane of NED, millimetres; vertex 0 (the inner corner of the
# outside) sees the whole profile, so a fan from it triangulates the caps.
L_PROFILE_XZ_MM = [(0, 0), (60, 0), (60, 5), (5, 5), (5, 30), (0, 30)]
L_WIDTH_Y_MM = (0.0, 40.0)


def prism(profile_uv, w_range, axes=(0, 2, 1), fan_centre=None):
    """Vertices and faces of a prism: `profile_uv` extruded along w over `w_range`.

    `axes` says which xyz axis u, v and w are. With `fan_centre` (u, v) the caps are
    fanned from an added centre vertex, otherwise from profile vertex 0.
    """
    profile = [tuple(map(float, p)) for p in profile_uv]
    if fan_centre is not None:
        profile_cap = [tuple(map(float, fan_centre))]
    else:
        profile_cap = []
    n = len(profile)
    vertices, faces = [], []

    def vertex(u, v, w):
        xyz = [0.0, 0.0, 0.0]
        xyz[axes[0]], xyz[axes[1]], xyz[axes[2]] = u, v, w
        vertices.append(xyz)
        return len(vertices) - 1

    w0, w1 = w_range
    bottom = [vertex(u, v, w0) for u, v in profile]
    top = [vertex(u, v, w1) for u, v in profile]
    if profile_cap:
        cb, ct = vertex(*profile_cap[0], w0), vertex(*profile_cap[0], w1)
        for i in range(n):
            j = (i + 1) % n
            faces.append((cb, bottom[j], bottom[i]))
            faces.append((ct, top[i], top[j]))
    else:
        for i in range(1, n - 1):
            faces.append((bottom[0], bottom[i + 1], bottom[i]))
            faces.append((top[0], top[i], top[i + 1]))
    for i in range(n):
        j = (i + 1) % n
        faces.append((bottom[i], bottom[j], top[j]))
        faces.append((bottom[i], top[j], top[i]))
    vertices, faces = np.array(vertices), np.array(faces)
    # Orientation depends on the profile's sense and the axes' handedness; make it outward.
    tri = vertices[faces]
    signed_volume = np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6.0
    if signed_volume < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def l_bracket_mm_ned():
    return prism(L_PROFILE_XZ_MM, L_WIDTH_Y_MM, axes=(0, 2, 1))


def quad_body_mm():
    # A plus-shaped profile (arms along +-u, +-v), rotated 45 deg to make an X frame.
    reach, half = 125.0, 10.0
    plus = [(reach, -half), (reach, half), (half, half), (half, reach), (-half, reach),
            (-half, half), (-reach, half), (-reach, -half), (-half, -half), (-half, -reach),
            (half, -reach), (half, -half)]
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    x_frame = [(c * u - s * v, s * u + c * v) for u, v in plus]
    return prism(x_frame, (-5.0, 5.0), axes=(0, 1, 2), fan_centre=(0.0, 0.0))


# quadx_body_mm_ned, in FLU millimetres before the NED export: (kind, parameters).
QUADX_MOUNT_XY_MM = 176.8
QUADX_MOUNT_RADIUS_MM = 15.0
QUADX_MOUNT_HEIGHT_MM = 8.0
QUADX_MOUNT_SIDES = 32
QUADX_ARM_WIDTH_MM, QUADX_PLATE_HALF_MM, QUADX_PLATE_MM = 12.0, 70.0, 4.0
QUADX_BATTERY_MM = ((-18.0, -20.0, 4.0), (82.0, 20.0, 34.0))    # lo, hi corners


def box_mesh(lo, hi, yaw_rad: float = 0.0):
    """A closed, outward-wound box from corner lo to hi, turned by yaw about z."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])], float)
    faces = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
                      (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    corners = corners @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T
    return _outward(corners, faces)


def cylinder_mesh(cx, cy, radius, z0, z1, sides):
    """A closed prism on a regular `sides`-gon (a tessellated upright cylinder)."""
    angles = 2 * np.pi * np.arange(sides) / sides
    ring = [(cx + radius * np.cos(a), cy + radius * np.sin(a)) for a in angles]
    return prism(ring, (z0, z1), axes=(0, 1, 2), fan_centre=(cx, cy))


def _outward(vertices, faces):
    tri = vertices[faces]
    if np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def quadx_parts_flu_mm():
    """The parts of quadx_body_mm_ned in FLU millimetres: [(kind, params, (V, F))]."""
    m, r, h = QUADX_MOUNT_XY_MM, QUADX_MOUNT_RADIUS_MM, QUADX_MOUNT_HEIGHT_MM
    half, t, w = QUADX_PLATE_HALF_MM, QUADX_PLATE_MM, QUADX_ARM_WIDTH_MM
    parts = [("box", ((-half, -half, 0.0), (half, half, t), 0.0),
              box_mesh((-half, -half, 0.0), (half, half, t)))]
    # Arm along each diagonal from the plate corner (r = half*sqrt 2) to the mount's edge.
    start, end = half * np.sqrt(2.0), m * np.sqrt(2.0) - r
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        yaw = np.arctan2(sy, sx)
        lo, hi = (start, -w / 2, 0.0), (end, w / 2, t)
        parts.append(("box", (lo, hi, yaw), box_mesh(lo, hi, yaw)))
        parts.append(("cylinder", (sx * m, sy * m, r, 0.0, h, QUADX_MOUNT_SIDES),
                      cylinder_mesh(sx * m, sy * m, r, 0.0, h, QUADX_MOUNT_SIDES)))
    lo, hi = QUADX_BATTERY_MM
    parts.append(("box", (lo, hi, 0.0), box_mesh(lo, hi)))
    return parts


def quadx_body(metres_per_unit: float = 0.001, frame: str = "ned"):
    """quadx_body in the given unit and axes ('ned': x, -y, -z; 'flu'; 'y-up': LUF, i.e.
    file (x, y, z) = FLU (y, z, x))."""
    vertices, faces = [], []
    for _kind, _params, (V, F) in quadx_parts_flu_mm():
        faces.append(F + sum(len(v) for v in vertices))
        vertices.append(V)
    V = np.vstack(vertices) * (0.001 / metres_per_unit)
    if frame == "ned":
        V = V * np.array([1.0, -1.0, -1.0])
    elif frame == "y-up":
        V = V[:, [1, 2, 0]]
    elif frame != "flu":
        raise ValueError(frame)
    return V, np.vstack(faces)


def write(path: Path, vertices, faces, header: bytes | None = None) -> None:
    import trimesh

    data = trimesh.Trimesh(vertices, faces, process=False).export(file_type="stl")
    if header is not None:
        data = header.ljust(80, b" ")[:80] + data[80:]
    path.write_bytes(data)


def main() -> None:
    write(HERE / "l_bracket_mm_ned.stl", *l_bracket_mm_ned(),
          header=b"l_bracket: millimetres, NED body axes (x fwd, y right, z down)")
    write(HERE / "quad_body_mm.stl", *quad_body_mm(),
          header=b"quad_body: millimetres, FLU body axes")
    write(HERE / "quadx_body_mm_ned.stl", *quadx_body(),
          header=b"quadx_body: millimetres, NED body axes, CAD origin = motor centre")


if __name__ == "__main__":
    main()
