"""`reedtool inertia`: declared link inertia against the geometry's; whole-robot properties."""

from __future__ import annotations

import re
from pathlib import Path

import click
import numpy as np

from reedtool.commands.params import model_inputs, one_model_request, validation_options
from reedtool.errors import ReedtoolError


# ------------------------------------------------------------------ --fix

_INERTIAL_OPEN = re.compile(r"<inertial\b[^>]*?(/?)>")


def _inertial_span(text: str, line: int) -> tuple[int, int]:
    """Character span of the <inertial> element that starts on `line` (1-based)."""
    start_of_line = 0
    for _ in range(line - 1):
        start_of_line = text.index("\n", start_of_line) + 1
    match = _INERTIAL_OPEN.search(text, start_of_line)
    if match is None:
        raise ValueError(f"no <inertial> at line {line}")
    if match.group(1):                       # <inertial/>
        return match.start(), match.end()
    close = text.find("</inertial>", match.end())
    if close < 0:
        raise ValueError(f"unclosed <inertial> at line {line}")
    return match.start(), close + len("</inertial>")


def fix_urdf_text(text: str, fixes: list[tuple[int, object]]) -> str:
    """Replace each <inertial> starting on the given line with a block for the given props.

    Text is spliced, not re-serialised, so everything else in the file stays byte for byte.
    """
    from reedtool.physics.inertia import inertial_xml

    spans = []
    for line, props in fixes:
        start, end = _inertial_span(text, line)
        indent = text[text.rfind("\n", 0, start) + 1:start]
        block = inertial_xml(props, indent=indent if not indent.strip() else "")
        spans.append((start, end, block.lstrip()))
    for start, end, block in sorted(spans, reverse=True):
        text = text[:start] + block + text[end:]
    return text


def apply_fix_urdf(model: Path, comparisons, force: bool) -> list[str]:
    from reedtool.io.fileio import atomic_write_text, read_xml_file
    from reedtool.io.urdf import parse_urdf

    todo = [(c, c.corrected()) for c in comparisons]
    todo = [(c, props) for c, props in todo if props is not None]
    if not todo:
        return ["--fix: nothing to change"]
    text, encoding = read_xml_file(model, what="URDF file")
    fixes = []
    for c, props in todo:
        if c.loc.line is None or Path(c.loc.file).resolve() != model.resolve():
            raise ReedtoolError(f"cannot locate the <inertial> of link '{c.link}'", file=model)
        fixes.append((c.loc.line, props))
    new_text = fix_urdf_text(text, fixes)
    # Check the edit before it replaces the user's file: every fixed link reads back as meant.
    check = parse_urdf(new_text, model)
    for c, props in todo:
        read_back = check.link_map[c.link].inertial
        if (read_back is None or not np.isclose(read_back.mass_kg, props.mass_kg, rtol=1e-9)
                or not np.allclose(read_back.inertia_in_link_axes(), props.inertia_kg_m2,
                                   rtol=1e-8, atol=1e-12 * np.abs(props.inertia_kg_m2).max())):
            raise ReedtoolError(f"internal check failed rewriting link '{c.link}'; "
                                "the file was left unchanged", file=model)
    backup = atomic_write_text(model, new_text, force=True, backup=True, encoding=encoding,
                               in_place=True)
    return [f"--fix: rewrote <inertial> of {', '.join(c.link for c, _ in todo)} in {model} "
            f"(backup: {backup})"]


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
    from reedtool.report import inertia_text
    from reedtool.workflows.inertia_check import check_inertia, still_failing

    report = check_inertia(model, request, fix=fix, ignore_validation=ignore_validation)
    if report.refused:
        if fmt == "text":
            click.echo(inertia_text.refusal_text(report), nl=False)
        else:
            click.echo(inertia_text.refusal_json(report))
        return 1
    render = inertia_text.render_json if fmt == "json" else inertia_text.render_text
    click.echo(render(report), nl=False)
    if not fix:
        return report.exit_code()
    # The report is on screen before the user's file is edited (a refused edit leaves it).
    is_urdf = model.suffix.lower() == ".urdf"
    if is_urdf:
        notes, fixed = apply_fix_urdf(model, report.comparisons, force), set()
    else:
        from reedtool.workflows.inertia_fix import apply_fix_xacro

        notes, fixed = apply_fix_xacro(model, report.comparisons)
    # Keep JSON on stdout parseable: fix notes go to stderr there.
    click.echo("\n".join(notes), err=(fmt == "json"))
    return report.exit_code(still_failing(report, fixed, is_urdf))
