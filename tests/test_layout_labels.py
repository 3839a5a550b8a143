"""`reedtool layout`: the arm-length labels never run into each other (issue 19).

A small octocopter's arms meet near the centre, and the labels at their middles
overlapped ("0.246 r0.246 m"). Each label's white box is a path in the SVG; no two may
intersect, and every distinct arm length is still written somewhere.
"""

from __future__ import annotations

import re

import numpy as np
from cli_helpers import run_cli
from lxml import etree
from rotors_builder import multirotor_urdf

SVG = "{http://www.w3.org/2000/svg}"


def ring_urdf(n: int, arm_m: float, prop_radius_m: float, stretch: float = 1.0) -> str:
    """n rotors of prop_radius_m on a ring, every odd arm stretch times as long."""
    return multirotor_urdf(
        n, name="ring", arm_m=arm_m, height_m=0.03, digits=5, body_inertia=(0.03, 0.03, 0.05),
        body_xml='<collision><geometry><cylinder radius="0.08" length="0.05"/></geometry>'
                 '</collision>',
        rotor_inertia=(1e-6, 1e-6, 2e-6), plugin_name="m{i}",
        rotor_xml=f'<visual><geometry><cylinder radius="{prop_radius_m}" length="0.005"/>'
                  '</geometry></visual>',
        per_rotor={i: {"arm_m": arm_m * stretch} for i in range(1, n, 2)},
        motor={"rotorDragCoefficient": None, "rollingMomentCoefficient": None,
               "rotorVelocitySlowdownSim": None})


def label_boxes(svg_path) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(text, lower corner, upper corner) of every arm-length label's white box."""
    root = etree.parse(str(svg_path)).getroot()
    out = []
    for group in root.iter(f"{SVG}g"):
        if not (group.get("id") or "").startswith("armlen-"):
            continue
        path = next(p for p in group.iter(f"{SVG}path") if p.get("d"))
        xy = np.array([float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", path.get("d"))])
        xy = xy.reshape(-1, 2)
        text = "".join(t for t in group.itertext()).strip() or \
            next(iter(group.iter(f"{SVG}text"))).text
        out.append((text, xy.min(axis=0), xy.max(axis=0)))
    return out


def overlapping(boxes) -> list[tuple[str, str]]:
    bad = []
    for i, (a, lo_a, hi_a) in enumerate(boxes):
        for b, lo_b, hi_b in boxes[i + 1:]:
            if np.all(lo_a < hi_b) and np.all(lo_b < hi_a):
                bad.append((a, b))
    return bad


def test_arm_labels_of_a_small_octocopter_do_not_overlap(tmp_path):
    model = tmp_path / "octo.urdf"
    model.write_text(ring_urdf(8, 0.246, 0.17))
    svg = tmp_path / "octo.svg"
    code, out = run_cli("layout", model, "-o", svg)
    assert code == 0, out
    boxes = label_boxes(svg)
    assert boxes and not overlapping(boxes)
    assert {text for text, _, _ in boxes} == {"0.246 m"}


def test_every_distinct_arm_length_is_written(tmp_path):
    model = tmp_path / "h.urdf"
    model.write_text(ring_urdf(8, 0.246, 0.17, stretch=1.3))    # arms of 0.246 and 0.32 m
    svg = tmp_path / "h.svg"
    assert run_cli("layout", model, "-o", svg)[0] == 0
    boxes = label_boxes(svg)
    assert not overlapping(boxes)
    assert {text for text, _, _ in boxes} == {"0.246 m", "0.32 m"}


def test_the_box_test_can_fail():
    box = (np.array([0.0, 0.0]), np.array([2.0, 1.0]))
    assert overlapping([("a", *box), ("b", box[0] + 0.5, box[1] + 0.5)]) == [("a", "b")]
    assert overlapping([("a", *box), ("b", box[0] + 2.5, box[1] + 2.5)]) == []
