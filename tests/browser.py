"""Headless Chromium as the judge of a page reedtool writes.

Debian's `chromium` (installed by .ci/run) opens the page from file:// with every network
path closed: a proxy that refuses (127.0.0.1:9, the discard port) and a resolver that
finds no host. A page that needs the network cannot draw there. WebGL runs on SwiftShader,
Chromium's CPU renderer, so no GPU or display is needed.

Two things are read back, each from its own run of the browser (about 8 s each):
- the DOM after the page settled (`--dump-dom`): the page's own flags, and what the
  console said, recorded by a probe script put at the top of a copy of the page;
- a screenshot (`--screenshot`) to look for the model's pixels.

`--virtual-time-budget` lets the page's timers and WebGL frames run as if 15 s had
passed, then the browser stops: the wait ends when the page is idle, not after a fixed sleep.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")

_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
    "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND",
    "--virtual-time-budget=15000",       # replaced by settled_dom's budget_ms
]

# Put before everything else in the page: every console.error call and every uncaught error
# or rejection lands in <html data-console-errors>, which --dump-dom then shows. Warnings are
# left out: under a virtual time budget model-viewer warns "rAF timed out", which says how
# the headless browser schedules frames, not that the page is wrong.
_PROBE = """<script>
(() => {
  const seen = [];
  const keep = (kind, args) => {
    seen.push(kind + ": " + Array.from(args).map(String).join(" "));
    document.documentElement.dataset.consoleErrors = JSON.stringify(seen);
  };
  const original = console.error;
  console.error = function (...args) { keep("error", args); original.apply(console, args); };
  window.addEventListener("error", (e) => keep("uncaught", [e.message]));
  window.addEventListener("unhandledrejection", (e) => keep("rejection", [e.reason]));
})();
</script>"""


def require_chromium():
    """Skip where no Chromium is installed, except in CI, which installs it and must run this."""
    if CHROMIUM:
        return
    if IN_CI:
        pytest.fail("CI must install Debian's chromium (see .ci/run): the browser test never skips there")
    pytest.skip("needs Debian's chromium (apt-get install chromium)")


def _run(page: Path, *args: str, budget_ms: int = 15000,
         timeout_s: float = 180) -> subprocess.CompletedProcess:
    flags = [flag if not flag.startswith("--virtual-time-budget") else
             f"--virtual-time-budget={budget_ms}" for flag in _FLAGS]
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run([CHROMIUM, *flags, f"--user-data-dir={profile}", *args,
                               page.resolve().as_uri()],
                              capture_output=True, text=True, timeout=timeout_s, check=False)


def settled_dom(page: Path, budget_ms: int = 15000) -> tuple[str, list[str]]:
    """The page's DOM once it settled, and the errors its console reported."""
    probed = page.with_name(f".probe-{page.name}")
    text = page.read_text(encoding="utf-8")
    probed.write_text(text.replace("<head>", "<head>" + _PROBE, 1), encoding="utf-8")
    try:
        dom = _run(probed, "--dump-dom", budget_ms=budget_ms).stdout
    finally:
        probed.unlink()
    found = re.search(r'data-console-errors="([^"]*)"', dom)
    errors = []
    if found:
        import html
        import json
        errors = json.loads(html.unescape(found.group(1)))
    return dom, errors


def screenshot(page: Path, out: Path, width: int = 900, height: int = 700) -> Path:
    _run(page, f"--window-size={width},{height}", f"--screenshot={out}")
    if not out.is_file():
        raise AssertionError(f"chromium wrote no screenshot of {page}")
    return out
