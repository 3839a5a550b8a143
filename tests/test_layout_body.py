"""`reedtool layout` draws the body where Gazebo has it: RotorS (and `new-package --ros 1`)
put the body's box on base_link_inertia, fixed to a bare base_link; the picture drew a
stand-in grey disc instead."""

import numpy as np
from cli_helpers import run_cli
from test_layout_picture import Picture, points

from reedtool.io.loader import load_robot
from reedtool.model import Box


def _box_on_fixed_child(model):
    """The model's own body box: the collision box of a link fixed to the base link."""
    robot = load_robot(model, {}, [])
    assert not robot.link_map[robot.base_link].collisions     # the bare RotorS base_link
    for joint in robot.joints:
        if joint.parent == robot.base_link and joint.type == "fixed":
            for shape in robot.link_map[joint.child].collisions:
                if isinstance(shape.geometry, Box):
                    return np.asarray(shape.geometry.size_m, dtype=float)
    raise AssertionError("no body box")


def test_body_box_on_a_link_fixed_to_the_base(tmp_path):
    code, out = run_cli("new-package", "body_quad", "--frame", "quad-x", "--ros", 1,
                        "-o", tmp_path)
    assert code == 0, out
    model = tmp_path / "body_quad" / "urdf" / "mav_generic_odometry_sensor.gazebo"
    svg = tmp_path / "l.svg"
    code, out = run_cli("layout", model, "-o", svg)
    assert code == 0, out
    size = _box_on_fixed_child(model)
    picture = Picture(svg)
    corners = picture.to_base(points(picture.ids["body"]))
    extent = corners.max(axis=0) - corners.min(axis=0)
    # Path coordinates printed to ~1e-6 pt, 1 pt ~ 1e-3 m through the anchor (the rotor
    # test's 2e-3 m bound); the stand-in disc is round, and sized from the arms.
    np.testing.assert_allclose(extent, size[:2], atol=2e-3)
    np.testing.assert_allclose((corners.max(axis=0) + corners.min(axis=0)) / 2, [0, 0],
                               atol=2e-3)
