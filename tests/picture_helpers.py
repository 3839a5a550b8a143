"""What a rendered picture shows, read from its pixels: the classes every view test uses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import image as mpimg


def colour_masks(png: Path) -> dict[str, np.ndarray]:
    """Boolean masks of a PNG's pixels by what they show: ccw discs (blue), cw discs
    (orange), the body (light grey) and the FRONT arrow (red).

    Discs and body are lit, so their colours are shaded versions of SPIN_RGBA and
    DEFAULT_RGBA; a hue test (which channel leads, by a margin of 40/255 that shading
    keeps) classifies them without depending on the light. White page and black text fall
    in none of the classes. "rgb" is the picture itself, as integers 0-255.
    """
    rgb = (mpimg.imread(png)[..., :3] * 255).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return {
        "rgb": rgb,
        "ccw": (b > r + 40) & (b > g),
        "cw": (r > b + 60) & (r > g) & (g > b),
        "grey": (abs(r - g) < 8) & (abs(g - b) < 8) & (r > 150) & (r < 235),
        "red": (r > 150) & (g < 80) & (b < 80),
    }
