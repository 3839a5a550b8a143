"""A ViewScene as one HTML page: the GLB embedded as a data URI, shown by <model-viewer>.

The page is a single file to attach to a CI run or open from disk. It loads one thing
from the network: Google's <model-viewer> web component, a pinned version from the jsDelivr
CDN (MODEL_VIEWER_URL), fetched by the browser; nothing is vendored into reedtool. Offline, the page still shows the
caption (bounding box, scale bar, notes) and says the viewer needs the network.
"""

from __future__ import annotations

import base64
import html

from reedtool.report.scene import SEVERITY_RGBA, SPIN_RGBA, ViewScene, glb_bytes

MODEL_VIEWER_URL = "https://cdn.jsdelivr.net/npm/@google/model-viewer@4.0.0/dist/model-viewer.min.js"

_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<script type="module" src="{script}"></script>
<style>
  body {{ font-family: sans-serif; margin: 0; background: #fafafa; }}
  header {{ padding: 0.6em 1em; }}
  h1 {{ font-size: 1.1em; margin: 0 0 0.3em 0; }}
  model-viewer {{ width: 100%; height: 78vh; background: #ffffff; }}
  .key span {{ display: inline-block; width: 0.9em; height: 0.9em; margin: 0 0.3em 0 1em;
               vertical-align: middle; }}
  .notes {{ color: #7a4a00; font-size: 0.9em; }}
</style>
</head>
<body>
<header>
<h1>{title}</h1>
<div id="caption">{caption}</div>
<div class="key">{key}</div>
{notes}
</header>
<model-viewer src="data:model/gltf-binary;base64,{glb}" camera-controls
  camera-orbit="-40deg 65deg auto" shadow-intensity="0.6" alt="{title}">
  <div slot="poster">Loading the 3-D viewer (model-viewer, {script}). If this text stays,
  the page could not reach it: it needs the network. The .glb file
  (reedtool view MODEL -o MODEL.glb) opens offline in Blender or VS Code.</div>
</model-viewer>
</body>
</html>
"""


def _swatch(rgba, label: str) -> str:
    r, g, b = rgba[:3]
    return f'<span style="background: rgb({r},{g},{b})"></span>{html.escape(label)}'


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
    key.append(_swatch((220, 40, 40), "x (forward)") + _swatch((40, 170, 40), "y (left)")
               + _swatch((40, 80, 220), "z (up)"))
    notes = "".join(f'<div class="notes">{html.escape(n)}</div>' for n in view.notes)
    return _PAGE.format(title=html.escape(title), script=MODEL_VIEWER_URL,
                        caption=html.escape(view.framing.caption()), key="".join(key),
                        notes=notes, glb=base64.b64encode(glb_bytes(view)).decode("ascii"))
