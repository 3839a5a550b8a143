"""A ViewScene as a PNG: matplotlib's 3-D axes, headless (Agg), no GPU, no display.

Triangles are drawn flat-shaded (a head light, so a face's colour shows its slope) with
the painter's algorithm matplotlib's 3-D axes use. Big meshes are decimated by keeping
every k-th triangle, so a CAD export of a million faces renders in about a second and
still shows its outline; decorations (rotor discs, arrows, axes, scale bar) are small
and always drawn whole. The caption gives the robot's bounding box and the scale bar's
length in metres, so a model 1000x too big reads as such at a glance.
"""

from __future__ import annotations

import io
import math

import numpy as np

from reedtool.report.scene import DECORATION_PREFIXES, FRONT_RGBA, SEVERITY_RGBA, SPIN_RGBA, \
    ViewScene, length_text

MAX_ROBOT_FACES = 15_000        # triangles of the robot's own geometry drawn at most
# (elevation, azimuth) of each named camera, matplotlib's convention (azimuth 0 looks
# from +x). top: from above with x forward up the page and y left to the left, as
# `layout` draws it; front: from ahead of the nose; side: from the left (+y); iso: from
# front-left, above, x forward pointing to the lower left.
VIEWS_DEG = {"top": (90.0, 180.0), "front": (0.0, 0.0), "side": (0.0, 90.0),
             "iso": (28.0, -130.0)}
DEFAULT_SIZE_PX = (576, 504)
DPI = 90


def _triangles(view: ViewScene):
    """(triangles (n, 3, 3) in the base frame, rgba (n, 4) in 0..1, decoration flags)."""
    scene, base = view.scene, view.base_link
    parts = []
    for node in scene.graph.nodes_geometry:
        T_base_node = scene.graph.get(node, base)[0]
        mesh = scene.geometry[scene.graph[node][1]]
        vertices = np.asarray(mesh.vertices, dtype=float) @ T_base_node[:3, :3].T \
            + T_base_node[:3, 3]
        faces = np.asarray(mesh.faces)
        colours = np.asarray(mesh.visual.face_colors, dtype=float)[:, :4] / 255.0
        parts.append((vertices[faces], colours, node.startswith(DECORATION_PREFIXES)))
    return parts


def decimated(parts, max_faces: int = MAX_ROBOT_FACES):
    """Every k-th triangle of the robot's meshes so at most `max_faces` remain."""
    robot_faces = sum(len(t) for t, _, decoration in parts if not decoration)
    stride = max(1, math.ceil(robot_faces / max_faces))
    out = []
    for triangles, colours, decoration in parts:
        if not decoration and stride > 1:
            triangles, colours = triangles[::stride], colours[::stride]
        out.append((triangles, colours, decoration))
    return out, stride


def _shaded(triangles: np.ndarray, colours: np.ndarray, view_dir: np.ndarray) -> np.ndarray:
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(normals, axis=1)
    length[length == 0] = 1.0
    light = np.abs(normals @ view_dir) / length
    out = colours.copy()
    out[:, :3] *= (0.45 + 0.55 * light)[:, None]
    return out


def _view_dir(name: str) -> np.ndarray:
    elevation, azimuth = (math.radians(v) for v in VIEWS_DEG[name])
    return np.array([math.cos(elevation) * math.cos(azimuth),
                     math.cos(elevation) * math.sin(azimuth), math.sin(elevation)])


def _draw(ax, name: str, view: ViewScene, triangles: np.ndarray, colours: np.ndarray) -> None:
    """One camera's picture on `ax`: orthographic, so lengths read true along the axes."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if len(triangles):
        shaded = _shaded(triangles, colours, _view_dir(name))
        # edges in the face colour close the anti-aliasing seams between triangles
        ax.add_collection3d(Poly3DCollection(triangles, facecolors=shaded, edgecolors=shaded,
                                             linewidths=0.3, zorder=1))
        low, high = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    else:
        low, high = view.framing.bounds_m
    # one scale on all three axes, each axis no shorter than 30 % of the longest, so a
    # flat multirotor is not lost in an empty cube
    centre = (low + high) / 2.0
    halves = np.maximum((high - low) / 2.0, 0.3 * max(float(np.max(high - low)) / 2.0, 1e-9))
    for setter, c, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, halves):
        setter(c - h, c + h)
    ax.computed_zorder = False        # the COM and labels are drawn over the meshes
    if view.com_m is not None:
        ax.scatter(*view.com_m, marker="x", s=80, linewidths=2.5, color="black", zorder=9,
                   depthshade=False)
    for label in view.labels:
        front = label.kind == "front"
        ax.text(*label.position_m, label.text, fontsize=9 if front else 8, fontweight="bold",
                color="#c81e1e" if front else "black", ha="center", va="center", zorder=11,
                bbox=None if front else dict(boxstyle="circle,pad=0.15", facecolor="white",
                                             edgecolor="#555555", linewidth=0.6))
    ax.set_proj_type("ortho")
    ax.set_box_aspect(tuple(halves), zoom=1.05)
    elevation, azimuth = VIEWS_DEG[name]
    ax.view_init(elev=elevation, azim=azimuth)
    ax.set_xlabel("x [m]", fontsize=8)
    ax.set_ylabel("y [m]", fontsize=8)
    ax.set_zlabel("z [m]", fontsize=8)
    ax.tick_params(labelsize=7)
    # an axis that points at the camera has all its ticks on one spot: leave it unlabelled
    depth = {"top": ax.zaxis, "front": ax.xaxis, "side": ax.yaxis}.get(name)
    if depth is not None:
        depth.set_ticks([])
        depth.set_label_text("")
    framing = view.framing
    bar_at = framing.bounds_m[0] + [framing.scale_bar_m / 2.0,
                                    -0.05 * float(np.max(framing.extent_m)), 0.0]
    ax.text(bar_at[0], bar_at[1], bar_at[2] + 0.03 * float(np.max(framing.extent_m)),
            length_text(framing.scale_bar_m), fontsize=9, fontweight="bold", ha="center",
            va="bottom", zorder=10)


def render_png(view: ViewScene, title: str, views: tuple[str, ...] = ("iso",),
               size_px: tuple[int, int] = DEFAULT_SIZE_PX) -> bytes:
    """The scene from each camera of `views` (VIEWS_DEG), side by side, `size_px` in all."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    parts, stride = decimated(_triangles(view))
    triangles = np.concatenate([t for t, _, _ in parts]) if parts else np.zeros((0, 3, 3))
    colours = np.concatenate([c for _, c, _ in parts]) if parts else np.zeros((0, 4))
    columns = 2 if len(views) == 4 else len(views)
    rows = math.ceil(len(views) / columns)
    fig = plt.figure(figsize=(size_px[0] / DPI, size_px[1] / DPI))
    for number, name in enumerate(views, start=1):
        ax = fig.add_subplot(rows, columns, number, projection="3d")
        _draw(ax, name, view, triangles, colours)
        if len(views) > 1:
            ax.set_title(name, fontsize=9)
    fig.suptitle(title, fontsize=10)
    notes = [view.framing.caption()]
    if stride > 1:
        notes.append(f"every {stride}th triangle of the meshes drawn")
    fig.text(0.5, 0.01, "\n".join(notes), ha="center", va="bottom", fontsize=8)
    _legend(fig, view)
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.08, top=0.93, wspace=0.0, hspace=0.05)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    plt.close(fig)
    return buffer.getvalue()


def _legend(fig, view: ViewScene) -> None:
    from matplotlib.patches import Patch

    entries = []
    spins = {int(np.sign(d.turning_sign)) for d in view.discs}
    for sign, label in ((1, "ccw rotor"), (-1, "cw rotor"), (0, "spin unknown")):
        if sign in spins:
            entries.append((SPIN_RGBA[sign], label))
    for severity in ("error", "warning", "info"):
        if severity in view.link_severity.values():
            entries.append((SEVERITY_RGBA[severity], f"{severity} finding"))
    if view.com_m is not None:
        entries.append(((0, 0, 0, 255), "COM"))
    entries.append((FRONT_RGBA, "FRONT (+x)"))
    if entries:
        fig.legend(handles=[Patch(facecolor=np.asarray(rgba) / 255.0, label=label)
                            for rgba, label in entries],
                   loc="upper left", fontsize=7, frameon=False)
