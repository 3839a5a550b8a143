"""`inertia`'s reports: per link the declared inertia against the geometry's and its
verdict, the whole robot's mass properties (Pinocchio, and reedtool's own sum), the shared
findings; as text and as JSON. Formats workflows.inertia_check's report; computes nothing."""

from __future__ import annotations

import json

from reedtool.io.json_values import finite_or_none

SCHEMA = "reedtool.inertia/1"


def _vec(v, fmt: str = ".6g") -> str:
    # Sub-picometre values are round-off, not geometry: show them as 0.
    return "(" + ", ".join(format((0.0 if abs(x) < 1e-12 else float(x)) + 0.0, fmt)
                           for x in v) + ")"


def _tensor_line(I) -> str:
    from reedtool.io.xml_numbers import clean_tensor

    I = clean_tensor(I)
    return (f"ixx {I[0, 0]:.4g}  iyy {I[1, 1]:.4g}  izz {I[2, 2]:.4g}  "
            f"ixy {I[0, 1]:.4g}  ixz {I[0, 2]:.4g}  iyz {I[1, 2]:.4g}")


def _props_json(props) -> dict | None:
    if props is None:
        return None
    out = {"mass_kg": props.mass_kg, "com_m": [float(x) for x in props.com_m],
           "inertia_kg_m2": [[float(x) for x in row] for row in props.inertia_kg_m2]}
    if props.volume_m3 is not None:
        out["volume_m3"] = props.volume_m3
    if props.from_hull:
        out["from_hull"] = True
    return out


def render_text(report) -> str:
    """`report`: a workflows.inertia_check.InertiaReport of a model that was computed."""
    model, robot, comparisons = report.model, report.robot, report.comparisons
    whole, own, findings = report.whole, report.own, report.findings
    from reedtool.io.xml_numbers import clean_tensor
    from reedtool.report import display_path

    lines = [f"{display_path(str(model))}: {len(robot.links)} links, base frame "
             f"'{robot.base_link}'", ""]
    for c in comparisons:
        where = display_path(c.loc.file) + (f":{c.loc.line}" if c.loc.line else "")
        lines.append(f"{c.link}  [{c.verdict}]  {where}")
        lines.append(f"  {c.message}")
        if c.declared is not None and c.derived is not None:
            lines.append(f"  mass      {c.declared.mass_kg:.6g} kg")
            lines.append(f"  COM       declared {_vec(c.declared.com_m)} m, geometry "
                         f"{_vec(c.derived.com_m)} m, offset {c.com_offset_m * 1000:.3g} mm")
            lines.append(f"  declared  {_tensor_line(c.declared.inertia_kg_m2)}")
            lines.append(f"  {c.geometry.split()[0]:<9} {_tensor_line(c.derived.inertia_kg_m2)}")
            lines.append(f"  relative difference {c.inertia_rel_diff:.3g}")
        elif c.declared is not None:
            lines.append(f"  mass      {c.declared.mass_kg:.6g} kg, COM {_vec(c.declared.com_m)} m")
            lines.append(f"  declared  {_tensor_line(c.declared.inertia_kg_m2)}")
        lines.append("")
    lines.append(f"whole robot (Pinocchio; base frame '{robot.base_link}', joints at zero):")
    lines.append(f"  total mass  {whole.mass_kg:.6g} kg")
    lines.append(f"  COM         {_vec(whole.com_m)} m")
    I = whole.inertia_kg_m2
    lines.append("  inertia about the COM, base axes [kg*m^2]:")
    for row in clean_tensor(I):
        lines.append("    [" + " ".join(f"{x:>13.6g}" for x in row) + " ]")
    lines.append(f"  reedtool's own sum over links {'agrees' if report.own_agrees else 'DISAGREES'}: "
                 f"mass {own.mass_kg:.6g} kg, COM {_vec(own.com_m)} m")
    failing = [c for c in comparisons if c.failing]
    warned = [c for c in comparisons if c.severity == "warning"]
    known = [c for c in comparisons if c.verdict == "slowdown-scaled"]
    lines.append("")
    for f in findings:
        where = display_path(f.file) + (f":{f.line}" if f.line else "") if f.file else ""
        lines.append(f"{f.severity} {f.code} {where}: {f.message} ({f.slug})")
    if findings:
        lines.append("")
    if known:
        lines.append("known exception (RotorS rotorVelocitySlowdownSim convention, not a "
                     "difference): " + ", ".join(c.link for c in known))
    if warned:
        lines.append(f"{len(warned)} link(s) to look at (warning, as in validate): "
                     + ", ".join(f"{c.link} ({c.verdict})" for c in warned))
    if failing:
        lines.append(f"{len(failing)} of {len(comparisons)} links need attention (error, as in "
                     "validate): " + ", ".join(f"{c.link} ({c.verdict})" for c in failing))
    if failing or warned:
        lines.append("pass --fix to write the geometry's inertia into the model (a .urdf, or "
                     "the <inertia/> in your xacro file it comes from)")
    if not failing and not warned:
        lines.append("no link inertia needs attention")
    return "\n".join(lines) + "\n"


def render_json(report) -> str:
    model, robot, comparisons = report.model, report.robot, report.comparisons
    whole, own, findings = report.whole, report.own, report.findings
    from reedtool.report.json_format import envelope

    doc = {
        **envelope(SCHEMA),
        "model": str(model),
        "base_link": robot.base_link,
        "links": [{
            "link": c.link, "file": c.loc.file, "line": c.loc.line, "verdict": c.verdict,
            "severity": c.severity,
            "message": c.message, "geometry": c.geometry,
            "declared": _props_json(c.declared), "derived": _props_json(c.derived),
            "inertia_rel_diff": finite_or_none(c.inertia_rel_diff),
            "trace_ratio": finite_or_none(c.trace_ratio),
            "com_offset_m": c.com_offset_m,
        } for c in comparisons],
        "whole_robot": {**_props_json(whole), "source": "pinocchio"},
        "own_sum": _props_json(own),
        "failing": sum(c.failing for c in comparisons),
        "findings": [f.to_dict() for f in findings],
    }
    return json.dumps(doc, indent=2) + "\n"


def refusal_text(report) -> str:
    """validate's errors that refuse the model, and the line saying so."""
    from reedtool.report.validation_note import validation_text

    verdict = report.verdict
    return validation_text(str(report.model), verdict.refusing, verdict.reported, True,
                           "computing it")


def refusal_json(report) -> str:
    from reedtool.report.json_format import envelope
    from reedtool.report.validation_note import why_line

    verdict = report.verdict
    return json.dumps({**envelope(SCHEMA), "model": str(report.model), "status": "refused",
                       "message": why_line(verdict.refusing, verdict.reported, True,
                                           "computing it"),
                       "findings": [f.to_dict() for f in verdict.errors]}, indent=2)
