"""Link poses in the base frame at zero joint positions (the pose a model is spawned in)."""

from __future__ import annotations

from collections import deque

import numpy as np

from reedtool.model import Robot


def link_poses(robot: Robot) -> dict[str, np.ndarray]:
    """T_base_link for every link reachable from the root through the joint tree.

    Unreachable links (a second root, or a cycle) are absent, and so is a joint's child
    that is not a link (S105): every key is a link of `robot`. Structure checks report
    those, and everything downstream simply does not see them. A non-finite origin (S102)
    gives non-finite poses below it; callers that need numbers check them.
    """
    roots = robot.root_links()
    if not roots:
        return {}
    links = robot.link_map
    children: dict[str, list] = {}
    for joint in robot.joints:
        if joint.parent in links and joint.child in links:
            children.setdefault(joint.parent, []).append(joint)
    T_base = {roots[0]: np.eye(4)}
    queue = deque([roots[0]])
    while queue:
        parent = queue.popleft()
        for joint in children.get(parent, ()):
            if joint.child in T_base:
                continue  # a cycle or a second path: keep the first pose found
            T_base[joint.child] = T_base[parent] @ joint.T_parent_joint
            queue.append(joint.child)
    return T_base
