"""`reedtool layout`: the picture shows every rotor where the model puts it.

For every frame new-package makes, the SVG is parsed (elements by id) and mapped back
to metres through the axis transform given by two anchors; each rotor's disc, number and
spin arrow must sit where the model's rotor table (discover_rotors) puts that rotor, with
the number and sense PX4's airframe reference gives its slot (generate.airframes).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli
from lxml import etree

from reedtool.report.layout_picture import ANCHOR_M
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import discover_rotors
from reedtool.generate.airframes import FRAMES, MULTIROTOR_FRAMES

SVG = "{http://www.w3.org/2000/svg}"
XLINK = "{http://www.w3.org/1999/xlink}"


@pytest.fixture(scope="module")
def pictures(tmp_path_factory) -> dict[str, tuple[Path, Path]]:
    out = tmp_path_factory.mktemp("layout")
    made = {}
    for frame in MULTIROTOR_FRAMES:
        name = f"l_{frame.replace('-', '_')}"
        code, output = run_cli("new-package", name, "--frame", frame, "--ros", 1, "-o", out)
        assert code == 0, output
        model = out / name / "urdf" / "mav_generic_odometry_sensor.gazebo"
        svg = out / f"{frame}.svg"
        code, output = run_cli("layout", model, "-o", svg)
        assert code == 0, output
        made[frame] = (model, svg)
    return made


def points(element) -> np.ndarray:
    """Every coordinate pair of the paths (and <use> markers) under `element`, SVG units."""
    out = []
    for node in element.iter():
        if node.tag == f"{SVG}path" and node.get("d"):
            numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", node.get("d"))]
            out += list(zip(numbers[0::2], numbers[1::2]))
        elif node.tag == f"{SVG}use":
            out.append((float(node.get("x")), float(node.get("y"))))
    return np.array(out, dtype=float)


class Picture:
    def __init__(self, path: Path):
        self.root = etree.parse(str(path)).getroot()
        self.ids = {el.get("id"): el for el in self.root.iter() if el.get("id")}
        o, u = points(self.ids["anchor"])[:2]
        # the anchor runs from base (0, 0) to (x, y) = (a, a), i.e. page (0, 0) to (-a, a)
        self.offset = o
        self.scale = np.array([(u[0] - o[0]) / -ANCHOR_M, (u[1] - o[1]) / ANCHOR_M])

    def to_base(self, svg_xy: np.ndarray) -> np.ndarray:
        """SVG coordinates -> base frame (x forward, y left) [m]."""
        page = (np.atleast_2d(svg_xy) - self.offset) / self.scale     # page (right, up)
        return np.column_stack([page[:, 1], -page[:, 0]])

    def centre(self, gid: str) -> np.ndarray:
        p = points(self.ids[gid])
        return self.to_base((p.min(axis=0) + p.max(axis=0)) / 2.0)[0]

    def text_at(self, gid: str) -> tuple[str, np.ndarray]:
        text = next(self.ids[gid].iter(f"{SVG}text"))
        return text.text, self.to_base(np.array([float(text.get("x")), float(text.get("y"))]))[0]


@pytest.mark.parametrize("frame", MULTIROTOR_FRAMES)
def test_every_rotor_drawn_where_the_model_puts_it(pictures, frame):
    model, svg = pictures[frame]
    picture = Picture(svg)
    rotors = {r.motor_number: r for r in discover_rotors(load_robot(model, {}, []))}
    airframe = FRAMES[frame]
    assert len(rotors) == airframe.rotor_count
    for slot in airframe.rotors:
        number = slot.motor_number + 1            # PX4's MAIN number
        rotor = rotors[slot.motor_number]
        centre = picture.centre(f"rotor-{number}")
        # Read back from the SVG's path coordinates, printed with 6 decimals of points
        # (~1e-6 pt) and mapped by the anchor (1 pt ~ 1e-3 m here): 2e-3 m holds it; a
        # misplaced rotor is >= 0.1 m off.
        np.testing.assert_allclose(centre, rotor.position_m[:2], atol=2e-3)
        # the airframe's bearing: clockwise from the nose seen from above
        bearing = math.degrees(math.atan2(-centre[1], centre[0]))
        # The 2e-3 m centre bound above at the generated arms' >= 0.18 m: 0.011 rad =
        # 0.64 deg; 1 deg holds it, a wrong slot is >= 30 deg off.
        assert (bearing - slot.bearing_deg + 180.0) % 360.0 - 180.0 == pytest.approx(0, abs=1)
        text, at = picture.text_at(f"label-{number}")
        assert text == str(number)
        radius = np.ptp(points(picture.ids[f"rotor-{number}"])[:, 0]) / 2 / abs(picture.scale[0])
        assert np.linalg.norm(at - rotor.position_m[:2]) < radius
        # the spin arrow circles the rotor's centre in its sense, seen from above
        arc = picture.to_base(points(picture.ids[f"spin-{number}"]))
        rel = arc - rotor.position_m[:2]
        angles = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))   # about +z (up), from +x
        turned = math.degrees(angles[-1] - angles[0])
        assert (turned > 180.0) if slot.direction == "ccw" else (turned < -180.0), turned
        assert np.ptp(np.linalg.norm(rel, axis=1)) < 1e-3 * radius + 1e-4
        assert rotor.turning_sign == (1 if slot.direction == "ccw" else -1)


def test_front_marker_points_forward(pictures):
    picture = Picture(pictures["quad-x"][1])
    front = picture.to_base(points(picture.ids["front"]))
    assert front[:, 0].min() > 0 and np.abs(front[:, 1]).max() < 0.05   # ahead, on the axis


def test_png_by_extension_and_no_silent_overwrite(pictures, tmp_path):
    model, _ = pictures["hex-x"]
    png = tmp_path / "hex.png"
    assert run_cli("layout", model, "-o", png)[0] == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    before = png.read_bytes()
    code, output = run_cli("layout", model, "-o", png)
    assert code == 2 and "--force" in output and png.read_bytes() == before
    code, output = run_cli("layout", model, "-o", tmp_path / "hex.jpg")
    assert code == 2 and ".svg or .png" in output and not (tmp_path / "hex.jpg").exists()


def test_validate_diagram_marks_the_rotor_a_finding_names(tmp_path):
    model = Path(__file__).parent / "fixtures" / "validate" / "R303_bad_direction.urdf"
    svg = tmp_path / "diagram.svg"
    code, output = run_cli("validate", model, "--diagram", svg, "--format", "json")
    assert code == 1 and '"R303"' in output
    rotors = discover_rotors(load_robot(model, {}, []))
    picture = Picture(svg)
    red = sorted(number for number in range(1, len(rotors) + 1)
                 if "#c0392b" in etree.tostring(picture.ids[f"rotor-{number}"]).decode())
    named = [r for r in rotors if r.name == "rotor_3"]
    assert red == [(named[0].motor_number if named[0].motor_number is not None
                    else rotors.index(named[0])) + 1]
    assert run_cli("validate", model, "--diagram", svg)[0] == 2      # no silent overwrite
