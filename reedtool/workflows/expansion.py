"""`expand` as one call: a xacro model (its arguments from the configuration, --launch and
the command line) expanded into URDF without ROS, after its legacy tags are rewritten on
request; refused, naming the tags, when legacy tags remain; written to the output file
(none of the model's own files) or returned for standard output. Each line meant for
standard error goes to the caller's `note` as it happens, so nothing here prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from reedtool.errors import ReedtoolError
from reedtool.workflows.robots import ModelRequest


def refuse_non_xacro(model: Path) -> None:
    """A mesh or an SDF file named as the model: say what it is rather than "malformed XML"
    or an SDF echoed back under a header telling the user to edit .xacro sources."""
    from reedtool.io.loader import SDF_SUFFIXES, refuse_mesh

    refuse_mesh(model)
    if model.is_dir() or model.suffix.lower() in SDF_SUFFIXES:
        what = "a Gazebo model directory (SDF)" if model.is_dir() else "SDF"
        raise ReedtoolError(f"is {what}: expand turns xacro into URDF, and SDF needs no "
                            "expansion", file=model,
                            hint=f"`reedtool validate {model.name}` checks it as Gazebo reads it")


def fix_legacy(model: Path, mappings: dict[str, str], package_paths: list[Path],
               note: Callable[[str], None]) -> None:
    """Rewrite the legacy tags of the model's own files (reedtool's never), a backup each."""
    from reedtool.io.fileio import atomic_write_text
    from reedtool.io.xacro_expand import display_path, scan_legacy
    from reedtool.resolve.packages import is_bundled

    scan = scan_legacy(model, mappings, package_paths)
    for path, text in scan.fixed_text.items():
        if is_bundled(path):
            continue  # reedtool's own files are never rewritten
        count = sum(1 for tag in scan.tags if tag.file == display_path(path))
        backup = atomic_write_text(path, text, force=True, backup=True, in_place=True)
        note(f"reedtool: rewrote {count} legacy xacro tag(s) in {display_path(path)} "
             f"(backup: {display_path(backup) if backup else 'none'})")


def expand_model(model: Path, request: ModelRequest, output: Path | None, *,
                 force: bool = False, legacy_fix: bool = False,
                 note: Callable[[str], None] = lambda line: None) -> str | None:
    """The URDF of `model`, written to `output` (then None is returned) or returned for
    standard output (`output` None)."""
    from reedtool.io.fileio import atomic_write_text, check_writable, note_input
    from reedtool.io.xacro_expand import expand_xacro
    from reedtool.workflows.robots import model_mappings

    refuse_non_xacro(model)
    mappings = model_mappings(model, request)
    package_paths = list(request.package_paths)
    note_input(model)
    if output is not None:
        check_writable(output, force)   # fail before the work, not after
    if legacy_fix:
        fix_legacy(model, mappings, package_paths, note)
    expansion = expand_xacro(model, mappings, package_paths)
    if expansion.legacy:
        for tag in expansion.legacy:
            note(f"reedtool: {tag}")
        raise ReedtoolError(
            f"{len(expansion.legacy)} legacy xacro tag(s): xacro 2.x and ROS copy them into "
            "the URDF unexpanded, so the model is broken as written", file=model,
            hint=f"rewrite them with 'reedtool expand --fix-legacy {model}'; "
                 "each file keeps a .bak backup")
    for warning in expansion.warnings:
        note(f"reedtool: warning: {warning}")
    if output is None:
        return expansion.urdf_xml
    for source in expansion.files:
        note_input(source)   # every xacro the model pulled in is off limits as output
    atomic_write_text(output, expansion.urdf_xml, force=force)
    note(f"reedtool: wrote {output}")
    return None
