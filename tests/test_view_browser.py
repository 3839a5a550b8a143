"""`view -o PAGE.html` in a real browser, with no network: the page draws the model.

Headless Chromium (tests/browser.py) opens the page from file:// with every network path
closed and SwiftShader for WebGL. What is asserted is what the browser did: the page's
own ready flag (set by model-viewer's `load` event, after the GLB was parsed and drawn),
no console error or warning, and the model's pixels in a screenshot: rotor discs in both
spin colours and the grey body. A copy of the page without the viewer script is the
control: the same checks find no flag and no model there, so they can fail.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from browser import require_chromium, screenshot, settled_dom
from picture_helpers import colour_masks
from cli_helpers import run_cli
from reedtool.report.html_viewer import MODEL_VIEWER_FILE

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_QUAD = ROOT / "examples/reed_quad_x/urdf/mav_generic_odometry_sensor.gazebo"
# The budget for the example quad's page, the vendored viewer included.
PAGE_BUDGET_BYTES = 3_000_000


def _keep(shot: Path, name: str) -> None:
    """REEDTOOL_SCREENSHOTS=DIR keeps the browser's screenshots (docs/images come from here)."""
    import os
    import shutil

    where = os.environ.get("REEDTOOL_SCREENSHOTS")
    if where:
        shutil.copyfile(shot, Path(where) / name)


def _spin_pixels(png: Path) -> dict[str, int]:
    """Disc and body pixels below the page's header (title, caption and colour key are
    HTML, not WebGL)."""
    masks = colour_masks(png)
    header_rows = 90
    return {kind: int(masks[kind][header_rows:, :].sum()) for kind in ("ccw", "cw", "grey")}


@pytest.fixture(scope="module")
def example_page(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("page") / "quad.html"
    code, text = run_cli("view", EXAMPLE_QUAD, "-o", out)
    assert code == 0, text
    return out


def test_the_page_fits_its_budget(example_page):
    assert example_page.stat().st_size < PAGE_BUDGET_BYTES


def test_the_page_draws_the_model_offline(example_page, tmp_path):
    require_chromium()
    dom, console = settled_dom(example_page)
    assert 'data-ready="1"' in dom, "model-viewer never reported the model drawn"
    assert "data-error" not in dom
    assert console == []
    shot = screenshot(example_page, tmp_path / "shot.png")
    _keep(shot, "view_page_chromium.png")
    pixels = _spin_pixels(shot)
    # Two discs of each spin, 0.24 m across on a 0.575 m frame, fill several thousand
    # pixels each at 900x700; 1000 is a floor no stray anti-aliasing reaches.
    assert pixels["ccw"] > 1000 and pixels["cw"] > 1000, pixels
    assert pixels["grey"] > 1000, pixels


def test_without_the_viewer_the_same_checks_fail(example_page, tmp_path):
    """The control: the checks above see the difference between a drawn and an undrawn page."""
    require_chromium()
    page = example_page.read_text(encoding="utf-8")
    start = page.index("<script>!function(")
    end = page.index("</script>", start) + len("</script>")
    blank = tmp_path / "no_viewer.html"
    blank.write_text(page[:start] + page[end:], encoding="utf-8")
    dom, _ = settled_dom(blank)
    assert 'data-ready="1"' not in dom
    pixels = _spin_pixels(screenshot(blank, tmp_path / "blank.png"))
    assert pixels["ccw"] < 50 and pixels["cw"] < 50, pixels


def test_the_vendored_viewer_is_the_pinned_release():
    """The file in the package is model-viewer's npm release named in vendor/README.md."""
    import hashlib
    import re

    vendor = ROOT / "reedtool/report/vendor"
    readme = (vendor / "README.md").read_text(encoding="utf-8")
    pinned = re.search(r"sha256 `([0-9a-f]{64})`", readme).group(1)
    assert hashlib.sha256((vendor / MODEL_VIEWER_FILE).read_bytes()).hexdigest() == pinned
    assert (vendor / "LICENSE-model-viewer").read_text().lstrip().startswith("Apache License")


# ------------------------------------------------------------------ hover replay

@pytest.fixture(scope="module")
def replay(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("replay") / "flight.html"
    code, text = run_cli("hover-test", EXAMPLE_QUAD, "--replay", out)
    assert code == 0, text
    return out


def _flight(page: Path) -> dict:
    import json
    import re

    return json.loads(re.search(r"const FLIGHT = (\{.*?\});</script>", page.read_text(),
                                re.S).group(1).replace("<\\/", "</"))


def test_the_replay_holds_the_flight_it_says(replay):
    """The page's data is the flight hover-test flew: it starts at the setpoint plus the
    default --offset (0.5, 0, 0) m with the default --roll 0.2 rad, over --duration 10 s."""
    flight = _flight(replay)
    start = [axis[0] for axis in flight["position_m"]]
    np.testing.assert_allclose(start, [0.5, 0.0, 2.0], atol=1e-12)   # written to 7 decimals
    assert flight["rpy_rad"][0][0] == pytest.approx(0.2, abs=1e-7)
    assert flight["t_s"][0] == 0.0 and flight["t_s"][-1] == pytest.approx(10.0, abs=0.011)
    assert len(flight["t_s"]) <= 600 and len(flight["omega_rad_s"]) == 4
    # it settles: the last frame is inside the band it draws
    assert flight["position_error_m"][-1] < flight["position_tol_m"]


def test_the_replay_plays_in_a_browser(replay, tmp_path):
    """With more (virtual) time the page shows a later frame, and after the flight's
    10 s it has reached the last one: it plays, offline, without errors."""
    import re

    require_chromium()
    frames = []
    for budget_ms in (1500, 12000):
        dom, console = settled_dom(replay, budget_ms=budget_ms)
        assert console == [] and 'data-ready="1"' in dom
        frames.append(int(re.search(r'data-frame="(\d+)"', dom).group(1)))
        ended = 'data-ended="1"' in dom
    n = len(_flight(replay)["t_s"])
    assert 0 < frames[0] < frames[1] == n - 1 and ended
    shot = screenshot(replay, tmp_path / "r.png")
    _keep(shot, "hover_replay_chromium.png")
    assert colour_masks(shot)["red"].sum() > 100                    # the FRONT arrow, the time cursor
