"""The hover plot: bands, settle and failure markers, the batch envelope, the format by
the file's extension."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest
from lxml import etree
from test_hover_test_cli import frame_urdf, run_cli

from reedtool.sim import HoverConfig
from reedtool.sim.batch import Spreads, robustness_batch
from reedtool.sim.params import symmetric_multirotor
from reedtool.sim.plot import failure_marks, render
from reedtool.sim.run import simulate_hover

SVG = "{http://www.w3.org/2000/svg}"


def ids(svg: bytes) -> set[str]:
    return {el.get("id") for el in etree.fromstring(svg).iter() if el.get("id")}


def test_svg_has_bands_settle_failure_and_envelope():
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=4.0)
    run = simulate_hover(params, config)
    batch = robustness_batch(params, 12, config, Spreads(), 0, record=True)
    # the envelope is over the batch's own vehicles: 12 flying at the start
    assert batch.envelope["flying"][0] == 12
    assert np.all(batch.envelope["p5"] <= batch.envelope["p95"])
    svg = render(run.series, params.omega_max_rad_s, run.initial_omega_rad_s, "t", fmt="svg",
                 position_tol_m=0.05, attitude_tol_deg=2.0, settle_time_s=run.settle_time_s,
                 failures=[(1.5, "rotor_0 fails")], envelope=batch.envelope)
    assert svg.lstrip().startswith(b"<?xml") and b"<svg" in svg[:400]
    found = ids(svg)
    assert {"tolerance", "attitude-tolerance", "settle", "failure-0", "envelope",
            "envelope-median", "position-error"} <= found
    text = svg.decode()
    assert "tolerance 5 cm" in text and "rotor_0 fails at 1.50 s" in text
    assert re.search(r"settled at \d+\.\d\d s", text)


def test_without_batch_or_failures_no_such_marks():
    params = symmetric_multirotor(4)
    run = simulate_hover(params, HoverConfig(duration_s=2.0))
    assert failure_marks(run) == []
    found = ids(render(run.series, params.omega_max_rad_s, run.initial_omega_rad_s, "t",
                       fmt="svg", position_tol_m=0.05))
    assert "envelope" not in found and "failure-0" not in found and "settle" not in found


@pytest.mark.parametrize("shape,expected", [
    ({"failures": [(0.5, "rotor_2")]}, [(0.5, "rotor_2 fails")]),
    ({"failures": [{"time_s": 1.0, "rotor": "front"}]}, [(1.0, "front fails")]),
    ({"failure_time_s": 2.0, "failed_rotor": "r1"}, [(2.0, "r1 fails")]),
    ({"failure_time_s": None}, []),
])
def test_failure_marks_read_every_shape(shape, expected):
    assert failure_marks(SimpleNamespace(**shape)) == expected


def test_plot_format_follows_the_extension(tmp_path, capsys):
    path = tmp_path / "quad.urdf"
    path.write_text(frame_urdf(4))
    svg = tmp_path / "run.svg"
    assert run_cli("hover-test", str(path), "--duration", "2", "--samples", "3",
                   "--plot", str(svg)) in (0, 1)
    data = svg.read_bytes()
    assert b"<svg" in data[:400] and "envelope" in ids(data)
    assert run_cli("hover-test", str(path), "--duration", "2", "--plot",
                   str(tmp_path / "run.jpg")) == 2
    assert "png or .svg" in capsys.readouterr().err
    assert not (tmp_path / "run.jpg").exists()
