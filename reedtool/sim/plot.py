"""PNG of a hover run: position, attitude and rotor speeds against their limits, over time.

matplotlib is imported here, inside the function, with the Agg backend: no display is
needed and `reedtool --help` never pays for it.
"""

from __future__ import annotations

import io

import numpy as np


def render_png(series: dict[str, np.ndarray], omega_max_rad_s: np.ndarray,
               trim_omega_rad_s: np.ndarray, title: str,
               events: tuple[tuple[float, str], ...] = ()) -> bytes:
    """The three-panel figure as PNG bytes (the caller writes them atomically).

    `events` (time [s], label), e.g. a rotor failure, are marked on every panel.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = series["t_s"]
    fig, (ax_pos, ax_att, ax_rot) = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for key, label in (("x_m", "x"), ("y_m", "y"), ("z_m", "z")):
        ax_pos.plot(t, series[key], label=label)
    ax_pos.set_ylabel("position [m]")
    ax_pos.legend(loc="upper right")
    ax_pos.grid(True, alpha=0.3)

    for key, label in (("roll_rad", "roll"), ("pitch_rad", "pitch"), ("yaw_rad", "yaw")):
        ax_att.plot(t, np.degrees(series[key]), label=label)
    ax_att.set_ylabel("attitude [deg]")
    ax_att.legend(loc="upper right")
    ax_att.grid(True, alpha=0.3)

    rotor_keys = [k for k in series if k.startswith("omega_")]
    for key in rotor_keys:
        ax_rot.plot(t, series[key], label=key[len("omega_"):-len("_rad_s")], linewidth=1)
    for limit in sorted(set(float(w) for w in omega_max_rad_s)):
        ax_rot.axhline(limit, color="red", linestyle="--", linewidth=1)
    for trim in sorted(set(round(float(w), 6) for w in trim_omega_rad_s)):
        ax_rot.axhline(trim, color="gray", linestyle=":", linewidth=1)
    ax_rot.set_ylabel("rotor speed [rad/s]\n(-- max, : trim)")
    ax_rot.set_xlabel("time [s]")
    ax_rot.set_ylim(bottom=0.0, top=1.05 * float(np.max(omega_max_rad_s)))
    if len(rotor_keys) <= 8:
        ax_rot.legend(loc="lower right", fontsize="small")
    ax_rot.grid(True, alpha=0.3)

    for time_s, label in events:
        for ax in (ax_pos, ax_att, ax_rot):
            ax.axvline(time_s, color="black", linestyle="-.", linewidth=1)
        ax_pos.annotate(label, (time_s, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(3, -12), textcoords="offset points", fontsize="small")
    fig.suptitle(title)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    return buffer.getvalue()
