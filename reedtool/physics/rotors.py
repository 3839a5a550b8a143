"""Rotor discovery: one Rotor type from RotorS, PX4 gazebo-classic and gz-sim motor plugins.

All three plugins use the same element names (jointName, linkName, turningDirection,
motorConstant, ...). Thrust acts along the rotor link's z axis in every one of them, so
that axis, expressed in the base frame, is the rotor's thrust axis here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reedtool.model import Plugin, Robot, SourceLoc
from reedtool.physics.kinematics import link_poses

# Plugin library (see Plugin.library) -> rotor kind.
MOTOR_PLUGINS = {
    "rotors_gazebo_motor_model": "rotors",
    "gazebo_motor_model": "px4",
    "gz-sim-multicopter-motor-model-system": "gz",
    "ignition-gazebo-multicopter-motor-model-system": "gz",
}
MOTOR_PLUGIN_NAMES = {"gz::sim::systems::MulticopterMotorModel": "gz",
                      "ignition::gazebo::systems::MulticopterMotorModel": "gz"}

MAVLINK_PLUGINS = {"rotors_gazebo_mavlink_interface", "gazebo_mavlink_interface"}

TURNING_SIGN = {"ccw": 1, "cw": -1}


@dataclass
class Rotor:
    name: str
    joint: str | None
    link: str | None
    position_m: np.ndarray          # rotor link origin in the base frame (NaN if the link is unknown)
    axis: np.ndarray                # unit thrust axis in the base frame (the rotor link's z axis)
    direction: str                  # as written: 'ccw', 'cw', or anything else (a finding)
    turning_sign: int               # +1 ccw, -1 cw, 0 unknown
    motor_number: int | None
    motor_constant: float           # thrust = motor_constant * omega^2 [N/(rad/s)^2]
    moment_constant: float          # yaw drag torque = moment_constant * thrust [m]
    max_rot_velocity_rad_s: float
    time_constant_up_s: float
    time_constant_down_s: float
    rotor_drag_coefficient: float
    rolling_moment_coefficient: float
    kind: str                       # 'rotors' | 'px4' | 'gz'
    plugin: Plugin
    loc: SourceLoc

    @property
    def max_thrust_N(self) -> float:
        return self.motor_constant * self.max_rot_velocity_rad_s ** 2


@dataclass
class RotorCountDeclaration:
    """A rotor count an autopilot interface plugin (MAVLink/PX4) declares."""

    rotor_count: int | None         # None: written, but not a whole number (see `text`)
    plugin: Plugin
    loc: SourceLoc
    text: str = ""                  # as written


def motor_plugin_kind(plugin: Plugin) -> str | None:
    return MOTOR_PLUGINS.get(plugin.library) or MOTOR_PLUGIN_NAMES.get(plugin.name or "")


def _number(plugin: Plugin, tag: str) -> float:
    text = plugin.param(tag)
    try:
        return float(text) if text is not None else math.nan
    except ValueError:
        return math.nan


def discover_rotors(robot: Robot) -> list[Rotor]:
    """Every motor-model plugin in the model, as a Rotor in the base frame."""
    poses = link_poses(robot)
    rotors = []
    for _block, plugin in robot.plugins():
        kind = motor_plugin_kind(plugin)
        if kind is None:
            continue
        link = plugin.param("linkName")
        joint = plugin.param("jointName")
        if link is None and joint in robot.joint_map:
            link = robot.joint_map[joint].child
        T_base_link = poses.get(link or "")
        if T_base_link is None:
            position, axis = np.full(3, math.nan), np.full(3, math.nan)
        else:
            position, axis = T_base_link[:3, 3].copy(), T_base_link[:3, 2].copy()
        direction = (plugin.param("turningDirection") or "").strip()
        motor_number_text = plugin.param("motorNumber")
        try:
            motor_number = int(motor_number_text) if motor_number_text is not None else None
        except ValueError:
            motor_number = None
        rotors.append(Rotor(
            name=link or joint or plugin.name or f"rotor{len(rotors)}",
            joint=joint, link=link, position_m=position, axis=axis,
            direction=direction, turning_sign=TURNING_SIGN.get(direction.lower(), 0),
            motor_number=motor_number,
            motor_constant=_number(plugin, "motorConstant"),
            moment_constant=_number(plugin, "momentConstant"),
            max_rot_velocity_rad_s=_number(plugin, "maxRotVelocity"),
            time_constant_up_s=_number(plugin, "timeConstantUp"),
            time_constant_down_s=_number(plugin, "timeConstantDown"),
            rotor_drag_coefficient=_number(plugin, "rotorDragCoefficient"),
            rolling_moment_coefficient=_number(plugin, "rollingMomentCoefficient"),
            kind=kind, plugin=plugin, loc=plugin.loc))
    return rotors


def declared_rotor_counts(robot: Robot) -> list[RotorCountDeclaration]:
    """Rotor counts declared by MAVLink/PX4 interface plugins.

    Read from an explicit <rotorCount>/<rotor_count> element, else from the number of
    rotor channels in <control_channels> (PX4's mavlink interface names them rotorN).
    """
    out = []
    for _block, plugin in robot.plugins():
        if plugin.library not in MAVLINK_PLUGINS:
            continue
        for tag in ("rotorCount", "rotor_count"):
            node = plugin.node.find(tag)
            if node is not None:
                text = (node.text or "").strip()
                count = int(text) if text.isdigit() else None
                out.append(RotorCountDeclaration(count, plugin, node.loc, text))
                break
        else:
            channels = plugin.node.find("control_channels")
            if channels is not None:
                rotor_channels = [c for c in channels.findall("channel")
                                  if c.attrib.get("name", "").lower().startswith("rotor")]
                if rotor_channels:
                    out.append(RotorCountDeclaration(len(rotor_channels), plugin, channels.loc))
    return out
