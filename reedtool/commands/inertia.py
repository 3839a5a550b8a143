"""`reedtool inertia`: declared link inertia against the geometry's; whole-robot properties."""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from reedtool.commands.params import model_inputs, one_model_request, validation_options
from reedtool.errors import ReedtoolError
from reedtool.io.json_values import finite_or_none


def _vec(v, fmt: str = ".6g") -> str:
    # Sub-picometre values are round-off, not geometry: show them as 0.
    return "(" + ", ".join(format((0.0 if abs(x) < 1e-12 else float(x)) + 0.0, fmt)
                           for x in v) + ")"


def _tensor_line(I) -> str:
    from reedtool.physics.inertia import clean_tensor

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


# Model-level findings `inertia` shares with `validate`: what makes the geometry it compares
# against meaningless (a mesh Gazebo cannot load, leaving its package, in the wrong unit)
# and a robot without mass. The per-link verdicts cover I201-I204, I208 and I209.
SHARED_CODES = ("S130", "S131", "I207", "I210")


def shared_findings(verdict) -> list:
    """validate's findings of SHARED_CODES (its configuration's severities and ignores)."""
    return [f for f in verdict.findings if f.code in SHARED_CODES]


def format_text(model: Path, robot, comparisons, whole, own, findings=()) -> str:
    from reedtool.physics.inertia import clean_tensor
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
    mass_gap = abs(own.mass_kg - whole.mass_kg)
    com_gap = float(np.linalg.norm(own.com_m - whole.com_m))
    agree = mass_gap <= 1e-9 * max(1.0, whole.mass_kg) and com_gap <= 1e-9
    lines.append(f"  reedtool's own sum over links {'agrees' if agree else 'DISAGREES'}: "
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


def format_json(model: Path, robot, comparisons, whole, own, findings=()) -> str:
    from reedtool.report.json_format import envelope

    doc = {
        **envelope("reedtool.inertia/1"),
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


# ------------------------------------------------------------------ --fix

def apply_fix_urdf(model: Path, comparisons, force: bool) -> list[str]:
    from reedtool.io.urdf_edit import rewrite_inertials

    todo = [(c, c.corrected()) for c in comparisons]
    todo = [(c, props) for c, props in todo if props is not None]
    if not todo:
        return ["--fix: nothing to change"]
    for c, _props in todo:
        if c.loc.line is None or Path(c.loc.file).resolve() != model.resolve():
            raise ReedtoolError(f"cannot locate the <inertial> of link '{c.link}'", file=model)
    backup = rewrite_inertials(model, [(c.link, c.loc.line, props) for c, props in todo])
    return [f"--fix: rewrote <inertial> of {', '.join(c.link for c, _ in todo)} in {model} "
            f"(backup: {backup})"]


def apply_fix_xacro(model: Path, comparisons) -> tuple[list[str], set[str]]:
    """--fix on a xacro model: each tensor to change is edited where the user wrote it.

    The <inertial> of a link may be written in a macro body (RotorS' multirotor_base_macro,
    in a file of reedtool's or of another package) with its tensor passed in as a block
    from the user's file (`<xacro:insert_block name="body_inertia"/>`). The literal
    <inertia/> to change is the one in the user's file (the call's file, inside the
    model's own package) whose six moments are the link's declared ones: it is edited
    there, with a numbered backup, when exactly one matches and every link it feeds gets
    the same correction. Anything else is printed, with the line to change in the user's
    file, never in a file of reedtool's install.
    """
    from reedtool.io.fileio import atomic_write_text, read_xml_file
    from reedtool.io.xacro_edit import inertia_elements_matching, replace_span, users_file
    from reedtool.physics.inertia import inertia_element, inertial_xml

    edits: dict[tuple[str, int, int], tuple[object, np.ndarray, list[str]]] = {}
    printed: list[str] = []
    texts: dict[str, tuple[str, str]] = {}
    for c in comparisons:
        props = c.corrected()
        if props is None:
            continue
        file = c.loc.file
        com_moves = not np.allclose(props.com_m, c.declared.com_m, atol=1e-12)
        spans = []
        if file and users_file(file, model) and not com_moves:
            if file not in texts:
                texts[file] = read_xml_file(Path(file), what="xacro file")
            spans = inertia_elements_matching(texts[file][0], c.declared.inertia_kg_m2)
        if len(spans) == 1:
            key = (file, spans[0].start, spans[0].end)
            if key in edits and not np.allclose(edits[key][1], props.inertia_kg_m2):
                edits[key][2].append(f"!{c.link}")       # two links, two corrections
            else:
                entry = edits.setdefault(key, (spans[0], props.inertia_kg_m2, []))
                entry[2].append(c.link)
            continue
        if c.loc.macro and not users_file(c.loc.macro_file, model):
            where = (f"written by the macro called at {c.loc} (the macro is not in your "
                     "package: pass the block there)")
        elif c.loc.macro:
            # The element is written once in the macro body; the call says which link.
            where = f"in the macro body at {c.loc.macro} (the call at {c.loc})"
        else:
            where = f"at {c.loc}"
        printed.append(f"--fix: link '{c.link}': replace the <inertial> {where} with")
        printed.append(inertial_xml(props, indent="  "))
        printed.append("")

    notes, fixed = [], set()
    by_file: dict[str, list] = {}
    for (file, _s, _e), (span, tensor, links) in edits.items():
        if any(link.startswith("!") for link in links):
            names = ", ".join(link.lstrip("!") for link in links)
            notes.append(f"--fix: links {names} share the <inertia/> at {file}:{span.line} "
                         "but need different tensors: give each its own; not changed")
            continue
        by_file.setdefault(file, []).append((span, tensor, links))
    for file, changes in by_file.items():
        text, encoding = texts[file]
        for span, tensor, _links in sorted(changes, key=lambda change: -change[0].start):
            text = replace_span(text, span, inertia_element(tensor))
        # The edit reads back as meant before it replaces the user's file.
        for span, tensor, links in changes:
            if len(inertia_elements_matching(text, tensor)) < 1:
                raise ReedtoolError(f"internal check failed rewriting the inertia of "
                                    f"{', '.join(links)}; the file was left unchanged",
                                    file=file)
        backup = atomic_write_text(Path(file), text, force=True, backup=True,
                                   encoding=encoding, in_place=True)
        for span, _tensor, links in changes:
            fixed.update(links)
            notes.append(f"--fix: rewrote the <inertia/> at {file}:{span.line} "
                         f"(link {', '.join(links)}; backup: {backup})")
    return (notes + printed or ["--fix: nothing to change"]), fixed


@click.command("inertia")
@model_inputs()
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
@click.option("--fix", is_flag=True,
              help="Write the geometry's inertia into the model (with a numbered .bak "
                   "backup): a .urdf's <inertial>, or the <inertia/> in your xacro file the "
                   "link's tensor comes from (a macro's block property, e.g. body_inertia "
                   "in NAME.xacro); what cannot be placed is printed with its line.")
@click.option("--force", is_flag=True,
              help="Kept for compatibility: --fix never overwrites a backup (it picks the first "
                   "free NAME.bak, NAME.bak.1, ...).")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, fmt: str,
            fix: bool, force: bool, ignore: tuple[str, ...] = (),
            ignore_validation: bool = False) -> int:
    """Compare each link's declared inertia with its geometry's; whole-robot mass properties.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.
    Geometry is the first collision shape, else the first visual, as a uniform solid with
    the declared mass. The verdicts are validate's (one function): exit 1 exactly when
    validate reports an inertia error (I201-I203, I207-I210) or a mesh Gazebo cannot load
    or must not open (S130, S131); 0 otherwise, 2 on unreadable input. validate's other
    errors are listed too; a structure error refuses the model (exit 1) unless --ignore
    CODE or --ignore-validation is given.
    """
    model, request = one_model_request("inertia", inputs, package_paths, model_name,
                                       launch_file, ignore)
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.workflows.validation import judge, judge_links
    from reedtool.checks.preflight import require_sound_model
    from reedtool.physics.inertia import compare_links, whole_robot
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.report.validation_note import validation_text, why_line

    robot, _ = load_robot_for(model, request, require_sound=False)
    if fix and robot.source_format != "urdf":
        # The blocks --fix writes or prints are URDF <inertial>; SDF spells them differently.
        raise ReedtoolError("--fix edits URDF and xacro models only", file=model,
                            hint="run without --fix and copy the geometry values into the "
                                 "SDF <inertial> by hand")
    if not robot.links:
        raise ReedtoolError("the model has no links", file=model)
    require_sound_model(robot)
    verdict = judge(model, robot, request, "inertia")
    if verdict.refusing and not ignore_validation:
        if fmt == "text":
            click.echo(validation_text(str(model), verdict.refusing, verdict.reported, True,
                                       "computing it"), nl=False)
        else:
            from reedtool.report.json_format import envelope

            click.echo(json.dumps({**envelope("reedtool.inertia/1"), "model": str(model),
                                   "status": "refused",
                                   "message": why_line(verdict.refusing, verdict.reported,
                                                       True, "computing it"),
                                   "findings": [f.to_dict() for f in verdict.errors]},
                                  indent=2))
        return 1
    # Each verdict's severity is its rule's, as the configuration sets it for validate.
    comparisons = judge_links(model, robot, request, compare_links(robot))
    own = whole_robot(robot)
    whole = whole_robot_pinocchio(robot)

    # The shared model-level findings (any severity), then validate's other errors.
    findings = shared_findings(verdict)
    shown = {(f.code, f.subject, f.message) for f in findings}
    findings += [f for f in verdict.errors if (f.code, f.subject, f.message) not in shown]
    render = format_json if fmt == "json" else format_text
    click.echo(render(model, robot, comparisons, whole, own, findings), nl=False)
    failing = [c for c in comparisons if c.failing]
    if fix:
        is_urdf = model.suffix.lower() == ".urdf"
        if is_urdf:
            notes, fixed = apply_fix_urdf(model, comparisons, force), set()
        else:
            notes, fixed = apply_fix_xacro(model, comparisons)
        # Keep JSON on stdout parseable: fix notes go to stderr there.
        click.echo("\n".join(notes), err=(fmt == "json"))
        # What --fix rewrote no longer fails; what it could only print still does.
        failing = [c for c in failing if c.corrected() is None
                   or (not is_urdf and c.link not in fixed)]
    errors = [f for f in findings if f.severity == "error" and f.code in SHARED_CODES]
    return 1 if failing or errors else 0
