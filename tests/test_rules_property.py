"""Property test: random valid robots (URDF and SDF text) never crash any rule.

Links in a tree of fixed/continuous/revolute joints, visuals that share mesh files
(tiny STL, COLLADA and OBJ written once per module), and rotors of every family: RotorS
gazebo_motor_model, gz-sim MulticopterMotorModel (actuator_number) and ArduPilotPlugin
control blocks. Findings are allowed (random inertia may well be implausible); an
exception from loading or from any registered rule is not.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mesh_helpers import box_triangles, write_dae, write_obj, write_stl

from reedtool.checks.registry import all_rules
from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot

MESHES = ("part.stl", "part.dae", "part_mm.dae", "part.obj")
_counter = itertools.count()


@pytest.fixture(scope="module")
def mesh_dir(tmp_path_factory) -> Path:
    directory = tmp_path_factory.mktemp("property")
    write_stl(directory / "part.stl", box_triangles((0.1, 0.05, 0.02)))
    write_dae(directory / "part.dae", box_triangles((0.1, 0.05, 0.02)))
    write_dae(directory / "part_mm.dae", box_triangles((100, 50, 20)), meter=0.001,
              up_axis="Y_UP", node_xml="<rotate>0 0 1 45</rotate>")
    write_obj(directory / "part.obj", box_triangles((0.1, 0.05, 0.02)))
    return directory


number = st.floats(min_value=1e-4, max_value=2.0, allow_nan=False)
shape = st.one_of(
    st.sampled_from(MESHES).map(lambda m: ("mesh", m)),
    st.tuples(st.just("box"), number, number, number),
    st.tuples(st.just("cylinder"), number, number),
    st.tuples(st.just("sphere"), number),
)
link_spec = st.fixed_dictionaries({
    "mass": st.one_of(st.just(0.0), number),
    "inertia": st.tuples(number, number, number) | st.just((0.0, 0.0, 0.0)),
    "visuals": st.lists(shape, max_size=3),
    "collision": st.none() | shape,
})
joint_spec = st.fixed_dictionaries({
    "parent": st.integers(min_value=0, max_value=100),
    "type": st.sampled_from(["fixed", "continuous", "revolute"]),
    "xyz": st.tuples(number, number, number),
    "rotor": st.none() | st.sampled_from(["rotors", "gz", "ardupilot"]),
    "ccw": st.booleans(),
})
robot_spec = st.tuples(link_spec, st.lists(st.tuples(joint_spec, link_spec), max_size=5))


def _geometry_urdf(g) -> str:
    kind = g[0]
    if kind == "mesh":
        return f'<mesh filename="{g[1]}" scale="1 1 1"/>'
    if kind == "box":
        return f'<box size="{g[1]} {g[2]} {g[3]}"/>'
    if kind == "cylinder":
        return f'<cylinder radius="{g[1]}" length="{g[2]}"/>'
    return f'<sphere radius="{g[1]}"/>'


def _geometry_sdf(g) -> str:
    kind = g[0]
    if kind == "mesh":
        return f"<mesh><uri>{g[1]}</uri><scale>1 1 1</scale></mesh>"
    if kind == "box":
        return f"<box><size>{g[1]} {g[2]} {g[3]}</size></box>"
    if kind == "cylinder":
        return f"<cylinder><radius>{g[1]}</radius><length>{g[2]}</length></cylinder>"
    return f"<sphere><radius>{g[1]}</radius></sphere>"


def _plugins(joints) -> str:
    out, channel = [], 0
    for i, (joint, _link) in enumerate(joints, start=1):
        family = joint["rotor"]
        if family is None or joint["type"] == "fixed":
            continue
        direction = "ccw" if joint["ccw"] else "cw"
        common = (f"<jointName>j{i}</jointName><linkName>l{i}</linkName>"
                  f"<turningDirection>{direction}</turningDirection>"
                  "<motorConstant>8.5e-06</motorConstant><momentConstant>0.016</momentConstant>"
                  "<maxRotVelocity>838</maxRotVelocity>"
                  "<rotorVelocitySlowdownSim>10</rotorVelocitySlowdownSim>")
        if family == "rotors":
            out.append(f'<plugin name="m{i}" filename="librotors_gazebo_motor_model.so">'
                       f"{common}<motorNumber>{i - 1}</motorNumber></plugin>")
        elif family == "gz":
            out.append(f'<plugin filename="gz-sim-multicopter-motor-model-system" '
                       f'name="gz::sim::systems::MulticopterMotorModel">{common}'
                       f"<actuator_number>{i - 1}</actuator_number></plugin>")
        else:
            sign = "" if joint["ccw"] else "-"
            out.append(f'<plugin name="ArduPilotPlugin" filename="ArduPilotPlugin">'
                       f'<control channel="{channel}"><jointName>j{i}</jointName>'
                       f"<multiplier>{sign}838</multiplier><type>VELOCITY</type>"
                       "<p_gain>0.2</p_gain></control></plugin>")
            channel += 1
    return "".join(out)


def robot_urdf(spec) -> str:
    root, joints = spec
    links, joint_xml = [("l0", root)], []
    for i, (joint, link) in enumerate(joints, start=1):
        parent = f"l{joint['parent'] % i}"
        limit = ('<limit lower="-1" upper="1" effort="1" velocity="1"/>'
                 if joint["type"] == "revolute" else "")
        x, y, z = joint["xyz"]
        joint_xml.append(f'<joint name="j{i}" type="{joint["type"]}"><parent link="{parent}"/>'
                         f'<child link="l{i}"/><origin xyz="{x} {y} {z}" rpy="0 0 0"/>'
                         f'<axis xyz="0 0 1"/>{limit}</joint>')
        links.append((f"l{i}", link))
    link_xml = []
    for name, link in links:
        ixx, iyy, izz = link["inertia"]
        body = (f'<inertial><mass value="{link["mass"]}"/><inertia ixx="{ixx}" ixy="0" ixz="0" '
                f'iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>')
        body += "".join(f"<visual><geometry>{_geometry_urdf(v)}</geometry></visual>"
                        for v in link["visuals"])
        if link["collision"] is not None:
            body += f"<collision><geometry>{_geometry_urdf(link['collision'])}</geometry></collision>"
        link_xml.append(f'<link name="{name}">{body}</link>')
    return (f'<?xml version="1.0"?>\n<robot name="r">{"".join(link_xml)}{"".join(joint_xml)}'
            f"<gazebo>{_plugins(joints)}</gazebo></robot>\n")


def robot_sdf(spec) -> str:
    root, joints = spec
    parts = []
    for i, link in enumerate([root] + [link for _j, link in joints]):
        pose = "0 0 0 0 0 0"
        if i:
            x, y, z = joints[i - 1][0]["xyz"]
            pose = f"{x} {y} {z} 0 0 0"
        ixx, iyy, izz = link["inertia"]
        body = (f"<pose>{pose}</pose><inertial><mass>{link['mass']}</mass><inertia>"
                f"<ixx>{ixx}</ixx><iyy>{iyy}</iyy><izz>{izz}</izz>"
                "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>")
        body += "".join(f'<visual name="v{k}"><geometry>{_geometry_sdf(v)}</geometry></visual>'
                        for k, v in enumerate(link["visuals"]))
        if link["collision"] is not None:
            body += f'<collision name="c"><geometry>{_geometry_sdf(link["collision"])}</geometry></collision>'
        parts.append(f'<link name="l{i}">{body}</link>')
    for i, (joint, _link) in enumerate(joints, start=1):
        limit = ("<limit><lower>-1</lower><upper>1</upper></limit>"
                 if joint["type"] == "revolute" else "")
        parts.append(f'<joint name="j{i}" type="{joint["type"]}"><parent>l{joint["parent"] % i}'
                     f"</parent><child>l{i}</child><axis><xyz>0 0 1</xyz>{limit}</axis></joint>")
    return (f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="r">{"".join(parts)}'
            f"{_plugins(joints)}</model></sdf>\n")


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow,
          HealthCheck.function_scoped_fixture])
@given(spec=robot_spec, as_sdf=st.booleans())
def test_every_rule_survives_random_valid_robots(mesh_dir, spec, as_sdf):
    path = mesh_dir / f"robot{next(_counter)}.{'sdf' if as_sdf else 'urdf'}"
    path.write_text(robot_sdf(spec) if as_sdf else robot_urdf(spec))
    robot = load_robot(path)
    findings = run_checks(robot)        # every registered rule, default selection
    known = {rule.code for rule in all_rules()}
    assert {f.code for f in findings} <= known
