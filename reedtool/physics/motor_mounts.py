"""Motor mounts found in a CAD body mesh, seen from above.

A multirotor body drawn in CAD ends each arm in a round motor mount: a boss or a pad whose
outline, seen from above, is a circle around the motor axis. The method, in the top view
(FLU x, y, CAD origin kept):

1. Polar view about the centre of the mesh's x-y bounding box: every vertex's distance r
   and bearing.
2. Arm tips are the outermost vertices: those with r >= t * r_max. Sorted by bearing,
   they fall into groups separated by empty sectors wider than ARM_GAP_DEG (arms of an
   octocopter are 45 deg apart; a tip spans a few degrees). t is tried at each of
   TIP_FRACTIONS, outermost first; the first t that gives exactly one group per rotor,
   with every group's tip within TIP_SPREAD of the median tip, is taken. A nose, a
   camera or a leg reaching as far as the arms gives another group, and no t then fits:
   the mounts are "not found", never guessed.
3. Each group's mount centre is a circle fitted (algebraic least squares, Kasa 1976) to
   the convex hull of the tip vertices in the top view: the outer arc of a round mount
   is on that hull, the arm's own vertices inside the mount are not. Hull points off the
   fitted circle by more than FIT_INLIER of its radius are dropped and the circle refitted.
   A tip that is not round (its hull points do not lie on one circle to within FIT_RMS)
   is not a mount.

The mount's top (its highest vertex within its circle) is where a motor sits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

ARM_GAP_DEG = 15.0
TIP_FRACTIONS = (0.9, 0.8, 0.7, 0.6)
TIP_SPREAD = 0.25        # each tip's radius within 25 % of the median tip's
FIT_INLIER = 0.02        # hull points within 2 % of the radius are on the circle
FIT_RMS = 0.01           # a round mount: RMS distance off the circle below 1 % of its radius
MIN_ARC_POINTS = 5       # a circle from fewer hull points is not evidence of roundness


@dataclass(frozen=True)
class Mount:
    xy_m: np.ndarray          # (2,) the mount's axis in the top view
    radius_m: float           # the fitted circle's radius
    top_z_m: float            # highest point of the mesh within the circle


@dataclass(frozen=True)
class MountReading:
    mounts: tuple[Mount, ...]  # () when none found
    reason: str                # how they were found, or why not


def _hull_2d(points: np.ndarray) -> np.ndarray:
    """Convex hull vertices of 2-D points (Andrew's monotone chain), counter-clockwise."""
    pts = np.unique(np.round(points, 12), axis=0)
    if len(pts) < 3:
        return pts

    def half(sequence):
        chain: list[np.ndarray] = []
        for p in sequence:
            while len(chain) >= 2:
                a, b = chain[-2], chain[-1]
                if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0:
                    break
                chain.pop()
            chain.append(p)
        return chain

    lower = half(pts)
    upper = half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def fit_circle(points: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(centre, radius, rms distance off the circle): Kasa's algebraic least squares,
    x^2 + y^2 + D x + E y + F = 0."""
    x, y = points[:, 0], points[:, 1]
    A = np.column_stack([x, y, np.ones_like(x)])
    b = -(x ** 2 + y ** 2)
    (D, E, F), *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = np.array([-D / 2.0, -E / 2.0])
    radius = math.sqrt(max(centre @ centre - F, 0.0))
    rms = float(np.sqrt(np.mean((np.linalg.norm(points - centre, axis=1) - radius) ** 2)))
    return centre, radius, rms


def _groups_by_bearing(bearing_deg: np.ndarray) -> list[np.ndarray]:
    """Indices of `bearing_deg` grouped where sorted neighbours are > ARM_GAP_DEG apart
    (on the circle)."""
    order = np.argsort(bearing_deg)
    b = bearing_deg[order]
    gaps = np.diff(np.concatenate([b, [b[0] + 360.0]]))
    cuts = np.flatnonzero(gaps > ARM_GAP_DEG)
    if len(cuts) == 0:
        return [order]
    # Start right after the first wide gap so no group wraps around.
    start = (cuts[0] + 1) % len(b)
    rolled = np.roll(order, -start)
    rolled_gaps = np.roll(gaps, -start)
    groups, current = [], [rolled[0]]
    for index, gap in zip(rolled[1:], rolled_gaps[:-1]):
        if gap > ARM_GAP_DEG:
            groups.append(np.array(current))
            current = []
        current.append(index)
    groups.append(np.array(current))
    return groups


def _round_mount(tip_xy: np.ndarray, vertices: np.ndarray) -> Mount | None:
    hull = _hull_2d(tip_xy)
    if len(hull) < MIN_ARC_POINTS:
        return None
    centre, radius, _ = fit_circle(hull)
    for _ in range(3):
        off = np.abs(np.linalg.norm(hull - centre, axis=1) - radius)
        inliers = hull[off <= FIT_INLIER * radius]
        if len(inliers) < MIN_ARC_POINTS:
            return None
        centre, radius, rms = fit_circle(inliers)
    if not (radius > 0 and rms <= FIT_RMS * radius):
        return None
    inside = np.linalg.norm(vertices[:, :2] - centre, axis=1) <= radius * (1 + FIT_INLIER)
    return Mount(centre, float(radius), float(vertices[inside, 2].max()))


def find_mounts(triangles_m: np.ndarray, count: int) -> MountReading:
    """`count` round motor mounts at the mesh's arm tips, ordered by bearing from the
    x axis (counter-clockwise seen from above), or none with the reason."""
    vertices = np.unique(np.asarray(triangles_m, dtype=float).reshape(-1, 3), axis=0)
    xy = vertices[:, :2]
    centre = (xy.min(axis=0) + xy.max(axis=0)) / 2.0
    d = xy - centre
    r = np.hypot(d[:, 0], d[:, 1])
    bearing = np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 360.0
    r_max = float(r.max())
    if r_max <= 0:
        return MountReading((), "the mesh has no extent seen from above")
    seen = []
    for fraction in TIP_FRACTIONS:
        outer = np.flatnonzero(r >= fraction * r_max)
        groups = [outer[g] for g in _groups_by_bearing(bearing[outer])]
        seen.append(len(groups))
        if len(groups) != count:
            continue
        tips = np.array([r[g].max() for g in groups])
        if np.any(np.abs(tips / np.median(tips) - 1.0) > TIP_SPREAD):
            continue
        mounts = []
        for group in groups:
            mount = _round_mount(xy[group], vertices[group])
            if mount is None:
                break
            mounts.append(mount)
        else:
            ordered = sorted(mounts, key=lambda m: math.atan2(*(m.xy_m - centre)[::-1])
                             % (2 * math.pi))
            radii = ", ".join(f"{m.radius_m * 1000:.3g}" for m in ordered)
            return MountReading(tuple(ordered),
                                f"{count} round mounts at the arm tips (radius {radii} mm), "
                                f"the vertices beyond {fraction:.0%} of the farthest seen "
                                "from above")
        return MountReading((), f"{count} arm tips seen from above, but not all round "
                                "(no circle through their outline): no motor mounts taken")
    counts = ", ".join(str(n) for n in dict.fromkeys(seen))
    return MountReading((), f"seen from above the mesh has {counts} outermost lobes, not "
                            f"{count} arm tips: no motor mounts taken")


def match_bearings(mounts: tuple[Mount, ...], bearings_deg: list[float],
                   centre_xy: np.ndarray) -> list[int] | None:
    """For each rotor slot (bearing clockwise from the nose, PX4's), the index of the
    mount at that bearing from `centre_xy`, each used once and within half the angle
    between neighbouring slots; None when the mounts do not follow the layout."""
    if len(mounts) != len(bearings_deg):
        return None
    tolerance = 180.0 / len(bearings_deg)
    chosen: list[int] = []
    for slot_bearing in bearings_deg:
        best, best_off = None, tolerance
        for index, mount in enumerate(mounts):
            if index in chosen:
                continue
            dx, dy = mount.xy_m - centre_xy
            mount_bearing = math.degrees(math.atan2(-dy, dx))    # clockwise from the nose
            off = abs((mount_bearing - slot_bearing + 180.0) % 360.0 - 180.0)
            if off < best_off:
                best, best_off = index, off
        if best is None:
            return None
        chosen.append(best)
    return chosen
