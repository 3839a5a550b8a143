"""`rules`: the rule catalogue filtered by the user's selectors (codes, prefixes or names,
as --select reads them), a family (by its letter or title, matched against each rule's
family in the registry) and a default severity.
"""

from __future__ import annotations

from reedtool.errors import ReedtoolError


def family_titles(family: str) -> set[str]:
    """The registry's family titles `family` names (its letter or its title, any case);
    an unknown family is refused with the families and a guess."""
    from reedtool.checks.registry import FAMILIES

    wanted = family.strip().lower()
    titles = {title for letter, (_module, title) in FAMILIES.items()
              if wanted in (letter.lower(), title.lower())}
    if titles:
        return titles
    from difflib import get_close_matches

    names = ", ".join(f"{letter} ({title})" for letter, (_m, title) in FAMILIES.items())
    lowered = {title.lower(): title for _m, title in FAMILIES.values()}
    # The family titles and their first words (`rotor` -> Rotors, `controler` ->
    # Controller cross-check), as the selectors' did-you-mean does for codes.
    words = {**lowered, **{t.split()[0]: full for t, full in lowered.items()}}
    close = get_close_matches(wanted, list(words), n=1, cutoff=0.6)
    guess = f"did you mean '{words[close[0]].lower()}'? " if close else ""
    raise ReedtoolError(f"unknown rule family '{family}'", hint=f"{guess}families: {names}")


def select_rules(selectors: tuple[str, ...], family: str | None, severity: str | None):
    """The rules matching every filter given (selectors: codes, prefixes or names, the
    user's own selection as for --select)."""
    from reedtool.checks.registry import all_rules
    from reedtool.checks.runner import Selection, parse_selectors

    rules = all_rules()
    if selectors:
        chosen = Selection(select=parse_selectors(selectors, origin="the command line"))
        rules = [r for r in rules if chosen.enabled(r.code)]
    if family:
        titles = family_titles(family)
        rules = [r for r in rules if r.family in titles]
    if severity:
        rules = [r for r in rules if r.severity == severity]
    return rules
