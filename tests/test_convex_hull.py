"""reedtool's numpy Quickhull against qhull (trimesh) and hand-derived volumes."""

from __future__ import annotations

import numpy as np
import pytest

from reedtool.errors import ReedtoolError
from reedtool.physics.convex_hull import convex_hull, hull_candidates
from reedtool.physics.inertia import solid_mass_properties
from reedtool.physics.mesh_topology import topology

RNG = np.random.default_rng(7)


def _sphere(n):
    v = RNG.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


CLOUDS = {
    "box with interior points": np.vstack([
        np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], float),
        RNG.random((500, 3)) * [1, 2, 3]]),
    "points on a sphere": _sphere(600),
    "gaussian cloud": RNG.normal(size=(20000, 3)),
    "grid with coplanar faces": np.array([[x, y, z] for x in range(6) for y in range(5)
                                          for z in range(4)], float),
    "thin disc": np.array([[np.cos(a), np.sin(a), z] for a in np.linspace(0, 2 * np.pi, 90,
                                                                           endpoint=False)
                           for z in (0.0, 0.005)]),
}


@pytest.mark.parametrize("name", list(CLOUDS))
def test_hull_matches_qhull(name):
    trimesh = pytest.importorskip("trimesh")
    points = CLOUDS[name]
    vertices, faces = convex_hull(points)
    ours = solid_mass_properties(vertices[faces])
    reference = trimesh.convex.convex_hull(points)
    theirs = solid_mass_properties(reference.vertices[reference.faces])
    assert topology(vertices[faces]).closed
    # The same hull (up to face order and triangulation of coplanar facets): the
    # divergence sums differ by rounding only, ~1e-14; 1e-9 is margin.
    assert ours.volume_m3 == pytest.approx(theirs.volume_m3, rel=1e-9)
    assert ours.inertia_kg_m2 == pytest.approx(theirs.inertia_kg_m2, rel=1e-8, abs=1e-12)


def test_hand_derived_volumes():
    box = CLOUDS["box with interior points"]
    vertices, faces = convex_hull(box)
    assert solid_mass_properties(vertices[faces]).volume_m3 == pytest.approx(6.0)
    assert len(vertices) == 8          # interior points are not hull vertices
    # The thinning keeps every hull vertex and drops the interior.
    assert len(hull_candidates(box)) < 100


@pytest.mark.parametrize("points", [np.zeros((5, 3)), RNG.random((50, 3)) * [1, 1, 0],
                                    np.outer(np.arange(10.0), [1, 2, 3])])
def test_flat_or_degenerate_is_refused(points):
    with pytest.raises(ReedtoolError, match="degenerate"):
        convex_hull(points)
