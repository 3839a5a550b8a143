"""`reedtool inertia` on the seed's wheel, on a xacro, and --fix against independent readers."""

import io
import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from reedtool.cli import main

FIXTURES = Path(__file__).parent / "fixtures" / "inertia"
from oracles import CHECK_URDF

# Seed 001's wheel by hand: m = 0.1 kg, r = 0.025 m, length 0.02 m.
WHEEL_AXIAL = 0.5 * 0.1 * 0.025**2                       # 3.125e-5 kg m^2
WHEEL_TRANSVERSE = 0.1 * (3 * 0.025**2 + 0.02**2) / 12   # 1.8958e-5 kg m^2


def run(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(["inertia", *(str(a) for a in args)])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_seed_wheel_declared_one_against_the_cylinders_1e_5(capsys):
    code, out, err = run([FIXTURES / "smartcar_wheel.urdf", "--format", "json"], capsys)
    assert code == 1, err
    doc = json.loads(out)
    wheel = next(link for link in doc["links"] if link["link"] == "left_front_wheel")
    assert wheel["verdict"] == "way-off"
    assert wheel["geometry"] == "collision cylinder"
    # Exact: the declared numbers, read and written through JSON (repr round trip).
    np.testing.assert_array_equal(np.diag(wheel["declared"]["inertia_kg_m2"]), [1.0, 1.0, 1.0])
    derived = np.array(wheel["derived"]["inertia_kg_m2"])
    # rpy (0, 1.57075, 1.57075) turns the cylinder axis onto the link's y axis
    np.testing.assert_allclose(np.diag(derived), [WHEEL_TRANSVERSE, WHEEL_AXIAL, WHEEL_TRANSVERSE],
                               rtol=1e-6)
    # Eigenvalues of R I R^T equal I's: eigvalsh is backward stable, ~cond * ulps of
    # the largest moment; the moments differ by < 10x, so ~1e-15; 1e-12 holds.
    np.testing.assert_allclose(np.linalg.eigvalsh(derived),
                               sorted([WHEEL_TRANSVERSE, WHEEL_TRANSVERSE, WHEEL_AXIAL]), rtol=1e-12)
    # A centred cylinder: the offset is a difference of equal copies, exactly 0 up to
    # an ulp of its 0.08 m position (1.4e-17).
    assert wheel["com_offset_m"] == pytest.approx(0.0, abs=1e-15)
    assert wheel["line"] == 24
    assert [link["verdict"] for link in doc["links"]] == ["way-off", "way-off"]
    whole = doc["whole_robot"]
    # Pinocchio's sum of decimal masses: a few ulps (~1e-16 kg).
    assert whole["source"] == "pinocchio" and whole["mass_kg"] == pytest.approx(1.1, abs=1e-12)
    # Two implementations of the same sums: a few ulps of ~0.1 m values.
    np.testing.assert_allclose(whole["com_m"], doc["own_sum"]["com_m"], atol=1e-12)


def test_text_output_names_the_numbers(capsys):
    code, out, err = run([FIXTURES / "smartcar_wheel.urdf"], capsys)
    assert code == 1
    assert "left_front_wheel  [way-off]" in out
    assert "declared  ixx 1  iyy 1  izz 1" in out
    assert "ixx 1.896e-05  iyy 3.125e-05  izz 1.896e-05" in out
    assert "total mass  1.1 kg" in out and "agrees" in out


def test_fix_rewrites_a_urdf_with_backup(tmp_path, capsys):
    model = tmp_path / "smartcar.urdf"
    original = (FIXTURES / "smartcar_wheel.urdf").read_text()
    model.write_text(original)
    code, out, err = run([model, "--fix"], capsys)
    assert code == 0, err
    assert (tmp_path / "smartcar.urdf.bak").read_text() == original
    assert subprocess.run([CHECK_URDF, str(model)], capture_output=True).returncode == 0

    import yourdfpy  # an independent URDF reader

    urdf = yourdfpy.URDF.load(io.BytesIO(model.read_bytes()), load_meshes=False)
    links = {link.name: link for link in urdf.robot.links}
    wheel = links["left_front_wheel"].inertial
    # Exact: the declared decimal, written back unchanged and parsed.
    assert wheel.mass == 0.1
    # Written with 10 significant digits (fmt_number: 5e-10 relative) and parsed by
    # yourdfpy, then eigvalsh: 1e-8 holds that rounding.
    np.testing.assert_allclose(np.linalg.eigvalsh(wheel.inertia),
                               sorted([WHEEL_TRANSVERSE, WHEEL_TRANSVERSE, WHEEL_AXIAL]), rtol=1e-8)
    # Exact decimals written and parsed: the default rtol 1e-7 is only a ceiling.
    np.testing.assert_allclose(wheel.origin[:3, 3], [0.08, 0.08, 0.025])
    base = links["base_link"].inertial
    np.testing.assert_allclose(np.diag(base.inertia),
                               [(0.16**2 + 0.05**2) / 12, (0.25**2 + 0.05**2) / 12,
                                (0.25**2 + 0.16**2) / 12], rtol=1e-8)
    # everything outside the two <inertial> blocks is unchanged, line for line
    new_lines = model.read_text().splitlines()
    assert new_lines[:4] == original.splitlines()[:4]
    assert "<collision>" in model.read_text() and "<limit effort=\"100\"" in model.read_text()
    # a second run finds nothing to fix, and refuses to clobber the backup without --force
    code, out, err = run([model], capsys)
    assert code == 0 and "no link inertia needs attention" in out
    code, out, err = run([model, "--fix"], capsys)
    assert code == 0 and "nothing to change" in out


def test_fix_never_overwrites_an_older_backup(tmp_path, capsys):
    model = tmp_path / "smartcar.urdf"
    original = (FIXTURES / "smartcar_wheel.urdf").read_text()
    model.write_text(original)
    (tmp_path / "smartcar.urdf.bak").write_text("precious")
    code, out, err = run([model, "--fix"], capsys)
    assert code == 0 and "smartcar.urdf.bak.1" in out + err
    assert (tmp_path / "smartcar.urdf.bak").read_text() == "precious"
    assert (tmp_path / "smartcar.urdf.bak.1").read_text() == original


def test_fix_on_xacro_rewrites_the_literal_inertia_in_the_macro_body(tmp_path, capsys):
    """Both wheels take their tensor from the one literal <inertia/> in the macro body of
    the user's file and need the same correction: it is rewritten there, once."""
    source = tmp_path / "wheel_macro.urdf.xacro"
    before = (FIXTURES / "wheel_macro.urdf.xacro").read_text()
    source.write_text(before)
    code, out, err = run([source, "--fix"], capsys)
    assert code == 0, out + err
    assert (tmp_path / "wheel_macro.urdf.xacro.bak").read_text() == before
    lines = before.splitlines()
    inertia_line = next(i for i, text in enumerate(lines, 1) if "<inertia " in text)
    assert f"rewrote the <inertia/> at {source}:{inertia_line} (link left_wheel, right_wheel" \
        in out
    # A solid cylinder r = 25 mm, 20 mm long, 0.1 kg, axis y: m r^2 / 2 about y and
    # m (3 r^2 + l^2) / 12 about x and z; 10 significant digits written.
    new_line = source.read_text().splitlines()[inertia_line - 1]
    values = dict(re.findall(r'(i\w\w)="([^"]+)"', new_line))
    transverse = 0.1 * (3 * 0.025 ** 2 + 0.02 ** 2) / 12
    assert float(values["iyy"]) == pytest.approx(0.1 * 0.025 ** 2 / 2, rel=1e-9)
    assert float(values["ixx"]) == pytest.approx(transverse, rel=1e-9)
    assert float(values["izz"]) == pytest.approx(transverse, rel=1e-9)
    # Only that line changed.
    assert [a == b for a, b in zip(lines, source.read_text().splitlines())].count(False) == 1


def test_fix_on_xacro_prints_blocks_with_their_lines(tmp_path, capsys):
    """A tensor written as an expression cannot be rewritten in place: printed, with the
    line of the macro body and of each call."""
    source = tmp_path / "wheel_macro.urdf.xacro"
    before = (FIXTURES / "wheel_macro.urdf.xacro").read_text().replace(
        'ixx="1.0"', 'ixx="${0.5 * 2}"')
    source.write_text(before)
    code, out, err = run([source, "--fix"], capsys)
    assert code == 1
    assert source.read_text() == before
    lines = before.splitlines()
    macro_line = next(i for i, text in enumerate(lines, 1) if "<inertial>" in text)
    call_lines = [i for i, text in enumerate(lines, 1) if "<xacro:wheel " in text]
    for link, call in zip(("left_wheel", "right_wheel"), call_lines):
        pattern = (rf"link '{link}': replace the <inertial> in the macro body at "
                   rf"\S*{source.name}:{macro_line} \(the call at \S*{source.name}:{call}\)")
        assert re.search(pattern, out), out
    assert out.count('iyy="3.125e-05"') == 2
    assert "base_link" not in out.split("--fix:", 1)[1]


def test_multilink_json_whole_robot(capsys):
    code, out, err = run([FIXTURES / "multilink.urdf", "--format", "json"], capsys)
    doc = json.loads(out)
    assert code == 0      # no geometry anywhere: nothing to compare, nothing failing
    assert {link["verdict"] for link in doc["links"]} == {"no-geometry", "no-inertial"}
    assert doc["whole_robot"]["mass_kg"] == pytest.approx(2.12, abs=1e-12)


def test_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    for args, message in (([tmp_path / "none.urdf"], "not found"), ([bad], "malformed XML")):
        code, out, err = run(args, capsys)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_imported_mesh_snippet_is_consistent_with_inertia_check(tmp_path, capsys):
    # import-stl's <inertial> for a mesh, read back by `inertia` through package://
    pkg = tmp_path / "src" / "demo_pkg"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>demo_pkg</name></package>")
    snippet = tmp_path / "link.xml"
    examples = Path(__file__).parents[1] / "meshes"
    with pytest.raises(SystemExit) as info:
        main(["import-stl", str(examples / "l_bracket_mm_ned.stl"), "--package", str(pkg),
              "--units", "mm", "--from-frame", "ned", "--mass", "0.05", "--collision", "hull",
              "--snippet", str(snippet)])
    assert info.value.code == 0
    model = pkg / "urdf" / "bracket.urdf"
    model.parent.mkdir()
    model.write_text(f'<robot name="b">\n{snippet.read_text()}</robot>\n')
    capsys.readouterr()
    code, out, err = run([model, "--package-path", tmp_path / "src", "--format", "json"], capsys)
    assert code == 0, err
    link = json.loads(out)["links"][0]
    # the collision hull is not the L, so the tensors differ, but within the "ok" band
    assert link["geometry"] == "collision mesh l_bracket_mm_ned_collision.stl"
    assert link["verdict"] in ("ok", "com-off", "differs")
    # Exact: the declared mass is carried through JSON (repr round trip).
    assert link["derived"]["mass_kg"] == 0.05
    hull_volume_m3 = (60 * 5 + 5 * 25 + 0.5 * 55 * 25) * 40 * 1e-9
    # Hull of whole-mm points from a float32 STL, scaled: rounding only (~1e-15);
    # 1e-6 allows qhull's own tolerance on which points are hull vertices.
    assert link["derived"]["volume_m3"] == pytest.approx(hull_volume_m3, rel=1e-6)


def test_json_carries_schema_tool_and_version(capsys):
    """Every command's JSON starts with the same envelope (issue 13)."""
    import json as _json

    from reedtool import __version__
    from reedtool.cli import main

    model = Path(__file__).parent / "fixtures" / "validate" / "clean_quad_x.urdf"
    with pytest.raises(SystemExit):
        main(["inertia", str(model), "--format", "json"])
    doc = _json.loads(capsys.readouterr().out)
    assert (doc["schema"], doc["tool"], doc["version"]) == ("reedtool.inertia/1", "reedtool",
                                                            __version__)
