"""Legacy xacro: detection with lines, and the --fix-legacy rewrite (seed 001 smartcar)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from lxml import etree

from reedtool.io.legacy_xacro import scan_and_fix
from reedtool.io.xacro_expand import expand_xacro, scan_legacy

FIXTURES = Path(__file__).parent / "fixtures" / "smartcar"
LEGACY = FIXTURES / "legacy" / "smartcar_description" / "urdf"
FIXED = FIXTURES / "fixed" / "smartcar_description" / "urdf"
MAIN = "smartcar.urdf.xacro"
from oracles import CHECK_URDF


def tag_lines(path: Path, pattern: str) -> list[int]:
    return [n for n, line in enumerate(path.read_text().splitlines(), 1) if re.search(pattern, line)]


def run_cli(*args: str) -> int:
    from reedtool.cli import main

    with pytest.raises(SystemExit) as info:
        main(list(args))
    return info.value.code


def test_smartcar_legacy_tags_reported_with_lines():
    scan = scan_legacy(LEGACY / MAIN)
    found = sorted((Path(t.file).name, t.line, t.tag, t.modern) for t in scan.tags)
    body, main = LEGACY / "smartcar_body.urdf.xacro", LEGACY / MAIN
    expected = sorted(
        [("smartcar_body.urdf.xacro", n, "property", "xacro:property")
         for n in tag_lines(body, r"<property ")]
        + [("smartcar_body.urdf.xacro", n, "include", "xacro:include")
           for n in tag_lines(body, r"<include ")]
        + [(MAIN, n, "include", "xacro:include") for n in tag_lines(main, r"<include ")]
        + [(MAIN, n, "smartcar_body", "xacro:smartcar_body")
           for n in tag_lines(main, r"<smartcar_body/>")])
    assert len(expected) == 6
    assert found == expected


def test_fixed_copy_has_no_legacy_tags():
    assert scan_legacy(FIXED / MAIN).tags == []


def test_cli_refuses_legacy_and_lists_each_tag(capsys):
    assert run_cli("expand", str(LEGACY / MAIN)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len([line for line in err if "-> write <xacro:" in line]) == 6
    assert err[-1].startswith("reedtool: error: ") and "--fix-legacy" in err[-1]


def test_fix_legacy_rewrites_like_the_hand_fixed_copy(tmp_path, capsys):
    work = tmp_path / "smartcar_description"
    shutil.copytree(LEGACY.parent, work)
    originals = {p.name: p.read_text() for p in (work / "urdf").iterdir()}
    out = tmp_path / "smartcar.urdf"
    assert run_cli("expand", str(work / "urdf" / MAIN), "--fix-legacy", "-o", str(out)) == 0
    for name in originals:
        assert (work / "urdf" / name).read_text() == (FIXED / name).read_text(), name
    # backups hold the user's original text, only for files that changed
    for name, text in originals.items():
        backup = work / "urdf" / (name + ".bak")
        assert backup.exists() == (text != (FIXED / name).read_text())
        if backup.exists():
            assert backup.read_text() == text

    root = etree.parse(str(out)).getroot()
    assert len(root.findall("link")) == 6 and len(root.findall("joint")) == 5
    result = subprocess.run([CHECK_URDF, str(out)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr


def test_in_memory_translation_gives_the_fixed_model():
    legacy = expand_xacro(LEGACY / MAIN)
    fixed = expand_xacro(FIXED / MAIN)
    strip = lambda xml: [(e.tag, dict(e.attrib)) for e in etree.fromstring(xml.encode()).iter()
                         if isinstance(e.tag, str)]
    assert strip(legacy.urdf_xml) == strip(fixed.urdf_xml)
    assert len(legacy.legacy) == 6 and fixed.legacy == []
    # the links come from the (legacy-called) macro: they map to the <smartcar_body/> line
    els = [e for e in etree.fromstring(legacy.urdf_xml.encode()).iter() if isinstance(e.tag, str)]
    loc = dict(zip([(e.tag, e.get("name")) for e in els], legacy.element_locs))[("link", "head")]
    assert (Path(loc.file).name, loc.line) == (MAIN, tag_lines(LEGACY / MAIN, "<smartcar_body/>")[0])
    body = LEGACY / "smartcar_body.urdf.xacro"
    assert (Path(loc.macro_file).name, loc.macro_line) == (body.name, tag_lines(body, '<link name="head">')[0])


def test_scanner_ignores_comments_cdata_and_prefixed_tags():
    text = ('<robot xmlns:xacro="http://ros.org/wiki/xacro">\n'
            '<!-- <property name="a" value="1"/> -->\n'
            '<xacro:property name="b" value="2"/>\n'
            '<gazebo><include><uri>model://x</uri></include></gazebo>\n'
            '<property name="c">\n  <inertia ixx="1"/>\n</property>\n'
            '</robot>\n')
    tags, fixed = scan_and_fix(text, "f.xacro", set())
    assert [(t.line, t.tag) for t in tags] == [(5, "property")]
    assert '<xacro:property name="c">' in fixed and "</xacro:property>" in fixed
    assert '<!-- <property name="a" value="1"/> -->' in fixed
    assert fixed.count("\n") == text.count("\n")


def test_fix_adds_missing_xacro_namespace():
    tags, fixed = scan_and_fix('<robot name="r">\n<property name="a" value="1"/>\n</robot>\n',
                               "f.xacro", set())
    assert len(tags) == 1
    root = etree.fromstring(fixed.encode())
    assert root.nsmap.get("xacro") == "http://ros.org/wiki/xacro"


def test_gazebo_plugin_parameter_named_like_a_macro_is_not_a_macro_call():
    # gz-sim's <rotorConfiguration><rotor> inside a <gazebo> block, in a file that also
    # defines a macro called `rotor`: only the unprefixed call outside <gazebo> is legacy.
    from reedtool.io.legacy_xacro import scan_and_fix

    text = """<robot xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:macro name="rotor" params="n"><link name="r${n}"/></xacro:macro>
  <rotor n="1"/>
  <gazebo>
    <plugin name="gz::sim::systems::MulticopterVelocityControl" filename="x">
      <rotorConfiguration><rotor><jointName>j</jointName></rotor></rotorConfiguration>
    </plugin>
  </gazebo>
</robot>
"""
    tags, fixed = scan_and_fix(text, "m.xacro", {"rotor"})
    assert [(t.line, t.kind) for t in tags] == [(3, "macro-call")]
    assert "<xacro:rotor n=\"1\"/>" in fixed and "<rotor><jointName>" in fixed
