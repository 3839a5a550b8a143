"""The model's moving joints against the rigid-body flight: passive joints flown locked
(which, and what that adds), and rotors that tilt on driven joints (a tilt-rotor frame).

The hover simulation is one rigid body. A model may have joints that move in Gazebo but
that no plugin drives: a pendulum, an unactuated gimbal, a manipulator's arms. They are
flown locked at their zero position (the pose Pinocchio's mass properties use), and the
report says so: each locked joint, the mass beyond it, and the inertia that mass adds
about the whole vehicle's COM (what a free joint would not pass to the body in the same
way). Rotor joints are the motors' own and are not "locked".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LockedJoint:
    name: str
    type: str
    links: tuple[str, ...]          # the links beyond it (its subtree)
    mass_kg: float
    inertia_about_com_kg_m2: np.ndarray   # (3, 3) of those links about the vehicle's COM

    def to_dict(self) -> dict:
        return {"joint": self.name, "type": self.type, "links": list(self.links),
                "mass_kg": self.mass_kg,
                "inertia_about_com_kg_m2": [[float(v) for v in row]
                                            for row in self.inertia_about_com_kg_m2]}


def locked_joints(robot, rotors, com_m) -> list[LockedJoint]:
    """Non-fixed joints that are neither a rotor's nor named by any plugin, outermost
    first (a joint inside a locked subtree is listed under it, not again)."""
    from reedtool.physics.inertia import combine, declared_mass_properties
    from reedtool.physics.kinematics import link_poses

    rotor_joints = {r.joint for r in rotors if r.joint}
    named = _plugin_names(robot)
    children: dict[str, list] = {}
    for joint in robot.joints:
        children.setdefault(joint.parent, []).append(joint)
    poses = link_poses(robot)
    out: list[LockedJoint] = []
    inside: set[str] = set()
    for joint in robot.joints:
        if (not joint.moves or joint.name in rotor_joints or joint.name in named
                or joint.child is None or joint.parent in inside):
            continue
        subtree = _subtree(joint.child, children)
        if any(r.link in subtree for r in rotors):
            continue            # a tilt-rotor's or gimbal's rotor: not a passive payload
        inside.update(subtree)
        parts = []
        for name in subtree:
            link = robot.link_map.get(name)
            props = declared_mass_properties(link) if link is not None else None
            if props is not None and name in poses:
                parts.append(props.transformed(poses[name]))
        if parts:
            total = combine(parts)
            mass, inertia = total.mass_kg, total.inertia_about(com_m)
        else:
            mass, inertia = 0.0, np.zeros((3, 3))
        out.append(LockedJoint(joint.name, joint.type, tuple(subtree), float(mass), inertia))
    return out


def _subtree(link: str, children: dict) -> list[str]:
    out, stack = [], [link]
    while stack:
        name = stack.pop()
        if name in out:
            continue
        out.append(name)
        stack.extend(j.child for j in children.get(name, ()) if j.child)
    return out


def _plugin_names(robot) -> set[str]:
    """Every text and attribute value inside any plugin: a joint a plugin drives is named
    there (jointName, joint_name, <joint> ...), with or without a namespace prefix."""
    names: set[str] = set()
    for _, plugin in robot.plugins():
        for node in plugin.node.iter():
            for value in [node.text, *node.attrib.values()]:
                if value:
                    value = value.strip()
                    names.add(value)
                    names.add(value.rsplit("::", 1)[-1])
                    names.add(value.rsplit("/", 1)[-1])
    return names


def describe(locked: list[LockedJoint], total_inertia_kg_m2) -> str:
    """One line per locked joint, for the text report."""
    J = np.diag(np.asarray(total_inertia_kg_m2, dtype=float))
    lines = []
    for lj in locked:
        d = np.diag(lj.inertia_about_com_kg_m2)
        share = ", ".join(f"{axis} {v:.3g} kg*m^2 ({100 * v / t:.0f}%)" if t > 0 else
                          f"{axis} {v:.3g} kg*m^2" for axis, v, t in zip("xyz", d, J))
        lines.append(f"{lj.name} ({lj.type}, {lj.mass_kg:.3g} kg beyond it): {share}")
    return "\n".join(lines)


def tilting_joints(robot, rotors) -> list[tuple[str, str]]:
    """(rotor, joint) for each rotor whose link rides on a moving joint that a plugin
    drives (a tilt servo), other than its own spinning joint: a tilt-rotor frame, whose
    attitude control uses the tilt that the fixed-axis trim and controller do not model."""
    parent_joint = {j.child: j for j in robot.joints if j.child}
    rotor_joints = {r.joint for r in rotors if r.joint}
    named = _plugin_names(robot)
    out = []
    for rotor in rotors:
        link, seen = rotor.link, set()
        while link in parent_joint and link not in seen:
            seen.add(link)
            joint = parent_joint[link]
            if joint.moves and joint.name not in rotor_joints and joint.name in named:
                out.append((rotor.name, joint.name))
                break
            link = joint.parent
    return out
