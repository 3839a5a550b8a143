"""hover-test --controller's section of the text report: the RotorS Lee controller files,
what they tell the controller against the model, the loops the gains make, and the
pre-flight findings. Formats the "controller" dict of workflows.lee_flight; computes
nothing."""

from __future__ import annotations

import math


def controller_lines(c: dict) -> list[str]:
    lines = [f"controller: RotorS Lee position controller at {c['control_rate_hz']:g} Hz from "
             + ", ".join(c["files"]) + " (numpy engine)"]
    lines += [f"  note: {note}" for note in c["notes"]]
    if c["entries"] != c["rotors"]:
        lines.append(f"  its rotor_configuration has {c['entries']} entries for "
                     f"{c['rotors']} rotors")
    ratio = c["yaml_mass_kg"] / c["model_mass_kg"] if c["model_mass_kg"] > 0 else math.nan
    offset = c["predicted_altitude_offset_m"]
    lines.append(f"  mass: file {c['yaml_mass_kg']:.6g} kg, model {c['model_mass_kg']:.6g} kg "
                 f"({100 * (ratio - 1):+.1f}%)"
                 + (f"; no integral term: hovers {100 * offset:+.1f} cm off the height it "
                    f"is sent" + (" (judged about that height)" if c.get("judged_about_offset")
                                  else "")
                    if offset is not None and abs(offset) >= 0.001 else ""))
    J_f, J_m = c["yaml_inertia_kg_m2"], c["model_inertia_kg_m2"]
    lines.append("  inertia diagonal: file " + ", ".join(f"{J_f[i][i]:.4g}" for i in range(3))
                 + "; model " + ", ".join(f"{J_m[i][i]:.4g}" for i in range(3)) + " kg*m^2")
    loops = c["loops"]
    lines.append("  loops on the model: attitude " + _loop(loops["attitude_natural_rad_s"],
                                                            loops["attitude_damping"])
                 + "; position " + _loop(loops["position_natural_rad_s"],
                                         loops["position_damping"]))
    for f in c["preflight"]:
        where = f"{f['file']}:{f['line']}" if f.get("line") else f["file"]
        lines.append(f"  {f['severity']} {f['code']} {where}: {f['message']}")
        if f.get("hint"):
            lines.append(f"      hint: {f['hint']}")
    return lines


def _loop(natural: list, damping: list) -> str:
    def one(w, z):
        if w is None or z is None or not (math.isfinite(w) and math.isfinite(z)):
            return "n/a"
        return f"{w:.3g} rad/s zeta {z:.2g}"
    return " / ".join(f"{axis} {one(w, z)}" for axis, w, z in zip("xyz", natural, damping))
