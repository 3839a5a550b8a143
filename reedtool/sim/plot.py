"""Figure of a hover run: errors against their tolerance bands, position, attitude and
rotor speeds against their limits, over time; PNG or SVG.

Panels: position error with the tolerance band, the settle time and, for a batch, the
envelope (5th-95th percentile and median of the vehicles still flying); attitude
(roll/pitch/yaw and the attitude error with its band); position x, y, z; rotor speeds
with their maximum and the trim. Failure times (a rotor stopping, when the run carries
them) are vertical markers on every panel.

matplotlib is imported here, inside the function, with the Agg backend: no display is
needed and `reedtool --help` never pays for it.
"""

from __future__ import annotations

import io
import math
from typing import Iterable

import numpy as np

FORMATS = ("png", "svg")


def render(series: dict[str, np.ndarray], omega_max_rad_s: np.ndarray,
           trim_omega_rad_s: np.ndarray, title: str, *, fmt: str = "png",
           position_tol_m: float | None = None, attitude_tol_deg: float | None = None,
           settle_time_s: float | None = None,
           failures: Iterable[tuple[float, str]] = (),
           envelope: dict[str, np.ndarray] | None = None) -> bytes:
    """The figure as `fmt` bytes (the caller writes them atomically).

    `failures`: (time [s], label) of events to mark, e.g. a rotor failing; `envelope`:
    batch.BatchReport.envelope.
    """
    if fmt not in FORMATS:
        raise ValueError(f"plot format must be one of {FORMATS}, got {fmt!r}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = series["t_s"]
    failures = [(float(ft), str(label)) for ft, label in failures
                if ft is not None and math.isfinite(float(ft))]
    with plt.rc_context({"svg.hashsalt": "reedtool-hover", "svg.fonttype": "none"}):
        fig, (ax_err, ax_att, ax_pos, ax_rot) = plt.subplots(
            4, 1, figsize=(8.5, 11), sharex=True, gridspec_kw={"height_ratios": [1.2, 1, 1, 1]})

        # ---- position error, tolerance band, batch envelope, settle time
        if envelope is not None and len(envelope.get("t_s", ())):
            et = envelope["t_s"]
            ax_err.fill_between(et, envelope["p5"], envelope["p95"], color="#9ecae1",
                                alpha=0.5, linewidth=0,
                                label="batch: 5th-95th percentile", gid="envelope")
            ax_err.plot(et, envelope["p50"], color="#3182bd", linestyle="--", linewidth=1,
                        label="batch: median", gid="envelope-median")
        if position_tol_m is not None:
            ax_err.axhspan(0.0, position_tol_m, color="#a1d99b", alpha=0.45,
                           label=f"tolerance {100 * position_tol_m:g} cm", gid="tolerance")
        ax_err.plot(t, series["position_error_m"], color="black", linewidth=1.4,
                    label="this run", gid="position-error")
        ax_err.set_ylabel("position error [m]")
        ax_err.set_ylim(bottom=0.0)
        if "attitude_error_deg" in series:
            ax_att.plot(t, series["attitude_error_deg"], color="black", linewidth=1.4,
                        label="attitude error", gid="attitude-error")
        for key, label in (("roll_rad", "roll"), ("pitch_rad", "pitch"), ("yaw_rad", "yaw")):
            ax_att.plot(t, np.degrees(series[key]), label=label, linewidth=1)
        if attitude_tol_deg is not None:
            ax_att.axhspan(-attitude_tol_deg, attitude_tol_deg, color="#a1d99b", alpha=0.45,
                           label=f"tolerance ±{attitude_tol_deg:g}°", gid="attitude-tolerance")
        ax_att.set_ylabel("attitude [deg]")

        for key, label in (("x_m", "x"), ("y_m", "y"), ("z_m", "z")):
            ax_pos.plot(t, series[key], label=label, linewidth=1.2)
        ax_pos.set_ylabel("position [m]")

        rotor_keys = [k for k in series if k.startswith("omega_")]
        for key in rotor_keys:
            ax_rot.plot(t, series[key], label=key[len("omega_"):-len("_rad_s")], linewidth=1)
        for i, limit in enumerate(sorted(set(float(w) for w in omega_max_rad_s))):
            ax_rot.axhline(limit, color="red", linestyle="--", linewidth=1,
                           label="max speed" if i == 0 else None)
        for i, trim in enumerate(sorted(set(round(float(w), 6) for w in trim_omega_rad_s))):
            ax_rot.axhline(trim, color="gray", linestyle=":", linewidth=1.2,
                           label="hover trim" if i == 0 else None)
        ax_rot.set_ylabel("rotor speed [rad/s]")
        ax_rot.set_xlabel("time [s]")
        top = float(np.max(omega_max_rad_s)) if len(omega_max_rad_s) else 1.0
        ax_rot.set_ylim(bottom=0.0, top=1.05 * top)

        # ---- markers on every panel
        for ax in (ax_err, ax_att, ax_pos, ax_rot):
            if settle_time_s is not None and math.isfinite(settle_time_s):
                ax.axvline(settle_time_s, color="#31a354", linewidth=1.4,
                           label=f"settled at {settle_time_s:.2f} s" if ax is ax_err else None,
                           gid="settle" if ax is ax_err else None)
            for j, (ft, label) in enumerate(failures):
                ax.axvline(ft, color="#c0392b", linewidth=1.6, linestyle="-.",
                           label=f"{label} at {ft:.2f} s" if ax is ax_err else None,
                           gid=f"failure-{j}" if ax is ax_err else None)
            ax.grid(True, alpha=0.3)
        # legends outside the curves, right of each panel
        for ax in (ax_err, ax_att, ax_pos, ax_rot):
            handles, labels = ax.get_legend_handles_labels()
            if ax is ax_rot and len(rotor_keys) > 8:
                keep = [i for i, lab in enumerate(labels) if lab in ("max speed", "hover trim")]
                handles, labels = [handles[i] for i in keep], [labels[i] for i in keep]
            if handles:
                ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                          fontsize="small", frameon=False)

        fig.suptitle(title)
        fig.tight_layout()
        buffer = io.BytesIO()
        fig.savefig(buffer, format=fmt, dpi=100,
                    metadata={"Date": None} if fmt == "svg" else None)
        plt.close(fig)
    return buffer.getvalue()


def render_png(series: dict[str, np.ndarray], omega_max_rad_s: np.ndarray,
               trim_omega_rad_s: np.ndarray, title: str) -> bytes:
    """The figure as PNG bytes, without bands or markers (kept for callers of old)."""
    return render(series, omega_max_rad_s, trim_omega_rad_s, title, fmt="png")


def failure_marks(run) -> list[tuple[float, str]]:
    """(time, label) of the failures a run carries, whatever shape it has them in:
    `failures` as [(time, rotor)] or [{"time_s", "rotor"}], or `failure_time_s` (with
    `failed_rotor`). None of them: no marks."""
    marks = []
    for item in getattr(run, "failures", None) or ():
        if isinstance(item, dict):
            ft = item.get("time_s", item.get("t_s"))
            who = item.get("rotor", item.get("name", ""))
        else:
            ft, who = (tuple(item) + ("",))[:2]
        if ft is not None:
            marks.append((float(ft), f"{who} fails".strip() if who != "" else "failure"))
    ft = getattr(run, "failure_time_s", None)
    if ft is not None and not marks:
        who = getattr(run, "failed_rotor", None)
        marks.append((float(ft), f"{who} fails" if who is not None else "failure"))
    return marks
