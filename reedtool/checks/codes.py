"""The code table: every rule code reedtool has ever given out, with its rule's name (slug),
the flight stack whose contract it holds the model to, and its lifecycle.

This is the catalogue's own list (as ruff keeps one): the registry takes a rule's stack from
here, tests/test_code_table.py holds the registry equal to it, and a code in RETIRED is never
registered again ("codes are never reused").

- stack: "core" (any model), "px4" (PX4's airframe/parameter contract), "ardupilot"
  (ArduPilot's frame classes, parameters and plugin), "rotors-lee" (RotorS'
  lee_position_controller_node). `validate` picks the controller cross-check rules of the
  flight stack a --airframe / --autopilot-params file belongs to by this field.
- lifecycle: "stable" (released; behaviour changes only as a bug fix) or "preview" (new,
  may still change). A code removed from the registry moves to RETIRED with the reason.

EXAMPLES gives a bad and a good model for every stable rule but those of NO_EXAMPLE (each with
why no standalone example can show it), each a whole URDF or SDF 1.9 file (example_format tells
which), or a Case: the model with the other files `reedtool validate` is given beside it (a
controller YAML, a PX4 airframe, an ArduPilot .parm, a mesh) and the command line that gives
them. docs/rules.md shows them and tests/test_code_table.py runs each: the bad one must give
its code, the good one must not and must load in libsdformat, and a bad SDF one of a
"refused" rule must be refused by it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

STACKS = ("core", "px4", "ardupilot", "rotors-lee")
LIFECYCLES = ("stable", "preview")

# code -> (slug, stack, lifecycle)
CODES: dict[str, tuple[str, str, str]] = {
    "S101": ("urdf-parse-error", "core", "stable"),
    "S102": ("non-finite-number", "core", "stable"),
    "S103": ("legacy-xacro-tag", "core", "stable"),
    "S104": ("single-root", "core", "stable"),
    "S105": ("joint-link-missing", "core", "stable"),
    "S106": ("duplicate-link-name", "core", "stable"),
    "S107": ("duplicate-joint-name", "core", "stable"),
    "S108": ("link-multiple-parents", "core", "stable"),
    "S109": ("kinematic-cycle", "core", "stable"),
    "S110": ("joint-type-invalid", "core", "stable"),
    "S111": ("joint-limit-missing", "core", "stable"),
    "S112": ("joint-limit-inverted", "core", "stable"),
    "S113": ("joint-axis-zero", "core", "stable"),
    "S114": ("gazebo-reference-missing", "core", "stable"),
    "S115": ("mesh-unresolved", "core", "stable"),
    "S116": ("geometry-size-invalid", "core", "stable"),
    "S117": ("link-dropped-by-sdf", "core", "stable"),
    "S118": ("plugin-link-merged", "core", "stable"),
    "S119": ("xml-tolerated", "core", "stable"),
    "S120": ("sdf-link-default-inertial", "core", "stable"),
    "S121": ("visual-mesh-mirrored", "core", "stable"),
    "S122": ("collision-mesh-mirrored", "core", "stable"),
    "S123": ("sdf-element-not-in-version", "core", "stable"),
    "S124": ("xml-declaration-late", "core", "stable"),
    "S125": ("sdf-pose-short", "core", "stable"),
    "S130": ("mesh-format-unsupported", "core", "stable"),
    "S131": ("mesh-uri-escapes", "core", "stable"),
    "S140": ("xacro-argument-unknown", "core", "stable"),
    "S141": ("xacro-argument-unused", "core", "stable"),
    "S142": ("suppression-code-unknown", "core", "stable"),
    "S143": ("suppression-unused", "core", "stable"),
    "S150": ("package-name-ambiguous", "core", "stable"),
    "S160": ("sdf-name-double-colon", "core", "stable"),
    "S161": ("sdf-name-collision", "core", "stable"),
    "S162": ("sdf-name-reserved", "core", "stable"),
    "S163": ("sdf-canonical-link-missing", "core", "stable"),
    "S164": ("sdf-frame-attached-to-invalid", "core", "stable"),
    "S165": ("sdf-pose-relative-to-invalid", "core", "stable"),
    "S166": ("sdf-joint-frames-invalid", "core", "stable"),
    "S167": ("sdf-model-without-link", "core", "stable"),
    "S168": ("sdf-version-missing", "core", "stable"),
    "S169": ("file-uri-absolute", "core", "stable"),
    "S170": ("sdf-material-script-uri", "core", "stable"),
    "S171": ("sdf-root-several-models", "core", "stable"),
    "S190": ("remote-resource-not-checked", "core", "stable"),
    "S191": ("sdf-classic-scoped-name", "core", "stable"),
    "I201": ("mass-not-positive", "core", "stable"),
    "I202": ("inertia-not-positive-definite", "core", "stable"),
    "I203": ("inertia-triangle-inequality", "core", "stable"),
    "I204": ("inertia-implausible-for-geometry", "core", "stable"),
    "I205": ("com-outside-geometry", "core", "stable"),
    "I206": ("mesh-scale-implausible", "core", "stable"),
    "I207": ("robot-mass-not-positive", "core", "stable"),
    "I208": ("massless-link-with-inertia", "core", "stable"),
    "I209": ("inertia-orders-off-geometry", "core", "stable"),
    "I210": ("mesh-unit-wrong", "core", "stable"),
    "I220": ("mass-implausible-for-size", "core", "stable"),
    "I221": ("link-denser-than-matter", "core", "stable"),
    "R301": ("motor-number-duplicate", "core", "stable"),
    "R302": ("motor-numbers-not-contiguous", "core", "stable"),
    "R303": ("rotor-direction-invalid", "core", "stable"),
    "R304": ("yaw-moment-imbalance", "core", "stable"),
    "R305": ("allocation-rank-deficient", "core", "stable"),
    "R306": ("allocation-ill-conditioned", "core", "stable"),
    "R307": ("trim-infeasible", "core", "stable"),
    "R308": ("thrust-to-weight-below-one", "core", "stable"),
    "R309": ("thrust-to-weight-low", "core", "stable"),
    "R310": ("hover-throttle-high", "core", "stable"),
    "R311": ("rotor-axis-tilted", "core", "stable"),
    "R312": ("rotor-count-mismatch", "core", "stable"),
    "R313": ("rotor-joint-not-continuous", "core", "stable"),
    "R314": ("rotor-plugin-target-missing", "core", "stable"),
    "R315": ("rotor-link-not-joint-child", "core", "stable"),
    "R316": ("rotor-constant-invalid", "core", "stable"),
    "R317": ("rotor-constants-estimated", "core", "stable"),
    "R318": ("ardupilot-spin-against-blades", "ardupilot", "stable"),
    "R319": ("rotor-role", "core", "stable"),
    "R320": ("rotor-tilt-pattern", "core", "stable"),
    "R340": ("thrust-to-weight-high", "core", "stable"),
    "R341": ("rotor-joint-axis-not-thrust-axis", "core", "stable"),
    "R342": ("uneven-hover-trim", "core", "stable"),
    "R343": ("size-implausible-for-mass", "core", "stable"),
    "R350": ("spin-order-not-fault-tolerant", "core", "stable"),
    "C401": ("controller-rotor-count", "core", "stable"),
    "C402": ("controller-rotor-joint-unknown", "core", "stable"),
    "C403": ("controller-rotor-order", "core", "stable"),
    "C404": ("controller-direction-mismatch", "core", "stable"),
    "C405": ("controller-angle-mismatch", "core", "stable"),
    "C406": ("controller-arm-length-mismatch", "core", "stable"),
    "C407": ("controller-force-constant-mismatch", "core", "stable"),
    "C408": ("controller-moment-constant-mismatch", "core", "stable"),
    "C409": ("controller-mass-mismatch", "core", "stable"),
    "C410": ("controller-inertia-mismatch", "core", "stable"),
    "C411": ("controller-entry-invalid", "core", "stable"),
    "C412": ("controller-com-link-missing", "core", "stable"),
    "C413": ("px4-rotor-count", "px4", "stable"),
    "C414": ("px4-output-mapping", "px4", "stable"),
    "C415": ("px4-rotor-position", "px4", "stable"),
    "C416": ("px4-rotor-spin", "px4", "stable"),
    "C417": ("px4-moment-ratio", "px4", "stable"),
    "C418": ("px4-thrust-axis", "px4", "stable"),
    "C419": ("px4-command-above-max", "px4", "stable"),
    "C420": ("px4-idle-command", "px4", "stable"),
    "C421": ("px4-hover-throttle", "px4", "stable"),
    "C422": ("px4-hover-throttle-mismatch", "px4", "stable"),
    "C423": ("px4-rotor-position-offset", "px4", "stable"),
    "C424": ("px4-command-below-max", "px4", "stable"),
    "C425": ("px4-param-out-of-range", "px4", "stable"),
    "C426": ("px4-thrust-axis-offset", "px4", "stable"),
    "C427": ("px4-thrust-axis-fixed", "px4", "stable"),
    "C430": ("ardupilot-frame-unknown", "ardupilot", "stable"),
    "C431": ("ardupilot-motor-count", "ardupilot", "stable"),
    "C432": ("ardupilot-motor-position", "ardupilot", "stable"),
    "C433": ("ardupilot-motor-spin", "ardupilot", "stable"),
    "C434": ("ardupilot-motor-unassigned", "ardupilot", "stable"),
    "C435": ("px4-simulator-mismatch", "px4", "stable"),
    "C436": ("px4-classic-command-above-max", "px4", "stable"),
    "C437": ("px4-classic-command-below-max", "px4", "stable"),
    "C438": ("px4-classic-idle-command", "px4", "stable"),
    "C439": ("px4-gz-bridge-unreachable", "px4", "stable"),
    "C450": ("lee-gain-not-positive", "rotors-lee", "stable"),
    "C451": ("lee-loop-unstable", "rotors-lee", "stable"),
    "C452": ("lee-mass-unit-slip", "rotors-lee", "stable"),
    "C453": ("lee-inertia-unit-slip", "rotors-lee", "stable"),
    "C454": ("lee-loop-underdamped", "rotors-lee", "stable"),
}

# code -> (slug it had, why it is not in the registry). Never registered again.
RETIRED: dict[str, tuple[str, str]] = {
    "S192": ("sdf-joint-named-like-link",
             "added on a development branch (a joint named like a link, refused by gz-sim's "
             "libsdformat) and dropped before any release; reserved, never reused"),
}

# A two-link arm, written out in each example so that every snippet is a whole model.
_BASE_INERTIAL = ('<inertial><mass value="2"/><inertia ixx="0.0083" ixy="0" ixz="0" '
                  'iyy="0.0083" iyz="0" izz="0.0133"/></inertial>')
_BASE = ('  <link name="base_link">\n'
         '    {inertial}\n'
         '    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>\n'
         '  </link>\n')
_ARM_INERTIAL = ('<inertial><mass value="0.5"/><inertia ixx="0.004" ixy="0" ixz="0" '
                 'iyy="0.004" iyz="0" izz="0.0006"/></inertial>')

# The arm as a 0.05 x 0.05 x 0.3 m box: its tensor is the solid box's, m (b^2 + c^2) / 12.
_ARM_BOX = ('<collision><origin xyz="0 0 0.15"/><geometry><box size="0.05 0.05 0.3"/>'
            '</geometry></collision>')


def _box_arm(mass_kg: str = "0.5", ixx: str = "0.00385", izz: str = "0.000208",
             com_z: str = "0.15") -> str:
    return (f'<inertial><origin xyz="0 0 {com_z}"/><mass value="{mass_kg}"/><inertia '
            f'ixx="{ixx}" ixy="0" ixz="0" iyy="{ixx}" iyz="0" izz="{izz}"/></inertial>'
            + _ARM_BOX)


def _arm(joint: str = '<axis xyz="0 1 0"/><limit lower="-1.57" upper="1.57" effort="10" '
                      'velocity="2"/>',
         arm: str = _ARM_INERTIAL, joint_type: str = "revolute", extra: str = "",
         joint_name: str = "elbow", origin: str = "0 0 0.05",
         base: str = _BASE_INERTIAL) -> str:
    return ('<robot name="arm">\n' + _BASE.format(inertial=base) +
            f'  <joint name="{joint_name}" type="{joint_type}">\n'
            f'    <parent link="base_link"/><child link="arm"/><origin xyz="{origin}"/>\n'
            f'    {joint}\n'
            '  </joint>\n'
            f'  <link name="arm">{arm}</link>\n' + extra + '</robot>\n')


# A RotorS-style X quadrotor (1.2 kg, 0.25 m arms; the rotor constants of RotorS' firefly):
# one (x, y, turning direction, motor number, joint type) per rotor, in PX4's quad-X order.
_QUAD_X = (("0.177", "-0.177", "ccw", "0", "continuous"),
           ("-0.177", "0.177", "ccw", "1", "continuous"),
           ("0.177", "0.177", "cw", "2", "continuous"),
           ("-0.177", "-0.177", "cw", "3", "continuous"))


def _quad(**change: tuple[int, int, str]) -> str:
    """The quad with rotor i's field j set to a value: change={"name": (i, j, value)}."""
    return _multirotor(_QUAD_X, **change)


def _multirotor(table: tuple[tuple[str, ...], ...], **change: tuple[int, int, str]) -> str:
    """The 1.2 kg RotorS-style vehicle with the rotors of `table` (as _QUAD_X), changed."""
    rotors = [list(r) for r in table]
    for i, j, value in change.values():
        rotors[i][j] = value
    out = ['<robot name="quad">\n  <link name="base_link">\n'
           '    <inertial><mass value="1.2"/><inertia ixx="0.00964" ixy="0" ixz="0" '
           'iyy="0.00964" iyz="0" izz="0.018"/></inertial>\n'
           '    <collision><geometry><box size="0.3 0.3 0.08"/></geometry></collision>\n'
           '  </link>\n']
    for k, (x, y, spin, number, joint_type) in enumerate(rotors):
        out.append(
            f'  <joint name="rotor_{k}_joint" type="{joint_type}"><parent link="base_link"/>'
            f'<child link="rotor_{k}"/>\n'
            f'    <origin xyz="{x} {y} 0.03"/><axis xyz="0 0 1"/>'
            + ('<limit lower="-3.14" upper="3.14" effort="1" velocity="900"/>'
               if joint_type == "revolute" else '') + '</joint>\n'
            f'  <link name="rotor_{k}"><inertial><mass value="0.005"/><inertia ixx="1.25e-05" '
            'ixy="0" ixz="0" iyy="1.25e-05" iyz="0" izz="2.5e-05"/></inertial>\n'
            '    <collision><geometry><cylinder radius="0.1" length="0.005"/></geometry>'
            '</collision></link>\n'
            f'  <gazebo><plugin name="rotor_{k}_motor_model" '
            'filename="librotors_gazebo_motor_model.so">\n'
            f'    <jointName>rotor_{k}_joint</jointName><linkName>rotor_{k}</linkName>'
            f'<turningDirection>{spin}</turningDirection><motorNumber>{number}</motorNumber>\n'
            '    <timeConstantUp>0.0125</timeConstantUp><timeConstantDown>0.025'
            '</timeConstantDown><maxRotVelocity>838</maxRotVelocity>\n'
            '    <motorConstant>8.54858e-06</motorConstant><momentConstant>0.016'
            '</momentConstant>\n  </plugin></gazebo>\n')
    return "".join(out) + "</robot>\n"


def _mass(value: str, inertia: str = 'ixx="0.004" iyy="0.004" izz="0.0006"') -> str:
    return (f'<inertial><mass value="{value}"/><inertia {inertia} ixy="0" ixz="0" iyz="0"/>'
            '</inertial>')

def _quad_rpy(*rpy: str) -> str:
    """The quad with rotor i's joint origin rotated by rpy[i]."""
    out = _quad()
    for (x, y, *_), angles in zip(_QUAD_X, rpy):
        out = out.replace(f'<origin xyz="{x} {y} 0.03"/>',
                          f'<origin xyz="{x} {y} 0.03" rpy="{angles}"/>')
    return out


def _hexa(spins: str) -> str:
    """A hexacopter, rotors every 60° on a 0.25 m circle from the nose, counterclockwise
    seen from above, turning as `spins` says ("P": ccw, "N": cw)."""
    xy = (("0.25", "0"), ("0.125", "0.2165"), ("-0.125", "0.2165"), ("-0.25", "0"),
          ("-0.125", "-0.2165"), ("0.125", "-0.2165"))
    return _multirotor(tuple((x, y, "ccw" if spin == "P" else "cw", str(k), "continuous")
                             for k, ((x, y), spin) in enumerate(zip(xy, spins))))

def _tilted_quad(comment: str = "") -> str:
    """The quad with rotor 0 rolled 0.1 rad (5.7°), `comment` on the line before."""
    return _quad().replace('    <origin xyz="0.177 -0.177 0.03"/>',
                           comment + '    <origin xyz="0.177 -0.177 0.03" rpy="0.1 0 0"/>')


def _quad_mass(mass_kg: str) -> str:
    """The quad with another base mass (thrust at full speed stays 24.0 N)."""
    return _quad().replace('<mass value="1.2"/>', f'<mass value="{mass_kg}"/>', 1)


def _quad_extra(extra: str) -> str:
    """The quad with more elements before </robot>."""
    return _quad().replace('</robot>\n', extra + '</robot>\n')


# RotorS' MAVLink interface, forwarding `rotorCount` motor commands.
_MAVLINK = ('  <gazebo><plugin name="mavlink_interface" '
            'filename="librotors_gazebo_mavlink_interface.so">'
            '<rotorCount>{count}</rotorCount></plugin></gazebo>\n')
# The hexacopter's rotors every 60° on a 0.25 m circle, as _hexa("PPNNPN").
_HEXA_X = (("0.25", "0", "ccw", "0", "continuous"), ("0.125", "0.2165", "ccw", "1", "continuous"),
           ("-0.125", "0.2165", "cw", "2", "continuous"), ("-0.25", "0", "cw", "3", "continuous"),
           ("-0.125", "-0.2165", "ccw", "4", "continuous"),
           ("0.125", "-0.2165", "cw", "5", "continuous"))
# RotorS' mav_name argument, the robot named by it.
_MAV_NAME_ARG = '  <xacro:arg name="mav_name" default="quad"/>\n'
# An IMU macro in RotorS' component_snippets style: a link on a fixed joint and its plugin.
_IMU_MACRO = ('  <xacro:macro name="imu">\n'
              '    <joint name="imu_joint" type="fixed"><parent link="base_link"/>'
              '<child link="imu_link"/></joint>\n'
              '    <link name="imu_link"><inertial><mass value="0.015"/><inertia ixx="1e-05" '
              'ixy="0" ixz="0" iyy="1e-05" iyz="0" izz="1e-05"/></inertial></link>\n'
              '  </xacro:macro>\n')
# An IMU on a link attached by a fixed joint (merged into base_link unless preserved).
_IMU = ('  <joint name="imu_joint" type="fixed"><parent link="base_link"/>'
        '<child link="imu_link"/></joint>\n'
        '  <link name="imu_link"><inertial><mass value="0.015"/><inertia ixx="1e-05" ixy="0" '
        'ixz="0" iyy="1e-05" iyz="0" izz="1e-05"/></inertial></link>\n'
        '  <gazebo><plugin name="imu" filename="librotors_gazebo_imu_plugin.so">'
        '<linkName>imu_link</linkName></plugin></gazebo>\n')



def _stl(name: str, *facets: tuple[tuple[float, float, float], ...]) -> str:
    """An ASCII STL (the text form CAD tools also export) of triangles given by corners."""
    out = [f"solid {name}"]
    for facet in facets:
        out += ["  facet normal 0 0 1", "    outer loop"]
        out += [f"      vertex {x:g} {y:g} {z:g}" for x, y, z in facet]
        out += ["    endloop", "  endfacet"]
    return "\n".join(out + [f"endsolid {name}"]) + "\n"


def _prop_stl(units_per_m: float) -> str:
    """A 9-inch (0.2286 m) two-blade propeller disc outline, flat, written in a CAD unit:
    1 (metres), 100 (centimetres) or 1000 (millimetres)."""
    r, w = 0.1143 * units_per_m, 0.012 * units_per_m
    return _stl("prop", ((-r, 0, 0), (0, -w, 0), (r, 0, 0)), ((r, 0, 0), (0, w, 0), (-r, 0, 0)))


def _quad_prop_visual(uri: str, scale: str = "", rotor: int = 0, kind: str = "visual",
                      table: tuple = _QUAD_X) -> str:
    """The multirotor of `table` with a propeller mesh drawn on rotor `rotor` (as RotorS'
    propeller_ccw.dae is) as its `kind` (visual or collision)."""
    scale = f' scale="{scale}"' if scale else ""
    return _multirotor(table).replace(
        f'<link name="rotor_{rotor}"><inertial>',
        f'<link name="rotor_{rotor}"><{kind}><geometry><mesh filename="{uri}"{scale}/>'
        f'</geometry></{kind}><inertial>', 1)


def _xacro(urdf: str, macros: str = "") -> str:
    """A URDF as a .urdf.xacro file (the xacro namespace declared), `macros` after <robot>."""
    return urdf.replace('<robot name="quad">',
                        '<robot name="quad" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                        + macros, 1)


_PROP_M = (("meshes/prop.stl", _prop_stl(1)),)
_PACKAGE_XML = ('<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
                '  <version>1.0.0</version>\n  <description>A quadrotor</description>\n'
                '  <maintainer email="me@example.com">me</maintainer>\n'
                '  <license>BSD</license>\n</package>\n')


# The quad's RotorS vehicle parameters (rotors_gazebo/resource/<mav>.yaml): mass 1.2 kg body
# + 4 x 5 g rotors; inertia about the COM (the rotors 0.177 m out on x and y, 0.03 m up):
# xx = 0.00964 + 4 (1.25e-05 + 0.005 (0.177² + 0.03²)) - 1.22 (4.92e-04)² = 0.010334.
# Entry i: the rotor with motorNumber i, angle from +x towards +y, arm 0.177·√2 m.
_ROTORS_ROWS = (("-0.785398", "1.0"), ("2.356194", "1.0"), ("0.785398", "-1.0"),
                ("-2.356194", "-1.0"))


def _rotors_yaml(mass_kg: str = "1.22",
                 inertia: str = "{xx: 0.010334, xy: 0.0, xz: 0.0, yy: 0.010334, yz: 0.0, "
                                "zz: 0.019353}",
                 rows: int = 4, **change: tuple[int, str, str]) -> str:
    """The quad's vehicle YAML with entry i's `key` set: change={"name": (i, key, text)}."""
    entries = [{"angle": angle, "arm_length": "0.250316", "rotor_force_constant": "8.54858e-06",
                "rotor_moment_constant": "0.016", "direction": direction}
               for angle, direction in _ROTORS_ROWS[:rows]]
    for i, key, value in change.values():
        if value:
            entries[i][key] = value
        else:
            del entries[i][key]
    lines = "".join(f"  '{i}': {{" + ", ".join(f"{k}: {v}" for k, v in e.items()) + "}\n"
                    for i, e in enumerate(entries))
    return f"mass: {mass_kg}\ninertia: {inertia}\nrotor_configuration:\n{lines}"


def _controller(yaml_text: str, gains: str = "") -> Case:
    """The RotorS quad with its vehicle YAML (and Lee gains) given to validate."""
    files = (("quad.yaml", yaml_text),)
    args = ("--controller", "quad.yaml")
    if gains:
        files += (("lee_controller_quad.yaml", gains),)
        args += ("--controller", "lee_controller_quad.yaml")
    return Case(_quad(), files, args, name="quad.urdf")


def _lee_gains(**change: str) -> str:
    """lee_controller_<mav>.yaml: RotorS' Firefly gains scaled to the quad (position and
    velocity by mass, attitude and rate by each principal moment), one line changed."""
    gains = {"position_gain": "{x: 4.7, y: 4.7, z: 4.7}",
             "velocity_gain": "{x: 3.7, y: 3.7, z: 3.7}",
             "attitude_gain": "{x: 0.89, y: 0.89, z: 0.03}",
             "angular_rate_gain": "{x: 0.15, y: 0.15, z: 0.036}"}
    gains.update(change)
    return "".join(f"{key}: {value}\n" for key, value in gains.items())


# PX4's x500 for gz-sim as one SDF 1.9 model (its base and the four MulticopterMotorModel
# systems of PX4-gazebo-models' x500, includes resolved): 2.0 kg body, 16 g rotors on a
# 0.174 m square, rotor k (x, y, turning direction) driven by motor number k, up to
# 1000 rad/s, motorConstant 8.54858e-06, momentConstant 0.016.
_X500_ROTORS = (("0.174", "-0.174", "ccw"), ("-0.174", "0.174", "ccw"),
                ("0.174", "0.174", "cw"), ("-0.174", "-0.174", "cw"))


def _x500(extra: str = "", *, base: str = "base_link", topic: str = "command/motor_speed",
          max_rad_s: str = "1000") -> str:
    """The x500; `extra` (more systems) before </model>, the base link named `base`, the
    motors listening on `topic`, spinning up to `max_rad_s`."""
    out = ['<?xml version="1.0"?>\n<sdf version="1.9">\n  <model name="x500">\n'
           f'    <link name="{base}">\n'
           '      <inertial><mass>2.0</mass><inertia><ixx>0.0216667</ixx><iyy>0.0216667</iyy>'
           '<izz>0.04</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>\n'
           '      <collision name="collision"><geometry><box><size>0.35 0.35 0.05</size></box>'
           '</geometry></collision>\n    </link>\n']
    for k, (x, y, _spin) in enumerate(_X500_ROTORS):
        out.append(
            f'    <link name="rotor_{k}">\n      <pose>{x} {y} 0.06 0 0 0</pose>\n'
            '      <inertial><mass>0.016</mass><inertia><ixx>3.8e-07</ixx><iyy>2.6e-05</iyy>'
            '<izz>2.6e-05</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>\n'
            '      <collision name="collision"><geometry><box><size>0.28 0.017 0.001</size>'
            '</box></geometry></collision>\n    </link>\n'
            f'    <joint name="rotor_{k}_joint" type="revolute"><parent>{base}</parent>'
            f'<child>rotor_{k}</child>\n'
            '      <axis><xyz>0 0 1</xyz><limit><lower>-1e+16</lower><upper>1e+16</upper>'
            '</limit></axis>\n    </joint>\n')
    for k, (_x, _y, spin) in enumerate(_X500_ROTORS):
        out.append(
            '    <plugin filename="gz-sim-multicopter-motor-model-system" '
            'name="gz::sim::systems::MulticopterMotorModel">\n'
            f'      <jointName>rotor_{k}_joint</jointName><linkName>rotor_{k}</linkName>'
            f'<turningDirection>{spin}</turningDirection>\n'
            '      <timeConstantUp>0.0125</timeConstantUp><timeConstantDown>0.025'
            f'</timeConstantDown><maxRotVelocity>{max_rad_s}</maxRotVelocity>\n'
            '      <motorConstant>8.54858e-06</motorConstant><momentConstant>0.016'
            '</momentConstant>\n'
            f'      <commandSubTopic>{topic}</commandSubTopic><motorNumber>{k}</motorNumber>'
            '<motorType>velocity</motorType>\n    </plugin>\n')
    return "".join(out) + extra + '  </model>\n</sdf>\n'


def _velocity_control(joints: tuple[str, ...] = ("rotor_0_joint", "rotor_1_joint",
                                                 "rotor_2_joint", "rotor_3_joint"),
                      com_link: str = "<comLinkName>base_link</comLinkName>") -> str:
    """gz-sim's MulticopterVelocityControl as its X3 example sets it, one <rotor> per joint
    in `joints` (direction +1 for the ccw rotors 0 and 1)."""
    rotors = "".join(
        f'        <rotor><jointName>{joint}</jointName><forceConstant>8.54858e-06'
        '</forceConstant><momentConstant>0.016</momentConstant>'
        f'<direction>{1 if joint[6] in "01" else -1}</direction></rotor>\n' for joint in joints)
    return ('    <plugin filename="gz-sim-multicopter-control-system" '
            'name="gz::sim::systems::MulticopterVelocityControl">\n'
            '      <commandSubTopic>cmd_vel</commandSubTopic><enableSubTopic>enable'
            f'</enableSubTopic>{com_link}\n'
            '      <velocityGain>2.7 2.7 2.7</velocityGain><attitudeGain>2 3 0.15</attitudeGain>'
            '<angularRateGain>0.4 0.52 0.18</angularRateGain>\n'
            '      <maximumLinearAcceleration>2 2 2</maximumLinearAcceleration>\n'
            '      <rotorConfiguration>\n' + rotors + '      </rotorConfiguration>\n'
            '    </plugin>\n')


def _px4_airframe(header: str, params: dict[str, str], **change: str | None) -> str:
    """A PX4 airframe script (ROMFS init.d-posix/airframes shape): `params` as
    `param set-default` lines, each of `change` set (None: the line left out)."""
    values = {**params, **change}
    return header + "".join(f"param set-default {name} {value}\n"
                            for name, value in values.items() if value is not None)


def _ca_rotors(arm_m: str, km: str) -> dict[str, str]:
    """CA_ROTOR0..3 of a quad X in PX4's order, positions in FRD (x forward, y right),
    KM positive for the counter-clockwise rotors 0 and 1."""
    signs = ((1, 1, ""), (-1, -1, ""), (1, -1, "-"), (-1, 1, "-"))
    out = {"CA_AIRFRAME": "0", "CA_ROTOR_COUNT": "4"}
    for i, (sx, sy, spin) in enumerate(signs):
        out[f"CA_ROTOR{i}_PX"] = ("-" if sx < 0 else "") + arm_m
        out[f"CA_ROTOR{i}_PY"] = ("-" if sy < 0 else "") + arm_m
        out[f"CA_ROTOR{i}_KM"] = spin + km
    return out


# PX4's 4001_gz_x500 for the x500 above: its CA table at the model's rotors, KM the motors'
# momentConstant, ESC output k driving motor k-1 from 150 to 1000 rad/s (the maxRotVelocity).
_GZ_AIRFRAME_HEADER = ("#!/bin/sh\n#\n# @name x500 (Gazebo Sim)\n#\n"
                       ". ${R}etc/init.d/rc.mc_defaults\n\n"
                       "PX4_SIMULATOR=${PX4_SIMULATOR:=gz}\n"
                       "PX4_SIM_MODEL=${PX4_SIM_MODEL:=x500}\n\n")
_GZ_PARAMS = {"SIM_GZ_EN": "1", **_ca_rotors("0.174", "0.016"),
              **{f"SIM_GZ_EC_FUNC{k}": str(100 + k) for k in range(1, 5)},
              **{f"SIM_GZ_EC_MIN{k}": "150" for k in range(1, 5)},
              **{f"SIM_GZ_EC_MAX{k}": "1000" for k in range(1, 5)},
              "MPC_THR_HOVER": "0.73"}


def _gz_px4(model: str = "", **change: str | None) -> Case:
    """The x500 (or `model`) with its PX4 airframe, changed, given by --airframe."""
    return Case(model or _x500(), (("4001_gz_x500", _px4_airframe(_GZ_AIRFRAME_HEADER,
                                                                   _GZ_PARAMS, **change)),),
                ("--airframe", "4001_gz_x500"), name="x500.sdf")


# PX4 Gazebo Classic: the RotorS quad with PX4's gazebo_mavlink_interface, whose channel i
# turns PX4's output u into (u + input_offset) * input_scaling + zero_position_armed rad/s
# for motor i: 100 + 738 u, up to the motors' 838 rad/s.
def _mavlink_channels(scaling: str = "738", armed: str = "100") -> str:
    channels = "".join(
        f'<channel name="rotor{i + 1}"><input_index>{i}</input_index><input_offset>0'
        f'</input_offset><input_scaling>{scaling}</input_scaling><zero_position_disarmed>0'
        f'</zero_position_disarmed><zero_position_armed>{armed}</zero_position_armed>'
        '<joint_control_type>velocity</joint_control_type></channel>\n' for i in range(4))
    return ('  <gazebo><plugin name="mavlink_interface" filename="libgazebo_mavlink_interface.so">'
            '\n    <control_channels>\n' + channels + '    </control_channels>\n'
            '  </plugin></gazebo>\n')


_CLASSIC_AIRFRAME_HEADER = ("#!/bin/sh\n#\n# @name quad (Gazebo Classic)\n#\n"
                            ". ${R}etc/init.d/rc.mc_defaults\n\n")
_CLASSIC_PARAMS = {**_ca_rotors("0.177", "0.016"),
                   **{f"PWM_MAIN_FUNC{k}": str(100 + k) for k in range(1, 5)},
                   "MPC_THR_HOVER": "0.67"}


def _classic_px4(scaling: str = "738", armed: str = "100", **change: str | None) -> Case:
    return Case(_quad_extra(_mavlink_channels(scaling, armed)),
                (("10015_gazebo-classic_quad", _px4_airframe(_CLASSIC_AIRFRAME_HEADER,
                                                             _CLASSIC_PARAMS, **change)),),
                ("--airframe", "10015_gazebo-classic_quad"), name="quad.urdf")


def _parm(**change: str | None) -> str:
    """ArduPilot's gazebo-iris defaults (.parm: NAME VALUE lines) for the iris above: quad X,
    motor m on servo output m, which the plugin's channel m-1 reads."""
    values = {"FRAME_CLASS": "1", "FRAME_TYPE": "1",
              **{f"SERVO{m}_FUNCTION": str(32 + m) for m in range(1, 5)},
              "MOT_SPIN_ARM": "0.1", "MOT_SPIN_MIN": "0.15", "MOT_THST_HOVER": "0.36", **change}
    return ("# quad X: motor 1 front-right CCW, 2 back-left CCW, 3 front-left CW, "
            "4 back-right CW\n"
            + "".join(f"{name} {value}\n" for name, value in values.items() if value is not None))


def _ardupilot(**change: str | None) -> Case:
    return Case(_ardupilot_quad(), (("iris.parm", _parm(**change)),),
                ("--autopilot-params", "iris.parm"), name="iris.sdf")


def _thrust_axes_frd(roll_rad: float) -> dict[str, str]:
    """CA_ROTORi_AX/AY/AZ of the x500 with rotor i rolled about its arm by ±roll_rad (the
    R320 pattern of _tilted_x500): the model rotor's thrust axis R_z(yaw) R_x(roll) z in FRD."""
    out = {}
    for i, (roll, yaw) in enumerate(_X500_TILTS):
        r, y = roll * roll_rad, yaw
        flu = (math.sin(y) * math.sin(r), -math.cos(y) * math.sin(r), math.cos(r))
        for axis, value in zip("XYZ", (flu[0], -flu[1], -flu[2])):
            out[f"CA_ROTOR{i}_A{axis}"] = f"{value:.4f}"
    return out


# Per x500 rotor: (roll sign, yaw of its pose in rad): each rotor rolled about its arm,
# alternating with its turning direction (the AscTec Neo's pattern, R320).
_X500_TILTS = ((1, -0.785398), (1, 2.356194), (-1, 0.785398), (-1, -2.356194))


def _tilted_x500(roll_rad: float) -> str:
    out = _x500()
    for (x, y, _spin), (sign, yaw) in zip(_X500_ROTORS, _X500_TILTS):
        out = out.replace(f"<pose>{x} {y} 0.06 0 0 0</pose>",
                          f"<pose>{x} {y} 0.06 {sign * roll_rad:g} 0 {yaw}</pose>")
    return out

# The same two-link arm as an SDF 1.9 model (Gazebo's own format).
_SDF_INERTIAL = ('<inertial><mass>{mass_kg}</mass><inertia><ixx>{i}</ixx><iyy>{i}</iyy>'
                 '<izz>{i}</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>')
_SDF_ARM_INERTIAL = _SDF_INERTIAL.format(mass_kg="0.5", i="0.004")
_SDF_BOX_VISUAL = ('<visual name="{name}"><geometry><box><size>0.05 0.05 0.3</size></box>'
                   '</geometry></visual>')


def _sdf(arm_name: str = "arm", arm_pose: str = "<pose>0 0 0.05 0 0 0</pose>",
         arm_body: str = _SDF_ARM_INERTIAL,
         child: str = "", model_attr: str = "", version: str = ' version="1.9"',
         extra: str = "", after: str = "") -> str:
    return ('<?xml version="1.0"?>\n'
            f'<sdf{version}>\n  <model name="arm"{model_attr}>\n'
            '    <link name="base_link">\n'
            '      ' + _SDF_INERTIAL.format(mass_kg="2", i="0.0083") + '\n'
            '      <collision name="collision"><geometry><box><size>0.2 0.2 0.1</size></box>'
            '</geometry></collision>\n'
            '    </link>\n'
            f'    <link name="{arm_name}">\n      {arm_pose}\n'
            f'      {arm_body}\n    </link>\n'
            '    <joint name="elbow" type="revolute"><parent>base_link</parent>'
            f'<child>{child or arm_name}</child>\n'
            '      <axis><xyz>0 1 0</xyz><limit><lower>-1.57</lower><upper>1.57</upper></limit>'
            '</axis>\n'
            '    </joint>\n' + extra + '  </model>\n' + after + '</sdf>\n')

# A gz-sim system: the model is for gz-sim (whose libsdformat DOM loads its materials).
_GZ_SYSTEM = ('    <plugin filename="gz-sim-joint-state-publisher-system" '
              'name="gz::sim::systems::JointStatePublisher"/>\n')


def _sdf_arm_visual(material: str) -> str:
    return _SDF_ARM_INERTIAL + _SDF_BOX_VISUAL.format(name="visual").replace(
        "</visual>", f"<material>{material}</material></visual>")

# ardupilot_gazebo's iris as SDF 1.9, flattened: per rotor (x, y, turning sign: +1 ccw).
_IRIS_ROTORS = (("0.13", "-0.22", 1), ("-0.13", "0.2", 1), ("0.13", "0.22", -1),
                ("-0.13", "-0.2", -1))


def _ardupilot_quad(flipped_channel: int = -1) -> str:
    """Two LiftDrag blades per rotor (lift when moving along <forward>) and an
    ArduPilotPlugin channel per rotor whose <multiplier> sign is the spin direction;
    `flipped_channel`'s multiplier has the wrong sign."""
    out = ['<?xml version="1.0"?>\n<sdf version="1.9">\n  <model name="iris">\n'
           '    <link name="base_link">\n'
           '      <inertial><mass>1.5</mass><inertia><ixx>0.029125</ixx><iyy>0.029125</iyy>'
           '<izz>0.055225</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>\n'
           '      <collision name="collision"><geometry><box><size>0.47 0.47 0.11</size></box>'
           '</geometry></collision>\n    </link>\n']
    controls = []
    for k, (x, y, sign) in enumerate(_IRIS_ROTORS):
        out.append(
            f'    <link name="rotor_{k}">\n      <pose>{x} {y} 0.023 0 0 0</pose>\n'
            '      <inertial><mass>0.025</mass><inertia><ixx>9.75e-06</ixx>'
            '<iyy>0.000166704</iyy><izz>0.000167604</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz>'
            '</inertia></inertial>\n    </link>\n'
            f'    <joint name="rotor_{k}_joint" type="revolute"><parent>base_link</parent>'
            f'<child>rotor_{k}</child>\n'
            '      <axis><xyz>0 0 1</xyz><limit><lower>-1e+16</lower><upper>1e+16</upper>'
            '</limit></axis>\n    </joint>\n')
        for blade, cp_x in ((1, 1), (2, -1)):
            out.append(
                f'    <plugin name="rotor_{k}_blade_{blade}" filename="libLiftDragPlugin">'
                '<a0>0.3</a0><cla>4.25</cla><cda>0.1</cda><area>0.002</area>'
                f'<air_density>1.2041</air_density><cp>{0.084 * cp_x:g} 0 0</cp>'
                f'<forward>0 {sign * cp_x} 0</forward><upward>0 0 1</upward>'
                f'<link_name>rotor_{k}</link_name></plugin>\n')
        multiplier = 838 * sign * (-1 if k == flipped_channel else 1)
        controls.append(f'      <control channel="{k}"><type>VELOCITY</type>'
                        f'<jointName>rotor_{k}_joint</jointName>'
                        f'<multiplier>{multiplier}</multiplier></control>\n')
    out.append('    <plugin name="arducopter_plugin" filename="libArduPilotPlugin">\n'
               + "".join(controls) + '    </plugin>\n  </model>\n</sdf>\n')
    return "".join(out)


@dataclass(frozen=True)
class Case:
    """An example that needs more than the model file: `files` are (path relative to the
    model's folder, text) written beside it, `args` the words after the model on
    `reedtool validate`'s command line, `name` the model's file name."""

    model: str
    files: tuple[tuple[str, str], ...] = ()
    args: tuple[str, ...] = ()
    name: str = ""

    @property
    def model_name(self) -> str:
        return self.name or f"model.{example_format(self.model)}"

    @property
    def command(self) -> str:
        return " ".join(("reedtool validate", self.model_name) + self.args)


def as_case(example: "str | Case") -> Case:
    """A plain example is a Case with no other file and no other word."""
    return example if isinstance(example, Case) else Case(example)


def example_format(text: str) -> str:
    """"sdf" for an example whose root element is <sdf>, "urdf" otherwise: the file suffix
    the loader and libsdformat read it by, and the label the rules page gives it."""
    return "sdf" if re.search(r"^\s*<sdf[\s>]", text, re.MULTILINE) else "urdf"


# code -> (bad, good): a whole URDF or SDF file (example_format), or a Case.
EXAMPLES: dict[str, tuple["str | Case", "str | Case"]] = {
    "S101": (_arm(arm=_mass("half")), _arm(arm=_mass("0.5"))),
    "S102": (_arm(origin="0 nan 0.05"), _arm()),
    "S104": (_arm(extra='  <link name="camera">' + _ARM_INERTIAL + '</link>\n'),
             _arm(extra='  <joint name="camera_mount" type="fixed"><parent link="arm"/>'
                        '<child link="camera"/></joint>\n'
                        '  <link name="camera">' + _ARM_INERTIAL + '</link>\n')),
    "S106": (_arm(extra='  <link name="arm">' + _ARM_INERTIAL + '</link>\n'), _arm()),
    "S107": (_arm(joint_name="mount",
                  extra='  <joint name="mount" type="fixed"><parent link="arm"/>'
                        '<child link="tool"/></joint>\n'
                        '  <link name="tool">' + _ARM_INERTIAL + '</link>\n'),
             _arm(extra='  <joint name="mount" type="fixed"><parent link="arm"/>'
                        '<child link="tool"/></joint>\n'
                        '  <link name="tool">' + _ARM_INERTIAL + '</link>\n')),
    "S110": (_arm(joint_type="hinge"), _arm()),
    "S111": (_arm(joint='<axis xyz="0 1 0"/>'), _arm()),
    "S112": (_arm(joint='<axis xyz="0 1 0"/><limit lower="1.57" upper="-1.57" effort="10" '
                        'velocity="2"/>'), _arm()),
    "S113": (_arm(joint='<axis xyz="0 0 0"/><limit lower="-1.57" upper="1.57" effort="10" '
                        'velocity="2"/>'), _arm()),
    "I201": (_arm(arm=_mass("0")), _arm(arm=_mass("0.5"))),
    "I202": (_arm(arm=_mass("0.5", 'ixx="0.004" iyy="0" izz="0.0006"')), _arm()),
    "I203": (_arm(arm=_mass("0.5", 'ixx="0.004" iyy="0.001" izz="0.0006"')), _arm()),
    "S105": (_arm().replace('<child link="arm"/>', '<child link="forearm"/>'), _arm()),
    "S108": (_arm(extra='  <joint name="arm_again" type="fixed"><parent link="base_link"/>'
                        '<child link="arm"/></joint>\n'), _arm()),
    "S109": (_arm(extra='  <joint name="back" type="fixed"><parent link="arm"/>'
                        '<child link="base_link"/></joint>\n'), _arm()),
    "S114": (_arm(extra='  <gazebo reference="arm_link"><material>Gazebo/Orange</material>'
                        '</gazebo>\n'),
             _arm(extra='  <gazebo reference="arm"><material>Gazebo/Orange</material>'
                        '</gazebo>\n')),
    "S116": (_arm(arm=_ARM_INERTIAL + '<visual><geometry><box size="0.05 0 0.3"/></geometry>'
                                      '</visual>'),
             _arm(arm=_ARM_INERTIAL + '<visual><geometry><box size="0.05 0.05 0.3"/>'
                                      '</geometry></visual>')),
    "S117": (_arm(arm='<collision><geometry><box size="0.05 0.05 0.3"/></geometry></collision>'),
             _arm(arm=_ARM_INERTIAL + '<collision><geometry><box size="0.05 0.05 0.3"/>'
                                      '</geometry></collision>')),
    "I207": (_arm(arm=_mass("0", 'ixx="0" iyy="0" izz="0"'), joint_type="fixed",
                  base=_mass("0", 'ixx="0" iyy="0" izz="0"')), _arm()),
    "I208": (_arm(arm=_mass("0"), joint_type="fixed"),
             _arm(arm=_mass("0", 'ixx="0" iyy="0" izz="0"'), joint_type="fixed")),
    # 100 times the box's tensor for its mass.
    "I204": (_arm(arm=_box_arm(ixx="0.385", izz="0.0208")), _arm(arm=_box_arm())),
    "I205": (_arm(arm=_box_arm(com_z="0.9")), _arm(arm=_box_arm())),
    # 100 kg in 0.75 litres: 133 000 kg/m^3, six times osmium.
    "I221": (_arm(arm=_box_arm("100", ixx="0.77", izz="0.0416")), _arm(arm=_box_arm())),
    "R301": (_quad(number=(3, 3, "2")), _quad()),
    "R302": (_quad(number=(3, 3, "4")), _quad()),
    "R303": (_quad(spin=(2, 2, "CW")), _quad()),
    "R304": (_quad(spin=(3, 2, "ccw")), _quad()),
    "R313": (_quad(joint=(0, 4, "revolute")), _quad()),
    # Both right rotors turn cw, both left ccw: yaw torque is roll torque.
    "R305": (_quad(front_right=(0, 2, "cw"), front_left=(2, 2, "ccw")), _quad()),
    # The back rotors moved forward of the COM: the front ones would have to push down.
    "R307": (_quad(back_left=(1, 0, "0.3"), back_right=(3, 0, "0.3")), _quad()),
    # 24.0 N of thrust at full speed: a 3 kg base (29.6 N in all) stays down; a 2 kg one
    # (19.8 N) hovers at 91 % speed.
    "R308": (_quad_mass("3"), _quad()),
    "R309": (_quad_mass("2"), _quad()),
    "R310": (_quad_mass("2"), _quad()),
    "R311": (_tilted_quad(), _quad()),
    "R312": (_quad_extra(_MAVLINK.format(count=6)), _quad_extra(_MAVLINK.format(count=4))),
    "R314": (_quad().replace('<jointName>rotor_0_joint<', '<jointName>rotor0_joint<'), _quad()),
    "R315": (_quad().replace('<linkName>rotor_0<', '<linkName>base_link<'), _quad()),
    "R316": (_quad().replace('<motorConstant>8.54858e-06<', '<motorConstant>0<', 1), _quad()),
    # maxRotVelocity 8000 rad/s (gz-sim's test quadrotor): thrust-to-weight 183.
    "R340": (_quad().replace('<maxRotVelocity>838<', '<maxRotVelocity>8000<'), _quad()),
    "R341": (_quad().replace('<axis xyz="0 0 1"/>', '<axis xyz="1 0 0"/>', 1), _quad()),
    # Back rotors 0.3 m behind the COM instead of 0.177 m: the COM sits ahead of the rotors'
    # centroid.
    "R342": (_quad(back_left=(1, 0, "-0.3"), back_right=(3, 0, "-0.3")), _quad()),
    # Yaw radius of gyration sqrt(0.5 / 1.22) = 0.64 m, 2.6x the 0.25 m rotor distance.
    "I220": (_quad().replace('ixx="0.00964" ixy="0" ixz="0" iyy="0.00964" iyz="0" izz="0.018"',
                             'ixx="0.3" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.5"'), _quad()),
    # 1.0 kg·m² placeholders on the arm: 380x its box's trace; the robot's yaw inertia 75x.
    "I209": (_arm(arm=_box_arm(ixx="1", izz="1")), _arm(arm=_box_arm())),
    "S118": (_quad_extra(_IMU),
             _quad_extra(_IMU + '  <gazebo reference="imu_joint"><preserveFixedJoint>true'
                                '</preserveFixedJoint></gazebo>\n')),
    "S119": (_arm(extra='  <!-- arm -- 0.3 m -->\n'), _arm(extra='  <!-- arm: 0.3 m -->\n')),
    "S124": ('<!-- generated -->\n<?xml version="1.0"?>\n' + _arm(),
             '<?xml version="1.0"?>\n<!-- generated -->\n' + _arm()),
    # R305's spin order with one rotor moved 27 mm towards the x axis: rank 4, condition
    # number 50.
    "R306": (_quad(front_right=(0, 2, "cw"), front_left=(2, 2, "ccw"),
                   back_right=(3, 1, "-0.15")), _quad()),
    # Arms of 25 m (cm read as m): 1.22 kg on a 50 m frame, 0.006 N/m² of footprint.
    "R343": (_quad(**{f"r{i}{j}": (i, j, v.replace("0.177", "17.7"))
                      for i, rotor in enumerate(_QUAD_X) for j, v in enumerate(rotor[:2])}),
             _quad()),
    "S120": (_sdf(arm_body=""), _sdf()),
    "S125": (_sdf(arm_pose="<pose>0 0 0.05</pose>"), _sdf()),
    "S160": (_sdf(arm_name="arm::link"), _sdf()),
    "S163": (_sdf(model_attr=' canonical_link="body"'),
             _sdf(model_attr=' canonical_link="base_link"')),
    "S165": (_sdf(arm_pose='<pose relative_to="elbow_frame">0 0 0.05 0 0 0</pose>'), _sdf()),
    "S167": (_sdf(extra='    <model name="camera"><pose>0 0 0.1 0 0 0</pose></model>\n'),
             _sdf()),
    "S168": (_sdf(version=""), _sdf()),
    "S171": (_sdf(after='  <model name="arm_2"><link name="base_link"/></model>\n'), _sdf()),
    "S161": (_sdf(arm_body=_SDF_ARM_INERTIAL + _SDF_BOX_VISUAL.format(name="visual") * 2),
             _sdf(arm_body=_SDF_ARM_INERTIAL + _SDF_BOX_VISUAL.format(name="visual")
                  + _SDF_BOX_VISUAL.format(name="visual_tip"))),
    "S162": (_sdf(extra='    <frame name="world" attached_to="arm"/>\n'),
             _sdf(extra='    <frame name="arm_tip" attached_to="arm"/>\n')),
    "S164": (_sdf(extra='    <frame name="arm_tip" attached_to="forearm"/>\n'),
             _sdf(extra='    <frame name="arm_tip" attached_to="arm"/>\n')),
    "S166": (_sdf(child="base_link"), _sdf()),
    # Gazebo classic's OGRE script name, in a model with a gz-sim system.
    "S170": (_sdf(arm_body=_sdf_arm_visual("<script><name>Gazebo/Orange</name></script>"),
                  extra=_GZ_SYSTEM),
             _sdf(arm_body=_sdf_arm_visual("<ambient>1 0.5 0 1</ambient>"
                                           "<diffuse>1 0.5 0 1</diffuse>"), extra=_GZ_SYSTEM)),
    # Removed in SDF 1.7; 1.7+ writes the frame as expressed_in.
    "S123": (_sdf().replace("<xyz>0 1 0</xyz>", "<xyz>0 1 0</xyz><use_parent_model_frame>true"
                                                "</use_parent_model_frame>"),
             _sdf().replace("<xyz>0 1 0</xyz>", '<xyz expressed_in="__model__">0 1 0</xyz>')),
    "S191": (_sdf(version=' version="1.6"').replace("<parent>base_link</parent>",
                                                    "<parent>arm::base_link</parent>"),
             _sdf(version=' version="1.6"')),
    # Each rotor rolled 5° about its arm, alternating with its turning direction (the
    # AscTec Neo's pattern).
    "R320": (_quad_rpy("0.087 0 -0.785", "0.087 0 2.356", "-0.087 0 0.785", "-0.087 0 -2.356"),
             _quad()),
    # Alternating spins lose full control with any rotor; Du et al.'s PPNNPN keeps it.
    "R350": (_hexa("PNPNPN"), _hexa("PPNNPN")),
    # I2O4-style typo (a letter l for a one); the good comment silences the deliberate tilt's
    # R311 in `validate` (inline suppressions apply after the rules ran).
    "S142": (_tilted_quad("    <!-- reedtool: ignore[R31l] -->\n"),
             _tilted_quad("    <!-- reedtool: ignore[R311] -->\n")),
    # A VTOL's pusher behind the quad: its thrust axis pitched 90° to body +x.
    "R319": (_multirotor(_QUAD_X + (("-0.3", "0", "ccw", "4", "continuous"),)).replace(
                 '<origin xyz="-0.3 0 0.03"/>', '<origin xyz="-0.3 0 0.03" rpy="0 1.5708 0"/>'),
             _quad()),
    # Channel 0's control block copied from a cw rotor onto a ccw one.
    "R318": (_ardupilot_quad(flipped_channel=0), _ardupilot_quad()),
    # A propeller exported in millimetres and read as metres: 228.6 m across, 646 times
    # the 0.354 m vehicle.
    "I210": (Case(_quad_prop_visual("meshes/prop.stl"), (("meshes/prop.stl", _prop_stl(1000)),),
                  name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl", "0.001 0.001 0.001"),
                  (("meshes/prop.stl", _prop_stl(1000)),), name="quad.urdf")),
    # The same propeller in centimetres on a 0.5 m hexacopter: 22.86 m across, 46 times the
    # vehicle (under the 50 times that makes the unit certain, I210).
    "I206": (Case(_quad_prop_visual("meshes/prop.stl", table=_HEXA_X),
                  (("meshes/prop.stl", _prop_stl(100)),), name="hexa.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl", "0.01 0.01 0.01", table=_HEXA_X),
                  (("meshes/prop.stl", _prop_stl(100)),), name="hexa.urdf")),
    # The file is meshes/prop.stl; the model names it with a capital P (Linux file names
    # have case).
    "S115": (Case(_quad_prop_visual("meshes/Prop.stl"), _PROP_M, name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl"), _PROP_M, name="quad.urdf")),
    # The clockwise propeller drawn as the counter-clockwise one mirrored in y (the MRS UAV
    # models' convention).
    "S121": (Case(_quad_prop_visual("meshes/prop.stl", "1 -1 1", rotor=2), _PROP_M,
                  name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl", rotor=2), _PROP_M, name="quad.urdf")),
    "S122": (Case(_quad_prop_visual("meshes/prop.stl", "1 -1 1", rotor=2, kind="collision"),
                  _PROP_M, name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl", rotor=2, kind="collision"), _PROP_M,
                  name="quad.urdf")),
    # A CAD part referenced as exported (STEP), in a Gazebo classic (RotorS) model.
    "S130": (Case(_quad_prop_visual("meshes/prop.step"),
                  (("meshes/prop.step", "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\nENDSEC;\n"
                                        "END-ISO-10303-21;\n"),), name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl"), _PROP_M, name="quad.urdf")),
    "S131": (Case(_quad_prop_visual("package://quad_description/../../../meshes/prop.stl"),
                  (("quad_description/package.xml", _PACKAGE_XML.format(name="quad_description")),
                   ("quad_description/meshes/prop.stl", _prop_stl(1))),
                  name="quad_description/urdf/quad.urdf"),
             Case(_quad_prop_visual("package://quad_description/meshes/prop.stl"),
                  (("quad_description/package.xml", _PACKAGE_XML.format(name="quad_description")),
                   ("quad_description/meshes/prop.stl", _prop_stl(1))),
                  name="quad_description/urdf/quad.urdf")),
    # A path on the author's machine (elsewhere also S115: the file is not there).
    "S169": (Case(_quad_prop_visual("file:///home/me/quad/meshes/prop.stl"), _PROP_M,
                  name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl"), _PROP_M, name="quad.urdf")),
    # gz-sim's X3 propeller mesh from Fuel.
    "S190": (Case(_quad_prop_visual("https://fuel.gazebosim.org/1.0/OpenRobotics/models/"
                                    "X3%20UAV/4/files/meshes/x3.dae"), _PROP_M,
                  name="quad.urdf"),
             Case(_quad_prop_visual("meshes/prop.stl"), _PROP_M, name="quad.urdf")),
    # A backup copy of the package beside it, its package.xml still naming quad_description.
    "S150": (Case(_quad_prop_visual("package://quad_description/meshes/prop.stl"),
                  (("src/quad_description/package.xml",
                    _PACKAGE_XML.format(name="quad_description")),
                   ("src/quad_description/meshes/prop.stl", _prop_stl(1)),
                   ("src/quad_description_backup/package.xml",
                    _PACKAGE_XML.format(name="quad_description")),
                   ("src/quad_description_backup/meshes/prop.stl", _prop_stl(1))),
                  ("--package-path", "src"), name="quad.urdf"),
             Case(_quad_prop_visual("package://quad_description/meshes/prop.stl"),
                  (("src/quad_description/package.xml",
                    _PACKAGE_XML.format(name="quad_description")),
                   ("src/quad_description/meshes/prop.stl", _prop_stl(1))),
                  ("--package-path", "src"), name="quad.urdf")),
    # An IMU macro called the pre-xacro-2 way (<imu/>): xacro copies the call, no IMU link
    # is made.
    "S103": (Case(_xacro(_quad_extra('  <imu/>\n'), _IMU_MACRO), name="quad.urdf.xacro"),
             Case(_xacro(_quad_extra('  <xacro:imu/>\n'), _IMU_MACRO), name="quad.urdf.xacro")),
    # RotorS' mav_name argument misspelt: xacro ignores it and the default stays.
    "S140": (Case(_xacro(_quad(), _MAV_NAME_ARG), args=("mav_nmae:=hex",),
                  name="quad.urdf.xacro"),
             Case(_xacro(_quad(), _MAV_NAME_ARG), args=("mav_name:=hex",),
                  name="quad.urdf.xacro")),
    # A launch file's argument for another node (CrazyS passes it to every vehicle).
    "S141": (Case(_xacro(_quad(), _MAV_NAME_ARG),
                  args=("mav_name:=hex", "enable_mellinger_controller:=true"),
                  name="quad.urdf.xacro"),
             Case(_xacro(_quad(), _MAV_NAME_ARG), args=("mav_name:=hex",),
                  name="quad.urdf.xacro")),
    # A suppression left after the tilted rotor it excused was made level again.
    "S143": (Case(_quad().replace('    <origin xyz="0.177 -0.177 0.03"/>',
                                  '    <!-- reedtool: ignore[R311] -->\n'
                                  '    <origin xyz="0.177 -0.177 0.03"/>'), name="quad.urdf"),
             Case(_tilted_quad("    <!-- reedtool: ignore[R311] -->\n"), name="quad.urdf")),
    # ArduPilot's iris: no motor constant written, k_f estimated from the two LiftDrag
    # blades as 2.167e-05 N/(rad/s)² per rotor; a RotorS motor writes its own (8.54858e-06),
    # nothing to explain.
    "R317": (_ardupilot_quad(), _quad()),
    # The vehicle YAML of a tricopter-turned-quad: three entries for four motors.
    "C401": (_controller(_rotors_yaml(rows=3)), _controller(_rotors_yaml())),
    # Entry 2 (the front-left rotor, cw) given direction +1 (ccw).
    "C404": (_controller(_rotors_yaml(d=(2, "direction", "1.0"))), _controller(_rotors_yaml())),
    # Entry 0 mirrored: +45° (front-left) for the front-right rotor at -45°.
    "C405": (_controller(_rotors_yaml(a=(0, "angle", "0.785398"))), _controller(_rotors_yaml())),
    # Entry 0's arm written as the rotor's x offset, 0.177 m, not its 0.2503 m distance.
    "C406": (_controller(_rotors_yaml(a=(0, "arm_length", "0.177"))),
             _controller(_rotors_yaml())),
    # RotorS' pelican force constant (9.9865e-06) on a motor with 8.54858e-06: 17 % off.
    "C407": (_controller(_rotors_yaml(k=(1, "rotor_force_constant", "9.9865e-06"))),
             _controller(_rotors_yaml())),
    # 0.025 m where the motor's momentConstant is 0.016: 56 % off.
    "C408": (_controller(_rotors_yaml(k=(3, "rotor_moment_constant", "0.025"))),
             _controller(_rotors_yaml())),
    # The base link's 1.2 kg without the rotors: 1.6 % under the 1.22 kg total.
    "C409": (_controller(_rotors_yaml(mass_kg="1.2")), _controller(_rotors_yaml())),
    # RotorS' firefly.yaml inertia copied unchanged: xx 0.0348 against 0.0103.
    "C410": (_controller(_rotors_yaml(inertia="{xx: 0.0347563, xy: 0.0, xz: 0.0, "
                                              "yy: 0.0458929, yz: 0.0, zz: 0.0977}")),
             _controller(_rotors_yaml())),
    # Entry 3 without its direction (RotorS would keep its default).
    "C411": (_controller(_rotors_yaml(d=(3, "direction", ""))), _controller(_rotors_yaml())),
    # The mass in grams: 1220 written where kg is read, 1000x the model's 1.22 kg.
    "C452": (_controller(_rotors_yaml(mass_kg="1220")), _controller(_rotors_yaml())),
    # The inertia in g·m²: 1000x the model's.
    "C453": (_controller(_rotors_yaml(inertia="{xx: 10.334, xy: 0.0, xz: 0.0, yy: 10.334, "
                                              "yz: 0.0, zz: 19.353}")),
             _controller(_rotors_yaml())),
    # The yaw attitude gain's sign lost: -0.03 pushes the heading away from its setpoint.
    "C450": (_controller(_rotors_yaml(), _lee_gains(attitude_gain="{x: 0.89, y: 0.89, z: -0.03}")),
             _controller(_rotors_yaml(), _lee_gains())),
    # The roll attitude gain 100x (89 for 0.89): the sampled loop diverges at 100 Hz (and
    # rings, C454).
    "C451": (_controller(_rotors_yaml(), _lee_gains(attitude_gain="{x: 89, y: 0.89, z: 0.03}")),
             _controller(_rotors_yaml(), _lee_gains())),
    # The roll rate gain a third of the scaled Firefly's: damping ratio
    # 0.04 / (2 sqrt(0.89 x 0.010334)) = 0.21 (0.78 with 0.15), under 0.3.
    "C454": (_controller(_rotors_yaml(),
                         _lee_gains(angular_rate_gain="{x: 0.04, y: 0.15, z: 0.036}")),
             _controller(_rotors_yaml(), _lee_gains())),
    # The table names rotor 3's joint as rotor3_joint.
    "C402": (_x500(_velocity_control(("rotor_0_joint", "rotor_1_joint", "rotor_2_joint",
                                      "rotor3_joint"))), _x500(_velocity_control())),
    # Entries 2 and 3 swapped: speed 2 goes to the motor with motorNumber 3.
    "C403": (_x500(_velocity_control(("rotor_0_joint", "rotor_1_joint", "rotor_3_joint",
                                      "rotor_2_joint"))), _x500(_velocity_control())),
    "C412": (_x500(_velocity_control(com_link="")), _x500(_velocity_control())),
    # A hexacopter's CA_ROTOR_COUNT 6 kept on the x500's airframe (and C414: rotors 4 and 5
    # on no output).
    "C413": (_gz_px4(CA_ROTOR_COUNT="6"), _gz_px4()),
    # ESC output 4 disabled (SIM_GZ_EC_FUNC4 0): CA rotor 3 reaches no motor.
    "C414": (_gz_px4(SIM_GZ_EC_FUNC4="0"), _gz_px4()),
    # CA rotor 0's y in FLU (left positive) where FRD wants right: bearing -45° for the
    # front-right motor at +45°.
    "C415": (_gz_px4(CA_ROTOR0_PY="-0.174"), _gz_px4()),
    # CA_ROTOR2_KM positive (ccw) for the front-left motor, which turns cw.
    "C416": (_gz_px4(CA_ROTOR2_KM="0.016"), _gz_px4()),
    # PX4's x500 airframe value, |KM| 0.05: 3.12x the motors' momentConstant 0.016.
    "C417": (_gz_px4(**{f"CA_ROTOR{i}_KM": ("-" if i > 1 else "") + "0.05" for i in range(4)}),
             _gz_px4()),
    # SIM_GZ_EC_MAX 1200 on motors that stop at 1000 rad/s: the top 19 % of PX4's output
    # does nothing.
    "C419": (_gz_px4(**{f"SIM_GZ_EC_MAX{k}": "1200" for k in range(1, 5)}), _gz_px4()),
    # An idle of 800 rad/s, above the 769 rad/s each rotor needs to hold the 2.064 kg up:
    # sqrt(2.064 x 9.80665 / 4 / 8.54858e-06).
    "C420": (_gz_px4(**{f"SIM_GZ_EC_MIN{k}": "800" for k in range(1, 5)}), _gz_px4()),
    # PX4's default 0.5 where the model hovers at (769 - 150) / (1000 - 150) = 0.729.
    "C422": (_gz_px4(MPC_THR_HOVER="0.5"), _gz_px4()),
    # PX4's x500 airframe describes the real frame (0.13, 0.22); the model is a 0.174 m
    # square: 64 mm and 14.4° of bearing apart, same quadrant.
    "C423": (_gz_px4(**{f"CA_ROTOR{i}_P{a}": v for i, (x, y) in enumerate(
        (("0.13", "0.22"), ("-0.13", "-0.20"), ("0.13", "-0.22"), ("-0.13", "0.20")))
        for a, v in (("X", x), ("Y", y))}), _gz_px4()),
    # SIM_GZ_EC_MAX 900 on motors that reach 1000 rad/s: PX4 gets (900/1000)² = 81 % of the
    # thrust.
    "C424": (_gz_px4(**{f"SIM_GZ_EC_MAX{k}": "900" for k in range(1, 5)}), _gz_px4()),
    # Above PX4's documented 0.1..0.8 (the model hovers at 0.729, C421).
    "C425": (_gz_px4(MPC_THR_HOVER="0.85"), _gz_px4()),
    # Motors on gz-sim's X3 topic (gazebo/command/motor_speed), not the command/motor_speed
    # PX4's gz bridge publishes on.
    "C439": (_gz_px4(_x500(topic="gazebo/command/motor_speed")), _gz_px4()),
    # PX4's gz airframe (SIM_GZ_EN 1) on a Gazebo Classic (RotorS) model; the good one is
    # the Classic airframe for it (PWM_MAIN_FUNC outputs).
    "C435": (Case(_quad_extra(_mavlink_channels()),
                  (("4001_gz_x500", _px4_airframe(_GZ_AIRFRAME_HEADER, _GZ_PARAMS)),),
                  ("--airframe", "4001_gz_x500"), name="quad.urdf"), _classic_px4()),
    # PX4's iris channel values (input_scaling 1000, zero_position_armed 100) on 838 rad/s
    # motors: up to 1100 rad/s, the top 26 % does nothing (and C422: the hover moves to 0.492).
    "C436": (_classic_px4(scaling="1000"), _classic_px4()),
    # input_scaling 600: PX4's full output is 700 rad/s, (700/838)² = 70 % of the thrust.
    "C437": (_classic_px4(scaling="600"), _classic_px4()),
    # An armed idle of 650 rad/s (650 + 188 u: still up to 838), above the 592 rad/s each
    # rotor needs to hover.
    "C438": (_classic_px4(scaling="188", armed="650"), _classic_px4()),
    # A parameter file that leaves the frame to SITL's defaults: FRAME_CLASS unset.
    "C430": (_ardupilot(FRAME_CLASS=None), _ardupilot()),
    # FRAME_CLASS 2 (hexa) for the quad: six motors mixed for four rotors.
    "C431": (_ardupilot(FRAME_CLASS="2"), _ardupilot()),
    # FRAME_TYPE 0 (plus): motor 1 straight ahead at 90° from the nose, not at 45°.
    "C432": (_ardupilot(FRAME_TYPE="0"), _ardupilot()),
    # FRAME_TYPE 3 (H): the X positions with every spin reversed.
    "C433": (_ardupilot(FRAME_TYPE="3"), _ardupilot()),
    # Motor 4's output given to a camera gimbal (SERVO4_FUNCTION 0): the back-right rotor
    # gets no motor.
    "C434": (_ardupilot(SERVO4_FUNCTION="0"), _ardupilot()),
    # Rotor 0 allocated as a forward pusher (CA_ROTOR0_AX 1, AZ 0): 90° from its upward thrust.
    "C418": (_gz_px4(CA_ROTOR0_AX="1", CA_ROTOR0_AZ="0"), _gz_px4()),
    # Rotor 0's axis written 15° forward (AX 0.2588, AZ -0.9659) on a level rotor.
    "C426": (_gz_px4(CA_ROTOR0_AX="0.2588", CA_ROTOR0_AZ="-0.9659"), _gz_px4()),
    # Rotors rolled 0.2 rad (11.5°) in a balanced pattern, PX4's table left at its upward
    # default (the quadtailsitter's convention); the good airframe gives PX4 the axes.
    "C427": (_gz_px4(_tilted_x500(0.2)), _gz_px4(_tilted_x500(0.2), **_thrust_axes_frd(0.2))),
}
# The rules whose documentation carries a bad and a good example.
EXAMPLE_CODES = frozenset(EXAMPLES)

# code -> why no standalone example can show the rule (docs/rules.md says so on its page).
NO_EXAMPLE: dict[str, str] = {
    "C421": "Every PX4 airframe whose MPC_THR_HOVER is within 0.15 of the throttle the model "
            "needs gets this line, and one further off gets C422 instead: no model and "
            "airframe get neither, so there is no good example to show. C422's good example "
            "gives this line (MPC_THR_HOVER 0.73 beside the 0.729 the x500 needs), C422's "
            "bad one is the only way not to get it.",
}
