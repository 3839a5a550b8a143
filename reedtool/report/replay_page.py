"""hover-test's flight as one self-contained HTML page that plays it back.

The page draws the vehicle with a 2-D canvas (no WebGL, no library, nothing fetched), so
it plays in any browser, from file://, as a CI artifact: the body's pose over time (its
arms from the centre of mass to each rotor, a FRONT arrow along body +x), each rotor's
disc coloured by its speed between 0 and its maximum, the path flown, the setpoint and
the settle band (a sphere of the position tolerance around it). Below, the position and
attitude errors against their tolerances and the rotor speeds, with a cursor at the
frame shown. Play/pause and a time slider; the page plays once on load.

What the page draws is the simulation's own sampled series (sim.run's, the same that
`--csv` writes), decimated to at most MAX_FRAMES frames; it computes nothing but the
projection. For scripts and browser tests the page sets on <body> `data-ready="1"` when
the first frame is drawn, `data-frame` to the frame shown, and `data-ended="1"` when the
playback reached the last frame.
"""

from __future__ import annotations

import html
import json
import math

import numpy as np

MAX_FRAMES = 600            # 60 s of playback at 10 frames of flight per second, at most


def _decimated(series: dict[str, np.ndarray]) -> tuple[dict[str, list[float]], int]:
    n = len(series["t_s"])
    stride = max(1, math.ceil(n / MAX_FRAMES))
    keep = np.arange(0, n, stride)
    if keep[-1] != n - 1:
        keep = np.append(keep, n - 1)      # the last sample always: where the flight ended
    return {key: [round(float(v), 7) for v in np.asarray(values)[keep]]
            for key, values in series.items()}, stride


def replay_document(series: dict[str, np.ndarray], *, rotor_positions_m: np.ndarray,
                    turning_signs, omega_max_rad_s: np.ndarray, rotor_names,
                    setpoint_m, position_tol_m: float, attitude_tol_deg: float,
                    settle_time_s: float | None, title: str, verdict: str) -> dict:
    """What the page plays: the decimated series and the vehicle's geometry, JSON-ready.

    `rotor_positions_m`: (n, 3) rotor centres relative to the centre of mass, body frame.
    """
    frames, stride = _decimated(series)
    omega_keys = [f"omega_{name}_rad_s" for name in rotor_names]
    return {
        "title": title, "verdict": verdict, "stride": stride,
        "t_s": frames["t_s"],
        "position_m": [frames["x_m"], frames["y_m"], frames["z_m"]],
        "rpy_rad": [frames["roll_rad"], frames["pitch_rad"], frames["yaw_rad"]],
        "position_error_m": frames["position_error_m"],
        "attitude_error_deg": frames["attitude_error_deg"],
        "omega_rad_s": [frames[key] for key in omega_keys if key in frames],
        "omega_max_rad_s": [float(v) for v in omega_max_rad_s],
        "rotor_positions_m": [[float(v) for v in p] for p in np.asarray(rotor_positions_m)],
        "turning_signs": [int(np.sign(s)) for s in turning_signs],
        "setpoint_m": [float(v) for v in setpoint_m],
        "position_tol_m": float(position_tol_m), "attitude_tol_deg": float(attitude_tol_deg),
        "settle_time_s": (float(settle_time_s) if settle_time_s is not None
                          and math.isfinite(settle_time_s) else None),
    }


def render_replay(document: dict) -> str:
    """The page, with `document` (replay_document's) inside it."""
    data = json.dumps(document, allow_nan=False, separators=(",", ":"))
    # JSON inside <script>: "</" would end the element early
    data = data.replace("</", "<\\/")
    return _PAGE.replace("__TITLE__", html.escape(document["title"])).replace(
        "__VERDICT__", html.escape(document["verdict"])).replace("__DATA__", data).replace(
        "__SCRIPT__", _SCRIPT)


_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>__TITLE__ - hover replay</title>
<style>
  body { font-family: sans-serif; margin: 0.6em 1em; background: #fafafa; }
  h1 { font-size: 1.1em; margin: 0 0 0.2em 0; }
  #verdict { margin-bottom: 0.4em; }
  canvas { background: #fff; border: 1px solid #ddd; display: block; margin-top: 0.3em; }
  #controls { margin: 0.3em 0; }
  #clock { font-family: monospace; margin-left: 0.6em; }
  .key span { display: inline-block; width: 0.9em; height: 0.9em; margin: 0 0.3em 0 1em;
              vertical-align: middle; }
</style>
</head>
<body>
<h1>__TITLE__</h1>
<div id="verdict">__VERDICT__</div>
<div class="key"><span style="background: linear-gradient(90deg, #2c7bb6, #ffffbf, #d7191c)"></span>rotor speed, 0 to its maximum
<span style="background: #c81e1e"></span>FRONT (body +x)
<span style="background: rgba(40,160,40,0.35)"></span>settle band (position tolerance about the setpoint)</div>
<div id="controls"><button id="play">pause</button>
<input id="slider" type="range" min="0" value="0" style="width: 50%">
<span id="clock"></span></div>
<canvas id="scene" width="860" height="460"></canvas>
<canvas id="plots" width="860" height="300"></canvas>
<script>const FLIGHT = __DATA__;</script>
<script>__SCRIPT__</script>
</body>
</html>
"""

_SCRIPT = r"""
(() => {
  const F = FLIGHT, n = F.t_s.length;
  const scene = document.getElementById("scene"), sc = scene.getContext("2d");
  const plots = document.getElementById("plots"), pc = plots.getContext("2d");
  const slider = document.getElementById("slider"), clock = document.getElementById("clock");
  const button = document.getElementById("play");
  slider.max = n - 1;

  // URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll), body -> world
  function rotation(r, p, y) {
    const cr = Math.cos(r), sr = Math.sin(r), cp = Math.cos(p), sp = Math.sin(p),
          cy = Math.cos(y), sy = Math.sin(y);
    return [[cy*cp, cy*sp*sr - sy*cr, cy*sp*cr + sy*sr],
            [sy*cp, sy*sp*sr + cy*cr, sy*sp*cr - cy*sr],
            [-sp, cp*sr, cp*cr]];
  }
  const apply = (R, v) => [0, 1, 2].map(i => R[i][0]*v[0] + R[i][1]*v[1] + R[i][2]*v[2]);

  // a fixed camera from front-left, above (as view's iso): world -> screen, orthographic
  const az = -130 * Math.PI / 180, el = 28 * Math.PI / 180;
  const right = [-Math.sin(az), Math.cos(az), 0];
  const up = [-Math.sin(el)*Math.cos(az), -Math.sin(el)*Math.sin(az), Math.cos(el)];
  const depthDir = [Math.cos(el)*Math.cos(az), Math.cos(el)*Math.sin(az), Math.sin(el)];
  const dot = (a, b) => a[0]*b[0] + a[1]*b[1] + a[2]*b[2];
  const arm = Math.max(...F.rotor_positions_m.map(p => Math.hypot(p[0], p[1])), 0.05);
  const positions = F.t_s.map((_, k) => [0, 1, 2].map(i => F.position_m[i][k]));
  const reach = Math.max(...positions.map(p => Math.hypot(p[0] - F.setpoint_m[0],
      p[1] - F.setpoint_m[1], p[2] - F.setpoint_m[2])), F.position_tol_m) + 1.6 * arm;
  const scale = Math.min(scene.width, scene.height) / (2.0 * reach);
  const screen = (w) => {
    const d = [w[0] - F.setpoint_m[0], w[1] - F.setpoint_m[1], w[2] - F.setpoint_m[2]];
    return [scene.width / 2 + scale * dot(d, right), scene.height / 2 - scale * dot(d, up)];
  };

  function speedColour(u) {          // 0 blue, 0.5 pale yellow, 1 red
    u = Math.max(0, Math.min(1, u));
    const stops = [[44, 123, 182], [255, 255, 191], [215, 25, 28]];
    const i = u < 0.5 ? 0 : 1, f = u < 0.5 ? u / 0.5 : (u - 0.5) / 0.5;
    const c = stops[i].map((a, j) => Math.round(a + f * (stops[i + 1][j] - a)));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  function disc(centre, R, radius, fill, stroke) {
    sc.beginPath();
    for (let k = 0; k <= 36; k++) {
      const a = 2 * Math.PI * k / 36;
      const w = apply(R, [radius * Math.cos(a), radius * Math.sin(a), 0]);
      const s = screen([centre[0] + w[0], centre[1] + w[1], centre[2] + w[2]]);
      k ? sc.lineTo(s[0], s[1]) : sc.moveTo(s[0], s[1]);
    }
    sc.fillStyle = fill; sc.fill(); sc.strokeStyle = stroke; sc.lineWidth = 1.5; sc.stroke();
  }

  function drawScene(k) {
    sc.clearRect(0, 0, scene.width, scene.height);
    // the settle band and the setpoint
    const c = screen(F.setpoint_m);
    sc.beginPath(); sc.arc(c[0], c[1], Math.max(3, scale * F.position_tol_m), 0, 2 * Math.PI);
    sc.fillStyle = "rgba(40,160,40,0.35)"; sc.fill();
    sc.strokeStyle = "#208020"; sc.beginPath(); sc.moveTo(c[0] - 6, c[1]); sc.lineTo(c[0] + 6, c[1]);
    sc.moveTo(c[0], c[1] - 6); sc.lineTo(c[0], c[1] + 6); sc.stroke();
    // the path flown so far
    sc.strokeStyle = "#999"; sc.lineWidth = 1; sc.beginPath();
    for (let j = 0; j <= k; j++) { const s = screen(positions[j]); j ? sc.lineTo(s[0], s[1]) : sc.moveTo(s[0], s[1]); }
    sc.stroke();
    // the vehicle: arms, rotor discs by speed (far ones first), FRONT arrow
    const p = positions[k], R = rotation(F.rpy_rad[0][k], F.rpy_rad[1][k], F.rpy_rad[2][k]);
    const rotors = F.rotor_positions_m.map((r, i) => {
      const w = apply(R, r);
      return {i, at: [p[0] + w[0], p[1] + w[1], p[2] + w[2]]};
    }).sort((a, b) => dot(a.at, depthDir) - dot(b.at, depthDir));
    const o = screen(p);
    for (const r of rotors) {
      const s = screen(r.at);
      sc.strokeStyle = "#444"; sc.lineWidth = 4; sc.beginPath(); sc.moveTo(o[0], o[1]); sc.lineTo(s[0], s[1]); sc.stroke();
      const u = F.omega_rad_s.length ? F.omega_rad_s[r.i][k] / F.omega_max_rad_s[r.i] : 0;
      disc(r.at, R, 0.45 * arm, speedColour(u), F.turning_signs[r.i] > 0 ? "#1f77b4" : "#e67e22");
    }
    const nose = apply(R, [arm, 0, 0]), tip = screen([p[0] + nose[0], p[1] + nose[1], p[2] + nose[2]]);
    sc.strokeStyle = "#c81e1e"; sc.lineWidth = 3; sc.beginPath(); sc.moveTo(o[0], o[1]); sc.lineTo(tip[0], tip[1]); sc.stroke();
    sc.fillStyle = "#c81e1e"; sc.font = "bold 12px sans-serif"; sc.fillText("FRONT", tip[0] + 4, tip[1]);
    sc.fillStyle = "#000"; sc.font = "12px sans-serif";
    sc.fillText(`scale: ${arm.toPrecision(3)} m arm`, 10, scene.height - 10);
  }

  function drawPlots(k) {
    pc.clearRect(0, 0, plots.width, plots.height);
    const t0 = F.t_s[0], t1 = F.t_s[n - 1] || 1, left = 60, w = plots.width - left - 10;
    const x = (t) => left + w * (t - t0) / ((t1 - t0) || 1);
    const panels = [
      ["position error [m]", [F.position_error_m], F.position_tol_m],
      ["attitude error [deg]", [F.attitude_error_deg], F.attitude_tol_deg],
      ["rotor speed [rad/s]", F.omega_rad_s, null]];
    const h = plots.height / panels.length;
    panels.forEach(([name, lines, tol], i) => {
      const top = i * h + 14, bottom = (i + 1) * h - 6;
      const peak = Math.max(...lines.flat(), tol || 0, 1e-9);
      const y = (v) => bottom - (bottom - top) * v / peak;
      if (tol !== null) {
        pc.fillStyle = "rgba(40,160,40,0.25)"; pc.fillRect(left, y(tol), w, bottom - y(tol));
      }
      lines.forEach((line, j) => {
        pc.strokeStyle = lines.length > 1 ? speedColour(j / Math.max(1, lines.length - 1)) : "#000";
        pc.lineWidth = 1.2; pc.beginPath();
        line.forEach((v, m) => { m ? pc.lineTo(x(F.t_s[m]), y(v)) : pc.moveTo(x(F.t_s[m]), y(v)); });
        pc.stroke();
      });
      pc.fillStyle = "#000"; pc.font = "11px sans-serif"; pc.fillText(name, left + 4, top);
      pc.fillText(peak.toPrecision(3), 4, top + 8); pc.fillText("0", 4, bottom);
    });
    if (F.settle_time_s !== null) {
      pc.strokeStyle = "#208020"; pc.setLineDash([4, 3]); pc.beginPath();
      pc.moveTo(x(F.settle_time_s), 0); pc.lineTo(x(F.settle_time_s), plots.height); pc.stroke(); pc.setLineDash([]);
    }
    pc.strokeStyle = "#c81e1e"; pc.beginPath(); pc.moveTo(x(F.t_s[k]), 0); pc.lineTo(x(F.t_s[k]), plots.height); pc.stroke();
  }

  let frame = 0, playing = true, last = null;
  function show(k) {
    frame = k; slider.value = k;
    drawScene(k); drawPlots(k);
    clock.textContent = `t = ${F.t_s[k].toFixed(2)} s of ${F.t_s[n - 1].toFixed(2)} s`;
    document.body.dataset.frame = String(k);
    document.body.dataset.ready = "1";
    if (k === n - 1) document.body.dataset.ended = "1";
  }
  // a timer, not requestAnimationFrame: hidden tabs and headless browsers hold frames
  // back, while timers (and a browser's virtual time) keep the flight's clock
  function tick() {
    const now = performance.now();
    if (playing) {
      // real time: the frame whose time has come since playback started
      if (last === null) last = now - 1000 * (F.t_s[frame] - F.t_s[0]);
      const t = F.t_s[0] + (now - last) / 1000;
      let k = frame;
      while (k < n - 1 && F.t_s[k + 1] <= t) k++;
      if (k !== frame) show(k);
      if (k === n - 1) { playing = false; button.textContent = "replay"; }
    }
    setTimeout(tick, 1000 / 30);
  }
  button.addEventListener("click", () => {
    if (!playing && frame === n - 1) show(0);
    playing = !playing; last = null;
    button.textContent = playing ? "pause" : "play";
  });
  slider.addEventListener("input", () => { playing = false; button.textContent = "play"; show(Number(slider.value)); });
  show(0);
  setTimeout(tick, 0);
})();
"""
