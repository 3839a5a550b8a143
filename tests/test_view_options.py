"""What a person reads off `view` and `layout` at a glance: which way is front, which rotor
is which, and whether the CAD body sits under the rotors.

The references are the model's own geometry (rotor positions from the loader, the mesh
read by trimesh), never the picture code's own numbers.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from matplotlib.path import Path as MplPath

from cli_helpers import run_cli
from picture_helpers import colour_masks
from reedtool.workflows.view import view_robot
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import discover_rotors
from reedtool.report.layout_picture import _silhouette, rotor_marks
from reedtool.report.scene import T_GLTF_ROS

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_QUAD = ROOT / "examples/reed_quad_x/urdf/mav_generic_odometry_sensor.gazebo"
CAD_BODY = ROOT / "meshes/quad_body_mm.stl"


@pytest.fixture(scope="module")
def example():
    return load_robot(EXAMPLE_QUAD)


def test_front_label_and_motor_numbers_sit_where_the_model_says(example):
    view = view_robot(example)
    rotors = discover_rotors(example)
    front = [label for label in view.labels if label.kind == "front"]
    assert len(front) == 1 and front[0].text == "FRONT"
    # ahead of the base origin along +x, on the centre line, above the body
    x, y, z = front[0].position_m
    arm_m = max(np.hypot(*np.asarray(r.position_m)[:2]) for r in rotors)
    assert x > arm_m and abs(y) < 1e-12 and z > view.framing.bounds_m[1][2]
    # each motor number (1-based, as the autopilot counts) beside its own rotor: nearer to
    # it than to any other rotor
    numbers = {mark.number: np.asarray(r.position_m) for mark, r in
               zip(rotor_marks(example, rotors), rotors)}
    for label in (label for label in view.labels if label.kind == "rotor"):
        distances = {n: np.linalg.norm(label.position_m[:2] - p[:2]) for n, p in numbers.items()}
        assert min(distances, key=distances.get) == int(label.text)
    assert sorted(int(label.text) for label in view.labels if label.kind == "rotor") == \
        sorted(numbers)


def test_html_hotspots_are_the_labels_in_gltf_axes(example, tmp_path):
    out = tmp_path / "q.html"
    assert run_cli("view", EXAMPLE_QUAD, "-o", out)[0] == 0
    page = out.read_text()
    spots = re.findall(r'class="hotspot (\w+)" slot="hotspot-\d+" '
                       r'data-position="(\S+)m (\S+)m (\S+)m">([^<]+)<', page)
    view = view_robot(example)
    assert len(spots) == len(view.labels)
    for (kind, gx, gy, gz, text), label in zip(spots, view.labels):
        # glTF is y-up: ROS (x, y, z) is glTF (x, z, -y) (glTF 2.0, 3.4)
        x, y, z = label.position_m
        assert (kind, text) == (label.kind, label.text)
        np.testing.assert_allclose([float(gx), float(gy), float(gz)], [x, z, -y],
                                   atol=1e-5 * np.max(np.abs(label.position_m)) + 1e-9)
    np.testing.assert_array_equal(T_GLTF_ROS[:3, :3] @ [1, 2, 3], [1, 3, -2])


def _centroid(mask: np.ndarray) -> np.ndarray:
    rows, cols = np.nonzero(mask)
    return np.array([cols.mean(), rows.mean()])


def test_top_view_has_front_up_and_left_on_the_left(example, tmp_path):
    """In the top view x (forward) points up the page and y (left) to the left, as `layout`
    and PX4's airframe pictures draw it: each rotor's disc lies in its own quadrant."""
    out = tmp_path / "top.png"
    code, text = run_cli("view", EXAMPLE_QUAD, "-o", out, "--views", "top", "--size", "600x600")
    assert code == 0, text
    masks = colour_masks(out)
    assert masks["rgb"].shape[:2] == (600, 600)
    blue, orange, red = masks["ccw"], masks["cw"], masks["red"]   # red: FRONT arrow, label
    centre = _centroid(blue | orange)
    front = _centroid(red)
    assert front[1] < centre[1] - 50            # above the rotors' centre, by a third of an arm
    rotors = discover_rotors(example)
    for rotor in rotors:
        x_m, y_m = np.asarray(rotor.position_m)[:2]
        mask = blue if rotor.turning_sign > 0 else orange
        rows, cols = np.nonzero(mask)
        # pixels of this spin colour in the quadrant the rotor's (x, y) maps to
        up, left = rows < centre[1], cols < centre[0]
        in_quadrant = (up == (x_m > 0)) & (left == (y_m > 0))
        assert in_quadrant.sum() > 500, (rotor.name, x_m, y_m)


def test_outline_discs_leave_the_frame_visible(tmp_path):
    filled, outline = tmp_path / "f.png", tmp_path / "o.png"
    for path, style in ((filled, "filled"), (outline, "outline")):
        assert run_cli("view", EXAMPLE_QUAD, "-o", path, "--views", "top", "--discs", style,
                       "--size", "500x500")[0] == 0
    def disc_pixels(path):
        masks = colour_masks(path)
        return int(masks["ccw"].sum() + masks["cw"].sum())

    # a ring 8 % of the radius wide covers 1 - 0.92^2 = 15 % of the disc; the spin arrows
    # stay: the outline picture holds well under half the filled one's disc colour
    assert disc_pixels(outline) < 0.5 * disc_pixels(filled)


@pytest.mark.parametrize("bad, says", [("--views", "choose among top"), ("--size", "WIDTHxHEIGHT")])
def test_bad_view_options_are_one_line(tmp_path, bad, says):
    value = "toppp" if bad == "--views" else "12x"
    code, text = run_cli("view", EXAMPLE_QUAD, "-o", tmp_path / "q.png", bad, value)
    assert code == 2 and says in text and "Traceback" not in text


def test_layout_draws_the_cad_body_silhouette_not_its_box(tmp_path):
    code, text = run_cli("new-package", "cadq", "--mesh", CAD_BODY, "--mesh-units", "mm",
                         "-o", tmp_path)
    assert code == 0, text
    model = tmp_path / "cadq" / "urdf" / "mav_generic_odometry_sensor.gazebo"
    robot = load_robot(model)
    triangles = _silhouette(robot)
    assert triangles is not None
    # the silhouette spans the mesh's own top-view extent (trimesh's reading, mm -> m)
    mesh = trimesh.load(CAD_BODY)
    extent_m = np.ptp(mesh.vertices[:, :2], axis=0) / 1000.0
    # (the body is not turned about z; both read the same float32 STL corners)
    np.testing.assert_allclose(np.ptp(triangles.reshape(-1, 2), axis=0), extent_m, rtol=1e-6)
    # an X-shaped frame: the centre is body, the corner of its bounding box is not
    low, high = triangles.reshape(-1, 2).min(axis=0), triangles.reshape(-1, 2).max(axis=0)
    centre = (low + high) / 2
    corner = low + 0.03 * (high - low)

    def covered(point):
        return any(MplPath(t).contains_point(point) for t in triangles)

    assert covered(centre) and not covered(corner)
    assert run_cli("layout", model, "-o", tmp_path / "l.svg")[0] == 0


def test_outline_discs_make_the_rotor_links_see_through(example):
    """--discs outline: the rotors' own geometry turns into a veil (alpha 50 of 255), so
    the mounts under it show; filled discs leave it opaque."""
    from reedtool.report.scene import ROTOR_FADE_ALPHA

    rotor_links = {r.link for r in discover_rotors(example) if r.link}
    for style, expected in (("outline", ROTOR_FADE_ALPHA), ("filled", 255)):
        view = view_robot(example, disc_style=style)
        scene = view.scene
        alphas = {int(np.max(np.asarray(scene.geometry[scene.graph[node][1]].visual
                                         .face_colors)[:, 3]))
                  for node in scene.graph.nodes_geometry
                  if scene.graph.transforms.parents.get(node) in rotor_links}
        assert alphas == {expected}, (style, alphas)
