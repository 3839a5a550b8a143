"""What TinyXML2 (libsdformat) reads is read; what nobody reads stays a one-line error."""

import pytest
from lxml import etree

from reedtool.errors import ReedtoolError
from reedtool.io.tolerant_xml import local_tag, parse_tolerant


def test_strict_xml_has_nothing_tolerated():
    root, tolerated = parse_tolerant('<sdf version="1.9"><!-- a - b --><model name="m"/></sdf>',
                                     "f.sdf")
    assert root.find("model").get("name") == "m" and tolerated == []


def test_double_hyphen_in_comment_is_read_and_lines_are_kept():
    text = '<sdf version="1.6">\n<!--\n run --msgtype x --\n-->\n<model name="m"/>\n</sdf>\n'
    with pytest.raises(etree.XMLSyntaxError):
        etree.fromstring(text.encode())          # what strict tools say
    root, tolerated = parse_tolerant(text, "f.sdf")
    assert root.find("model").sourceline == 5
    assert [(t.line, t.what) for t in tolerated] == [(2, "'--' inside a comment")]


def test_undeclared_prefix_is_read_on_attributes_and_elements():
    text = ('<sdf version="1.9">\n<model name="m">\n<sensor name="f" gz:type="flow"/>\n'
            '<gz:extra>1</gz:extra>\n</model>\n</sdf>\n')
    root, tolerated = parse_tolerant(text, "f.sdf")
    sensor = root.find("model/sensor")
    assert sensor.sourceline == 3 and sensor.get("name") == "f"
    assert [local_tag(c) for c in root.find("model")] == ["sensor", "gz:extra"]
    assert [(t.line, t.what.split("'")[1]) for t in tolerated] == [(3, "gz:")]


def test_declared_prefix_is_not_reported():
    text = '<sdf xmlns:gz="http://gazebosim.org/schema"><model gz:x="1" name="m"/></sdf>'
    assert parse_tolerant(text, "f.sdf")[1] == []


@pytest.mark.parametrize("text, line", [
    ('<sdf>\n<model name="m">\n<link name="a">\n</model>\n</sdf>', 4),
    ('<sdf>\n<!-- a -- b -->\n<model name="m">\n</sdf>', 4),       # tolerated + broken
])
def test_malformed_xml_stays_a_one_line_error(text, line):
    with pytest.raises(ReedtoolError) as info:
        parse_tolerant(text, "f.sdf")
    assert info.value.line == line and "malformed XML" in info.value.message
    assert "\n" not in info.value.one_line()


def test_colons_in_text_and_values_are_not_prefixes():
    text = ('<sdf version="1.9">\n<!-- a -- b -->\n<model name="m">\n'
            '<uri a="x:y=1">model://m</uri>\n<note>see: a:b = c</note>\n</model>\n</sdf>\n')
    _root, tolerated = parse_tolerant(text, "f.sdf")
    assert [t.what for t in tolerated] == ["'--' inside a comment"]


# --------------------------------------------------- every format Gazebo reads with it

def test_collada_with_double_hyphen_comment_is_read(tmp_path):
    """assimp reads COLLADA leniently: a '--' comment (a CAD exporter's command line) is a
    mesh Gazebo shows, so reedtool reads its triangles too."""
    from reedtool.io.dae import parse_dae

    dae = ('<?xml version="1.0"?>\n<!-- exported -- with --units mm -->\n'
           '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">\n'
           '<asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>\n'
           '<library_geometries><geometry id="g"><mesh>\n'
           '<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>\n'
           '<technique_common><accessor source="#pa" count="3" stride="3">'
           '<param name="X" type="float"/><param name="Y" type="float"/>'
           '<param name="Z" type="float"/></accessor></technique_common></source>\n'
           '<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>\n'
           '<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/>'
           '<p>0 1 2</p></triangles>\n</mesh></geometry></library_geometries>\n'
           '<library_visual_scenes><visual_scene id="s"><node id="n">'
           '<instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>\n'
           '<scene><instance_visual_scene url="#s"/></scene>\n</COLLADA>\n')
    with pytest.raises(etree.XMLSyntaxError):
        etree.fromstring(dae.encode())
    mesh = parse_dae(dae.encode(), tmp_path / "part.dae")
    assert mesh.triangles.shape == (1, 3, 3)


def test_launch_file_with_double_hyphen_comment_is_read(tmp_path):
    from reedtool.io.launch import read_launch

    (tmp_path / "quad.urdf").write_text('<robot name="q"><link name="b"/></robot>')
    launch = tmp_path / "spawn.launch"
    launch.write_text('<launch>\n<!-- run with --screen -- or not -->\n'
                      '<arg name="model" default="$(dirname)/quad.urdf"/>\n'
                      '<param name="robot_description" command="$(find xacro)/xacro '
                      '$(arg model) mav_name:=q"/>\n</launch>\n')
    call = read_launch(launch)
    assert call.mappings.get("mav_name") == "q" and call.model.name == "quad.urdf"


def test_urdf_still_refuses_what_tinyxml2_refuses():
    from reedtool.io.urdf import parse_urdf

    with pytest.raises(ReedtoolError) as exc:
        parse_urdf('<robot name="r">\n<link name="a">\n</robot>\n', "r.urdf")
    assert exc.value.line is not None and "malformed XML" in exc.value.message


@pytest.mark.parametrize("text, what, line", [
    # PX4 classic's generated depth_camera.sdf: a comment line, then the declaration.
    ('<!-- generated -->\n<?xml version="1.0"?>\n<sdf version="1.6"><model name="m"/></sdf>\n',
     "XML declaration after a comment (TinyXML2, so gz-sim, refuses it)", 2),
    # PX4 classic's cloudship.sdf: blank lines before the declaration.
    ('\n\n\n<?xml version="1.0"?>\n<sdf version="1.6"><model name="m"/></sdf>\n',
     "XML declaration not at the start (after blank lines)", 4),
])
def test_misplaced_xml_declaration_is_read(text, what, line):
    with pytest.raises(etree.XMLSyntaxError):
        etree.fromstring(text.encode())
    root, tolerated = parse_tolerant(text, "f.sdf")
    assert root.find("model").get("name") == "m"
    assert [(t.line, t.what) for t in tolerated] == [(line, what)]


def test_angle_bracket_in_attribute_and_bare_ampersand_are_read_as_text():
    """An STL converter's `<node id="<STL_BINARY>">` and the MRS meshes' `Motor&Proplr`:
    TinyXML2 reads both characters as they are; so does reedtool, lines kept."""
    text = ('<COLLADA>\n<node id="<STL_BINARY>"/>\n<node name="MOTOR Motor&Proplr">a &amp; b</node>'
            '\n<!-- a & b < c -->\n<x/>\n</COLLADA>\n')
    root, tolerated = parse_tolerant(text, "part.dae")
    nodes = root.findall("node")
    assert nodes[0].get("id") == "<STL_BINARY>" and nodes[0].sourceline == 2
    assert nodes[1].get("name") == "MOTOR Motor&Proplr" and nodes[1].text == "a & b"
    assert root.find("x").sourceline == 5
    assert sorted((t.line, t.what) for t in tolerated) == [
        (2, "'<' inside an attribute value"), (3, "'&' that starts no entity")]


def test_late_declaration_is_a_warning_only_for_models_not_made_for_gazebo_classic(tmp_path):
    """S124's fixture has no plugin (gz-sim may load it: warning). With a Gazebo classic
    plugin it is loaded by TinyXML, which reads it: S119 alone."""
    from pathlib import Path

    from reedtool.checks.runner import run_checks
    from reedtool.io.loader import load_robot

    fixture = Path(__file__).parent / "fixtures" / "validate" / \
        "S124_bad_comment_before_declaration.sdf"
    text = fixture.read_text().replace(
        "  </model>", '    <plugin name="imu" filename="libgazebo_imu_plugin.so"/>\n  </model>')
    path = tmp_path / "classic.sdf"
    path.write_text(text)
    assert sorted(f.code for f in run_checks(load_robot(path))) == ["S119"]
