"""A robot (and validate's findings on it) -> its rotor layout picture, written to a file:
the rotors, the COM and the rotors the findings name, handed to the drawing in
report/layout_picture.py.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.report.layout_picture import output_format, render_layout


def write_layout(robot, path: Path, force: bool, marked_names: set[str] = frozenset()) -> None:
    """Render the layout of `robot` to `path` (format by extension), atomically."""
    from reedtool.io.fileio import atomic_write_bytes
    from reedtool.physics.rotors import discover_rotors

    fmt = output_format(path)
    rotors = discover_rotors(robot)
    if not rotors:
        raise ReedtoolError("no rotors found, nothing to draw", file=robot.source_file,
                            hint="a multirotor needs motor plugins (RotorS "
                                 "gazebo_motor_model, PX4 or gz MulticopterMotorModel)")
    com = _com(robot)
    atomic_write_bytes(path, render_layout(robot, rotors, com, fmt,
                                           marked_names=marked_names), force=force)


def write_diagram(robot, path: Path, findings, force: bool) -> None:
    """`validate --diagram`: the layout with the rotors the findings name marked red.

    A finding names a rotor when its subject is the rotor's name, link or joint, or its
    message quotes one of them.
    """
    from reedtool.physics.rotors import discover_rotors

    output_format(path)
    if path.exists() and not force:
        raise ReedtoolError("refusing to overwrite an existing file", file=path,
                            hint="pass --force to replace it")
    marked = set()
    for rotor in discover_rotors(robot):
        names = {n for n in (rotor.name, rotor.link, rotor.joint) if n}
        for f in findings:
            if (f.subject in names
                    or any(f"'{n}'" in f.message or f'"{n}"' in f.message for n in names)):
                marked.add(rotor.name)
    write_layout(robot, path, force, marked)


def _com(robot):
    try:
        from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

        com = whole_robot_pinocchio(robot).com_m
        return com if np.all(np.isfinite(com)) else None
    except ReedtoolError:
        return None


def draw_layout(model: Path, request, output: Path, force: bool, *,
                ignore_validation: bool = False, on_validation=None) -> bool:
    """`layout` as one call: the model loaded and judged by validate's refusal policy,
    `on_validation(verdict, refused)` told (for the caller to show the errors), then, unless
    refused, the picture written with the rotors the errors name in red. True when drawn."""
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.workflows.validation import judge

    robot, _ = load_robot_for(model, request)
    verdict = judge(model, robot, request, "layout")
    refused = bool(verdict.refusing) and not ignore_validation
    if on_validation is not None:
        on_validation(verdict, refused)
    if refused:
        return False
    write_diagram(robot, output, verdict.errors, force)
    return True
