"""Where reedtool picks rules by what they are (validate's refusal groups, the flight-stack
agreement, the scenery exemption, `rules --family`), it reads each rule's family and stack
from the registry, never a code's letters or a module's name (issue 29 item 2). A family
named wrongly would select nothing and pass silently: each name used is one the registry
gives, and each selection holds the rules it is documented to hold."""

from __future__ import annotations

from reedtool.checks.registry import FAMILIES, all_rules

TITLES = {title for _module, title in FAMILIES.values()}


def test_every_family_named_is_a_registry_family():
    from reedtool.checks.runner import SCENERY_EXEMPT_FAMILIES
    from reedtool.workflows.validate_run import CONTROLLER_FAMILY, STRUCTURE_FAMILY
    from reedtool.workflows.validation import REFUSAL_GROUPS

    named = {*SCENERY_EXEMPT_FAMILIES, CONTROLLER_FAMILY, STRUCTURE_FAMILY,
             *(g.family for g in REFUSAL_GROUPS.values() if g.family is not None)}
    assert named <= TITLES, named - TITLES


def test_every_code_a_refusal_group_names_is_a_rule():
    from reedtool.workflows.validation import REFUSAL_GROUPS

    codes = {r.code for r in all_rules()}
    named = {c for g in REFUSAL_GROUPS.values() for c in (*g.leave_out, *g.codes)}
    assert sorted(named - codes) == [], sorted(named - codes)


def test_the_flight_stack_agreement_reads_family_and_stack():
    """The rules a .parm file must pass are the controller cross-checks of ArduPilot's
    stack (C430-C434, docs/architecture.md's flightstack_rules), not R318, the rotor rule
    that also carries the stack: the agreement line would otherwise wait on a rotor's
    blade sign."""
    from reedtool.workflows.validate_run import CONTROLLER_FAMILY

    ardupilot = [r.code for r in all_rules()
                 if r.family == CONTROLLER_FAMILY and r.stack == "ardupilot"]
    assert ardupilot == ["C430", "C431", "C432", "C433", "C434"]
    assert "R318" in {r.code for r in all_rules() if r.stack == "ardupilot"}


def test_rules_family_filter_reads_the_registry():
    from reedtool.workflows.rule_catalogue import select_rules

    rotors = select_rules((), "rotors", None)
    assert rotors and {r.family for r in rotors} == {"Rotors"}
    assert select_rules((), "R", None) == rotors
    assert [r.code for r in select_rules(("R30",), "structure", None)] == []
