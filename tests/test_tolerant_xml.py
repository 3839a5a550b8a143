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
