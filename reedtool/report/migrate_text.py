"""`migrate`'s text report: the port plan's rows by action, the proof's counts and
side-by-side figures, the differences. Formats workflows.migration's result; computes
nothing."""

from __future__ import annotations

import json

SCHEMA = "reedtool.migrate/1"


def render_json(result) -> str:
    from reedtool.report.json_format import envelope

    return json.dumps({**envelope(SCHEMA), **result.to_dict()}, indent=2, allow_nan=False)


def render_text(result) -> str:
    rows, proof = result.rows, result.proof
    lines = [f"migrate {result.source} -> {result.target} ({len(result.files)} files)"]
    for action in ("mapped", "folded", "dropped", "unknown"):
        chosen = [r for r in rows if r.action == action]
        if not chosen:
            continue
        title = {"unknown": "kept out (no gz counterpart known)"}.get(action, action)
        lines.append(f"{title}:")
        for row in chosen:
            arrow = f" -> {row.output}" if row.output else ""
            lines.append(f"  {row.source}: {row.element}{arrow}")
            lines.append(f"      {row.why}")
            if row.carried:
                lines.append("      carried: " + ", ".join(f"{k} {v}" for k, v in
                                                           row.carried.items()))
    counted = ", ".join(f"{k} {v}" for k, v in proof.compared.items())
    lines.append(f"proof (read back, compared to {proof.to_dict()['rel_tol']:g} relative): "
                 f"{counted}")
    side = proof.side_by_side
    if "mass" in side:
        a, b = side["mass"]["original"], side["mass"]["port"]
        lines.append(f"  mass {a['mass_kg']:.9g} kg -> {b['mass_kg']:.9g} kg")
    for rotor in side.get("rotors", []):
        lines.append(f"  rotor {rotor['rotor']}: {rotor['number_from'][0]} "
                     f"{rotor['number'][0]} -> {rotor['number_from'][1]} {rotor['number'][1]}, "
                     f"{rotor['direction'][0]} -> {rotor['direction'][1]}")
    if "trim" in side:
        a, b = side["trim"]["original"], side["trim"]["port"]
        lines.append(f"  trim: {a['message']} | port: {b['message']}")
    if "hover" in side:
        a, b = side["hover"]["original"], side["hover"]["port"]
        lines.append(f"  hover-test: original {a['status']}, port {b['status']}")
    for note in proof.notes:
        lines.append(f"  note: {note}")
    carried = [f for f in side.get("findings", {}).get("port", []) if " error:" in f]
    if carried:
        lines.append("  the port carries the original's errors (Gazebo Sim may refuse it; "
                     "fix the source and migrate again):")
        lines += [f"    {finding}" for finding in carried]
    if proof.equal:
        lines.append("EQUAL: the port reads back as the original")
    else:
        lines.append(f"DIFFERENT ({len(proof.differences)}):")
        lines += [f"  {d}" for d in proof.differences]
    return "\n".join(lines)
