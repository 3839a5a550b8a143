"""The seed's path (issue 26): a SolidWorks-style quad-X body in mm and NED, its COM 15 mm
ahead of the motor centre -> new-package -> validate. The CAD frame is kept, the COM is in
<inertial><origin>, the rotors sit on the motor mounts, and the trim says what the offset
costs. References: the body's parts by the box and prism formulas, the trim by a hand
moment balance, the whole-vehicle COM by Pinocchio on the expanded URDF."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli

ROOT = Path(__file__).parents[1]
SEED_BODY = ROOT / "meshes" / "quadx_body_mm_ned.stl"
MOUNT_M = 0.1768


def _examples():
    spec = importlib.util.spec_from_file_location("make_examples", ROOT / "meshes" / "make_examples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


EX = _examples()


def analytic_body_com_flu_m() -> np.ndarray:
    """COM of the parts (uniform density) by the formulas: a box's centre, a regular
    n-gon prism's axis, each weighted by its volume (box: product of edges; n-gon prism:
    n/2 r^2 sin(2 pi/n) h). Parts touch but never overlap."""
    volume_sum, moment = 0.0, np.zeros(3)
    for kind, params, _mesh in EX.quadx_parts_flu_mm():
        if kind == "box":
            lo, hi, yaw = (np.array(params[0]), np.array(params[1]), params[2])
            c, s = np.cos(yaw), np.sin(yaw)
            centre = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ ((lo + hi) / 2)
            volume = float(np.prod(hi - lo))
        else:
            cx, cy, r, z0, z1, n = params
            centre = np.array([cx, cy, (z0 + z1) / 2])
            volume = n / 2 * r * r * np.sin(2 * np.pi / n) * (z1 - z0)
        volume_sum += volume
        moment += volume * centre
    return moment / volume_sum / 1000.0


def new_package(tmp_path, name, mesh, *extra):
    return run_cli("new-package", name, "--frame", "quad-x", "--mesh", mesh, "--mass", "1.2",
                   "-o", tmp_path, *extra)


def expanded_urdf(pkg: Path) -> str:
    code, out = run_cli("expand", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                        "--package-path", pkg.parent)
    assert code == 0, out
    return out


def rotor_origins(urdf: str) -> np.ndarray:
    from lxml import etree

    root = etree.fromstring(urdf.encode())
    rows = []
    for joint in root.iter("joint"):
        if re.search(r"rotor_\d+_joint$", joint.get("name")):
            rows.append([float(v) for v in joint.find("origin").get("xyz").split()])
    return np.array(rows)


def test_the_mounts_of_the_seed_body_are_found_where_it_was_drawn():
    from reedtool.physics.mesh_import import import_mesh
    from reedtool.physics.motor_mounts import find_mounts

    imported = import_mesh(SEED_BODY, from_frame="ned", mass_kg=1.2)
    reading = find_mounts(imported.triangles_m, 4)
    assert len(reading.mounts) == 4, reading.reason
    # Drawn at (+-176.8, +-176.8) mm, radius 15, 8 mm tall; the file holds float32 (about
    # 1.5e-5 mm of spacing at 200 mm): 1e-7 m holds the centre and radius.
    expected = {(sx * MOUNT_M, sy * MOUNT_M) for sx in (1, -1) for sy in (1, -1)}
    found = {tuple(np.round(m.xy_m, 7)) for m in reading.mounts}
    assert found == {tuple(np.round(e, 7)) for e in expected}
    for mount in reading.mounts:
        assert mount.radius_m == pytest.approx(0.015, abs=1e-7)
        assert mount.top_z_m == pytest.approx(0.008, abs=1e-7)


def test_mounts_are_not_taken_where_there_are_none():
    from reedtool.io.stl import read_stl
    from reedtool.physics.motor_mounts import find_mounts

    # The plain X frame's arms end square: tips, but no round mounts.
    flat = read_stl(ROOT / "meshes" / "quad_body_mm.stl").triangles / 1000.0
    reading = find_mounts(flat, 4)
    assert reading.mounts == () and "not all round" in reading.reason
    # Four arms are not six.
    seed = EX.quadx_body(1.0, "flu")
    triangles = seed[0][seed[1]]
    reading = find_mounts(triangles, 6)
    assert reading.mounts == () and "not 6 arm tips" in reading.reason


def test_a_nose_as_long_as_the_arms_hides_the_mounts_rather_than_fooling_them():
    from reedtool.physics.motor_mounts import find_mounts

    V, F = EX.quadx_body(1.0, "flu")
    nose_V, nose_F = EX.box_mesh((70.0, -10.0, 4.0), (280.0, 10.0, 30.0))   # a camera boom
    triangles = np.vstack([V[F], nose_V[nose_F]]) / 1000.0
    reading = find_mounts(triangles, 4)
    assert reading.mounts == ()


def test_a_hexacopter_body_with_mounts_of_another_size():
    """Six 11 mm mounts on a 300 mm circle, built here (not the seed's builder's layout)."""
    from reedtool.physics.motor_mounts import find_mounts, match_bearings

    parts = [EX.box_mesh((-60.0, -60.0, 0.0), (60.0, 60.0, 5.0))]
    centres = []
    for k in range(6):
        bearing = np.radians(30.0 + 60.0 * k)        # counter-clockwise from x
        c = 300.0 * np.array([np.cos(bearing), np.sin(bearing)])
        centres.append(c / 1000.0)
        parts.append(EX.cylinder_mesh(c[0], c[1], 11.0, 0.0, 12.0, 24))
        parts.append(EX.box_mesh((90.0, -4.0, 0.0), (289.0, 4.0, 5.0), bearing))
    triangles = np.vstack([V[F] for V, F in parts]) / 1000.0
    reading = find_mounts(triangles, 6)
    assert len(reading.mounts) == 6, reading.reason
    # A 24-gon's vertices lie on the circle: the fit is exact to float64 round-off.
    for mount in reading.mounts:
        assert min(np.linalg.norm(mount.xy_m - c) for c in centres) < 1e-9
        assert mount.radius_m == pytest.approx(0.011, rel=1e-9)
    # PX4's hex-x bearings (clockwise from the nose): 90, -90, -30, 150, 30, -150.
    order = match_bearings(reading.mounts, [90.0, -90.0, -30.0, 150.0, 30.0, -150.0],
                           np.zeros(2))
    for slot_bearing, index in zip([90.0, -90.0, -30.0, 150.0, 30.0, -150.0], order):
        dx, dy = reading.mounts[index].xy_m
        assert np.degrees(np.arctan2(-dy, dx)) == pytest.approx(slot_bearing, abs=1e-6)


def test_seed_path_keeps_the_cad_body_under_the_rotors(tmp_path):
    import pinocchio as pin

    code, out = new_package(tmp_path, "seed_quad", SEED_BODY, "--mesh-frame", "ned")
    assert code == 0, out
    pkg = tmp_path / "seed_quad"
    urdf = expanded_urdf(pkg)

    # 1. The mesh is where the CAD put it: NED -> FLU turns (x, y, z) into (x, -y, -z), mm
    #    -> m; no translation. Written vertices against the file's, by hand.
    from reedtool.io.stl import read_stl

    source = read_stl(SEED_BODY).triangles.reshape(-1, 3)
    written = read_stl(pkg / "meshes" / "body.stl").triangles.reshape(-1, 3)
    np.testing.assert_allclose(written, source * [1e-3, -1e-3, -1e-3], atol=1e-7)

    # 2. The body's COM is in <inertial><origin>: the parts' analytic COM. The mesh
    #    integral over float32 vertices agrees to ~1e-7 relative; 1e-6 m holds it.
    com_body = analytic_body_com_flu_m()
    assert com_body[0] == pytest.approx(0.0155, abs=1e-4)          # 15.5 mm forward
    match = re.search(r'<link name="seed_quad/base_link_inertia">\s*<inertial>\s*'
                      r'<origin rpy="[^"]*" xyz="([^"]+)"', urdf) or \
        re.search(r'<link name="seed_quad/base_link_inertia">\s*<inertial>\s*'
                  r'<origin xyz="([^"]+)"', urdf)
    np.testing.assert_allclose([float(v) for v in match.group(1).split()], com_body, atol=1e-6)

    # 3. The rotors are on the mounts, rotor_offset_top (0.026 m) above their 8 mm tops.
    rotors = rotor_origins(urdf)
    expected = np.array([[MOUNT_M, -MOUNT_M], [-MOUNT_M, MOUNT_M], [MOUNT_M, MOUNT_M],
                         [-MOUNT_M, -MOUNT_M]])       # PX4 order: FR, BL, FL, BR
    np.testing.assert_allclose(rotors[:, :2], expected, atol=2e-7)
    np.testing.assert_allclose(rotors[:, 2], 0.034, atol=2e-7)
    assert "every rotor is on its mount" in out
    assert "kept in its CAD frame: base_link is the CAD origin, the mesh is not moved" in out

    # 4. Whole-vehicle COM by Pinocchio (its own URDF reader) against the hand sum: the
    #    body's at its COM, rotors (5 g each, symmetric about the origin in x, y), the
    #    RotorS sensors (15.03 g) at the origin.
    # A free-flyer root: a fixed base would fold the body into the universe, which
    # centerOfMass leaves out.
    model = pin.buildModelFromXML(urdf, pin.JointModelFreeFlyer())
    data = model.createData()
    com_pin = pin.centerOfMass(model, data, pin.neutral(model))
    total = float(data.mass[0])
    assert total == pytest.approx(1.2 + 4 * 0.005 + 0.01503, abs=1e-9)
    c_x = 1.2 * com_body[0] / total
    assert com_pin[0] == pytest.approx(c_x, abs=1e-6)
    assert abs(com_pin[1]) < 1e-6

    # 4b. Drake's own URDF parser (another consumer, meshes loaded from package://)
    #     reads the same body COM and whole-vehicle COM.
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.package_map().Add("seed_quad", str(pkg))
    parser.AddModelsFromString(urdf, "urdf")
    plant.Finalize()
    body = plant.GetBodyByName("seed_quad/base_link_inertia")
    np.testing.assert_allclose(body.default_com(), com_body, atol=1e-6)
    drake_com = plant.CalcCenterOfMassPositionInWorld(plant.CreateDefaultContext())
    np.testing.assert_allclose(drake_com, com_pin, atol=1e-9)

    # 5. The trim, by hand: rotors at x = +-a, COM at x = c; pitch balance
    #    T_front (a - c) = T_back (a + c) and 2 T_front + 2 T_back = m g give
    #    T_front = m g (a + c) / (4 a), T_back = m g (a - c) / (4 a).
    a, weight = MOUNT_M, total * 9.80665
    t_front, t_back = weight * (a + c_x) / (4 * a), weight * (a - c_x) / (4 * a)
    line = next(line for line in out.splitlines() if "per rotor:" in line)
    shown = dict(re.findall(r"(\w+) ([\d.]+) N", line))
    for name, value in shown.items():
        # Printed with 3 significant digits: half a unit in the last place.
        assert float(value) == pytest.approx(t_front if "front" in name else t_back,
                                             abs=0.005), (name, line)
    apart = 100 * (t_front / t_back - 1)
    assert f"{apart:.0f} % apart" in out

    # 6. validate loads it and says the same about the trim (R342, a warning).
    code, report = run_cli("validate", pkg / "urdf" / "mav_generic_odometry_sensor.gazebo",
                           "--package-path", tmp_path)
    assert code == 0, report
    assert "R342" in report and f"{apart:.0f} % apart" in report


def test_rotors_about_a_named_centre_with_an_arm_length(tmp_path):
    """--arm-length places the pattern about --center; a centre off the mounts is said."""
    code, out = new_package(tmp_path, "com_quad", SEED_BODY, "--mesh-frame", "ned",
                            "--arm-length", "176.8 mm", "--center", "com")
    assert code == 0, out
    assert "NOT over the mesh's motor mounts" in out
    rotors = rotor_origins(expanded_urdf(tmp_path / "com_quad"))
    com = analytic_body_com_flu_m()
    # About the COM: x = c +- a, y = c_y +- a, z = c_z + 0.026. STL float32: 1e-6 m.
    xs = sorted({round(v, 6) for v in rotors[:, 0]})
    np.testing.assert_allclose(xs, [com[0] - MOUNT_M, com[0] + MOUNT_M], atol=1e-6)
    np.testing.assert_allclose(rotors[:, 2], com[2] + 0.026, atol=1e-6)
    # Rotors symmetric about the COM: four equal thrusts (the x offset of the rotors'
    # centroid from the whole-vehicle COM is the rotors' own 20 g pulling it back to c).
    code, out = new_package(tmp_path, "origin_quad", SEED_BODY, "--mesh-frame", "ned",
                            "--arm-length", "176.8 mm", "--center", "15.2,0,0 mm")
    assert code == 0, out
    rotors = rotor_origins(expanded_urdf(tmp_path / "origin_quad"))
    np.testing.assert_allclose(sorted({round(v, 7) for v in rotors[:, 0]}),
                               [0.0152 - MOUNT_M, 0.0152 + MOUNT_M], atol=1e-9)


@pytest.mark.parametrize("unit, metres_per_unit", [("m", 1.0), ("in", 0.0254), ("mm", 0.001)])
@pytest.mark.parametrize("axes, flag", [("ned", "ned"), ("y-up", "y-up"), ("flu", None)])
def test_the_same_body_in_any_unit_and_axes_gives_the_same_model(tmp_path, unit,
                                                                 metres_per_unit, axes, flag):
    from reedtool.io.stl import read_stl

    V, F = EX.quadx_body(metres_per_unit, axes)
    mesh = tmp_path / f"body_{unit}_{axes}.stl"
    EX.write(mesh, V, F)
    extra = ("--mesh-frame", flag) if flag else ()
    arm = ("--arm-length", "176.8 mm")    # the seed's command line
    code, out = new_package(tmp_path / "first", "q", mesh, *extra)
    if unit == "in":
        # 15.1 units across at 1.2 kg: an inch body (0.38 m, 4,860 kg/m^3) or a cm one
        # (0.15 m, 79,600 kg/m^3, a frame under a heavy body): asked, not guessed.
        assert code == 2 and "fit in and cm" in out and "--mesh-units in or" in out, out
    else:
        assert code == 0, out
    # With the arm length, the unit that puts the mesh's mounts under the rotors decides.
    code, out = new_package(tmp_path / "a", "q", mesh, *extra, *arm)
    assert code == 0, out
    assert f"units: {unit} (" in out
    assert "every rotor is on its mount" in out
    urdf = expanded_urdf(tmp_path / "a" / "q")
    # The reference: the mm/NED seed body as written by new-package, built once here.
    ref_dir = tmp_path / "ref"
    code, ref_out = new_package(ref_dir, "q", SEED_BODY, "--mesh-frame", "ned", *arm)
    assert code == 0, ref_out
    ref = expanded_urdf(ref_dir / "q")
    # float32 in any of these units spaces values near 0.2 m by <= 3e-8 m; rotor positions
    # are written to 1e-7 m: 2e-7 m holds both.
    np.testing.assert_allclose(rotor_origins(urdf), rotor_origins(ref), atol=2e-7)
    np.testing.assert_allclose(read_stl(tmp_path / "a" / "q" / "meshes" / "body.stl").triangles,
                               read_stl(ref_dir / "q" / "meshes" / "body.stl").triangles,
                               atol=1e-7)

    def inertial(text):
        block = text[text.index('name="q/base_link_inertia"'):]
        block = block[:block.index("</inertial>")]
        return [float(v) for v in re.findall(r'"(-?[\d.]+(?:e-?\d+)?)"', block)]
    # Mass properties from float32 vertices: ~1e-7 relative; 1e-6 of the largest holds.
    a, b = inertial(urdf), inertial(ref)
    np.testing.assert_allclose(a, b, atol=1e-6 * max(map(abs, b)))


def test_an_inch_frame_the_size_of_a_cm_one_is_asked_about(tmp_path):
    """The issue's 15-inch frame: a 15 x 15 x 2 plate and 1.2 kg fit inches (0.38 m,
    163 kg/m^3) and centimetres (0.15 m, 2,667 kg/m^3) alike: refused, naming both."""
    from reedtool.io.stl import stl_bytes

    V, F = EX.box_mesh((-7.5, -7.5, 0.0), (7.5, 7.5, 2.0))
    mesh = tmp_path / "frame15.stl"
    mesh.write_bytes(stl_bytes(V[F]))
    code, out = new_package(tmp_path, "inchy", mesh)
    assert code == 2 and not (tmp_path / "inchy").exists()
    assert "which unit?" in out and "fit in and cm" in out
    assert "--mesh-units in or --mesh-units cm" in out
    # Millimetres (0.015 m, 2.7e6 kg/m^3) is not offered: it is neither a body's size nor
    # a density any matter has.
    assert "--mesh-units mm" not in out
    code, out = new_package(tmp_path, "inchy", mesh, "--mesh-units", "in", "--center", "com")
    assert code == 0, out


def test_a_given_unit_the_cues_disagree_with_is_said(tmp_path):
    code, out = new_package(tmp_path, "slip", SEED_BODY, "--mesh-frame", "ned",
                            "--mesh-units", "in", "--center", "com", "--arm-length", "0.18")
    # The user's word is taken, and what it makes of the body is said: 383.6 in = 9.74 m.
    assert code == 0, out
    assert ("  note: as in the mesh is implausible (9.74 m across, a body is 0.03-3 m): "
            "check --mesh-units") in out.splitlines()


def test_import_stl_refuses_a_z_down_mesh_instead_of_turning_it_upside_down(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "package.xml").write_text("<package format='2'><name>pkg</name></package>")
    code, out = run_cli("import-stl", SEED_BODY, "--package", pkg, "--mass", "1.2")
    assert code == 2 and "which way is up?" in out and "--from-frame ned" in out
    assert not (pkg / "meshes").exists()
    code, out = run_cli("import-stl", SEED_BODY, "--package", pkg, "--mass", "1.2",
                        "--from-frame", "ned")
    assert code == 0, out
    assert "frame: NED → FLU: 180° about x" in out
    assert "lies above its origin" in out


def test_an_iris_shaped_body_puts_the_rotors_on_its_uneven_mounts(tmp_path):
    """PX4's iris has its front motors 0.22 m out to the side and its back ones 0.20 m
    (iris.sdf rotor poses (0.13, +-0.22), (-0.13, +-0.20)); reedtool's mount finder puts
    them within 8 mm of those on iris.stl itself. Built here in that shape (our own
    parts): the rotors land on the mounts, not on a symmetric pattern."""
    from reedtool.io.stl import stl_bytes

    mounts_mm = [(130.0, -220.0), (-130.0, 200.0), (130.0, 220.0), (-130.0, -200.0)]
    parts = [EX.box_mesh((-60.0, -50.0, 0.0), (60.0, 50.0, 20.0))]
    for x, y in mounts_mm:
        parts.append(EX.cylinder_mesh(x, y, 16.0, 0.0, 25.0, 40))
        length = np.hypot(x, y)
        yaw = np.arctan2(y, x)
        parts.append(EX.box_mesh((75.0, -6.0, 5.0), (length - 15.0, 6.0, 15.0), yaw))
    mesh = tmp_path / "iris_like.stl"
    mesh.write_bytes(stl_bytes(np.vstack([V[F] for V, F in parts])))
    code, out = new_package(tmp_path, "irisish", mesh, "--mesh-units", "mm")
    assert code == 0, out
    assert "4 round mounts at the arm tips" in out and "every rotor is on its mount" in out
    rotors = rotor_origins(expanded_urdf(tmp_path / "irisish"))
    # PX4 order FR, BL, FL, BR = the mounts as listed; 40-gon vertices on the circle:
    # the fitted centre to float32 (1e-7 m).
    np.testing.assert_allclose(rotors[:, :2], np.array(mounts_mm) / 1000.0, atol=2e-7)
    np.testing.assert_allclose(rotors[:, 2], 0.025 + 0.026, atol=2e-7)
    code, report = run_cli("validate", tmp_path / "irisish" / "urdf" /
                           "mav_generic_odometry_sensor.gazebo", "--package-path", tmp_path)
    assert code == 0, report


def test_a_named_centre_without_an_arm_length_takes_the_arm_from_the_mounts(tmp_path):
    code, out = new_package(tmp_path, "c", SEED_BODY, "--mesh-frame", "ned", "--center", "com")
    assert code == 0, out
    assert "rotors at arm_length 0.1768 m (measured from the motor mounts) about the rotor " \
           "centre" in out
    rotors = rotor_origins(expanded_urdf(tmp_path / "c"))
    com = analytic_body_com_flu_m()
    # The mounts' pattern (a = 176.8 mm, float32: 1e-6 m) about the body COM.
    np.testing.assert_allclose(np.abs(rotors[:, 0] - com[0]), MOUNT_M, atol=1e-6)
    np.testing.assert_allclose(np.abs(rotors[:, 1] - com[1]), MOUNT_M, atol=1e-6)
    # Centred on the COM, the rotors are off the mounts by the COM's x offset, and say so.
    assert "NOT over the mesh's motor mounts" in out


@pytest.mark.parametrize("sides, radius_mm, arm_width_mm", [
    (8, 15.0, 12.0), (12, 20.0, 8.0), (16, 14.0, 30.0), (64, 10.0, 12.0)])
def test_mounts_of_any_tessellation_and_arm_width(sides, radius_mm, arm_width_mm):
    """Round mounts drawn as 8- to 64-gons, arms narrower or wider than them: the centres
    as drawn. The polygons' vertices lie on the circle, in float64 here: 1e-9 m."""
    from reedtool.physics.motor_mounts import find_mounts

    parts = [EX.box_mesh((-70.0, -70.0, 0.0), (70.0, 70.0, 4.0))]
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        reach = 176.8 * np.sqrt(2.0) - radius_mm / 2
        parts.append(EX.box_mesh((99.0, -arm_width_mm / 2, 0.0), (reach, arm_width_mm / 2, 4.0),
                                 np.arctan2(sy, sx)))
        parts.append(EX.cylinder_mesh(sx * 176.8, sy * 176.8, radius_mm, 0.0, 8.0, sides))
    reading = find_mounts(np.vstack([V[F] for V, F in parts]) / 1000.0, 4)
    assert len(reading.mounts) == 4, reading.reason
    drawn = [np.array([sx, sy]) * MOUNT_M for sx in (1, -1) for sy in (1, -1)]
    for mount in reading.mounts:
        assert min(np.linalg.norm(mount.xy_m - d) for d in drawn) < 1e-9


def test_the_gz_sim_package_keeps_the_cad_frame_too(tmp_path):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    code, out = new_package(tmp_path, "gz_seed", SEED_BODY, "--mesh-frame", "ned",
                            "--ros", "2")
    assert code == 0, out
    pkg = tmp_path / "gz_seed"
    code, urdf = run_cli("expand", pkg / "urdf" / "gz_seed.urdf.xacro", "--package-path",
                         tmp_path)
    assert code == 0, urdf
    urdf = urdf[urdf.index("<?xml"):]
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.package_map().Add("gz_seed", str(pkg))
    parser.AddModelsFromString(urdf, "urdf")
    plant.Finalize()
    # The body COM from the parts' formulas (float32 mesh: 1e-6 m); the rotors on the
    # mounts, 0.026 m above their 8 mm tops (written to 1e-7 m).
    com = plant.GetBodyByName("base_link_inertia").default_com()
    np.testing.assert_allclose(com, analytic_body_com_flu_m(), atol=1e-6)
    context = plant.CreateDefaultContext()
    for k, (sx, sy) in enumerate(((1, -1), (-1, 1), (1, 1), (-1, -1))):
        X = plant.GetBodyByName(f"rotor_{k}").EvalPoseInWorld(context)
        np.testing.assert_allclose(X.translation(), [sx * MOUNT_M, sy * MOUNT_M, 0.034],
                                   atol=2e-7)
    code, report = run_cli("validate", pkg / "urdf" / "gz_seed.urdf.xacro")
    assert code == 0 and "R342" in report, report
