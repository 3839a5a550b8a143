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


if __name__ == "__main__":
    main()
