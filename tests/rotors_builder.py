"""One writer of RotorS-style multirotor URDF (or xacro) text for the tests.

A base link, n rotor links on continuous joints around it, and one motor plugin per rotor.
The defaults are RotorS' firefly (rotors_simulator, rotors_description/urdf/firefly.xacro;
hummingbird.xacro has the same motor block): six rotors on a 0.215 m arm, 0.037 m above
the base, the first at 30 degrees, spins alternating from ccw, 1.5 kg body, 5 g rotors.
A test passes only what its model changes, so the numbers it asserts stay next to it.

The text is written, never read back here: what the tests assert about it comes from the
numbers they pass (hand derivations, published figures), not from this module.
"""

from __future__ import annotations

import math

# firefly.xacro's motor block, by the plugin's element names (librotors_gazebo_motor_model).
ROTORS_MOTOR = {
    "timeConstantUp": 0.0125,              # [s]
    "timeConstantDown": 0.025,             # [s]
    "maxRotVelocity": 838,                 # [rad/s]
    "motorConstant": 8.54858e-06,          # [kg m/s^2] thrust = k omega^2
    "momentConstant": 0.016,               # [m] drag torque = k_m thrust
    "rotorDragCoefficient": 8.06428e-05,
    "rollingMomentCoefficient": 1e-06,
    "rotorVelocitySlowdownSim": 10,
}
# firefly.xacro's body_inertia [kg m^2].
FIREFLY_BODY_INERTIA = (0.0347563, 0.0458929, 0.0977)
# firefly.xacro's rotor_inertia: box_inertia(x=radius 0.1, y=0.015, z=0.003) of
# mass_rotor * rotor_velocity_slowdown_sim = 0.05 kg, i.e. m/12 (y^2+z^2), (x^2+z^2), (x^2+y^2).
FIREFLY_ROTOR_INERTIA = tuple(0.05 / 12 * (a * a + b * b)
                              for a, b in ((0.015, 0.003), (0.1, 0.003), (0.1, 0.015)))

PLUGINS = {
    "rotors": ('filename="librotors_gazebo_motor_model.so" name="{name}"', "motorNumber"),
    "gz": ('filename="gz-sim-multicopter-motor-model-system" '
           'name="gz::sim::systems::MulticopterMotorModel"', "actuator_number"),
}
XACRO_NS = ' xmlns:xacro="http://www.ros.org/wiki/xacro"'


def _inertial(kg, diag) -> str:
    ixx, iyy, izz = diag
    return (f'<inertial><mass value="{kg}"/><inertia ixx="{ixx}" ixy="0" ixz="0" '
            f'iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>')


def _num(value, digits: int | None) -> str:
    return f"{value}" if digits is None else f"{value:.{digits}f}"


def multirotor_urdf(n: int = 6, *, name: str = "firefly", arm_m: float = 0.215,
                    height_m: float = 0.037, angles_rad=None, spins=None, positions=None,
                    digits: int | None = None, body_kg=1.5, body_inertia=FIREFLY_BODY_INERTIA,
                    body_xml: str = "", rotor_kg=0.005, rotor_inertia=FIREFLY_ROTOR_INERTIA,
                    rotor_xml: str = "", plugin: str = "rotors", plugin_name: str = "motor_{i}",
                    motor_defaults: dict | None = None, motor: dict | None = None,
                    numbered: bool = True, per_rotor: dict | None = None,
                    imu_kg: float | None = None, imu_origin: str = 'xyz="0 0 0"',
                    extra: str = "", xacro: bool = False) -> str:
    """URDF text of an n-rotor RotorS-style multirotor.

    arm_m, angles_rad (default (i + 0.5) 2 pi / n) and height_m place rotor i at
    (arm cos a, arm sin a, height); positions (a list of (x, y, z)) replaces them. digits
    rounds the written x, y, z (None: Python's shortest repr). spins defaults to ccw, cw, ...
    motor overrides entries of motor_defaults (default ROTORS_MOTOR); None as a value drops
    the element. per_rotor {i: {...}} overrides for rotor i: "arm_m", "spin", or plugin
    elements. body_xml / rotor_xml go inside the base / every rotor link (collision, visual),
    imu_kg adds RotorS' imu_link (1e-5 kg m^2) on a fixed joint at imu_origin, extra goes
    before </robot>. body_kg may be text such as "$(arg body_kg)" with xacro=True.
    """
    per_rotor = per_rotor or {}
    constants = dict(ROTORS_MOTOR if motor_defaults is None else motor_defaults)
    constants.update(motor or {})
    opening, number_tag = PLUGINS[plugin]
    head = '<?xml version="1.0"?>\n' + f'<robot name="{name}"{XACRO_NS if xacro else ""}>'
    parts = [head, f'<link name="base_link">{body_xml}{_inertial(body_kg, body_inertia)}</link>']
    if imu_kg is not None:
        parts.append(f'<link name="imu_link">{_inertial(imu_kg, (1e-5,) * 3)}</link>'
                     f'<joint name="imu_joint" type="fixed"><origin {imu_origin}/>'
                     '<parent link="base_link"/><child link="imu_link"/></joint>')
    for i in range(n):
        own = per_rotor.get(i, {})
        if positions is not None:
            x, y, z = positions[i]
        else:
            angle = angles_rad[i] if angles_rad is not None else 2 * math.pi * (i + 0.5) / n
            arm = own.get("arm_m", arm_m)
            x, y, z = arm * math.cos(angle), arm * math.sin(angle), height_m
        spin = own.get("spin", spins[i] if spins is not None else ("ccw", "cw")[i % 2])
        elements = {**constants, **{k: v for k, v in own.items() if k not in ("arm_m", "spin")}}
        if numbered:
            elements[number_tag] = i
        body = "".join(f"<{tag}>{value}</{tag}>" for tag, value in elements.items()
                       if value is not None)
        parts.append(
            f'<link name="rotor_{i}">{rotor_xml}{_inertial(rotor_kg, rotor_inertia)}</link>'
            f'<joint name="rotor_{i}_joint" type="continuous"><origin xyz="{_num(x, digits)} '
            f'{_num(y, digits)} {_num(z, digits)}"/><axis xyz="0 0 1"/>'
            f'<parent link="base_link"/><child link="rotor_{i}"/></joint>'
            f'<gazebo><plugin {opening.format(name=plugin_name.format(i=i))}>'
            f'<jointName>rotor_{i}_joint</jointName><linkName>rotor_{i}</linkName>'
            f'<turningDirection>{spin}</turningDirection>{body}</plugin></gazebo>')
    parts.append(f"{extra}</robot>")
    return "\n".join(parts) + "\n"
