"""Bad input never ends in a traceback: one line on stderr naming the file, exit 2.

One table of (command line, exit code, fragment the line must contain) over every
subcommand, run in-process in one scratch directory; plus the cases where a finding, not
an error, is the right answer (asserted by rule code), and the "nothing is lost" checks
(no temporary file or half import left behind, file modes, encodings kept).
"""

from __future__ import annotations

import codecs
import json
import os
import stat
import struct
import time
from pathlib import Path

import pytest

from reedtool.cli import main

# A two-link URDF; each variant replaces one field. Lines: 4 <mass>, 10 joint <origin>.
URDF = """<?xml version="1.0"?>
<robot{robot_name}>
  <link name="base_link">
    <inertial><mass value="{mass}"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial>
    <collision><geometry>{geometry}</geometry></collision>
  </link>
  <joint name="j" type="{joint_type}">
    <parent link="{parent}"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="{rpy}"/><axis xyz="0 0 1"/>
  </joint>
  <link name="arm">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>{extra}
</robot>
"""


def urdf(**changes) -> str:
    fields = dict(robot_name=' name="r"', mass="1.5", geometry='<box size="0.2 0.2 0.1"/>',
                  joint_type="continuous", parent="base_link", rpy="0 0 0", extra="")
    fields.update(changes)
    return URDF.format(**fields)


def binary_stl(triangles, count=None) -> bytes:
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *(c for v in t for c in v), 0)
                    for t in triangles)
    return b"x".ljust(80) + struct.pack("<I", len(triangles) if count is None else count) + body


TETRA = [((0, 0, 0), (0, 0.1, 0), (0.1, 0, 0)), ((0, 0, 0), (0.1, 0, 0), (0, 0, 0.1)),
         ((0, 0, 0), (0, 0, 0.1), (0, 0.1, 0)), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1))]
XACRO = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n{}\n  <link name="a"/>\n</robot>\n'
LAUGHS = ('<?xml version="1.0"?>\n<!DOCTYPE r [\n <!ENTITY a "aaaaaaaaaa">\n'
          + "".join(f' <!ENTITY {n} "{("&" + p + ";") * 10}">\n'
                    for n, p in zip("bcdefghij", "abcdefghi"))
          + ']>\n<robot name="&j;"><link name="l"/></robot>\n')

# A quad with RotorS motor plugins (tests/fixtures/core); variants break one plugin value.
QUAD = (Path(__file__).parent / "fixtures" / "core" / "quad_x_rotors.urdf").read_text()
DRAG_ABC = QUAD.replace("<rotorDragCoefficient>8.06428e-05<", "<rotorDragCoefficient>abc<", 1)
DRAG_ABC_LINE = DRAG_ABC[:DRAG_ABC.index(">abc<")].count("\n") + 1

FILES: dict[str, str | bytes] = {
    "drag_abc.urdf": DRAG_ABC,
    "rotor_count_abc.urdf": QUAD.replace("<rotorCount>6</rotorCount>", "<rotorCount>abc</rotorCount>"),
    "model.urdf": urdf(),
    "empty.urdf": "",
    "garbage.urdf": bytes(range(256)) * 4,
    "laughs.urdf": LAUGHS,
    "mass_nan.urdf": urdf(mass="nan"),
    "mass_word.urdf": urdf(mass="heavy"),
    "rpy2.urdf": urdf(rpy="0 0"),
    "noname.urdf": urdf(robot_name=""),
    "self_parent.urdf": urdf(parent="arm"),
    "revolute.urdf": urdf(joint_type="revolute"),
    "dup_link.urdf": urdf(extra='\n  <link name="arm"/>'),
    "nolinks.urdf": '<robot name="r"/>',
    "empty_mesh.urdf": urdf(geometry='<mesh filename="empty.stl"/>'),
    "tetra.stl": binary_stl(TETRA),
    "empty.stl": b"",
    "truncated.stl": binary_stl(TETRA)[:-20],
    "nan.stl": "solid x\nfacet normal 0 0 0\nouter loop\nvertex nan 0 0\nvertex 1 0 0\n"
               "vertex 0 1 0\nendloop\nendfacet\nendsolid x\n",
    "loop.xacro": XACRO.format('  <xacro:macro name="loop"><xacro:loop/></xacro:macro>\n'
                               '  <xacro:loop/>'),
    "range.xacro": XACRO.format('  <link name="${len([x for x in range(10**9)])}"/>'),
    "factorial.xacro": XACRO.format('  <link name="${factorial(10**7)}"/>'),
    "include.xacro": XACRO.format('  <xacro:include filename="$(arg f)"/>'),
    "env.xacro": XACRO.format('  <link name="$(env REEDTOOL_NO_SUCH_VARIABLE)"/>'),
    "nopkg.xacro": XACRO.format('  <xacro:include filename="$(find no_such_pkg)/x.xacro"/>'),
    "pkg/package.xml": "<package format=\"3\"><name>pkg</name></package>",
    "spec_binary.yaml": b"\xff\xfe\x00mass: 1",
    "spec_frame.yaml": "frame: banana\n",
    "spec_list.yaml": "- 1\n- 2\n",
    "spec_license.yaml": "license: [a, b]\n",
    "spec_negative.yaml": "mass: -1\n",
    "a_file": "",
}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("bad_input")
    for name, content in FILES.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    (root / "a_dir").mkdir()
    (root / "zero.urdf").symlink_to("/dev/zero")
    return root


def run(args, capsys) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as exit_info:
        main([str(a) for a in args])
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


# (id, command line, exit code, fragment of the one error line)
CASES = [
    # --- any model-reading command: the file itself
    ("validate-empty", ["validate", "empty.urdf"], 2, "empty.urdf:1"),
    ("validate-binary", ["validate", "garbage.urdf"], 2, "garbage.urdf"),
    ("inertia-binary", ["inertia", "garbage.urdf"], 2, "not valid UTF-8"),
    ("validate-device", ["validate", "zero.urdf"], 2, "zero.urdf"),
    ("validate-billion-laughs", ["validate", "laughs.urdf"], 2, "laughs.urdf"),
    ("expand-billion-laughs", ["expand", "laughs.urdf"], 2, "laughs.urdf"),
    ("inertia-directory", ["inertia", "a_dir"], 2, "a_dir"),
    ("hover-directory", ["hover-test", "a_dir"], 2, "a_dir"),
    # --- models urdfdom would silently mangle: refused with the line, not computed on
    ("inertia-mass-nan", ["inertia", "mass_nan.urdf"], 2, "mass_nan.urdf:4"),
    ("hover-mass-nan", ["hover-test", "mass_nan.urdf"], 2, "mass_nan.urdf:4"),
    ("hover-mass-word", ["hover-test", "mass_word.urdf"], 2, "mass_word.urdf:4"),
    ("inertia-rpy-two-numbers", ["inertia", "rpy2.urdf"], 2, "rpy2.urdf:10"),
    ("inertia-no-robot-name", ["inertia", "noname.urdf"], 2, "noname.urdf:2"),
    ("inertia-joint-own-parent", ["inertia", "self_parent.urdf"], 2, "cycle"),
    ("hover-revolute-no-limit", ["hover-test", "revolute.urdf"], 2, "revolute.urdf:8"),
    ("inertia-duplicate-link", ["inertia", "dup_link.urdf"], 2, "dup_link.urdf:15"),
    ("hover-no-links", ["hover-test", "nolinks.urdf"], 2, "nolinks.urdf"),
    # --- xacro
    ("expand-recursion", ["expand", "loop.xacro"], 2, "loop.xacro:"),
    ("expand-huge-range", ["expand", "range.xacro"], 2, "range.xacro:2"),
    ("expand-huge-factorial", ["expand", "factorial.xacro"], 2, "factorial.xacro:2"),
    ("expand-include-device", ["expand", "include.xacro", "f:=/dev/zero"], 2, "/dev/zero"),
    ("expand-env-unset", ["expand", "env.xacro"], 2, "env.xacro:2"),
    ("expand-no-package", ["expand", "nopkg.xacro"], 2, "no_such_pkg"),
    ("expand-arg-no-separator", ["expand", "loop.xacro", "foo"], 2, "'foo'"),
    ("expand-arg-two-separators", ["expand", "loop.xacro", "a:=b:=c"], 2, "a:=b:=c"),
    ("validate-arg-blank-name", ["validate", "model.urdf", " :=1"], 2, "' :=1'"),
    ("hover-arg-no-name", ["hover-test", "model.urdf", ":=x"], 2, "':=x'"),
    # --- options
    ("validate-unknown-format", ["validate", "model.urdf", "--format", "xml"], 2, "--format"),
    ("validate-empty-select", ["validate", "model.urdf", "--select", ""], 2, "--select"),
    ("validate-controller-binary", ["validate", "model.urdf", "--controller", "garbage.urdf"],
     2, "garbage.urdf"),
    # Written but unreadable drag would otherwise fly as "no drag" and pass.
    ("hover-drag-unreadable", ["hover-test", "drag_abc.urdf"], 2, f"drag_abc.urdf:{DRAG_ABC_LINE}"),
    ("hover-zero-samples", ["hover-test", "model.urdf", "--samples", "0"], 2, "--samples"),
    ("hover-negative-seed", ["hover-test", "model.urdf", "--samples", "2", "--seed", "-1"],
     2, "--seed"),
    ("hover-nan-spread", ["hover-test", "model.urdf", "--samples", "2", "--com-spread", "nan"],
     2, "--com-spread"),
    ("hover-nan-pass-rate", ["hover-test", "model.urdf", "--min-pass-rate", "nan"],
     2, "--min-pass-rate"),
    ("hover-endless-duration", ["hover-test", "model.urdf", "--duration", "1e9"], 2, "--duration"),
    ("hover-too-many-steps", ["hover-test", "model.urdf", "--duration", "1e4", "--rate", "1e4"],
     2, "steps"),
    ("hover-zero-rate", ["hover-test", "model.urdf", "--rate", "0"], 2, "rate"),
    ("hover-negative-duration", ["hover-test", "model.urdf", "--duration", "-1"], 2, "duration"),
    # --- import-stl
    ("stl-empty", ["import-stl", "empty.stl", "--package", "pkg"], 2, "empty.stl"),
    ("stl-truncated", ["import-stl", "truncated.stl", "--package", "pkg"], 2, "truncated.stl"),
    ("stl-nan", ["import-stl", "nan.stl", "--package", "pkg"], 2, "nan.stl"),
    ("stl-no-package-xml", ["import-stl", "tetra.stl", "--package", "a_dir"], 2, "a_dir"),
    ("stl-negative-mass", ["import-stl", "tetra.stl", "--package", "pkg", "--mass", "-1"],
     2, "--mass"),
    ("stl-zero-density", ["import-stl", "tetra.stl", "--package", "pkg", "--density", "0"],
     2, "--density"),
    ("stl-simplify-word", ["import-stl", "tetra.stl", "--package", "pkg", "--collision",
                           "simplify:abc"], 2, "simplify:abc"),
    ("stl-simplify-zero", ["import-stl", "tetra.stl", "--package", "pkg", "--collision",
                           "simplify:0"], 2, "simplify:0"),
    ("stl-snippet-below-a-file", ["import-stl", "tetra.stl", "--package", "pkg", "--snippet",
                                  "a_file/s.xml"], 2, "a_file"),
    ("stl-snippet-unwritable", ["import-stl", "tetra.stl", "--package", "pkg", "--snippet",
                                "/proc/reedtool-snippet.xml"], 2, "/proc/reedtool-snippet.xml"),
    ("stl-directory", ["import-stl", "a_dir", "--package", "pkg"], 2, "a_dir"),
    # --- new-package
    ("new-bad-name", ["new-package", "Bad-Name"], 2, "Bad-Name"),
    ("new-output-is-a-file", ["new-package", "x", "-o", "a_file"], 2, "a_file"),
    ("new-spec-binary", ["new-package", "x", "--spec", "spec_binary.yaml"], 2, "spec_binary.yaml"),
    ("new-spec-device", ["new-package", "x", "--spec", "/dev/zero"], 2, "/dev/zero"),
    ("new-spec-unknown-frame", ["new-package", "x", "--spec", "spec_frame.yaml"],
     2, "spec_frame.yaml"),
    ("new-spec-is-a-list", ["new-package", "x", "--spec", "spec_list.yaml"], 2, "spec_list.yaml"),
    ("new-spec-license-list", ["new-package", "x", "--spec", "spec_license.yaml"],
     2, "license"),
    ("new-spec-negative-mass", ["new-package", "x", "--spec", "spec_negative.yaml"],
     2, "spec_negative.yaml"),
]


@pytest.mark.parametrize("args, code, fragment", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_bad_input_is_one_line(workdir, monkeypatch, capsys, args, code, fragment):
    monkeypatch.chdir(workdir)
    before = set(workdir.rglob("*"))
    exit_code, _out, err = run(args, capsys)
    left_behind = sorted(set(workdir.rglob("*")) - before, reverse=True)
    for path in left_behind:   # keep the shared directory clean for the other cases
        path.rmdir() if path.is_dir() and not path.is_symlink() else path.unlink()
    assert exit_code == code, err
    assert "Traceback" not in err and "internal error" not in err
    assert err.count("\n") == 1 and err.startswith("reedtool: error: "), err
    assert fragment in err
    assert not left_behind, "a failed command left files behind (temporary or half-written)"


# Where the model is readable but wrong, validate reports a rule, not an error.
FINDINGS = [
    ("noname.urdf", "S101"),
    ("mass_nan.urdf", "S102"),
    ("nolinks.urdf", "S104"),
    ("self_parent.urdf", "S109"),
    ("empty_mesh.urdf", "S115"),
    ("rotor_count_abc.urdf", "R312"),   # not a whole number: was silently dropped
]


@pytest.mark.parametrize("model, code", FINDINGS)
def test_validate_reports_a_finding(workdir, monkeypatch, capsys, model, code):
    monkeypatch.chdir(workdir)
    exit_code, out, err = run(["validate", model, "--format", "json"], capsys)
    assert exit_code == 1 and err == ""
    assert code in {f["code"] for f in json.loads(out)["findings"]}


def test_runaway_expression_is_stopped_by_the_clock(tmp_path):
    from reedtool.errors import ReedtoolError
    from reedtool.io.xacro_expand import expand_xacro

    model = tmp_path / "nested.xacro"
    model.write_text(XACRO.format(
        "  <link name=\"${len([1 for a in 'a'*9999999 for b in 'a'*9999999])}\"/>"))
    start = time.monotonic()
    with pytest.raises(ReedtoolError) as error:
        expand_xacro(model, time_budget_s=0.2)
    assert time.monotonic() - start < 5
    assert error.value.line == 2 and "nested.xacro" in error.value.file


def test_new_files_get_the_usual_mode(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "m.xacro").write_text(XACRO.format(""))
    old_mask = os.umask(0o022)
    try:
        assert run(["expand", "m.xacro", "-o", "out/m.urdf"], capsys)[0] == 0
    finally:
        os.umask(old_mask)
    assert stat.S_IMODE((tmp_path / "out" / "m.urdf").stat().st_mode) == 0o644


@pytest.mark.parametrize("encoding, declaration", [
    ("iso-8859-1", '<?xml version="1.0" encoding="ISO-8859-1"?>\n'),
    ("utf-16", '<?xml version="1.0" encoding="UTF-16"?>\n'),
    ("utf-8-sig", '<?xml version="1.0"?>\n'),
])
def test_xml_in_any_declared_encoding_is_read(tmp_path, encoding, declaration):
    from lxml import etree

    from reedtool.io.loader import load_robot

    path = tmp_path / "enc.urdf"
    text = declaration + '<robot name="r\u00e9"><link name="b\u00e4se"/></robot>\n'
    path.write_bytes(text.encode(encoding))
    robot = load_robot(path)
    reference = etree.parse(str(path)).getroot()   # libxml2 decodes it on its own
    assert robot.name == reference.get("name") == "r\u00e9"
    assert [link.name for link in robot.links] == ["b\u00e4se"]


def test_inertia_fix_keeps_the_file_encoding(tmp_path, monkeypatch, capsys):
    from lxml import etree

    monkeypatch.chdir(tmp_path)
    text = urdf(robot_name=' name="r\u00e9"').replace('<?xml version="1.0"?>',
                                                      '<?xml version="1.0" encoding="ISO-8859-1"?>')
    Path("m.urdf").write_bytes(text.encode("iso-8859-1"))
    code, _out, err = run(["inertia", "m.urdf", "--fix"], capsys)
    assert code in (0, 1) and "error" not in err
    root = etree.parse("m.urdf").getroot()
    assert root.get("name") == "r\u00e9"
    assert Path("m.urdf").read_bytes() != text.encode("iso-8859-1")   # it did fix something
    assert Path("m.urdf.bak").read_bytes() == text.encode("iso-8859-1")


def test_package_xml_escapes_user_text(tmp_path, monkeypatch, capsys):
    from catkin_pkg.package import parse_package
    from lxml import etree

    monkeypatch.chdir(tmp_path)
    Path("spec.yaml").write_text('description: "Tom & Jerry <drone>"\n'
                                 'maintainer: "A & B"\nmaintainer_email: "ab@example.com"\n')
    assert run(["new-package", "tj", "--spec", "spec.yaml"], capsys)[0] == 0
    manifest = tmp_path / "tj" / "package.xml"
    package = parse_package(str(manifest))   # catkin_pkg accepts it (it refused it before)
    assert package.maintainers[0].name == "A & B"
    assert etree.parse(str(manifest)).findtext("description") == "Tom & Jerry <drone>"


def test_decoder_names_the_line_of_a_bad_byte(tmp_path):
    from reedtool.errors import ReedtoolError
    from reedtool.io.fileio import read_text_file

    path = tmp_path / "t.yaml"
    path.write_bytes(codecs.BOM_UTF8 + b"a: 1\nb: \xff\n")
    with pytest.raises(ReedtoolError) as error:
        read_text_file(path)
    assert error.value.line == 2
