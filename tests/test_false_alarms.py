"""Issue 27's false-alarm classes, each held against an independent reference: the good
fixture stays quiet for the rule that once fired on its upstream shape, and the bad one
of the same class keeps its true finding (tests/fixtures/false_alarms/README.md)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robots

FIXTURES = Path(__file__).parent / "fixtures" / "false_alarms"


def _findings(path: Path, *extra_args):
    return [f for robot in load_robots(path) for f in run_checks(robot)]


def _codes(path: Path, severities=("error", "warning")) -> set[str]:
    return {f.code for f in _findings(path) if f.severity in severities}


# ------------------------------------------------------------------ "no limit" numbers

def _libsdformat_error(path: Path) -> str | None:
    """libsdformat's verdict in a child process (Drake aborts the process on some limits)."""
    code = ("import sys; sys.path.insert(0, %r); import sdformat_oracle as o; "
            "e = o.libsdformat_error(%r, []); print('OK' if e is None else 'ERR ' + e)"
            % (str(Path(__file__).parent), str(path)))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    return None if out.stdout.strip().endswith("OK") else out.stdout + out.stderr


def test_sdf_infinite_limits_are_no_limit():
    """libsdformat parses <lower>-inf</lower> as a number: the joint has no limit, as with
    DBL_MAX or sdformat's own +-1e16, and -1 effort/velocity."""
    path = FIXTURES / "S102_good_sdf_inf_limits.sdf"
    assert _libsdformat_error(path) is None
    assert _codes(path) == set()
    (robot,) = load_robots(path)
    joint = robot.joint_map["yaw_joint"]
    assert joint.type == "continuous"          # unbounded both ways, as the loader reads it
    assert joint.limit.effort == float("inf") and joint.limit.velocity == float("inf")


def test_urdf_infinite_limit_stays_an_error():
    """urdfdom (through Pinocchio) refuses "-inf" in a limit: S102 is right there."""
    pinocchio = pytest.importorskip("pinocchio")
    path = FIXTURES / "S102_bad_urdf_inf_limit.urdf"
    with pytest.raises(ValueError):
        pinocchio.buildModelFromUrdf(str(path))
    assert pinocchio.buildModelFromXML(path.read_text().replace('lower="-inf"',
                                                                'lower="-1.79769e+308"'))
    assert "S102" in _codes(path)
    assert "S102" not in {f.code for f in run_checks(load_robots(path)[0])
                          if "1.79769e+308" in f.message}


def test_nan_is_never_a_limit(tmp_path):
    path = tmp_path / "nan.sdf"
    path.write_text((FIXTURES / "S102_good_sdf_inf_limits.sdf").read_text()
                    .replace("<lower>-inf</lower>", "<lower>nan</lower>"))
    assert "S102" in _codes(path)


# ------------------------------------------------------------------ messages

def test_a_possessive_is_not_a_quote():
    """shorten_names cut the text between the apostrophes of "link 'x'" and "geometry's"
    as if it were an 80-character name (RotorS omav's I204: "...apping it for its
    geometry's")."""
    from reedtool.errors import shorten_names

    message = ("link 'omav/tilt_unit_3': inertia is 12.3x larger than its visual mesh's "
               "(radius of gyration 0.05 m vs 0.014 m); swapping it for its geometry's "
               "changes the whole-robot inertia by 4 % at most, so a wrong tensor and a "
               "placeholder geometry fly alike")
    assert shorten_names(message) == message
    long_name = "n" * 500
    assert len(shorten_names(f"link '{long_name}' has no mass")) < 200


# ------------------------------------------------------------------ Fuel / web URIs

def test_fuel_mesh_and_include_are_not_errors():
    """gz-sim fetches https://fuel... meshes and includes when the world loads (gz-fuel-
    tools): not S115 with "pass --package-path", one S190 info per URI instead, and the
    rest of the model is still checked."""
    path = FIXTURES / "S115_good_fuel" / "model.sdf"
    findings = _findings(path)
    assert {f.code for f in findings if f.severity != "info"} == set()
    infos = [f for f in findings if f.code == "S190"]
    assert len(infos) == 2 and all("could not check it" in f.message for f in infos)
    assert {f.line for f in infos} == {10, 17}


def test_a_missing_local_mesh_is_still_an_error(tmp_path):
    text = (FIXTURES / "S115_good_fuel" / "model.sdf").read_text().replace(
        "https://fuel.gazebosim.org/1.0/OpenRobotics/models/X3 UAV/4/files/meshes/x3.dae",
        "meshes/x3.dae")
    path = tmp_path / "model.sdf"
    path.write_text(text)
    assert "S115" in _codes(path)


# ------------------------------------------------------------------ static scenery

RUNWAY_SDF = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="runway">
    <static>{static}</static>
    <link name="link">
      <visual name="visual">
        <geometry><mesh><uri>runway.dae</uri></mesh></geometry>
      </visual>
      <collision name="collision">
        <geometry><box><size>1500 30 0.1</size></box></geometry>
      </collision>
    </link>
  </model>
</sdf>
"""


@pytest.fixture
def runway(tmp_path):
    """ardupilot_gz's runway in shape: a static model, one link without <inertial>, a
    COLLADA strip 1500 m long in metres (<unit meter="1">)."""
    from mesh_helpers import box_triangles, write_dae

    write_dae(tmp_path / "runway.dae", box_triangles((1500.0, 30.0, 0.1)), meter=1.0)

    def write(static: str) -> Path:
        path = tmp_path / "model.sdf"
        path.write_text(RUNWAY_SDF.format(static=static))
        return path
    return write


def test_a_static_runway_is_scenery_not_a_millimetre_part(runway):
    """A static model is never moved by Gazebo: its 1.5 km mesh is not a unit mistake
    (I210) and its missing <inertial> gives no kilogram anything is computed from (S120)."""
    assert _codes(runway("true"), ("error", "warning", "info")) & {"I206", "I210", "S120",
                                                                   "I204", "I209"} == set()
    assert _codes(runway("1")) == set()


def test_the_same_mesh_on_a_moving_model_stays_found(runway):
    codes = _codes(runway("false"))
    assert "I210" in codes and "S120" in codes


# ------------------------------------------------------------------ Classic scoped names

def test_classic_scoped_names_resolve_as_classic_does():
    """`iris_cam::base_link` inside model iris_cam (SDF 1.6, Classic plugins) is its own
    base_link for Gazebo Classic: no S104/S105, one tree of two links."""
    path = FIXTURES / "S105_good_classic_scoped_name.sdf"
    assert _codes(path) == set()
    (robot,) = load_robots(path)
    (joint,) = robot.joints
    assert (joint.parent, joint.child) == ("base_link", "camera_link")


def test_classic_scoped_names_warn_when_gz_sim_may_be_the_target(tmp_path):
    """Without Classic plugins the file may be meant for gz-sim, whose libsdformat refuses
    the scoped name (the oracle says so): a warning, still no structure error."""
    text = (FIXTURES / "S105_good_classic_scoped_name.sdf").read_text()
    start = text.index('    <plugin name="camera_controller"')
    end = text.index("</plugin>", start) + len("</plugin>\n")
    path = tmp_path / "model.sdf"
    path.write_text(text[:start] + text[end:])
    assert "not found" in (_libsdformat_error(path) or "")
    codes = _codes(path)
    assert "S191" in codes and not codes & {"S104", "S105"}


def test_a_link_of_another_model_stays_missing():
    assert {"S105", "S104"} <= _codes(FIXTURES / "S105_bad_classic_other_model.sdf")


# ------------------------------------------------------------------ a joint named like a link

def test_a_joint_named_like_its_link_is_not_a_frame_cycle():
    """Classic keeps joints and links apart: no "cycle of relative_to frames", the camera
    hangs where its link's pose puts it."""
    path = FIXTURES / "S161_good_classic_joint_named_like_link.sdf"
    findings = _findings(path)
    assert not [f for f in findings if "cycle" in f.message]
    assert {f.code for f in findings if f.severity != "info"} == set()
    (robot,) = load_robots(path)
    (joint,) = robot.joints
    assert joint.child == "camera_link"
    assert joint.T_parent_joint[0, 3] == pytest.approx(0.1, abs=1e-12)   # <pose>0.1 0 0 ...


def test_the_shared_name_is_refused_once_from_sdf_1_7(tmp_path):
    """Below SDF 1.7 libsdformat renames a joint that takes its link's name (a warning;
    Drake turns that warning into its own refusal). From 1.7 it refuses the file: one
    finding, S161, and no cascade of frame-graph findings (libsdformat checks names
    before it builds a frame graph, so it never reports a cycle through the shared name)."""
    import sdformat_oracle

    text = (FIXTURES / "S161_good_classic_joint_named_like_link.sdf").read_text()
    start = text.index('    <plugin name="camera_controller"')
    end = text.index("</plugin>", start) + len("</plugin>\n")
    for version, expected in (("1.6", []), ("1.9", ["S161"])):
        path = tmp_path / f"model_{version}.sdf"
        path.write_text((text[:start] + text[end:]).replace('version="1.6"',
                                                            f'version="{version}"'))
        error = _libsdformat_error(path) or ""
        assert "Non-unique name" in error
        drake_only = sdformat_oracle.drake_only_reason(error, version)
        assert (drake_only is not None) == (version == "1.6")
        findings = _findings(path)
        assert [f.code for f in findings if f.severity == "error"] == expected
        assert not [f for f in findings if "cycle" in f.message]


# ------------------------------------------------------------------ hover-test refusals

def _judged(tmp_path, edit):
    from reedtool.workflows.robots import ModelRequest
    from reedtool.workflows.validation import judge

    text = (Path(__file__).parent / "fixtures/validate/clean_quad_x.urdf").read_text()
    path = tmp_path / "quad.urdf"
    path.write_text(edit(text))
    (robot,) = load_robots(path)
    return judge(path, robot, ModelRequest(), "hover-test")


def _rotor_izz(text: str, izz: str) -> str:
    start = text.index('<link name="rotor_1">')
    at = text.index('izz="2.5e-05"', start)
    return text[:at] + f'izz="{izz}"' + text[at + len('izz="2.5e-05"'):]


def test_a_rotor_tensor_error_does_not_refuse_the_flight(tmp_path):
    """rotor_1's disc tensor breaks the triangle inequality (1.25e-5 + 1.25e-5 < 5e-5):
    I203, an error validate keeps. Its largest moment, 5e-5 kg·m², is 0.5 % of the
    quad's smallest principal moment (about 0.0101 kg·m²: 0.00964 for the body plus the
    rotors' 4 x 0.005 kg at 0.177 m on each axis), far inside the ±10 % hover-test's
    batch flies: listed beside the result, not refused."""
    verdict = _judged(tmp_path, lambda t: _rotor_izz(t, "5e-05"))
    assert [f.code for f in verdict.reported] == ["I203"]
    assert verdict.refusing == []


def test_the_body_tensor_error_still_refuses(tmp_path):
    """The body's own tensor is most of the robot's: I203 on it refuses."""
    verdict = _judged(tmp_path, lambda t: t.replace('izz="0.018"', 'izz="0.05"'))
    assert [f.code for f in verdict.refusing] == ["I203"]


def test_a_rotor_tensor_that_could_change_the_flight_refuses(tmp_path):
    """The same rotor with a 0.004 kg·m² tensor (40 % of the smallest robot moment)
    could fly differently from any valid one: refused."""
    verdict = _judged(tmp_path, lambda t: _rotor_izz(t, "0.004"))
    assert "I203" in [f.code for f in verdict.refusing]


# ------------------------------------------------------------------ several collisions

def test_a_rotor_of_can_and_disc_is_judged_by_both():
    """The first collision is the motor can (r 14 mm, 20 mm long), the second the prop disc
    (r 0.1 m, 5 mm): the declared tensor is the disc's. Judged by the can alone it was
    38x too large (a false I204 on every rotor); judged by the link's body it is right."""
    path = FIXTURES / "I204_good_motor_can_and_prop_disc.urdf"
    assert _codes(path) == set()


def test_the_link_body_is_its_shapes_at_one_density():
    """By hand: the disc holds pi 0.1² 0.005 = 1.5708e-4 m³, the can pi 0.014² 0.02 =
    1.2315e-5 m³, so 0.005 kg splits 0.92730 : 0.07270; about the spin axis (both on it)
    Izz = m_disc r_disc²/2 + m_can r_can²/2."""
    import math

    from reedtool.physics.inertia import link_geometry

    (robot,) = load_robots(FIXTURES / "I204_good_motor_can_and_prop_disc.urdf")
    body = link_geometry(robot.link_map["rotor_0"], 0.005).body
    v_disc, v_can = math.pi * 0.1 ** 2 * 0.005, math.pi * 0.014 ** 2 * 0.02
    m_disc, m_can = 0.005 * v_disc / (v_disc + v_can), 0.005 * v_can / (v_disc + v_can)
    izz = m_disc * 0.1 ** 2 / 2 + m_can * 0.014 ** 2 / 2
    assert body.inertia_kg_m2[2, 2] == pytest.approx(izz, rel=1e-12)   # analytic both ways
    # The can sits 12 mm below the disc: the COM moves down by m_can 0.012 / m.
    assert body.com_m[2] == pytest.approx(-0.012 * m_can / 0.005, rel=1e-12)


def test_a_rotor_tensor_no_shape_explains_stays_found(tmp_path):
    """1e-3 kg·m² on the same 5 g rotor: 40x the disc's, 2,000x the can's: no
    distribution of its mass over its shapes gives it."""
    text = (FIXTURES / "I204_good_motor_can_and_prop_disc.urdf").read_text()
    old = 'ixx="1.25104167e-05" ixy="0" ixz="0" iyy="1.25104167e-05" iyz="0" izz="2.5e-05"'
    start = text.index('<link name="rotor_0">')
    at = text.index(old, start)
    path = tmp_path / "quad.urdf"
    path.write_text(text[:at] + 'ixx="5e-04" ixy="0" ixz="0" iyy="5e-04" iyz="0" izz="1e-03"'
                    + text[at + len(old):])
    assert _codes(path) & {"I204", "I209"}


def test_a_tilt_unit_on_a_placeholder_box_is_not_compared():
    """0.28 kg in a 5 mm box needs 2.24e6 kg/m³ (osmium: 22,590): a placeholder."""
    path = Path(__file__).parent / "fixtures/inertia/tilt_unit_placeholder_box.urdf"
    assert "I204" not in _codes(path)


# ------------------------------------------------------------------ discovery

def test_a_package_keeping_its_models_elsewhere_is_not_empty(tmp_path):
    """ntnu-arl's rmf_gz keeps its robot under resources/robots/: validate on the package
    checks it rather than saying the package holds no model."""
    from reedtool.workflows.targets import expand_targets

    pkg = tmp_path / "rmf_gz"
    (pkg / "resources" / "robots" / "rmf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>rmf_gz</name></package>")
    model = pkg / "resources" / "robots" / "rmf" / "model.sdf"
    model.write_text((FIXTURES / "S102_good_sdf_inf_limits.sdf").read_text())
    targets = expand_targets([str(pkg)], include_tree=lambda path: [path])
    assert [t.path for t in targets] == [model]


# ------------------------------------------------------------------ xacro recursion

def test_a_macro_looping_once_per_led_expands_as_xacro_does():
    """58 levels of a self-calling macro (COEX Clover's LED strip shape): xacro expands
    it, so reedtool does too (it refused at 50 as a "runaway recursion")."""
    import xacro

    path = FIXTURES / "xacro_good_led_ring_loop.urdf.xacro"
    reference = xacro.process_file(str(path)).toxml()
    assert reference.count("<visual>") == 58
    (robot,) = load_robots(path)
    assert len(robot.link_map["led_ring"].visuals) == 58
    assert _codes(path) == set()


def test_a_recursion_xacro_cannot_expand_is_still_refused(tmp_path):
    """Beyond 248 levels xacro itself fails (RecursionError): one clean input error."""
    from reedtool.errors import ReedtoolError

    path = tmp_path / "deep.urdf.xacro"
    path.write_text((FIXTURES / "xacro_good_led_ring_loop.urdf.xacro").read_text()
                    .replace('count="58"', 'count="400"'))
    with pytest.raises(ReedtoolError, match="nested more than"):
        load_robots(path)


def test_a_static_floor_with_an_impossible_tensor_loads(tmp_path):
    """aws-robomaker's warehouse floor shape: static, 1000 kg, a tensor breaking the
    triangle inequality. libsdformat loads it (the oracle), and Gazebo never moves it:
    no I203. The same model made dynamic keeps I203."""
    text = RUNWAY_SDF.format(static="1").replace(
        '<link name="link">',
        '<link name="link"><inertial><mass>1000</mass><inertia><ixx>1.2e6</ixx>'
        '<iyy>2.0e6</iyy><izz>8.3e6</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia>'
        '</inertial>').replace("<mesh><uri>runway.dae</uri></mesh>",
                               "<box><size>20 20 0.1</size></box>")
    path = tmp_path / "floor.sdf"
    path.write_text(text)
    assert _libsdformat_error(path) is None
    assert _codes(path) == set()
    path.write_text(text.replace("<static>1</static>", "<static>0</static>"))
    assert "I203" in _codes(path)


def test_a_world_model_wrapping_a_static_include_is_scenery(runway):
    """aws-robomaker's worlds wrap each static asset as <model><include>...</include>
    </model>: the wrapper has no body of its own, so it is as static as what it holds."""
    model_dir = runway("true").parent
    world = model_dir.parent / "world.sdf"
    world.write_text(f"""<?xml version="1.0"?>
<sdf version="1.6">
  <world name="w">
    <model name="runway_001">
      <include><uri>{model_dir / "model.sdf"}</uri></include>
      <pose>0 0 -0.09 0 0 0</pose>
    </model>
    <model name="crate">
      <link name="crate_link">
        <inertial><mass>1</mass><inertia><ixx>0.1667</ixx><iyy>0.1667</iyy><izz>0.1667</izz>
          <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
        <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
      </link>
    </model>
  </world>
</sdf>
""")
    robots = load_robots(world)
    assert [r.name for r in robots] == ["crate"]


# ------------------------------------------------------------------ SDF trees

def test_a_static_stand_may_hold_a_free_ball():
    path = FIXTURES / "S104_good_static_stand_free_ball.sdf"
    assert _libsdformat_error(path) is None
    assert _codes(path) == set()


def test_a_loose_link_in_a_moving_model_stays_a_second_root(tmp_path):
    path = tmp_path / "loose.sdf"
    path.write_text((FIXTURES / "S104_good_static_stand_free_ball.sdf").read_text()
                    .replace("<static>true</static>", "<static>false</static>")
                    .replace('<link name="stand">', '<link name="stand"><inertial><mass>1'
                             '</mass><inertia><ixx>0.08</ixx><iyy>0.08</iyy><izz>0.001</izz>'
                             '<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>'))
    assert "S104" in _codes(path)


def test_a_joint_to_the_sdf_world_frame_is_no_missing_link():
    path = FIXTURES / "S105_good_sdf_joint_to_world.sdf"
    assert _libsdformat_error(path) is None
    assert _codes(path) == set()


def test_a_urdf_world_link_must_still_exist(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text("""<robot name="arm">
  <link name="base_link"><inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="rig_to_world" type="fixed"><parent link="world"/><child link="base_link"/></joint>
</robot>""")
    assert "S105" in _codes(path)


def test_a_file_of_gazebo_extensions_only_is_not_a_model(tmp_path):
    """mantis' slung_load.gazebo: <robot> holding only <gazebo> plugin blocks, a fragment
    for a model to include; no "the model has no <link>" on it."""
    from reedtool.workflows.targets import expand_targets

    (tmp_path / "quad.urdf").write_text((Path(__file__).parent /
                                         "fixtures/validate/clean_quad_x.urdf").read_text())
    (tmp_path / "extras.gazebo").write_text(
        '<?xml version="1.0"?>\n<robot>\n  <gazebo>\n    <plugin name="p" '
        'filename="libgazebo_ros_control.so"/>\n  </gazebo>\n</robot>\n')
    targets = expand_targets([str(tmp_path)], include_tree=lambda path: [path])
    assert [t.path.name for t in targets if t.path] == ["quad.urdf"]
