"""The light mesh readers (COLLADA, OBJ) against hand-derived numbers and trimesh, and the
promise that `validate` never imports trimesh or scipy."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from mesh_helpers import box_triangles, dae_text, write_dae, write_obj

from reedtool.errors import ReedtoolError
from reedtool.io.dae import parse_dae
from reedtool.io.meshes import read_mesh
from reedtool.io.obj import parse_obj
from reedtool.physics.inertia import mesh_mass_properties

ROOT = Path(__file__).resolve().parents[1]


def extent(triangles):
    v = np.asarray(triangles).reshape(-1, 3)
    return v.max(axis=0) - v.min(axis=0)


def test_dae_unit_and_node_transforms():
    # 1530 x 200 x 30 mm, translated 10 mm along x then turned 90 deg about z.
    dae = parse_dae(dae_text(box_triangles((1530, 200, 30)), meter=0.001,
                             node_xml="<translate>10 0 0</translate>"
                                      "<rotate>0 0 1 90</rotate>").encode())
    # Exact: the <unit meter> attribute read by float().
    assert dae.unit_declared and dae.metres_per_unit == 0.001
    # mm * 0.001 and a 90 deg turn (cos = 6e-17): a few ulps; default rel 1e-6 is a ceiling.
    assert extent(dae.triangles_m) == pytest.approx([0.2, 1.53, 0.03])
    centre = dae.triangles_m.reshape(-1, 3).mean(axis=0)
    # Mean of 36 points of ~0.8 m: rounding ~1e-16 each; 1e-12 m holds.
    assert centre == pytest.approx([0.01, 0, 0], abs=1e-12)
    # Divergence-theorem sum of 12 triangles: rounding only; default rel 1e-6 is a ceiling.
    assert mesh_mass_properties(dae.triangles_m).volume_m3 == pytest.approx(1.53 * 0.2 * 0.03)


def test_dae_matrix_scale_and_up_axis():
    M = "2 0 0 1  0 1 0 0  0 0 1 0  0 0 0 1"          # scale x by 2, move x by 1
    dae = parse_dae(dae_text(box_triangles((1, 2, 3)), meter=None, up_axis="Y_UP",
                             node_xml=f"<matrix>{M}</matrix><scale>1 1 0.5</scale>",
                             polylist=True).encode())
    # Exact: the default.
    assert not dae.unit_declared and dae.metres_per_unit == 1.0
    # x doubled, z halved; then Y up -> Z up swaps the y and z extents.
    assert extent(dae.triangles) == pytest.approx([2.0, 1.5, 2.0])


def test_dae_bounds_agree_with_trimesh(tmp_path):
    """An independent reader (trimesh + pycollada) on the same file, transforms included."""
    trimesh = pytest.importorskip("trimesh")
    path = write_dae(tmp_path / "part.dae", box_triangles((0.3, 0.2, 0.1), centre=(1, 2, 3)),
                     node_xml="<translate>0.5 0 0</translate><rotate>1 0 0 30</rotate>")
    ours = read_mesh(path).triangles.reshape(-1, 3)
    theirs = trimesh.load(str(path), force="mesh").vertices
    # Another reader applies the node transforms in its own order (and may hold
    # float32): 6e-8 of ~3.5 m = 2e-7 m; abs 1e-6 m holds, a missed transform is 0.1 m.
    assert ours.min(axis=0) == pytest.approx(theirs.min(axis=0), abs=1e-6)
    assert ours.max(axis=0) == pytest.approx(theirs.max(axis=0), abs=1e-6)


def test_obj_faces_and_agreement_with_trimesh(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    path = write_obj(tmp_path / "part.obj", box_triangles((1, 2, 3)))
    triangles = read_mesh(path).triangles
    assert triangles.shape == (12, 3, 3)
    # Whole-number box: exact up to rounding; default rel 1e-6 is a ceiling.
    assert mesh_mass_properties(triangles).volume_m3 == pytest.approx(6.0)
    theirs = trimesh.load(str(path), force="mesh", process=False)
    assert float(theirs.volume) == pytest.approx(6.0)
    # A quad with v/vt/vn corners and relative indices: two triangles.
    quad = parse_obj(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4/1/1 -3/2/1 -2/3/1 -1/4/1\n")
    assert quad.shape == (2, 3, 3)


@pytest.mark.parametrize("data", [b"<COLLADA>", b"<svg/>", b"\x00\x01binary"])
def test_dae_that_is_not_collada_is_refused(data):
    with pytest.raises(ReedtoolError):
        parse_dae(data)


def test_validate_never_imports_trimesh_or_scipy(tmp_path):
    """Importing the command and validating a RotorS-style model with .dae visuals (one of
    them open, so its inertia comes from its convex hull)."""
    write_dae(tmp_path / "body.dae", box_triangles((300, 300, 80)), meter=0.001)
    write_dae(tmp_path / "prop.dae", box_triangles((200, 20, 5)), meter=0.001)
    # An open canopy (two triangles missing) as a link's only geometry: its mass
    # properties come from its convex hull, the 0.1 x 0.1 x 0.05 m box.
    write_dae(tmp_path / "canopy.dae", box_triangles((100, 100, 50))[:-2], meter=0.001)
    (tmp_path / "m.urdf").write_text("""<?xml version="1.0"?>
<robot name="m">
  <link name="base_link"><inertial><mass value="1"/>
    <inertia ixx="0.008033" ixy="0" ixz="0" iyy="0.008033" iyz="0" izz="0.015"/></inertial>
    <visual><geometry><mesh filename="body.dae"/></geometry></visual>
    <visual><geometry><mesh filename="body.dae"/></geometry></visual>
    <collision><geometry><box size="0.3 0.3 0.08"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base_link"/><child link="rotor"/>
    <origin xyz="0.2 0 0.05"/><axis xyz="0 0 1"/></joint>
  <link name="rotor"><inertial><mass value="0.005"/>
    <inertia ixx="1.25e-05" ixy="0" ixz="0" iyy="1.25e-05" iyz="0" izz="2.5e-05"/></inertial>
    <visual><geometry><mesh filename="prop.dae"/></geometry></visual>
    <collision><geometry><cylinder length="0.005" radius="0.1"/></geometry></collision></link>
  <joint name="c" type="fixed"><parent link="base_link"/><child link="canopy"/>
    <origin xyz="0 0 0.065"/></joint>
  <link name="canopy"><inertial><mass value="0.1"/>
    <inertia ixx="0.00010417" ixy="0" ixz="0" iyy="0.00010417" iyz="0" izz="0.00016667"/>
    </inertial><visual><geometry><mesh filename="canopy.dae"/></geometry></visual></link>
</robot>
""")
    code = textwrap.dedent(f"""
        import sys
        import reedtool.commands.validate
        from reedtool.cli import main
        try:
            main(["validate", {str(tmp_path / "m.urdf")!r}])
        except SystemExit as exc:
            print("exit", exc.code)
        print(sorted({{m.split(".")[0] for m in sys.modules}} & {{"trimesh", "scipy"}}))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False,
                          cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert done.stdout.strip().splitlines()[-2:] == ["exit 0", "[]"], done.stdout + done.stderr


def test_import_honours_the_dae_unit_and_guesses_only_without_one(tmp_path):
    from reedtool.physics.mesh_import import import_mesh

    # 300 x 200 x 100 with meter="0.01": centimetres declared, so 3 m x 2 m x 1 m, even
    # though a guess from the size alone would call 300 units millimetres.
    declared = import_mesh(write_dae(tmp_path / "cm.dae", box_triangles((300, 200, 100)),
                                     meter=0.01), units="auto")
    assert (declared.units.unit, declared.units.guessed) == ("cm", False)
    # Unit scaling of whole numbers by 0.01: a few ulps; default rel 1e-6 is a ceiling.
    assert declared.size_m == pytest.approx([3.0, 2.0, 1.0])
    assert declared.mass.volume_m3 == pytest.approx(6.0)
    obj = write_obj(tmp_path / "mm.obj", box_triangles((300, 200, 100)))
    # Without a unit and a mass, 300 units is a 0.3 m part in mm or a 3 m one in cm: asked.
    with pytest.raises(ReedtoolError, match="which unit.*fit mm and cm"):
        import_mesh(obj, units="auto")
    # 6 kg: 1000 kg/m^3 as mm, 1 kg/m^3 as cm (below any body): mm, guessed.
    unitless = import_mesh(obj, units="auto", mass_kg=6.0)
    assert (unitless.units.unit, unitless.units.guessed) == ("mm", True)
    # Whole mm times 0.001: one rounding; default rel 1e-6 is a ceiling.
    assert unitless.size_m == pytest.approx([0.3, 0.2, 0.1])


def test_dae_nested_nodes_and_library_node_instances():
    """A part placed twice: a nested node (translate 2 m in x) and an <instance_node> of a
    library node (translate -2 m); the file in centimetres. Extent: 4 m + the 1 m cube."""
    base = dae_text(box_triangles((100, 100, 100)), meter=0.01)
    nested = ('<node id="outer"><translate>200 0 0</translate>'
              '<node id="inner"><instance_geometry url="#g"/></node></node>'
              '<node id="other"><translate>-200 0 0</translate>'
              '<instance_node url="#lib"/></node>')
    library = ('<library_nodes><node id="lib"><instance_geometry url="#g"/></node>'
               '</library_nodes>')
    text = base.replace('<node id="n" name="part"><instance_geometry url="#g"/></node>',
                        nested).replace("<library_visual_scenes>",
                                        library + "<library_visual_scenes>")
    dae = parse_dae(text.encode())
    assert len(dae.triangles) == 24
    # Nested node transforms of whole numbers: a few ulps; default rel 1e-6 is a ceiling.
    assert extent(dae.triangles_m) == pytest.approx([5.0, 1.0, 1.0])


# ------------------------------------------------------------ one loader table

def test_the_loader_table_reads_what_gazebo_classic_loads_and_says_what_was_declared(tmp_path):
    """Every format Gazebo Classic loads has a light reader in the table; one return type
    says what the file declared (COLLADA's unit and up axis) and which file it was."""
    from mesh_helpers import write_stl

    from reedtool.io.meshes import CLASSIC_MESH_SUFFIXES, LIGHT_SUFFIXES, MESH_READERS, MeshFile

    assert set(CLASSIC_MESH_SUFFIXES) <= set(MESH_READERS) and LIGHT_SUFFIXES == tuple(MESH_READERS)
    box = box_triangles((1, 2, 3))
    files = {"stl": write_stl(tmp_path / "b.stl", box), "obj": write_obj(tmp_path / "b.obj", box),
             "dae": write_dae(tmp_path / "b.dae", box_triangles((1000, 2000, 3000)), meter=0.001,
                              up_axis="Z_UP")}
    for kind, path in files.items():
        read = read_mesh(path)
        assert isinstance(read, MeshFile) and read.source == path
        # The same 1 x 2 x 3 m box, in metres as Gazebo sizes it: mm * 0.001, a few ulps.
        assert extent(read.triangles_m) == pytest.approx([1, 2, 3], rel=1e-12), kind
    dae = read_mesh(files["dae"])
    assert (dae.unit_declared, dae.metres_per_unit, dae.up_axis) == (True, 0.001, "Z_UP")
    assert read_mesh(files["stl"]).up_axis is None       # STL declares no axis


def test_no_module_reads_a_mesh_file_past_the_table():
    """Only io/meshes.py (through its table) and the format readers it names open mesh
    files: a second path would read the same file differently (units, refusals, cache)."""
    import ast

    readers = {"read_stl", "parse_stl", "read_dae", "parse_dae", "read_obj", "parse_obj",
               "load_mesh", "load"}
    allowed = {Path("reedtool/io/meshes.py"), Path("reedtool/io/stl.py"),
               Path("reedtool/io/dae.py"), Path("reedtool/io/obj.py")}
    found = []
    for path in sorted((ROOT / "reedtool").rglob("*.py")):
        relative = path.relative_to(ROOT)
        if relative in allowed:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module in (
                    "reedtool.io.stl", "reedtool.io.dae", "reedtool.io.obj"):
                found += [f"{relative}: imports {a.name}" for a in node.names
                          if a.name in readers]
            if isinstance(node, ast.Attribute) and node.attr in ("load", "load_mesh") \
                    and isinstance(node.value, ast.Name) and node.value.id == "trimesh":
                found.append(f"{relative}:{node.lineno}: trimesh.{node.attr}")
    assert found == []
