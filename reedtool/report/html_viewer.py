"""A ViewScene as one self-contained HTML page: the GLB and the viewer inside the file.

The page is a single file to attach to a CI run or open from disk, behind a firewall,
months later: it loads nothing from the network. Google's <model-viewer> web component
(three.js inside) is vendored into the package (report/vendor/, its version, checksum
and licences in vendor/README.md) and inlined into the page as a classic script, so it
runs from file:// where a module script from another origin would be refused.

When the viewer has drawn the model, the page sets `data-ready="1"` on <body> (and
`data-error` with the message when it cannot): a browser test, or a person's script,
waits on that flag instead of on a guess at how long WebGL takes.
"""

from __future__ import annotations

import base64
import html
from functools import lru_cache
from importlib import resources

import numpy as np

from reedtool.report.scene import FRONT_RGBA, SEVERITY_RGBA, SPIN_RGBA, T_GLTF_ROS, ViewScene, \
    glb_bytes

MODEL_VIEWER_VERSION = "4.4.0"
MODEL_VIEWER_FILE = "model-viewer-umd.min.js"

_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<script>{script}</script>
<style>
  body {{ font-family: sans-serif; margin: 0; background: #fafafa; }}
  header {{ padding: 0.6em 1em; }}
  h1 {{ font-size: 1.1em; margin: 0 0 0.3em 0; }}
  model-viewer {{ width: 100%; height: 78vh; background: #ffffff; }}
  .key span {{ display: inline-block; width: 0.9em; height: 0.9em; margin: 0 0.3em 0 1em;
               vertical-align: middle; }}
  .notes {{ color: #7a4a00; font-size: 0.9em; }}
  .hotspot {{ border: 1px solid #555; border-radius: 1em; background: #fff; padding: 0 0.35em;
              font: bold 12px sans-serif; pointer-events: none; }}
  .hotspot.front {{ color: #c81e1e; border-color: #c81e1e; }}
</style>
</head>
<body>
<header>
<h1>{title}</h1>
<div id="caption">{caption}</div>
<div class="key">{key}</div>
{notes}
</header>
<model-viewer id="viewer" src="data:model/gltf-binary;base64,{glb}" camera-controls
  camera-orbit="-40deg 65deg auto" shadow-intensity="0.6" alt="{title}">
{hotspots}
  <div slot="poster">Loading the 3-D view (model-viewer {version}, inside this page). If this
  text stays, this browser has no WebGL; the .glb file (reedtool view MODEL -o MODEL.glb)
  opens in Blender or VS Code.</div>
</model-viewer>
<script>
  const viewer = document.getElementById("viewer");
  viewer.addEventListener("load", () => {{ document.body.dataset.ready = "1"; }});
  viewer.addEventListener("error", (event) => {{
    document.body.dataset.error = String((event.detail && event.detail.type) || "error");
  }});
</script>
</body>
</html>
"""


def _swatch(rgba, label: str) -> str:
    r, g, b = rgba[:3]
    return f'<span style="background: rgb({r},{g},{b})"></span>{html.escape(label)}'


@lru_cache(maxsize=1)
def _viewer_script() -> str:
    """The vendored model-viewer, safe to inline: no `</script` can end the element early."""
    text = resources.files("reedtool.report").joinpath("vendor", MODEL_VIEWER_FILE).read_text(
        encoding="utf-8")
    return text.replace("</script", "<\\/script")


def _hotspots(view: ViewScene) -> str:
    """The labels (FRONT, motor numbers) as model-viewer hotspots, which stay on their point
    as the model turns. Positions are in the glTF scene's frame: y up, as T_GLTF_ROS turns it."""
    spots = []
    for number, label in enumerate(view.labels):
        x, y, z = (T_GLTF_ROS[:3, :3] @ np.asarray(label.position_m, dtype=float)).tolist()
        spots.append(f'  <div class="hotspot {label.kind}" slot="hotspot-{number}" '
                     f'data-position="{x:.6g}m {y:.6g}m {z:.6g}m">{html.escape(label.text)}</div>')
    return "\n".join(spots)


def render_html(view: ViewScene, title: str) -> str:
    key = []
    spins = {int(d.turning_sign > 0) - int(d.turning_sign < 0) for d in view.discs}
    for sign, label in ((1, "ccw rotor"), (-1, "cw rotor"), (0, "spin unknown")):
        if sign in spins:
            key.append(_swatch(SPIN_RGBA[sign], label))
    for severity in ("error", "warning", "info"):
        if severity in view.link_severity.values():
            key.append(_swatch(SEVERITY_RGBA[severity], f"{severity} finding"))
    key.append(_swatch((0, 0, 0), "COM, scale bar"))
    key.append(_swatch(FRONT_RGBA, "FRONT arrow (+x)"))
    key.append(_swatch((220, 40, 40), "x (forward)") + _swatch((40, 170, 40), "y (left)")
               + _swatch((40, 80, 220), "z (up)"))
    notes = "".join(f'<div class="notes">{html.escape(n)}</div>' for n in view.notes)
    return _PAGE.format(title=html.escape(title), script=_viewer_script(),
                        version=MODEL_VIEWER_VERSION,
                        caption=html.escape(view.framing.caption()), key="".join(key),
                        notes=notes, hotspots=_hotspots(view), glb=base64.b64encode(glb_bytes(view)).decode("ascii"))
