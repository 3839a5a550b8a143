"""The code table (reedtool/checks/codes.py) is the registry's list: every registered rule
is in it with the same name, its stack and lifecycle; retired codes stay out; and each
documented example does what the page says (the bad model gives its code, the good one not).
"""

from __future__ import annotations

import pytest

from reedtool.checks import registry
from reedtool.checks.codes import (CODES, EXAMPLE_CODES, EXAMPLES, LIFECYCLES, RETIRED, STACKS,
                                   example_format)
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
        bad, good = EXAMPLES[code]
        assert bad.strip() and good.strip() and bad != good, code


@pytest.mark.parametrize("code", sorted(EXAMPLE_CODES))
def test_documented_examples_do_what_they_say(code, tmp_path):
    bad, good = EXAMPLES[code]
    found = {}
    for kind, text in (("bad", bad), ("good", good)):
        path = tmp_path / f"{kind}.{example_format(text)}"
        path.write_text(text, encoding="utf-8")
        found[kind] = {f.code for f in run_checks(load_robot(path), Selection())}
    assert code in found["bad"]
    assert code not in found["good"]


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

    good = EXAMPLES[code][1]
    path = tmp_path / f"good.{example_format(good)}"
    path.write_text(good, encoding="utf-8")
    assert sdformat_oracle.libsdformat_error(path) is None


def rule_clause(code: str) -> str:
    return next(r.clause for r in all_rules() if r.code == code)


@pytest.mark.parametrize("code", sorted(c for c in EXAMPLE_CODES
                                        if example_format(EXAMPLES[c][0]) == "sdf"
                                        and rule_clause(c) == "refused"))
def test_bad_sdf_examples_of_refusal_rules_are_refused_by_the_consumer(code, tmp_path):
    """A rule whose clause says libsdformat refuses the model is held to that: its bad SDF
    example does not load in libsdformat (through Drake)."""
    import sdformat_oracle

    path = tmp_path / "bad.sdf"
    path.write_text(EXAMPLES[code][0], encoding="utf-8")
    assert sdformat_oracle.libsdformat_error(path) is not None
