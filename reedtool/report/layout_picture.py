"""The rotor layout picture: a top view, as PX4's airframe reference draws it.

x (forward) points up the page and y (left) to the left, so the picture is the vehicle
seen from above with its nose up. Each rotor is a disc of its radius (the rotor link's
collision cylinder, else its visual cylinder, else a default that keeps neighbours
apart) with its motor number as the autopilot counts it (1-based: RotorS
`motorNumber` + 1, the MAIN output) above the model's own index, an arrow for its spin
(ccw / cw seen from above), and its arm from the centre of mass labelled with the arm
length. The body is the base link's outline from above (its own or a fixed child's):
a visual mesh's silhouette (every triangle projected onto the xy plane, so a CAD body's
arms and motor mounts show under the rotor discs), else its box or cylinder; a front
arrow marks the nose, a cross marks the COM.

SVG elements carry ids (`rotor-N`, `spin-N`, `label-N`, `arm-N`, `com`, `front`, and two
a hairline `anchor` from (x, y) = (0, 0) to (ANCHOR_M, ANCHOR_M) m) so
that tests and other tools can find what is drawn where. `reedtool layout` and
`validate --diagram` (the rotors its findings name drawn in red) both draw it here; what
is drawn (rotors, COM, marks) is computed by the caller.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

FORMATS = {".svg": "svg", ".png": "png"}
ANCHOR_M = 0.05     # the `anchor` line runs from base (0, 0) to (ANCHOR_M, ANCHOR_M)


@dataclass
class RotorMark:
    number: int                 # as the autopilot counts (1-based)
    index: int | None           # the model's motor index (RotorS motorNumber), if written
    name: str
    x_m: float                  # base frame
    y_m: float
    z_m: float
    radius_m: float
    turning_sign: int           # +1 ccw, -1 cw, 0 unknown
    marked: bool = False        # named by a finding


def output_format(path: Path) -> str:
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ReedtoolError(f"cannot tell the picture format from '{path.suffix or path.name}'",
                            file=path, hint="name the output .svg or .png")
    return fmt


def rotor_marks(robot, rotors, marked_names: set[str] = frozenset()) -> list[RotorMark]:
    """The rotors as drawn: numbered, with their disc radius."""
    from reedtool.model import Cylinder

    positions = np.array([r.position_m for r in rotors], dtype=float).reshape(-1, 3)
    default_r = _default_radius(positions)
    marks = []
    for order, rotor in enumerate(rotors):
        radius = None
        link = robot.link_map.get(rotor.link) if rotor.link else None
        if link is not None:
            for shape in [*link.collisions, *link.visuals]:
                if isinstance(shape.geometry, Cylinder) and shape.geometry.radius_m > 0:
                    radius = float(shape.geometry.radius_m)
                    break
        index = rotor.motor_number
        number = (index + 1) if index is not None else order + 1
        p = positions[order]
        marks.append(RotorMark(number, index, rotor.name, float(p[0]), float(p[1]),
                               float(p[2]), radius or default_r, rotor.turning_sign,
                               rotor.name in marked_names or (rotor.link or "") in marked_names))
    return marks


def _default_radius(positions: np.ndarray) -> float:
    """0.45 of the smallest distance between rotors that are apart in the top view."""
    xy = positions[:, :2]
    gaps = [float(np.linalg.norm(a - b)) for i, a in enumerate(xy) for b in xy[i + 1:]]
    gaps = [g for g in gaps if g > 1e-6 and math.isfinite(g)]
    if gaps:
        return 0.45 * min(gaps)
    reach = [float(np.linalg.norm(p)) for p in xy if math.isfinite(float(np.linalg.norm(p)))]
    return 0.3 * max(reach) if reach and max(reach) > 0 else 0.1


def _body_shapes(robot):
    """(shape, T_base_geom) of the base link, then of the links fixed to it, nearest first:
    Gazebo folds those into one body, and RotorS puts the body's box on a link fixed to a
    bare base_link (base_link_inertia)."""
    T_base = {robot.base_link: np.eye(4)}
    order = [robot.base_link] if robot.base_link in robot.link_map else []
    for name in order:                      # grows as fixed children are found
        for joint in robot.joints:
            if (joint.parent == name and joint.type == "fixed" and joint.child not in T_base
                    and joint.child in robot.link_map):
                T_base[joint.child] = T_base[name] @ joint.T_parent_joint
                order.append(joint.child)
    for name in order:
        link = robot.link_map[name]
        for shape in [*link.collisions, *link.visuals]:
            yield shape, T_base[name] @ shape.T_link_geom


MAX_SILHOUETTE_FACES = 20_000   # triangles drawn at most (every k-th beyond); rasterised in SVG


def _silhouette(robot) -> np.ndarray | None:
    """(n, 3, 2) top-view triangles of the body's visual meshes in the base frame, or None.

    Filled together they are the mesh's silhouette from above, holes and all: what a CAD
    user checks the rotors against. A mesh that cannot be read is left to the box or
    cylinder (validate names the problem)."""
    from reedtool.errors import ReedtoolError
    from reedtool.io.meshes import read_mesh
    from reedtool.model import Mesh

    parts = []
    for shape, T in _body_shapes(robot):
        g = shape.geometry
        if not isinstance(g, Mesh) or g.path is None or shape not in _visuals(robot):
            continue
        try:
            triangles = read_mesh(g.path).triangles_m
        except ReedtoolError:
            continue
        scale = np.ones(3) if g.scale is None else np.broadcast_to(
            np.asarray(g.scale, dtype=float), (3,))
        points = triangles.reshape(-1, 3) * scale @ T[:3, :3].T + T[:3, 3]
        points = points.reshape(-1, 3, 3)[..., :2]
        parts.append(points[np.all(np.isfinite(points), axis=(1, 2))])
    if not parts:
        return None
    triangles = np.concatenate(parts)
    stride = max(1, math.ceil(len(triangles) / MAX_SILHOUETTE_FACES))
    return triangles[::stride] if len(triangles) else None


def _visuals(robot) -> list:
    return [shape for link in robot.links for shape in link.visuals]


def _footprint(robot):
    """('box', half_x, half_y, cx, cy) / ('circle', r, cx, cy) of the body, or None."""
    from reedtool.model import Box, Cylinder

    for shape, T in _body_shapes(robot):
        g = shape.geometry
        if not np.all(np.isfinite(T)):
            continue
        cx, cy = float(T[0, 3]), float(T[1, 3])
        if isinstance(g, Box):
            # footprint of the box's extent projected onto the xy plane
            half = np.abs(T[:3, :3]) @ (np.asarray(g.size_m, dtype=float) / 2.0)
            return ("box", float(half[0]), float(half[1]), cx, cy)
        if isinstance(g, Cylinder):
            return ("circle", float(g.radius_m), cx, cy)
    return None


def render_layout(robot, rotors, com_m, fmt: str, title: str = "",
                  marked_names: set[str] = frozenset()) -> bytes:
    """The top view as SVG or PNG bytes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Circle, FancyArrow, Polygon, Rectangle

    marks = rotor_marks(robot, rotors, marked_names)

    def page(x, y):                     # base (x forward, y left) -> page (right, up)
        return -y, x

    with plt.rc_context({"svg.fonttype": "none", "svg.hashsalt": "reedtool-layout"}):
        fig, ax = plt.subplots(figsize=(6.5, 7.0))
        ax.set_aspect("equal")
        ax.axis("off")
        reach = max([math.hypot(m.x_m, m.y_m) + m.radius_m for m in marks] + [0.1])
        cx, cy = (float(com_m[0]), float(com_m[1])) if com_m is not None else (0.0, 0.0)
        silhouette = _silhouette(robot)
        foot = _footprint(robot) if silhouette is None else None
        if silhouette is not None:
            on_page = np.stack([-silhouette[..., 1], silhouette[..., 0]], axis=-1)
            ax.add_collection(PolyCollection(on_page, facecolors="#cfcfcf",
                                             edgecolors="#cfcfcf", linewidths=0.2, zorder=1,
                                             rasterized=fmt == "svg", gid="body"))
        elif foot is not None and foot[0] == "box":
            _, hx, hy, bx, by = foot
            X, Y = page(bx, by)
            ax.add_patch(Rectangle((X - hy, Y - hx), 2 * hy, 2 * hx, facecolor="#d9d9d9",
                                   edgecolor="#555555", zorder=1, gid="body"))
        elif foot is not None:
            _, r, bx, by = foot
            ax.add_patch(Circle(page(bx, by), r, facecolor="#d9d9d9", edgecolor="#555555",
                                zorder=1, gid="body"))
        else:
            ax.add_patch(Circle(page(cx, cy), 0.2 * reach, facecolor="#d9d9d9",
                                edgecolor="#555555", zorder=1, gid="body"))
        # coaxial rotors share a place: the upper one's label above, the lower one's below
        shared = {}
        for m in marks:
            shared.setdefault((round(m.x_m, 4), round(m.y_m, 4)), []).append(m)
        arm_labels: list = []       # placed last, where they overlap no other text
        for m in marks:
            X, Y = page(m.x_m, m.y_m)
            colour = "#c0392b" if m.marked else ("#1f77b4" if m.turning_sign > 0 else
                                                 "#e67e22" if m.turning_sign < 0 else "#7f7f7f")
            arm_from = page(cx, cy)
            # the arm stops at the disc's edge, leaving the number and index readable
            span = math.hypot(X - arm_from[0], Y - arm_from[1])
            keep = max(span - m.radius_m, 0.0) / span if span > 0 else 0.0
            arm_to = (arm_from[0] + keep * (X - arm_from[0]), arm_from[1] + keep * (Y - arm_from[1]))
            ax.plot([arm_from[0], arm_to[0]], [arm_from[1], arm_to[1]], color="#555555",
                    linewidth=3, zorder=2, solid_capstyle="round", gid=f"arm-{m.number}")
            arm_m = math.hypot(m.x_m - cx, m.y_m - cy)
            group = sorted(shared[(round(m.x_m, 4), round(m.y_m, 4))], key=lambda k: -k.z_m)
            if group[0] is m:       # coaxial rotors share one arm and one length label
                arm_labels.append((m.number, arm_from, arm_to, f"{arm_m:.3g} m"))
            level = group.index(m)
            coax = len(group) > 1
            ax.add_patch(Circle((X, Y), m.radius_m * (1.0 + 0.12 * level), facecolor=colour,
                                alpha=0.18 if not coax else 0.10, edgecolor=colour,
                                linewidth=2.5 if m.marked else 1.2,
                                linestyle="-" if level == 0 else "--", zorder=3,
                                gid=f"rotor-{m.number}"))
            if m.turning_sign != 0:
                _spin_arrow(ax, X, Y, m.radius_m * (0.78 + 0.22 * level), m.turning_sign,
                            colour, m.number)
            dy = 0.0 if not coax else (0.3 if level == 0 else -0.3) * m.radius_m
            index = f"idx {m.index}" if m.index is not None else "no idx"
            if coax:
                index += ", upper" if level == 0 else ", lower"
            ax.text(X, Y + dy, f"{m.number}", fontsize=15, fontweight="bold", ha="center",
                    va="center", color="black", zorder=7, gid=f"label-{m.number}")
            ax.text(X, Y + dy - 0.28 * m.radius_m, index, fontsize=6.5, ha="center",
                    va="center", color="#333333", zorder=7, gid=f"index-{m.number}")
        # COM, front marker, invisible anchors for tools
        if com_m is not None:
            X, Y = page(cx, cy)
            ax.plot([X], [Y], marker="x", markersize=10, color="black", zorder=8, gid="com",
                    linestyle="none")
            ax.text(X + 0.03 * reach, Y - 0.05 * reach, "COM", fontsize=8, zorder=8)
        tip = reach * 1.22
        ax.add_patch(FancyArrow(0.0, reach * 1.02, 0.0, tip - reach * 1.02 - 0.06 * reach,
                                width=0.012 * reach, head_width=0.08 * reach,
                                head_length=0.06 * reach, color="black", zorder=8, gid="front"))
        ax.text(0.0, tip + 0.03 * reach, "FRONT (x)", ha="center", va="bottom", fontsize=9)
        # from base (0, 0) to base (x, y) = (ANCHOR_M, ANCHOR_M), hairline, under the body
        ax.plot([0.0, -ANCHOR_M], [0.0, ANCHOR_M], color="white", linewidth=0.05, zorder=0,
                gid="anchor")
        # legend: the spin colours
        handles = [Polygon([[0, 0]], closed=True, facecolor=c, alpha=0.5, edgecolor=c,
                           label=lab)
                   for c, lab in (("#1f77b4", "ccw seen from above"),
                                  ("#e67e22", "cw seen from above"))]
        if any(m.marked for m in marks):
            handles.append(Polygon([[0, 0]], closed=True, facecolor="#c0392b", alpha=0.5,
                                   label="named by a finding"))
        ax.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, -0.06),
                  ncol=len(handles), fontsize=8, frameon=False)
        pad = 0.12 * reach
        ax.set_xlim(-reach - pad, reach + pad)
        ax.set_ylim(-reach - pad, reach * 1.35)
        ax.set_title(title or f"{robot.name}: {len(marks)} rotors, top view "
                     f"(x forward up, y left)", fontsize=10)
        fig.tight_layout()
        _place_arm_labels(ax, arm_labels)
        buffer = io.BytesIO()
        fig.savefig(buffer, format=fmt, dpi=110, metadata={"Date": None} if fmt == "svg"
                    else None)
        plt.close(fig)
    return buffer.getvalue()


def _place_arm_labels(ax, arms: list) -> None:
    """Each arm's length on its arm where it overlaps no text drawn so far: mid-arm, else
    further out or in. Neighbouring arms of a small octocopter meet near the centre, and
    their mid-arm labels ran into each other ("0.246 r0.246 m"). A label that fits nowhere
    is left out when another arm shows the same length, else drawn mid-arm anyway."""
    renderer = ax.figure.canvas.get_renderer()
    # Text extents grown by half an em: the label's white box (pad 0.15 em) and a gap.
    gap_px = 0.5 * 7 * ax.figure.dpi / 72

    def extent(text):
        return text.get_window_extent(renderer).padded(gap_px)

    taken = [extent(t) for t in ax.texts]
    shown: set[str] = set()
    for number, start, end, text in arms:
        for fraction in (0.5, 0.65, 0.8, 0.35, 0.9):
            label = _arm_label(ax, start[0] + fraction * (end[0] - start[0]),
                               start[1] + fraction * (end[1] - start[1]), text, number)
            box = extent(label)
            if not any(box.overlaps(other) for other in taken):
                break
            label.remove()
        else:
            if text in shown:
                continue
            label = _arm_label(ax, (start[0] + end[0]) / 2, (start[1] + end[1]) / 2, text,
                               number)
            box = extent(label)
        taken.append(box)
        shown.add(text)


def _arm_label(ax, x: float, y: float, text: str, number: int):
    """An arm's length label at (x, y) on the page, boxed so the arm does not cross it."""
    return ax.text(x, y, text, fontsize=7, color="#333333", ha="center", va="center", zorder=6,
                   bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                         "alpha": 0.8}, gid=f"armlen-{number}")


def _spin_arrow(ax, X: float, Y: float, r: float, sign: int, colour: str, number: int) -> None:
    """An arc of 240 deg around the disc centre, drawn in the spin's sense, with a head."""
    from matplotlib.patches import Polygon

    start = math.radians(150.0)
    theta = start + sign * np.linspace(0.0, math.radians(240.0), 49)
    xs, ys = X + r * np.cos(theta), Y + r * np.sin(theta)
    ax.plot(xs, ys, color=colour, linewidth=1.6, zorder=4, gid=f"spin-{number}")
    end, tangent = theta[-1], theta[-1] + sign * math.pi / 2
    tip = np.array([X + r * math.cos(end), Y + r * math.sin(end)])
    d = np.array([math.cos(tangent), math.sin(tangent)])
    n = np.array([-d[1], d[0]])
    size = 0.22 * r
    ax.add_patch(Polygon([tip + d * size, tip - d * 0.2 * size + n * 0.6 * size,
                          tip - d * 0.2 * size - n * 0.6 * size], closed=True,
                         color=colour, zorder=4, gid=f"spinhead-{number}"))


