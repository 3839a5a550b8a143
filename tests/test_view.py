"""`reedtool view`: the 3-D scene, its GLB, PNG and HTML outputs.

References are independent of the scene builder: reedtool's own kinematics
(physics.kinematics.link_poses) for the link poses the GLB must carry, yourdfpy reading
the URDF file by itself for the same poses, the fixtures' turningDirection text read with
lxml for the disc colours, and hand-derived extents of the X3 fixture for the framing.

Tolerances: link poses are a product of at most four 4x4 transforms of O(1) entries
(rotations, translations under 1 m), each rounding at ~1e-16; glTF stores node matrices
as JSON decimal text, which trimesh writes and reads at float64 precision (shortest
repr, exact round trip). 1e-9 is six orders above that error and six below the smallest
mistake that matters to a picture (a micrometre).
"""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from lxml import etree

from cli_helpers import run_cli
from reedtool.io.loader import load_robot
from reedtool.physics.kinematics import link_poses
from reedtool.workflows.view import view_robot
from reedtool.report.scene import DECORATION_PREFIXES, SEVERITY_RGBA, glb_bytes, nice_length

ROOT = Path(__file__).resolve().parents[1]
SEED_QUAD = ROOT / "examples/reed_quad_x/urdf/mav_generic_odometry_sensor.gazebo"
GZ = ROOT / "tests/fixtures/gz"
TILTED = ROOT / "tests/fixtures/core/tilted_mixed.urdf"
POSE_TOL = 1e-9          # see the module docstring
# The spin colours, written out here (blue ccw, orange cw, as `layout` draws them).
CCW_RGB, CW_RGB = (31, 119, 180), (230, 126, 34)
GREY_RGB = (178, 178, 178)


def _read_glb(data: bytes) -> trimesh.Scene:
    return trimesh.load(io.BytesIO(data), file_type="glb")


def _expected_spins(urdf_xml: str) -> dict[str, tuple[int, int, int]]:
    """rotor link -> its expected colour, from the motor plugins' text (lxml, not reedtool)."""
    root = etree.fromstring(urdf_xml.encode())
    spins = {}
    for plugin in root.iter("plugin"):
        link, direction = plugin.findtext("linkName"), plugin.findtext("turningDirection")
        if link and direction:
            spins[link.strip()] = CCW_RGB if direction.strip() == "ccw" else CW_RGB
    return spins


@pytest.fixture(scope="module")
def seed_quad():
    return load_robot(SEED_QUAD)


@pytest.mark.parametrize("model", [SEED_QUAD, TILTED, GZ / "x3_quad.urdf", GZ / "x3_quad.sdf"],
                         ids=lambda p: p.name)
def test_glb_has_one_node_per_link_at_reedtools_link_pose(model):
    robot = load_robot(model)
    T_base = link_poses(robot)
    read = _read_glb(glb_bytes(view_robot(robot)))
    nodes = list(read.graph.nodes)
    for link in robot.links:
        assert nodes.count(link.name) == 1, link.name
    for link, T_base_link in T_base.items():
        T_glb = read.graph.get(link, robot.base_link)[0]
        assert np.max(np.abs(T_glb - T_base_link)) < POSE_TOL, link
    # the tilted fixture is the one with rotations: make sure they are there to compare
    if model == TILTED:
        assert abs(T_base["rotor_a"][0, 0]) < 1e-12     # yawed 90 degrees by its arm


def test_glb_root_turns_ros_z_up_into_gltf_y_up(seed_quad):
    read = _read_glb(glb_bytes(view_robot(seed_quad)))
    T_world_base = read.graph.get(seed_quad.base_link)[0]
    # base z (up) is glTF +y, base x (forward) stays +x
    assert np.allclose(T_world_base[:3, :3] @ [0, 0, 1], [0, 1, 0], atol=1e-15)
    assert np.allclose(T_world_base[:3, :3] @ [1, 0, 0], [1, 0, 0], atol=1e-15)


@pytest.mark.parametrize("model", [SEED_QUAD, GZ / "x3_quad.urdf"], ids=lambda p: p.name)
def test_a_disc_at_each_rotor_coloured_by_its_spin(model):
    from reedtool.physics.rotors import discover_rotors

    robot = load_robot(model)
    spins = _expected_spins(robot.urdf_xml)
    assert sorted(set(spins.values())) == sorted({CCW_RGB, CW_RGB})   # both spins present
    view = view_robot(robot)
    read = _read_glb(glb_bytes(view))
    T_base = link_poses(robot)
    rotors = discover_rotors(robot)
    assert len(view.discs) == len(rotors) == len(spins)
    for rotor in rotors:
        node = f"rotor_disc/{rotor.name}"
        T_base_disc = read.graph.get(node, robot.base_link)[0]
        # at the rotor link's origin, the disc's normal along the link's z (thrust) axis
        T_base_link = T_base[rotor.link]
        assert np.max(np.abs(T_base_disc[:3, 3] - T_base_link[:3, 3])) < POSE_TOL
        assert np.max(np.abs(T_base_disc[:3, 2] - T_base_link[:3, 2])) < POSE_TOL
        colours = read.geometry[read.graph[node][1]].visual.face_colors[:, :3]
        assert {tuple(int(c) for c in rgb) for rgb in colours} == {spins[rotor.link]}


def test_sdf_and_urdf_of_one_robot_give_the_same_scene():
    urdf = view_robot(load_robot(GZ / "x3_quad.urdf"))
    sdf = view_robot(load_robot(GZ / "x3_quad.sdf"))
    assert (urdf.source, sdf.source) == ("yourdfpy", "reedtool")
    assert urdf.base_link == sdf.base_link
    assert sorted(urdf.T_base_link) == sorted(sdf.T_base_link)

    def shapes(view):
        """link -> sorted corner lists of its geometry in the base frame."""
        out = {}
        for node in view.scene.graph.nodes_geometry:
            if node.startswith(DECORATION_PREFIXES):
                continue
            parent = view.scene.graph.transforms.parents[node]
            T = view.scene.graph.get(node, view.base_link)[0]
            mesh = view.scene.geometry[view.scene.graph[node][1]]
            points = mesh.vertices @ T[:3, :3].T + T[:3, 3]
            out.setdefault(parent, []).append(np.array([points.min(0), points.max(0)]))
        return out

    a, b = shapes(urdf), shapes(sdf)
    assert sorted(a) == sorted(b)
    for link in a:
        assert len(a[link]) == len(b[link])
        for box_a, box_b in zip(a[link], b[link]):
            assert np.max(np.abs(box_a - box_b)) < POSE_TOL, link
    for link in urdf.T_base_link:
        assert np.max(np.abs(urdf.T_base_link[link] - sdf.T_base_link[link])) < POSE_TOL
    discs_a = {d.name: d for d in urdf.discs}
    discs_b = {d.name: d for d in sdf.discs}
    assert sorted(discs_a) == sorted(discs_b)
    for name in discs_a:
        assert np.max(np.abs(discs_a[name].T_base_disc - discs_b[name].T_base_disc)) < POSE_TOL
        assert discs_a[name].rgba == discs_b[name].rgba
    assert np.max(np.abs(urdf.framing.bounds_m - sdf.framing.bounds_m)) < POSE_TOL


@pytest.mark.parametrize("model", [SEED_QUAD, TILTED, GZ / "x3_quad.urdf"], ids=lambda p: p.name)
def test_yourdfpy_link_transforms_equal_reedtools(model):
    import yourdfpy

    robot = load_robot(model)
    # yourdfpy reads the URDF text on its own (for xacro: the expansion)
    urdf = yourdfpy.URDF.load(io.BytesIO(robot.urdf_xml.encode()), load_meshes=False)
    for link, T_base_link in link_poses(robot).items():
        assert np.max(np.abs(urdf.get_transform(link, urdf.base_link) - T_base_link)) < POSE_TOL


def test_the_urdf_path_goes_through_yourdfpy_and_the_sdf_path_does_not(monkeypatch):
    import yourdfpy

    calls = []
    real_load = yourdfpy.URDF.load

    def spy(*args, **kwargs):
        calls.append(kwargs.get("filename_handler"))
        return real_load(*args, **kwargs)

    monkeypatch.setattr(yourdfpy.URDF, "load", staticmethod(spy))
    # view_robot -> report.scene.build_scene -> yourdfpy on the URDF path
    view_robot(load_robot(SEED_QUAD))
    assert len(calls) == 1 and callable(calls[0])
    view_robot(load_robot(GZ / "x3_quad.sdf"))
    assert len(calls) == 1


def test_yourdfpy_filename_handler_resolves_package_uris_with_reedtools_packages(tmp_path):
    """A package:// mesh found through --package-path, drawn at its size in metres."""
    pkg = tmp_path / "my_pkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>my_pkg</name></package>")
    trimesh.creation.box(extents=[0.3, 0.2, 0.1]).export(pkg / "meshes" / "body.stl")
    model = tmp_path / "elsewhere" / "robot.urdf"
    model.parent.mkdir()
    model.write_text("""<robot name="r"><link name="base"><visual><geometry>
      <mesh filename="package://my_pkg/meshes/body.stl"/></geometry></visual></link></robot>""")
    view = view_robot(load_robot(model, package_paths=[pkg]))
    assert view.notes == []
    assert np.allclose(view.framing.extent_m, [0.3, 0.2, 0.1], atol=1e-12)


def test_x3_framing_matches_its_hand_derived_extent():
    # box 0.47 x 0.47 x 0.11 about the origin; rotor discs of radius 0.1 at (+-0.13, +-0.22):
    # x: max(0.235, 0.13 + 0.1) = 0.235; y: 0.22 + 0.1 = 0.32; z: the box's 0.055.
    # trimesh's 32-section cylinder has vertices at 0 and 90 degrees, so the extent is exact.
    view = view_robot(load_robot(GZ / "x3_quad.urdf"))
    assert np.allclose(view.framing.bounds_m, [[-0.235, -0.32, -0.055], [0.235, 0.32, 0.055]],
                       atol=1e-12)
    assert view.framing.scale_bar_m == pytest.approx(0.1, rel=1e-15)   # 0.64 / 4 -> 0.1


@pytest.mark.parametrize("length, bar", [(0.16, 0.1), (0.25, 0.2), (0.5, 0.5), (0.99, 0.5),
                                         (1.0, 1.0), (7.0, 5.0), (160.0, 100.0), (2e-4, 2e-4)])
def test_scale_bar_is_a_1_2_5_length_not_above_the_quarter_extent(length, bar):
    assert nice_length(length) == pytest.approx(bar, rel=1e-12)


def test_scale_bar_of_the_seed_quad_and_its_millimetre_mesh_differ_by_1000(tmp_path, seed_quad):
    """The seed quad's own geometry exported as one STL in millimetres (no <mesh scale>):
    the mistake the picture must make obvious."""
    quad = view_robot(seed_quad)
    read = _read_glb(glb_bytes(quad))
    parts = []
    for node in read.graph.nodes_geometry:
        if node.startswith(DECORATION_PREFIXES):
            continue
        mesh = read.geometry[read.graph[node][1]].copy()
        mesh.apply_transform(read.graph.get(node, seed_quad.base_link)[0])
        parts.append(mesh)
    body = trimesh.util.concatenate(parts)
    body.apply_scale(1000.0)
    body.export(tmp_path / "quad_mm.stl")
    (tmp_path / "quad_mm.urdf").write_text(
        '<robot name="quad_mm"><link name="base"><visual><geometry>'
        '<mesh filename="quad_mm.stl"/></geometry></visual></link></robot>')

    code_a, out_a = run_cli("view", SEED_QUAD, "-o", tmp_path / "quad.png")
    code_b, out_b = run_cli("view", tmp_path / "quad_mm.urdf", "-o", tmp_path / "mm.png")
    assert (code_a, code_b) == (0, 0)
    bar_a = float(re.search(r"scale bar ([0-9.e+-]+) m", out_a).group(1))
    bar_b = float(re.search(r"scale bar ([0-9.e+-]+) m", out_b).group(1))
    assert (bar_a, bar_b) == (0.1, 100.0)
    mm = view_robot(load_robot(tmp_path / "quad_mm.urdf"))
    # STL stores float32: the corners agree to float32's 6e-8 relative, the bar exactly
    assert np.allclose(mm.framing.bounds_m, 1000.0 * quad.framing.bounds_m, rtol=1e-6)
    assert mm.framing.scale_bar_m / quad.framing.scale_bar_m == pytest.approx(1000.0, rel=1e-12)
    for png in ("quad.png", "mm.png"):
        assert (tmp_path / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _x3_with(tmp_path, old: str, new: str) -> Path:
    text = (GZ / "x3_quad.urdf").read_text()
    assert old in text
    out = tmp_path / "x3_quad.urdf"
    out.write_text(text.replace(old, new, 1))
    return out


def test_collision_shows_the_collision_geometry(tmp_path):
    model = _x3_with(tmp_path, '<collision><geometry><box size="0.47 0.47 0.11"/>',
                     '<collision><geometry><box size="0.3 0.3 0.3"/>')
    assert run_cli("view", model, "-o", tmp_path / "v.glb")[0] == 0
    assert run_cli("view", model, "--collision", "-o", tmp_path / "c.glb")[0] == 0

    def base_extent(glb):
        read = _read_glb(glb.read_bytes())
        [node] = [n for n in read.graph.nodes_geometry
                  if read.graph.transforms.parents[n] == "X3/base_link"
                  and not n.startswith(DECORATION_PREFIXES)]
        return read.geometry[read.graph[node][1]].extents

    assert np.allclose(base_extent(tmp_path / "v.glb"), [0.47, 0.47, 0.11], atol=1e-12)
    assert np.allclose(base_extent(tmp_path / "c.glb"), [0.3, 0.3, 0.3], atol=1e-12)


def test_findings_colour_the_links_they_name_by_severity(tmp_path):
    # 0.2 > 0.029125 + 0.055225: the base inertia breaks the triangle inequality (error I203)
    model = _x3_with(tmp_path, 'ixx="0.029125"', 'ixx="0.2"')
    code, out = run_cli("view", model, "--findings", "-o", tmp_path / "f.glb")
    assert code == 0 and "links coloured" in out
    read = _read_glb((tmp_path / "f.glb").read_bytes())

    def colours(link):
        return {tuple(int(c) for c in rgb)
                for n in read.graph.nodes_geometry
                if read.graph.transforms.parents[n] == link
                and not n.startswith(DECORATION_PREFIXES)
                for rgb in read.geometry[read.graph[n][1]].visual.face_colors[:, :3]}

    assert colours("X3/base_link") == {SEVERITY_RGBA["error"][:3]}
    assert colours("X3/rotor_0") == {GREY_RGB}
    # without --findings the base stays grey
    run_cli("view", model, "-o", tmp_path / "plain.glb")
    read = _read_glb((tmp_path / "plain.glb").read_bytes())
    assert colours("X3/base_link") == {GREY_RGB}


def test_html_is_one_page_with_the_glb_embedded(tmp_path):
    import base64

    out = tmp_path / "quad.html"
    code, _ = run_cli("view", SEED_QUAD, "-o", out)
    assert code == 0
    page = out.read_text()
    data = re.search(r'src="data:model/gltf-binary;base64,([A-Za-z0-9+/=]+)"', page).group(1)
    read = _read_glb(base64.b64decode(data))
    assert load_robot(SEED_QUAD).base_link in read.graph.nodes
    assert "bounding box 0.575 m x 0.575 m x 0.06 m" in page and "scale bar 0.1 m" in page
    # Self-contained: no element of the page names a script, stylesheet or image to fetch
    # (the inlined scripts' own text is left out of the search: it holds strings, not elements).
    markup = re.sub(r"<script>.*?</script>", "", page, flags=re.S)
    assert re.findall(r'(?:src|href)="(?!data:)([^"]+)"', markup) == []
    assert "<script>!function(" in page                      # the vendored viewer, inlined


def test_existing_output_is_refused_without_force(tmp_path):
    out = tmp_path / "q.glb"
    out.write_bytes(b"mine")
    code, text = run_cli("view", GZ / "x3_quad.urdf", "-o", out)
    assert code == 2 and "--force" in text and out.read_bytes() == b"mine"
    assert run_cli("view", GZ / "x3_quad.urdf", "-o", out, "--force")[0] == 0
    assert out.read_bytes()[:4] == b"glTF"


def test_unknown_output_suffix_is_exit_2(tmp_path):
    code, text = run_cli("view", GZ / "x3_quad.urdf", "-o", tmp_path / "q.obj")
    assert code == 2 and ".glb, .png or .html" in text


def test_launch_file_gives_the_model_and_its_arguments(tmp_path):
    launch = tmp_path / "spawn.launch"
    launch.write_text(f"""<launch>
  <param name="robot_description"
         command="$(find xacro)/xacro '{SEED_QUAD}' mav_name:=launched namespace:=launched"/>
</launch>""")
    code, _ = run_cli("view", "--launch", launch, "-o", tmp_path / "l.glb")
    assert code == 0
    read = _read_glb((tmp_path / "l.glb").read_bytes())
    assert "launched/base_link" in read.graph.nodes


def test_view_help_imports_no_heavy_library():
    code = ("import sys; from reedtool.cli import main\n"
            "try:\n    main(['view', '--help'])\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in ('trimesh', 'yourdfpy', 'matplotlib', 'numpy', 'lxml')"
            " if m in sys.modules))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip().splitlines()[-1] == "[]"


def test_spin_arrow_turns_the_way_the_rotor_spins():
    """The arc starts at 150 degrees and sweeps 240 in the spin's sense about the thrust
    axis: its head ends near 150 + 240 = 30 degrees for ccw, 150 - 240 = -90 for cw."""
    import math

    view = view_robot(load_robot(GZ / "x3_quad.urdf"))
    for disc in view.discs:
        arrow = view.scene.geometry[view.scene.graph[f"spin_arrow/{disc.name}"][1]]
        head = np.asarray(arrow.vertices)[-3:].mean(axis=0)     # the head's three corners
        angle = math.degrees(math.atan2(head[1], head[0]))
        expected = 30.0 if disc.turning_sign > 0 else -90.0
        # the head reaches 0.28 r past the arc's end along the tangent: a few degrees on
        assert abs((angle - expected + 180.0) % 360.0 - 180.0) < 15.0, disc.name


def test_docs_show_the_pictures_they_link_and_keep_them_small():
    doc = ROOT / "docs" / "view.md"
    links = re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", doc.read_text())
    assert len(links) >= 2
    for link in links:
        picture = doc.parent / link
        assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", link
        assert picture.stat().st_size < 200_000, link


def test_meshes_are_sized_as_gazebo_sizes_them_collada_unit_and_scale(tmp_path):
    """A COLLADA box of 30 x 20 x 10 units with <unit meter="0.01"> (centimetres) and a
    <mesh scale="2 1 1">: Gazebo shows 0.6 x 0.2 x 0.1 m. trimesh alone keeps the unit as
    metadata and would show 60 x 20 x 10."""
    from mesh_helpers import box_triangles, write_dae

    write_dae(tmp_path / "body.dae", box_triangles([30.0, 20.0, 10.0]), meter=0.01)
    model = tmp_path / "r.urdf"
    model.write_text('<robot name="r"><link name="base"><visual><geometry>'
                     '<mesh filename="body.dae" scale="2 1 1"/></geometry></visual></link>'
                     '</robot>')
    view = view_robot(load_robot(model))
    # decimal text through float64 and one multiplication by 0.01: ~1e-16 relative
    assert np.allclose(view.framing.extent_m, [0.6, 0.2, 0.1], rtol=1e-12, atol=0)


def test_a_urdf_yourdfpy_cannot_read_is_drawn_from_reedtools_reading(tmp_path):
    # 'one' is not a number: yourdfpy stops there, reedtool records it and reads on (the
    # joint origin made whole, so every link has a place)
    text = (ROOT / "tests/fixtures/core/broken_numbers.urdf").read_text()
    model = tmp_path / "unreadable_mass.urdf"
    model.write_text(text.replace('<origin xyz="0 0"/>', '<origin xyz="0 0 0.1"/>'))
    view = view_robot(load_robot(model))
    assert view.source == "reedtool"
    assert any("yourdfpy cannot read this URDF" in note for note in view.notes)
    assert np.all(np.isfinite(view.framing.bounds_m))


@pytest.mark.parametrize("suffix", ["png", "glb", "html"])
def test_a_link_with_no_finite_pose_is_one_line_exit_2(tmp_path, suffix):
    """`<origin xyz="0 0"/>` reads as NaN: the child has nowhere to be drawn, so every
    output format refuses with the link named (was a matplotlib ValueError for PNG and a
    'nan m' bounding box for GLB)."""
    out = tmp_path / f"m.{suffix}"
    code, text = run_cli("view", ROOT / "tests/fixtures/core/broken_numbers.urdf", "-o", out)
    assert code == 2 and "cannot place link 'arm'" in text
    assert len(text.strip().splitlines()) == 1 and not out.exists()


def test_a_file_without_links_is_one_line_exit_2(tmp_path):
    model = tmp_path / "macros.urdf"
    model.write_text('<robot name="parts"/>')
    code, text = run_cli("view", model, "-o", tmp_path / "m.png")
    assert code == 2 and "no links" in text and not (tmp_path / "m.png").exists()


def test_a_flat_mesh_is_drawn_and_an_empty_one_is_named(tmp_path):
    """A flat propeller decal (one square, two triangles) has no volume but is a picture;
    a mesh without triangles cannot be drawn and is named on stderr, the rest drawn."""
    from mesh_helpers import write_stl

    square = np.array([[[0, 0, 0], [0.2, 0, 0], [0.2, 0.1, 0]],
                       [[0, 0, 0], [0.2, 0.1, 0], [0, 0.1, 0]]], dtype=float)
    write_stl(tmp_path / "decal.stl", square)
    write_stl(tmp_path / "empty.stl", np.zeros((0, 3, 3)))
    model = tmp_path / "r.urdf"
    model.write_text('<robot name="r"><link name="base">'
                     '<visual><geometry><mesh filename="decal.stl"/></geometry></visual>'
                     '<visual><geometry><mesh filename="empty.stl"/></geometry></visual>'
                     '</link></robot>')
    view = view_robot(load_robot(model))
    assert np.allclose(view.framing.extent_m, [0.2, 0.1, 0.0], atol=1e-7)   # float32 STL
    assert len(view.notes) == 1 and "empty.stl" in view.notes[0]


def test_a_generated_hexacopter_shows_six_discs_three_each_way_on_one_circle(tmp_path):
    """`new-package --frame hex-x`: six rotors on a circle, spins alternating (3 ccw, 3 cw),
    neighbours 60 degrees apart."""
    import math

    assert run_cli("new-package", "hexa", "--frame", "hex-x", "--ros", "2",
                   "-o", tmp_path)[0] == 0
    view = view_robot(load_robot(tmp_path / "hexa/urdf/hexa.urdf.xacro"))
    assert len(view.discs) == 6
    assert sorted(d.rgba[:3] for d in view.discs) == sorted([CCW_RGB] * 3 + [CW_RGB] * 3)
    centres = np.array([d.T_base_disc[:3, 3] for d in view.discs])
    radii = np.hypot(centres[:, 0], centres[:, 1])
    # the generator writes positions as decimal text of their doubles; reading them back
    # and composing one transform rounds at ~1e-16, far under 1e-9
    assert np.ptp(radii) < 1e-9 * radii.max()
    order = np.argsort(np.arctan2(centres[:, 1], centres[:, 0]))
    angles = np.degrees(np.unwrap(np.arctan2(centres[order, 1], centres[order, 0])))
    assert np.allclose(np.diff(angles), 60.0, atol=1e-6)   # 1e-9 m at 0.2 m: ~3e-7 degrees
    spins = [view.discs[i].turning_sign for i in order]
    assert all(a == -b for a, b in zip(spins, spins[1:] + spins[:1]))   # alternating
    assert math.isclose(view.framing.scale_bar_m, 0.1)


def test_a_ros_package_names_its_one_model_as_in_every_model_command(tmp_path):
    """The shared model inputs (docs/commands.md): the seed quad's package is its model."""
    code, out = run_cli("view", ROOT / "examples/reed_quad_x", "-o", tmp_path / "p.glb")
    assert code == 0
    read = _read_glb((tmp_path / "p.glb").read_bytes())
    assert {link.name for link in load_robot(SEED_QUAD).links} <= set(read.graph.nodes)
