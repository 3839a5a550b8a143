"""The one unit and axis reading of a CAD mesh (reedtool/physics/mesh_units.py), and
validate's mesh-unit rules naming the unit it finds. References: unit factors by
definition (1 in = 25.4 mm exactly), densities and sizes by hand."""

from __future__ import annotations

import numpy as np
import pytest
from mesh_helpers import box_triangles

from reedtool.errors import ReedtoolError
from reedtool.io.stl import stl_bytes
from reedtool.physics.mesh_units import (
    UnitCues,
    choose_axes,
    choose_units,
    signed_volume,
    units_read_as_metres,
)


def test_size_alone_refuses_what_two_units_fit():
    # 450 units: a 0.45 m part in mm, a 4.5 m one in cm (both 0.01-5 m): asked.
    with pytest.raises(ReedtoolError, match="fit mm and cm") as info:
        choose_units("auto", UnitCues(450.0, None))
    assert info.value.hint == "pass --units mm or --units cm"
    # 0.45 units: only metres (0.45 mm, 4.5 mm, 11 mm in the others; 11 mm is a part too!)
    with pytest.raises(ReedtoolError, match="fit in and m"):
        choose_units("auto", UnitCues(0.45, None))
    # 8 units: cm (0.08 m) and in (0.2 m); m (8 m) and mm (8 mm) are not parts.
    with pytest.raises(ReedtoolError, match="fit in and cm"):
        choose_units("auto", UnitCues(8.0, None))


def test_the_mass_settles_what_the_size_leaves_open():
    # 450 x 450 x 60 box, 1.5 kg: as mm 0.01215 m^3 -> 123 kg/m^3; as cm 12.15 m^3 ->
    # 0.12 kg/m^3, below any body: mm.
    volume = 450.0 * 450.0 * 60.0
    choice = choose_units("auto", UnitCues(450.0, volume, 1.5), flag="--mesh-units")
    assert (choice.unit, choice.metres_per_unit, choice.guessed) == ("mm", 0.001, True)
    assert "123 kg/m^3" in choice.reason and "cm (0.123 kg/m^3" in choice.reason


def test_density_always_tells_mm_from_inch():
    """The body density window (10 .. 1e5 kg/m^3) is narrower than 25.4^3 = 16,387, the
    density ratio of the same numbers read as mm and as inches: never both."""
    for density in (10.0, 300.0, 5_000.0, 99_000.0):
        volume_m3 = 1.2 / density
        for unit, s in (("mm", 0.001), ("in", 0.0254)):
            cues = UnitCues(0.3 / s, volume_m3 / s ** 3, 1.2, None, "body")
            fits = [u for u in ("mm", "in") if __import__(
                "reedtool.physics.mesh_units", fromlist=["judge_unit"]).judge_unit(u, cues)[0]]
            assert fits == [unit], (density, unit, fits)


def test_an_arm_length_no_unit_can_hold_is_named_as_the_cause():
    """The issue's `--arm-length 18` (metres meant as cm or inches?) on a 0.38 m mm body:
    25 m rotor radius over a 0.19 m half-span is 133, beyond 12; the mesh itself is a
    body only in mm. The refusal names the arm length, not the unit."""
    cues = UnitCues(383.6, 246994.0, 1.2, 18.0 * 2 ** 0.5, "body")
    with pytest.raises(ReedtoolError, match="the arm length puts the rotors 25.4558 m out, "
                                            "which fits this body in no unit: as mm") as info:
        choose_units("auto", cues, flag="--mesh-units")
    assert "133 half-spans out" in info.value.message
    assert "check --arm-length" in info.value.hint


def test_a_given_unit_is_taken_and_a_slip_is_said():
    choice = choose_units("in", UnitCues(383.6, 246994.0, 1.2, None, "body"),
                          flag="--mesh-units")
    assert choice.metres_per_unit == 0.0254 and not choice.guessed      # exact by definition
    assert choice.note.startswith("as in the mesh is implausible (9.74 m across")
    with pytest.raises(ReedtoolError, match="unknown unit"):
        choose_units("furlong", UnitCues(1.0, None))


def test_a_declared_collada_unit_is_taken_as_gazebo_takes_it():
    choice = choose_units("auto", UnitCues(300.0, None), declared_m=0.01)
    assert (choice.unit, choice.guessed) == ("cm", False)


def test_axes_z_down_and_y_up_are_refused_under_auto_and_kept_when_named():
    lying_below = box_triangles((300.0, 300.0, 40.0)) - np.array([150.0, 150.0, 40.0])
    with pytest.raises(ReedtoolError, match="which way is up") as info:
        choose_axes("auto", lying_below / 1000.0)
    assert "--from-frame ned" in info.value.hint and "--from-frame frd" in info.value.hint
    frame, reading = choose_axes("ned", lying_below / 1000.0)
    assert frame.code == "frd" and reading.suggested == ()
    standing = box_triangles((300.0, 60.0, 350.0)) / 1000.0      # Y-up: y is the height
    with pytest.raises(ReedtoolError, match="350 mm tall"):
        choose_axes("auto", standing)
    frame, reading = choose_axes("flu", standing)                # the user's word is taken
    assert frame.code == "flu" and "(taken as given with --from-frame flu)" in reading.reason


def test_signed_volume_of_a_box_is_its_product():
    assert signed_volume(box_triangles((2.0, 3.0, 5.0))) == pytest.approx(30.0, rel=1e-12)


def test_validate_names_inches_for_an_inch_mesh_read_as_metres(tmp_path):
    """A 1.5 m airframe plate drawn in inches (59 x 59 x 1 in) on an 8 kg link, read as
    metres: 59 m across (I206/I210 start at 20 m). In mm it would be 59 mm and 2.3e6
    kg/m^3 (no matter is); in cm 0.59 m and 2,300 kg/m^3; in inches 1.5 m and 140 kg/m^3:
    both are named, inches first, each with its scale."""
    from reedtool.checks.runner import run_checks
    from reedtool.io.loader import load_robot

    (tmp_path / "frame.stl").write_bytes(stl_bytes(box_triangles((59.0, 59.0, 1.0))))
    urdf = tmp_path / "q.urdf"
    urdf.write_text(
        '<robot name="q"><link name="base"><inertial><mass value="8"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="2"/></inertial>'
        '<visual><geometry><mesh filename="frame.stl"/></geometry></visual></link></robot>')
    assert units_read_as_metres(59.0, 59 * 59 * 1.0, 8.0) == ["in", "cm"]
    findings = [f for f in run_checks(load_robot(urdf)) if f.code in ("I206", "I210")]
    assert len(findings) == 1, findings
    assert "looks like inches or centimetres read as metres" in findings[0].message
    assert 'scale="0.0254 0.0254 0.0254" (inches)' in findings[0].hint
    assert 'scale="0.01 0.01 0.01" (centimetres)' in findings[0].hint
