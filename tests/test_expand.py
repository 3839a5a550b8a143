"""`reedtool expand` on the seed quadrotor, source mapping, and the error messages.

Oracles: check_urdf (urdfdom), yourdfpy, Pinocchio, pip's xacro itself (same expansion
without reedtool's hooks), and line numbers found by plain text search in the fixtures.
"""

from __future__ import annotations

import re
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from reedtool.errors import ReedtoolError
from reedtool.resolve.packages import BUNDLED_PACKAGES_DIR
from reedtool.io.xacro_expand import expand_xacro

FIXTURES = Path(__file__).parent / "fixtures"
SEED_URDF_DIR = FIXTURES / "seed000" / "reed_gazebo" / "urdf"
SEED_MODEL = SEED_URDF_DIR / "mav_generic_odometry_sensor.gazebo"
SEED_UNTOUCHED = SEED_URDF_DIR / "mav_generic_odometry_sensor.untouched.gazebo"
LAUNCH_ARGS = {  # what the seed's RotorS-style mav.launch passes
    "mav_name": "reed_quad_x", "namespace": "reed_quad_x",
    "enable_mavlink_interface": "true", "enable_ground_truth": "true",
    "enable_logging": "false", "log_file": "reed_quad_x", "wait_to_record_bag": "false",
}
from oracles import CHECK_URDF

A = 0.18738


def first_line(path: Path, needle: str, start: int = 1) -> int:
    """1-based number of the first line at or after `start` containing `needle`."""
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if number >= start and needle in line:
            return number
    raise AssertionError(f"{needle!r} not in {path}")


def elements(urdf_xml: str):
    root = etree.fromstring(urdf_xml.encode())
    return [e for e in root.iter() if isinstance(e.tag, str)]


@pytest.fixture(scope="module")
def seed():
    return expand_xacro(SEED_MODEL, LAUNCH_ARGS)


@pytest.fixture(scope="module")
def seed_urdf_file(seed, tmp_path_factory):
    path = tmp_path_factory.mktemp("seed") / "reed_quad_x.urdf"
    path.write_text(seed.urdf_xml)
    return path


# ------------------------------------------------------------- acceptance (issue 2)

def test_seed_passes_check_urdf(seed_urdf_file):
    result = subprocess.run([str(CHECK_URDF), str(seed_urdf_file)], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout


def test_seed_loads_in_yourdfpy_and_pinocchio(seed, seed_urdf_file):
    import pinocchio
    import yourdfpy

    urdf = yourdfpy.URDF.load(str(seed_urdf_file), load_meshes=False, build_scene_graph=True,
                              load_collision_meshes=False, build_collision_scene_graph=False)
    assert urdf.base_link == "reed_quad_x/base_link"
    assert {f"reed_quad_x/rotor_{i}" for i in range(4)} <= set(urdf.link_map)

    # a free-flyer root, as for any multirotor: otherwise fixed-to-world mass is not counted
    model = pinocchio.buildModelFromXML(seed.urdf_xml, pinocchio.JointModelFreeFlyer())
    data = model.createData()
    masses = [float(e.get("value")) for e in elements(seed.urdf_xml) if e.tag == "mass"]
    # 1.5 kg body, 4 x 5 g rotors, 15 g IMU, three 10 mg sensor links
    assert sum(masses) == pytest.approx(1.5 + 4 * 0.005 + 0.015 + 3e-5)
    assert pinocchio.computeTotalMass(model, data) == pytest.approx(sum(masses))
    assert model.nv == 6 + 4  # free flyer + the four continuous rotor joints; sensors are fixed


def test_seed_rotors_directions_constants_and_declared_count():
    from reedtool.io.loader import load_robot
    from reedtool.physics.rotors import declared_rotor_counts, discover_rotors

    robot = load_robot(SEED_MODEL, LAUNCH_ARGS)
    rotors = {r.plugin.name.removesuffix("_motor_model"): r for r in discover_rotors(robot)}
    expected = {"front_right": ((A, -A), "ccw"), "back_left": ((-A, A), "ccw"),
                "front_left": ((A, A), "cw"), "back_right": ((-A, -A), "cw")}
    assert sorted(rotors) == sorted(expected)
    for name, ((x, y), direction) in expected.items():
        # xacro arithmetic printed with Python's repr and read back: a few ulps of 0.2 m.
        np.testing.assert_allclose(rotors[name].position_m, [x, y, 0.026], atol=1e-12)
        np.testing.assert_allclose(rotors[name].axis, [0, 0, 1], atol=1e-12)
        assert rotors[name].direction == direction
        # Decimal constants through xacro text: exact (repr round trip); default rel 1e-6 below
        # is only a ceiling.
        assert rotors[name].motor_constant == pytest.approx(8.54858e-06, rel=1e-12)
        assert rotors[name].moment_constant == pytest.approx(0.016)
        assert rotors[name].max_rot_velocity_rad_s == pytest.approx(838)
    assert [d.rotor_count for d in declared_rotor_counts(robot)] == [6]


def test_untouched_seed_names_bad_parameter_line_and_spelling():
    with pytest.raises(ReedtoolError) as info:
        expand_xacro(SEED_UNTOUCHED, LAUNCH_ARGS)
    err = info.value
    assert Path(err.file).resolve() == SEED_UNTOUCHED.resolve()
    assert err.line == first_line(SEED_UNTOUCHED, "measurement_pisor=")
    text = err.one_line()
    assert "\n" not in text
    assert "measurement_pisor" in text and "'measurement_divisor'" in text
    assert "odometry_plugin_macro" in text


def test_fixture_rotors_description_on_package_path_wins():
    override = FIXTURES / "rotors_override"
    expansion = expand_xacro(SEED_MODEL, LAUNCH_ARGS, package_paths=[override])
    names = [e.get("name") for e in elements(expansion.urdf_xml)]
    assert "rotors_override_marker" in names
    assert expansion.resolver.find("rotors_description") == \
        (override / "rotors_description").absolute()
    macro_files = {Path(loc.macro_file).resolve() for loc in expansion.element_locs
                   if loc.macro_file}
    assert macro_files and all(str(f).startswith(str(override.resolve())) for f in macro_files)

    bundled = expand_xacro(SEED_MODEL, LAUNCH_ARGS)
    assert "rotors_override_marker" not in [e.get("name") for e in elements(bundled.urdf_xml)]
    assert bundled.resolver.find("rotors_description") == BUNDLED_PACKAGES_DIR / "rotors_description"


# ------------------------------------------------------------- source mapping

def test_element_locs_line_up_with_urdf_elements(seed):
    els = elements(seed.urdf_xml)
    assert len(els) == len(seed.element_locs)
    assert [loc.urdf_line for loc in seed.element_locs] == [e.sourceline for e in els]


def test_link_made_by_macro_maps_to_call_line_and_macro_body_line(seed):
    user_file = SEED_URDF_DIR / "reed_quad_x.xacro"
    calls = [n for n, line in enumerate(user_file.read_text().splitlines(), 1)
             if line.startswith("<xacro:vertical_rotor")]
    body = BUNDLED_PACKAGES_DIR / "rotors_description" / "urdf" / "multirotor_base.xacro"
    link_line = first_line(body, '<link name="${robot_namespace}/rotor_${motor_number}">')
    locs = {(e.tag, e.get("name")): loc for e, loc in zip(elements(seed.urdf_xml), seed.element_locs)}
    for motor, call_line in enumerate(calls):
        loc = locs[("link", f"reed_quad_x/rotor_{motor}")]
        assert Path(loc.file).resolve() == user_file.resolve()
        assert loc.line == call_line
        assert Path(loc.macro_file).resolve() == body.resolve()
        assert loc.macro_line == link_line


def test_literal_block_keeps_its_own_line_and_property_block_maps_to_its_macro_call(seed):
    user_file = SEED_URDF_DIR / "reed_quad_x.xacro"
    pairs = list(zip(elements(seed.urdf_xml), seed.element_locs))
    joint_origin = next(loc for e, loc in pairs if e.tag == "origin"
                        and e.getparent().get("name") == "reed_quad_x/rotor_0_joint")
    assert (Path(joint_origin.file).resolve(), joint_origin.line) == \
        (user_file.resolve(), first_line(user_file, "<origin xyz=\"${arm_length_front_x} -"))
    assert joint_origin.macro_file is None
    # the rotor inertia is produced by `xacro:box_inertia` inside the rotor_inertia block
    rotor_inertia = next(loc for e, loc in pairs if e.tag == "inertia"
                         and e.getparent().getparent().get("name") == "reed_quad_x/rotor_0")
    assert rotor_inertia.line == first_line(user_file, "<xacro:box_inertia")
    body_inertia = next(loc for e, loc in pairs if e.tag == "inertia"
                        and e.getparent().getparent().get("name") == "reed_quad_x/base_link_inertia")
    assert body_inertia.line == first_line(user_file, '<inertia ixx="0.0347563"')


def test_robot_element_and_top_level_file(seed):
    root_loc = seed.element_locs[0]
    assert Path(root_loc.file).resolve() == SEED_MODEL.resolve()
    assert root_loc.line == first_line(SEED_MODEL, "<robot ")


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def test_same_result_as_plain_xacro(tmp_path):
    """Our hooks must not change what xacro produces (no $(find) here, so xacro runs alone)."""
    import xacro

    _write(tmp_path, "parts.xacro", """
        <robot xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="leg" params="side reflect *origin **extra">
            <link name="${side}_leg"><xacro:insert_block name="extra"/></link>
            <joint name="${side}_hip" type="revolute">
              <xacro:insert_block name="origin"/>
              <parent link="base"/><child link="${side}_leg"/>
              <limit lower="${-reflect}" upper="${reflect}" effort="1" velocity="1"/>
            </joint>
          </xacro:macro>
        </robot>
        """)
    main = _write(tmp_path, "main.xacro", """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:arg name="with_tail" default="true"/>
          <xacro:property name="w" value="0.2"/>
          <xacro:include filename="parts.xacro"/>
          <link name="base"/>
          <xacro:leg side="l" reflect="1">
            <origin xyz="0 ${w/2} 0"/>
            <extra><visual><geometry><box size="${w} 1 1"/></geometry></visual></extra>
          </xacro:leg>
          <xacro:leg side="r" reflect="-1">
            <origin xyz="0 ${-w/2} 0"/>
            <extra/>
          </xacro:leg>
          <xacro:if value="$(arg with_tail)"><link name="tail"/></xacro:if>
          <xacro:unless value="$(arg with_tail)"><link name="no_tail"/></xacro:unless>
        </robot>
        """)
    for mappings in ({}, {"with_tail": "false"}):
        ours = expand_xacro(main, mappings)
        reference = xacro.process_file(str(main), mappings=dict(mappings)).toprettyxml(indent="  ")
        assert [(e.tag, dict(e.attrib), (e.text or "").strip()) for e in elements(ours.urdf_xml)] == \
            [(e.tag, dict(e.attrib), (e.text or "").strip()) for e in elements(reference)]
        assert len(ours.element_locs) == len(elements(ours.urdf_xml))


def test_expansion_is_reentrant_and_restores_xacro(seed):
    import xml.dom.minidom

    import xacro

    original_parse, original_clone = xacro.parse, xml.dom.minidom._clone_node
    again = expand_xacro(SEED_MODEL, LAUNCH_ARGS)
    assert again.urdf_xml == seed.urdf_xml
    assert again.element_locs == seed.element_locs
    assert xacro.parse is original_parse and xml.dom.minidom._clone_node is original_clone
    assert "_reedtool_pow" not in xacro._global_symbols


def test_macro_defined_in_user_file_maps_to_innermost_user_call(tmp_path):
    main = _write(tmp_path, "m.xacro", """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="inner" params="n">
            <link name="link_${n}"/>
          </xacro:macro>
          <xacro:macro name="outer" params="n">
            <xacro:inner n="${n}"/>
          </xacro:macro>
          <xacro:outer n="1"/>
        </robot>
        """)
    expansion = expand_xacro(main)
    loc = dict(zip([e.get("name") for e in elements(expansion.urdf_xml)], expansion.element_locs))["link_1"]
    # the innermost call in a user file is <xacro:inner> inside outer's body
    assert loc.line == first_line(main, '<xacro:inner n="${n}"/>')
    assert loc.macro_line == first_line(main, '<link name="link_${n}"/>')


# ------------------------------------------------------------- error messages

ERROR_CASES = {
    "unknown-parameter": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="wheel" params="radius width"><link name="w"/></xacro:macro>
          <xacro:wheel radius="1"
                       widht="2"/>
        </robot>"""}, "m.xacro", 'widht="2"', ["'wheel'", "'widht'", "did you mean 'width'"]),
    "missing-include": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <link name="a"/>
          <xacro:include filename="not_there.xacro"/>
        </robot>"""}, "m.xacro", "not_there", ["not_there.xacro", "No such file"]),
    "include-cycle": ({"a.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:include filename="b.xacro"/>
        </robot>""", "b.xacro": """
        <robot xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:include filename="a.xacro"/>
        </robot>"""}, "b.xacro", "a.xacro", ["include cycle", "a.xacro -> b.xacro -> a.xacro"]),
    "malformed-xml": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <link name="a">
          <joint name="j" type="fixed"/>
        </robot>"""}, "m.xacro", "</robot>", ["malformed XML", "mismatched tag"]),
    "undefined-property": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:property name="body_width" value="0.4"/>
          <link name="a"><visual><geometry>
            <box size="${body_widht} 1 1"/>
          </geometry></visual></link>
        </robot>"""}, "m.xacro", "body_widht", ["'body_widht'", "did you mean 'body_width'"]),
    "undefined-arg": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <link name="$(arg prefix)base"/>
        </robot>"""}, "m.xacro", "$(arg prefix)", ["'prefix'", "prefix:=VALUE"]),
    "unknown-macro": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="wheel" params=""><link name="w"/></xacro:macro>
          <xacro:wheal/>
        </robot>"""}, "m.xacro", "<xacro:wheal", ["xacro:wheal", "did you mean 'wheel'"]),
    "runaway-recursion": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="chain" params="n">
            <link name="l${n}"/>
            <xacro:chain n="${n+1}"/>
          </xacro:macro>
          <xacro:chain n="0"/>
        </robot>"""}, "m.xacro", '<xacro:chain n="${n+1}"/>', ["runaway", "chain"]),
    "runaway-expression": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <link name="${9**9**9}"/>
        </robot>"""}, "m.xacro", "9**9**9", ["run away", "9**9**9"]),
    "missing-package": ({"m.xacro": """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:include filename="$(find no_such_pkg)/urdf/x.xacro"/>
        </robot>"""}, "m.xacro", "no_such_pkg", ["'no_such_pkg'", "searched", "--package-path"]),
}


@pytest.mark.parametrize("case", sorted(ERROR_CASES))
def test_mistakes_are_one_line_errors_with_file_and_line(case, tmp_path):
    files, blamed, needle, words = ERROR_CASES[case]
    for name, text in files.items():
        _write(tmp_path, name, text)
    first = tmp_path / sorted(files)[0]
    with pytest.raises(ReedtoolError) as info:
        expand_xacro(first, {})
    err = info.value
    text = err.one_line()
    assert "\n" not in text
    assert Path(err.file).resolve() == (tmp_path / blamed).resolve(), text
    assert err.line == first_line(tmp_path / blamed, needle), text
    for word in words:
        assert word in text, text


def test_exponential_expansion_is_stopped_by_the_time_budget(tmp_path):
    main = _write(tmp_path, "m.xacro", """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:macro name="tree" params="n">
            <xacro:if value="${n > 0}">
              <xacro:tree n="${n-1}"/>
              <xacro:tree n="${n-1}"/>
            </xacro:if>
            <a/>
          </xacro:macro>
          <xacro:tree n="40"/>
        </robot>
        """)
    with pytest.raises(ReedtoolError, match="expansion stopped after 0.3 s") as info:
        expand_xacro(main, time_budget_s=0.3)
    assert Path(info.value.file).resolve() == main.resolve()


def test_xacro_warnings_are_collected_not_printed(tmp_path, capfd):
    main = _write(tmp_path, "m.xacro", """
        <robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
          <xacro:property name="x" value="1" colour="red"/>
          <link name="a${x}"/>
        </robot>
        """)
    expansion = expand_xacro(main)
    assert any("unknown attribute" in w and "colour" in w for w in expansion.warnings)
    assert capfd.readouterr().err == ""


# ------------------------------------------------------------- CLI

def run_cli(*args: str) -> int:
    from reedtool.cli import main

    with pytest.raises(SystemExit) as info:
        main(list(args))
    return info.value.code


def test_cli_writes_stdout_and_refuses_to_overwrite(tmp_path, capsys):
    argv = [str(SEED_MODEL), *(f"{k}:={v}" for k, v in LAUNCH_ARGS.items())]
    assert run_cli("expand", *argv) == 0
    out = capsys.readouterr().out
    assert len([e for e in elements(out) if e.tag == "link"]) == 10

    target = tmp_path / "out.urdf"
    target.write_text("keep me")
    assert run_cli("expand", *argv, "-o", str(target)) == 2
    assert "--force" in capsys.readouterr().err
    assert target.read_text() == "keep me"
    assert run_cli("expand", *argv, "-o", str(target), "--force") == 0
    assert target.read_text() == out


def test_cli_error_is_one_line_exit_2(capsys):
    assert run_cli("expand", str(SEED_UNTOUCHED),
                   *(f"{k}:={v}" for k, v in LAUNCH_ARGS.items())) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("reedtool: error: ")
    assert re.search(r"untouched\.gazebo:18: .*measurement_divisor", err[0])
