"""`hover-test`'s text report (model, trim table, tuning, the flight, the batch, the
verdict and the last line) and its sampled time series as CSV. Formats the report of
workflows.flight / workflows.hover_test; computes nothing."""

from __future__ import annotations

import csv
import io
import json
import math

SCHEMA = "reedtool.hover-test/1"


def render_json(result) -> str:
    """`result`: a workflows.hover_test.HoverTestReport; NaN and infinity as null (a
    refusal carries no number)."""
    from reedtool.io.json_values import finite_tree
    from reedtool.report.json_format import envelope

    document = {**envelope(SCHEMA), **result.document}
    if result.refused:
        return json.dumps(document, indent=2)
    return json.dumps(finite_tree(document), indent=2, allow_nan=False)


def render_text(report: dict) -> str:
    """The whole text report of a flown (or judged unflyable) vehicle."""
    lines = _model_lines(report["model"]) + _trim_lines(report["trim"])
    if report.get("controller") is not None:
        from reedtool.report.lee_text import controller_lines

        lines += controller_lines(report["controller"])
    if report["sim"] is not None:
        lines += _sim_lines(report["sim"])
    if report["batch"] is not None:
        lines += _batch_lines(report["batch"])
    verdict = report.get("verdict")
    if verdict is not None:
        lines.append(f"verdict: {verdict['status'].upper()}: {verdict['message']}")
    from reedtool.sim.verdict import final_line

    lines.append(final_line(report.get("status", ""), report["passed"],
                            report.get("require", "flies"), report.get("message", "")))
    return "\n".join(lines)


def _model_lines(model: dict) -> list[str]:
    lines = [f"hover-test {model['name']}: {model['rotors']} rotors, "
             f"mass {model['mass_kg']:.4g} kg, COM ({', '.join(f'{v:.4g}' for v in model['com_m'])}) m"]
    others = [r for r in model.get("rotor_table", ()) if r["role"] != "lift"]
    if others:
        lines.append("not used for hover: " + ", ".join(f"{r['name']} ({r['role']})"
                                                         for r in others))
    for line in model.get("derived", ()):
        lines.append(f"derived: {line}")
    for lj in model.get("locked_joints", ()):
        # Passive joints (no plugin drives them) are flown rigid: say so, with what the
        # mass beyond them adds to the inertia about the COM.
        added = [lj["inertia_about_com_kg_m2"][i][i] for i in range(3)]
        total = [model["inertia_kg_m2"][i][i] for i in range(3)]
        share = ", ".join(f"{axis} {a:.3g} kg*m^2 ({100 * a / t:.0f}%)" if t > 0 else
                          f"{axis} {a:.3g} kg*m^2" for axis, a, t in zip("xyz", added, total))
        lines.append(f"locked rigid: {lj['joint']} ({lj['type']}, no plugin drives it; "
                     f"{lj['mass_kg']:.3g} kg beyond it adds {share} about the COM)")
    return lines


def _trim_lines(trim: dict) -> list[str]:
    if trim["feasible"]:
        lines = [f"trim: {trim['message']}"]
    else:
        lines = [f"trim: INFEASIBLE ({trim['cause']}): {trim['message']}"]
    if trim["rotors"]:
        width = max(len(r["name"]) for r in trim["rotors"])
        lines.append(f"  {'rotor':<{width}}  {'thrust N':>9}  {'omega rad/s':>11}  {'throttle':>8}")
        for r in trim["rotors"]:
            # A saturated rotor shows what it can give, and what the allocation asked.
            limit = {"max": "  at max, needs {:.4g} N", "min": "  at 0, needs {:.4g} N"
                     }.get(r.get("limit") or "", "").format(r.get("demand_N"))
            lines.append(f"  {r['name']:<{width}}  {_num(r['thrust_N'], '9.4f')}  "
                         f"{_num(r['omega_rad_s'], '11.2f')}  {_pct(r['throttle']):>8}{limit}")
    if trim["feasible"]:
        a = trim["torque_authority_N_m"]
        authority = ("" if not all(math.isfinite(v) for v in a.values()) else
                     f"; torque authority at hover: roll {a['roll']:.3g}, "
                     f"pitch {a['pitch']:.3g}, yaw {a['yaw']:.3g} N*m")
        lines.append(f"  thrust-to-weight {trim['thrust_to_weight']:.3f}{authority}")
    return lines


def _sim_lines(sim: dict) -> list[str]:
    from reedtool.sim.verdict import tuning_line

    c, lines = sim["config"], []
    if sim["gains"].get("controller") != "rotors-lee":
        lines.append(f"tuning: {tuning_line(sim['gains'])}")
    lines.append(f"sim: {sim['status'].upper()}: {sim['message']}")
    lines.append(f"  start {c['offset_m']} m off, roll {c['roll_rad']:g} pitch "
                 f"{c['pitch_rad']:g} yaw {c['yaw_rad']:g} rad; {c['duration_s']:g} s at "
                 f"{c['rate_hz']:g} Hz ({c['integrator']}; engine {sim['engine']})")
    lines.append(f"  max error {sim['max_position_error_m']:.3f} m, "
                 f"{sim['max_attitude_error_deg']:.1f} deg; final "
                 f"{100 * sim['final_position_error_m']:.2f} cm, "
                 f"{sim['final_attitude_error_deg']:.2f} deg; max throttle "
                 f"{_pct(sim['max_throttle'])}")
    if sim["passed"]:
        speeds = ", ".join(f"{w:.2f}" for w in sim["final_omega_rad_s"].values())
        lines.append(f"  final rotor speeds {speeds} rad/s")
    return lines


def _batch_lines(batch: dict) -> list[str]:
    s = batch["spreads"]
    counts = ", ".join(f"{k} {v}" for k, v in sorted(batch["counts"].items()))
    lines = [f"batch: {batch['passed']}/{batch['samples']} passed "
             f"({100 * batch['pass_rate']:.1f}%, need "
             f"{100 * batch['min_pass_rate']:.0f}%): {counts}"]
    lines.append(f"  spreads: mass +-{100 * s['mass_rel']:g}%, COM +-{1000 * s['com_m']:g} mm, "
                 f"inertia +-{100 * s['inertia_rel']:g}%, motor constant "
                 f"+-{100 * s['motor_constant_rel']:g}%; seed {batch['seed']}"
                 + (f"; from {batch['start_scale']:.3g} of the start (the recoverable margin)"
                    if batch.get("start_scale", 1.0) != 1.0 else ""))
    for w in batch["worst"]:
        lines.append(f"  #{w['index']}: {w['status']}: {w['message']} "
                     f"(mass {w['mass_kg']:.4g} kg, COM shift "
                     f"{', '.join(f'{1000 * v:.1f}' for v in w['com_shift_m'])} mm)")
    return lines


def series_csv(series: dict) -> str:
    """The sampled time series (one column per key) as CSV text, 9 significant digits."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    keys = list(series)
    writer.writerow(keys)
    for row in zip(*(series[k] for k in keys)):
        writer.writerow([f"{float(v):.9g}" for v in row])
    return buffer.getvalue()


def _num(value, spec: str) -> str:
    return format(value, spec) if value is not None and math.isfinite(value) else "n/a".rjust(
        int(spec.split(".")[0]))


def _pct(value) -> str:
    return f"{100 * value:.1f}%" if value is not None and math.isfinite(value) else "n/a"
