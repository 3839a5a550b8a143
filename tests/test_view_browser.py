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
from matplotlib import image as mpimg

from browser import require_chromium, screenshot, settled_dom
from cli_helpers import run_cli
from reedtool.report.html_viewer import MODEL_VIEWER_FILE

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_QUAD = ROOT / "examples/reed_quad_x/urdf/mav_generic_odometry_sensor.gazebo"
# The budget for the example quad's page, the vendored viewer included.
PAGE_BUDGET_BYTES = 3_000_000


def _spin_pixels(png: Path) -> dict[str, int]:
    """Pixels by what they show: blue (ccw discs), orange (cw discs), body grey.

    The discs are lit, so their colours are shaded versions of SPIN_RGBA; a hue test
    (which channel leads, by a margin of 40/255 that shading keeps) classifies them
    without depending on the light. The page's white and the caption's black text
    fall in none of the classes.
    """
    rgb = (mpimg.imread(png)[..., :3] * 255).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    header_rows = 90                             # title, caption and colour key (HTML, not WebGL)
    view = np.s_[header_rows:, :]
    blue = (b > r + 40) & (b > g)
    orange = (r > b + 60) & (r > g) & (g > b)
    grey = (abs(r - g) < 8) & (abs(g - b) < 8) & (r > 150) & (r < 235)
    return {"ccw": int(blue[view].sum()), "cw": int(orange[view].sum()),
            "grey": int(grey[view].sum())}


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
    pixels = _spin_pixels(screenshot(example_page, tmp_path / "shot.png"))
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
