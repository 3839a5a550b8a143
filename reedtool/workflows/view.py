"""A model path -> what `view` draws: the robot with its arguments, reedtool's link poses,
its rotors, centre of mass and (on request) the links validate's findings name, handed to
the scene builder in report/scene.py.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reedtool.workflows.robots import ModelRequest
from reedtool.errors import ReedtoolError

SEVERITY_RANK = {"error": 0, "warning": 1, "info": 2}


def link_severities(robot, findings) -> dict[str, str]:
    """link -> the worst severity of the findings that name it: the link itself, a joint
    whose child it is, or a rotor on it."""
    from reedtool.physics.rotors import discover_rotors

    names = {link.name: link.name for link in robot.links}
    names.update({j.name: j.child for j in robot.joints if j.child in robot.link_map})
    for rotor in discover_rotors(robot):
        if rotor.link in robot.link_map:
            names.setdefault(rotor.name, rotor.link)
    worst: dict[str, str] = {}
    for finding in findings:
        link = names.get(finding.subject or "")
        if link is not None and (link not in worst or
                                 SEVERITY_RANK[finding.severity] < SEVERITY_RANK[worst[link]]):
            worst[link] = finding.severity
    return worst


def com_m(robot) -> np.ndarray | None:
    """The whole robot's centre of mass in the base frame (reedtool's sum of the declared
    inertials), None without mass or on a broken tree (validate says why)."""
    from reedtool.physics.inertia import whole_robot

    try:
        props = whole_robot(robot)
    except (ValueError, KeyError, ZeroDivisionError):
        return None
    com = np.asarray(props.com_m, dtype=float)
    return com if props.mass_kg > 0 and np.all(np.isfinite(com)) else None


def view_robot(robot, *, collision: bool = False, findings=None, disc_style: str = "filled"):
    """A loaded robot as a ViewScene (report/scene.py)."""
    from reedtool.physics.kinematics import link_poses
    from reedtool.physics.rotors import discover_rotors
    from reedtool.report.scene import build_scene

    if not robot.links:
        raise ReedtoolError("the model has no links: nothing to show", file=robot.source_file,
                            hint="pass the top-level model, not a file of macros it includes")
    if not robot.root_links():
        raise ReedtoolError("no root link: every link is some joint's child, so nothing "
                            "says where the robot is", file=robot.source_file,
                            hint="run `reedtool validate` on the model; it names the loop")
    T_base_link = link_poses(robot)
    unplaced = sorted(name for name, T in T_base_link.items() if not np.all(np.isfinite(T)))
    if unplaced:
        # a NaN joint origin leaves its child (and everything below it) nowhere to draw
        shown = ", ".join(f"'{name}'" for name in unplaced[:3])
        more = f" and {len(unplaced) - 3} more" if len(unplaced) > 3 else ""
        raise ReedtoolError(f"cannot place link {shown}{more}: a joint origin on its way "
                            "from the root is not a finite number", file=robot.source_file,
                            hint="run `reedtool validate` on the model; it names the number "
                                 "and its line")
    return build_scene(robot, T_base_link, discover_rotors(robot), com_m=com_m(robot),
                       collision=collision, disc_style=disc_style,
                       link_severity=link_severities(robot, findings) if findings else None)


def withhold_outside_meshes(robot, model: Path) -> list[str]:
    """Leave out of the picture every mesh file outside the model's packages (an absolute
    file:// URI, a path climbing out with ..): the page or GLB would carry a copy of it.
    Returns the URIs withheld; each is drawn as not shown, with the reason in the notes."""
    from reedtool.resolve.references import outside_reason
    from reedtool.model import Mesh

    default_root = Path(model) if Path(model).is_dir() else Path(model).parent
    withheld = []
    for link in robot.links:
        for shape in [*link.visuals, *link.collisions]:
            mesh = shape.geometry
            if not isinstance(mesh, Mesh):
                continue
            reason = outside_reason(mesh.uri, mesh.path, shape.loc.file, default_root)
            if reason is not None:
                mesh.path = None
                mesh.resolve_error = f"{reason}: not embedded; pass --embed-outside-files"
                withheld.append(mesh.uri)
    return withheld


def view_model(model: Path, request: ModelRequest, *, collision: bool = False,
               with_findings: bool = False, disc_style: str = "filled",
               embed_outside_files: bool = False):
    """`model` with its arguments (configuration, --launch, name:=value) -> (ViewScene,
    validate's findings on it, or None without `with_findings`). A mesh file from outside
    the model's packages is not drawn (so not embedded) unless `embed_outside_files`."""
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.workflows.validation import validation_findings

    robot, _ = load_robot_for(model, request, require_sound=False)
    findings = validation_findings(model, robot, request) if with_findings else None
    if not embed_outside_files:
        withhold_outside_meshes(robot, model)
    return view_robot(robot, collision=collision, findings=findings,
                      disc_style=disc_style), findings
