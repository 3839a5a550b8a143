"""The code table (reedtool/checks/codes.py) is the registry's list: every registered rule
is in it with the same name, its stack and lifecycle; retired codes stay out; every stable
rule has a bad and a good example but the few NO_EXAMPLE justifies; and each example does
what the page says (the bad one gives its code, the good one not). A model alone runs
through the rules; a Case (files beside the model, validate's words) through
`reedtool validate` as the page shows it.
"""

from __future__ import annotations

import re

import pytest

from reedtool.checks import registry
from reedtool.checks.codes import (CODES, EXAMPLE_CODES, EXAMPLES, LIFECYCLES, NO_EXAMPLE,
                                   RETIRED, STACKS, Case, as_case, example_format)
from reedtool.checks.registry import all_rules, rule
from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot


def test_registry_equals_the_table():
    registered = {r.code: (r.slug, r.stack, r.lifecycle) for r in all_rules()}
    assert registered == CODES
    for slug, stack, lifecycle in CODES.values():
        assert stack in STACKS and lifecycle in LIFECYCLES, slug


def test_retired_codes_stay_out_and_cannot_register_again():
    registered = {r.code for r in all_rules()}
    slugs = {r.slug for r in all_rules()}
    for code, (slug, why) in RETIRED.items():
        assert code not in registered and code not in CODES
        assert slug not in slugs, f"{code}'s name came back under another code"
        assert why
        with pytest.raises(ValueError, match="retired"):
            rule(code, "brand-new-name", "error", "x", clause="refused")(lambda ctx: iter(()))
        assert code not in registry._RULES


def test_stack_follows_what_each_rule_reads():
    """Independent of the table: the PX4 and ArduPilot cross-checks are the flightstack
    module's rules named after their stack, the Lee rules are lee_rules'."""
    for r in all_rules():
        module = r.check.__module__.rsplit(".", 1)[1]
        if module == "flightstack_rules":
            assert r.stack == r.slug.split("-")[0], r.code
        elif module == "lee_rules":
            assert r.stack == "rotors-lee", r.code
        elif r.stack != "core":
            assert r.slug.startswith(r.stack), r.code


@pytest.mark.parametrize("kind", ["px4", "ardupilot"])
def test_validate_picks_the_same_flight_stack_rules_as_before(kind):
    """validate's agreement line selects by stack metadata; the set is the one the module
    name and slug prefix gave (no behaviour change)."""
    by_metadata = {r.code for r in all_rules() if r.code.startswith("C") and r.stack == kind}
    by_module = {r.code for r in all_rules()
                 if r.check.__module__.endswith(".flightstack_rules") and r.slug.startswith(kind)}
    assert by_metadata == by_module and by_metadata


def test_every_example_code_has_a_bad_and_a_good_model():
    assert EXAMPLE_CODES <= set(CODES)
    for code in EXAMPLE_CODES:
        bad, good = (as_case(e) for e in EXAMPLES[code])
        assert bad.model.strip() and good.model.strip() and bad != good, code


def test_every_stable_rule_has_examples_or_says_why_not():
    """The page's promise: a stable rule without a bad and a good example is one of the
    explicitly justified few, and none of those has examples after all."""
    stable = {code for code, (_, _, lifecycle) in CODES.items() if lifecycle == "stable"}
    assert stable - EXAMPLE_CODES == set(NO_EXAMPLE)
    assert not set(NO_EXAMPLE) & EXAMPLE_CODES
    assert all(len(why) > 40 for why in NO_EXAMPLE.values())


def test_c421_is_shown_by_c422s_good_example(tmp_path, monkeypatch):
    """NO_EXAMPLE's claim for C421: C422's good pair gives it, C422's bad pair does not."""
    bad, good = EXAMPLES["C422"]
    assert "C421" in _found(good, tmp_path / "good", monkeypatch)
    assert "C421" not in _found(bad, tmp_path / "bad", monkeypatch)


def _write(case: Case, folder) -> None:
    folder.mkdir()
    for name, text in ((case.model_name, case.model),) + case.files:
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")


def _found(example: "str | Case", folder, monkeypatch) -> set[str]:
    """The codes the example gives: a model alone through the rules, a Case (files or
    words beside the model, or a run-level rule) through `reedtool validate` as the page
    shows it, in the folder the files were written to."""
    case = as_case(example)
    _write(case, folder)
    if not isinstance(example, Case):
        return {f.code for f in run_checks(load_robot(folder / case.model_name), Selection())}
    import json

    from click.testing import CliRunner

    from reedtool.cli import cli

    monkeypatch.chdir(folder)
    result = CliRunner().invoke(cli, ["validate", "--format", "json", "--no-color",
                                      case.model_name, *case.args])
    assert result.exit_code in (0, 1), result.output
    return {f["code"] for f in json.loads(result.stdout)["findings"]}


@pytest.mark.parametrize("code", sorted(EXAMPLE_CODES))
def test_documented_examples_do_what_they_say(code, tmp_path, monkeypatch):
    bad, good = EXAMPLES[code]
    assert code in _found(bad, tmp_path / "bad", monkeypatch)
    assert code not in _found(good, tmp_path / "good", monkeypatch)


def test_rules_json_carries_stack_and_lifecycle(capsys):
    import json

    from reedtool.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["rules", "--format", "json"])
    assert exc.value.code == 0
    listed = {r["code"]: (r["slug"], r["stack"], r["lifecycle"])
              for r in json.loads(capsys.readouterr().out)["rules"]}
    assert listed == CODES


@pytest.mark.parametrize("code", sorted(EXAMPLE_CODES))
def test_good_examples_load_in_the_consumer(code, tmp_path):
    """The independent reference: the page's good model is one Drake's parser (libsdformat's
    URDF reading, or its SDF reading) loads without an error, so "good" is not only
    reedtool's own verdict."""
    import sdformat_oracle

    good = as_case(EXAMPLES[code][1])
    _write(good, tmp_path / "good")
    assert sdformat_oracle.libsdformat_error(_consumed(good, tmp_path / "good")) is None


def _consumed(case: Case, folder):
    """The file Gazebo reads: the model, or a xacro file expanded by xacro itself (with the
    example's name:=value words), the way roslaunch hands it over."""
    path = folder / case.model_name
    if path.suffix != ".xacro":
        return path
    import xacro

    mappings = dict(word.split(":=", 1) for word in case.args if ":=" in word)
    urdf = path.with_suffix("")
    urdf.write_text(xacro.process_file(str(path), mappings=mappings).toxml(), encoding="utf-8")
    return urdf


def rule_clause(code: str) -> str:
    return next(r.clause for r in all_rules() if r.code == code)


@pytest.mark.parametrize("code", sorted(c for c in EXAMPLE_CODES
                                        if example_format(as_case(EXAMPLES[c][0]).model) == "sdf"
                                        and rule_clause(c) == "refused" and c[0] == "S"))
def test_bad_sdf_examples_of_refusal_rules_are_refused_by_the_consumer(code, tmp_path):
    """A structure rule whose clause says Gazebo refuses the model is held to that: its bad
    SDF example does not load in libsdformat (through Drake). (A controller rule's refusal,
    C411-C412, is the plugin's: a system that does not start; libsdformat does not read a
    plugin's elements.)"""
    import sdformat_oracle

    bad = as_case(EXAMPLES[code][0])
    _write(bad, tmp_path / "bad")
    assert sdformat_oracle.libsdformat_error(_consumed(bad, tmp_path / "bad")) is not None


def test_the_good_vehicle_yaml_is_the_quads_by_hand():
    """The controller examples' good quad.yaml, held to the quad's numbers derived here
    (parallel axis theorem over the body and four rotors, bearings and arms from the rotor
    table), not to reedtool's reading: a wrong 'good' file would make every C40x pair
    prove nothing."""
    import math

    import numpy as np
    import yaml

    # The RotorS quad of the examples: rotor (x, y, spin) with motorNumber 0..3.
    rotors = ((0.177, -0.177, "ccw"), (-0.177, 0.177, "ccw"), (0.177, 0.177, "cw"),
              (-0.177, -0.177, "cw"))
    body_kg, rotor_kg, rotor_z_m = 1.2, 0.005, 0.03
    I_body = np.diag([0.00964, 0.00964, 0.018])
    I_rotor = np.diag([1.25e-05, 1.25e-05, 2.5e-05])
    positions = [np.array([x, y, rotor_z_m]) for x, y, _ in rotors]
    mass = body_kg + 4 * rotor_kg
    com = sum(rotor_kg * p for p in positions) / mass
    I = I_body + body_kg * (com @ com * np.eye(3) - np.outer(com, com))
    for p in positions:
        d = p - com
        I = I + I_rotor + rotor_kg * (d @ d * np.eye(3) - np.outer(d, d))
    good = EXAMPLES["C401"][1]
    assert '<mass value="1.2"/>' in good.model and good.model.count('<mass value="0.005"/>') == 4
    table = yaml.safe_load(dict(good.files)["quad.yaml"])
    # The file writes 2-3 decimals of mass and 6 of each moment: tolerances are half a
    # unit of the last written digit.
    assert table["mass"] == pytest.approx(mass, abs=0.005)
    for key, (i, j) in {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1)}.items():
        assert table["inertia"][key] == pytest.approx(I[i, j], abs=5e-7), key
    for number, (x, y, spin) in enumerate(rotors):
        entry = table["rotor_configuration"][str(number)]
        assert f'<origin xyz="{x:g} {y:g} {rotor_z_m:g}"/>' in good.model
        assert entry["angle"] == pytest.approx(math.atan2(y, x), abs=5e-7)
        assert entry["arm_length"] == pytest.approx(math.hypot(x, y), abs=5e-7)
        assert entry["direction"] == (1.0 if spin == "ccw" else -1.0)


def test_the_good_px4_thrust_axes_are_the_tilted_rotors():
    """C427's good airframe gives PX4 each tilted rotor's axis: derived here as the SDF
    pose's rotation (extrinsic roll, pitch, yaw: R = Rz Ry Rx) applied to the rotor's z axis,
    turned into FRD (x, -y, -z), against the airframe's CA_ROTORi_AX/AY/AZ lines."""
    import numpy as np

    def rot_x(a):
        return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])

    def rot_z(a):
        return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])

    good = EXAMPLES["C427"][1]
    airframe = {name: float(value) for name, value in re.findall(
        r"param set-default (CA_ROTOR\d_A[XYZ]) (\S+)", dict(good.files)["4001_gz_x500"])}
    for i, (x, y) in enumerate(((0.174, -0.174), (-0.174, 0.174), (0.174, 0.174),
                                (-0.174, -0.174))):
        roll, pitch, yaw = (float(v) for v in re.search(
            rf"<pose>{x:g} {y:g} 0.06 (\S+) (\S+) (\S+)</pose>", good.model).groups())
        assert pitch == 0.0      # exact: the pose writes "0"
        flu = rot_z(yaw) @ rot_x(roll) @ np.array([0.0, 0.0, 1.0])
        frd = (flu[0], -flu[1], -flu[2])
        # Written with 4 decimals: half a unit of the last one.
        for axis, value in zip("XYZ", frd):
            assert airframe[f"CA_ROTOR{i}_A{axis}"] == pytest.approx(value, abs=5e-5)
        assert np.degrees(np.arccos(-frd[2])) == pytest.approx(11.46, abs=0.01)  # > C427's 10°
