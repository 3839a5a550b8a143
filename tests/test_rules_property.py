"""Property test: random valid robots (URDF and SDF text) never crash any rule, and
broken ones (NaN, inf, 1e300, -0.0, dangling or self-parented joints, empty names)
neither; a broken number is reported by its reader alone.

Links in a tree of fixed/continuous/revolute joints, visuals that share mesh files
(tiny STL, COLLADA and OBJ written once per module), and rotors of every family: RotorS
gazebo_motor_model, gz-sim MulticopterMotorModel (actuator_number) and ArduPilotPlugin
control blocks. Findings are allowed (random inertia may well be implausible); an
exception from loading or from any registered rule is not.
"""

from __future__ import annotations

import itertools
import os
import re
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


def _joint_ends(i: int, joint: dict) -> tuple[str, str]:
    """Parent and child link names of broken joint i: itself, a ghost, empty, or (parent)
    an earlier link."""
    parent = {"self": f"l{i}", "ghost": "ghost", "": ""}.get(
        joint["parent"], f"l{joint['parent'] % i}" if isinstance(joint["parent"], int) else "")
    child = {"own": f"l{i}", "ghost": "ghost", "": ""}[joint["child"]]
    return parent, child


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
    # The runner turns a rule's exception into a finding with the rule's own code, worded
    # "internal error in this rule: ..." (validate exits 3): the codes alone cannot show a
    # crash, that wording does.
    crashed = [f"{f.code}: {f.message}" for f in findings
               if f.message.startswith("internal error in this rule")]
    assert not crashed
    known = {rule.code for rule in all_rules()}
    assert {f.code for f in findings} <= known


# ------------------------------------------------------------------ broken robots
# Every number may be NaN, inf, huge, a negative zero or a unit slip; joints may name a
# missing child, their own link as parent, or nothing; names may be empty. Findings are
# expected (that is the point); an exception, or a rule's internal error, is not.

# 60 examples each keep the suite fast (~2 s); REEDTOOL_PROPERTY_EXAMPLES=1000 for a
# deeper search (run before changing a reader or a rule's physics).
BROKEN_EXAMPLES = int(os.environ.get("REEDTOOL_PROPERTY_EXAMPLES", "60"))
WEIRD = ("nan", "inf", "-inf", "1e300", "-1e300", "-0.0", "0", "0.35m", "1e-300")
weird_number = st.one_of(st.sampled_from(WEIRD), number.map(repr))
triple = st.tuples(weird_number, weird_number, weird_number).map(" ".join)
broken_link = st.fixed_dictionaries({
    "name": st.sampled_from(["", "dup"]) | st.none(),       # None: the usual unique name
    "mass": weird_number,
    "inertia": st.tuples(*[weird_number] * 6),
    "com": triple,
    "box": triple,
    "radius": weird_number,
})
broken_joint = st.fixed_dictionaries({
    "parent": st.integers(min_value=0, max_value=100) | st.sampled_from(["self", "ghost", ""]),
    "child": st.sampled_from(["own", "own", "own", "ghost", ""]),
    "type": st.sampled_from(["continuous", "continuous", "fixed", "revolute", "bogus"]),
    "xyz": triple,
    "rpy": triple,
    "axis": triple,
    "limit": st.tuples(weird_number, weird_number),
    "rotor": st.none() | st.sampled_from(["rotors", "gz", "ardupilot"]),
    "constants": st.tuples(weird_number, weird_number, weird_number),   # k, km, w_max
    "number": st.sampled_from(["0", "1", "nan", "-1", "1e300", "x"]),
})
broken_robot = st.tuples(broken_link, st.lists(st.tuples(broken_joint, broken_link),
                                               min_size=1, max_size=5))


def broken_urdf(spec) -> str:
    root, joints = spec
    names = ["l0"] + [f"l{i}" for i in range(1, len(joints) + 1)]
    links = []
    for name, link in zip(names, [root] + [link for _j, link in joints]):
        name = name if link["name"] is None else link["name"]
        inertia = " ".join(f'{k}="{v}"' for k, v in zip(
            ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), link["inertia"]))
        links.append(
            f'<link name="{name}"><inertial><origin xyz="{link["com"]}"/>'
            f'<mass value="{link["mass"]}"/><inertia {inertia}/></inertial>'
            f'<collision><geometry><box size="{link["box"]}"/></geometry></collision>'
            f'<visual><geometry><cylinder radius="{link["radius"]}" length="0.01"/>'
            f"</geometry></visual></link>")
    parts, plugins = [], []
    for i, (joint, _link) in enumerate(joints, start=1):
        parent, child = _joint_ends(i, joint)
        lower, upper = joint["limit"]
        parts.append(
            f'<joint name="j{i}" type="{joint["type"]}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{joint["xyz"]}" rpy="{joint["rpy"]}"/>'
            f'<axis xyz="{joint["axis"]}"/><limit lower="{lower}" upper="{upper}" '
            f'effort="1" velocity="1"/></joint>')
        k, km, w_max = joint["constants"]
        common = (f"<jointName>j{i}</jointName><linkName>l{i}</linkName>"
                  f"<turningDirection>{'ccw' if i % 2 else 'cw'}</turningDirection>"
                  f"<motorConstant>{k}</motorConstant><momentConstant>{km}</momentConstant>"
                  f"<maxRotVelocity>{w_max}</maxRotVelocity>"
                  f"<timeConstantUp>{km}</timeConstantUp>"
                  f"<rotorDragCoefficient>{k}</rotorDragCoefficient>"
                  "<rotorVelocitySlowdownSim>10</rotorVelocitySlowdownSim>")
        if joint["rotor"] == "rotors":
            plugins.append(f'<plugin name="m{i}" filename="librotors_gazebo_motor_model.so">'
                           f'{common}<motorNumber>{joint["number"]}</motorNumber></plugin>')
        elif joint["rotor"] == "gz":
            plugins.append('<plugin filename="gz-sim-multicopter-motor-model-system" '
                           f'name="gz::sim::systems::MulticopterMotorModel">{common}'
                           f'<actuator_number>{joint["number"]}</actuator_number></plugin>')
        elif joint["rotor"] == "ardupilot":
            plugins.append(f'<plugin name="ArduPilotPlugin" filename="ArduPilotPlugin">'
                           f'<control channel="{joint["number"]}"><jointName>j{i}</jointName>'
                           f"<multiplier>{w_max}</multiplier><type>VELOCITY</type></control>"
                           "</plugin>")
    return (f'<?xml version="1.0"?>\n<robot name="r">{"".join(links)}{"".join(parts)}'
            f"<gazebo>{''.join(plugins)}</gazebo></robot>\n")


def broken_sdf(spec) -> str:
    """The same robot as SDF: poses on links, joints by name, plugins in the model."""
    urdf = broken_urdf(spec)
    root, joints = spec
    parts = []
    for i, link in enumerate([root] + [link for _j, link in joints]):
        name = f"l{i}" if link["name"] is None else link["name"]
        pose = "0 0 0 0 0 0" if i == 0 else \
            f'{joints[i - 1][0]["xyz"]} {joints[i - 1][0]["rpy"]}'
        ixx, ixy, ixz, iyy, iyz, izz = link["inertia"]
        parts.append(
            f'<link name="{name}"><pose>{pose}</pose><inertial><pose>{link["com"]} 0 0 0</pose>'
            f'<mass>{link["mass"]}</mass><inertia><ixx>{ixx}</ixx><ixy>{ixy}</ixy>'
            f"<ixz>{ixz}</ixz><iyy>{iyy}</iyy><iyz>{iyz}</iyz><izz>{izz}</izz></inertia>"
            f'</inertial><collision name="c"><geometry><box><size>{link["box"]}</size></box>'
            f'</geometry></collision><visual name="v"><geometry><cylinder><radius>'
            f'{link["radius"]}</radius><length>0.01</length></cylinder></geometry></visual>'
            "</link>")
    for i, (joint, _link) in enumerate(joints, start=1):
        parent, child = _joint_ends(i, joint)
        lower, upper = joint["limit"]
        parts.append(
            f'<joint name="j{i}" type="{joint["type"]}"><parent>{parent}</parent>'
            f'<child>{child}</child><axis><xyz>{joint["axis"]}</xyz><limit><lower>{lower}'
            f"</lower><upper>{upper}</upper></limit></axis></joint>")
    plugins = urdf[urdf.index("<gazebo>") + len("<gazebo>"):urdf.index("</gazebo>")]
    return (f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="r">{"".join(parts)}'
            f"{plugins}</model></sdf>\n")


def physics_of(robot) -> None:
    """What `inertia`, `hover-test` and `authority` compute: returns, or a ReedtoolError."""
    from reedtool.errors import ReedtoolError
    from reedtool.physics.inertia import whole_robot
    from reedtool.physics.kinematics import link_poses
    from reedtool.physics.rotors import discover_rotors, lift_rotors
    from reedtool.physics.trim import solve_trim, solve_trim_6dof

    for compute in (lambda: link_poses(robot), lambda: whole_robot(robot),
                    lambda: discover_rotors(robot)):
        try:
            compute()
        except ReedtoolError:
            pass
    for solve in (solve_trim, solve_trim_6dof):
        try:
            whole = whole_robot(robot)
            solve(whole.mass_kg, whole.com_m, lift_rotors(discover_rotors(robot)))
        except ReedtoolError:
            pass


# Valid robots of up to eight rotors (R350 searches six to eight) with one to three of
# their numbers broken, or one structural slip: what a typo or a bad xacro expression
# makes of a model that was fine. Only the reader's finding may speak of the number.
NUMBER_SITE = re.compile(r'(?<=[">\s])-?\d+(?:\.\d+)?(?:e-?\d+)?(?=[\s"<])')
STRUCTURE_SLIPS = (
    (r'<child link="l1"/>', '<child link="ghost"/>'),          # a dangling child
    (r'<parent link="l0"/><child link="l1"/>', '<parent link="l1"/><child link="l1"/>'),
    (r'<link name="l1">', '<link name="">'),                   # an empty name
    (r'<joint name="j1"', '<joint name=""'),
)
valid_robot = st.tuples(link_spec, st.lists(st.tuples(joint_spec, link_spec), min_size=1,
                                            max_size=8))


@st.composite
def damaged_model(draw) -> tuple[str, bool]:
    """(text, is SDF)."""
    as_sdf = draw(st.booleans())
    text = (robot_sdf if as_sdf else robot_urdf)(draw(valid_robot))
    if not as_sdf and draw(st.booleans()):
        old, new = draw(st.sampled_from(STRUCTURE_SLIPS))
        return text.replace(old, new, 1), as_sdf
    body = text.index("?>") + 2               # not the XML declaration's version="1.0"
    sites = [m.span() for m in NUMBER_SITE.finditer(text, body)]
    chosen = sorted(draw(st.sets(st.sampled_from(sites), min_size=1, max_size=3)),
                    reverse=True)
    for start, end in chosen:
        text = text[:start] + draw(st.sampled_from(WEIRD)) + text[end:]
    return text, as_sdf


# the readers' findings quote the raw text: S101/S102 a number, R316 a plugin value, R302 a
# <motorNumber> that is no integer, S168 the <sdf version> (libsdformat reads the
# document's version before anything else)
READER_CODES = {"S101", "S102", "R302", "R316", "S168"}
UNKNOWN_NUMBER = re.compile(r"(?<!['\"=])\b(nan|inf)\b", re.IGNORECASE)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # NaN arithmetic, by design
@settings(max_examples=BROKEN_EXAMPLES, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(model=damaged_model())
def test_a_broken_number_is_reported_by_its_reader_alone(model):
    from reedtool.checks.runner import has_internal_errors
    from reedtool.errors import ReedtoolError
    from reedtool.io.sdf import parse_sdf
    from reedtool.io.urdf import parse_urdf

    text, as_sdf = model
    try:
        robot = parse_sdf(text, "damaged.sdf") if as_sdf else parse_urdf(text, "damaged.urdf")
    except ReedtoolError:
        return
    findings = run_checks(robot)
    assert not [f"{f.code}: {f.message}" for f in findings if has_internal_errors([f])]
    cascades = [f"{f.code}: {f.message} / {f.hint}" for f in findings
                if f.code not in READER_CODES
                and UNKNOWN_NUMBER.search(f"{f.message} {f.hint or ''}")]
    assert not cascades
    physics_of(robot)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # NaN arithmetic, by design
@settings(max_examples=BROKEN_EXAMPLES, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(spec=broken_robot, as_sdf=st.booleans())
def test_every_rule_survives_broken_robots(spec, as_sdf):
    from reedtool.checks.runner import has_internal_errors
    from reedtool.errors import ReedtoolError
    from reedtool.io.sdf import parse_sdf
    from reedtool.io.urdf import parse_urdf

    try:
        robot = (parse_sdf(broken_sdf(spec), "broken.sdf") if as_sdf
                 else parse_urdf(broken_urdf(spec), "broken.urdf"))
    except ReedtoolError:
        return                      # refused as a whole with one line: allowed
    findings = run_checks(robot)
    crashed = [f"{f.code}: {f.message}" for f in findings if has_internal_errors([f])]
    assert not crashed
    physics_of(robot)
