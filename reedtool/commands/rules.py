"""`reedtool rules`: the rule catalogue, filtered by family, code prefix or name."""

from __future__ import annotations

import json

import click

from reedtool.errors import ReedtoolError

SCHEMA = "reedtool.rules/1"


def select_rules(selectors: tuple[str, ...], family: str | None, severity: str | None):
    """The rules matching every filter given (selectors: codes, prefixes or names)."""
    from reedtool.checks.registry import FAMILIES, all_rules
    from reedtool.checks.runner import parse_selectors

    rules = all_rules()
    if selectors:
        prefixes = parse_selectors(selectors, origin="the command line")
        rules = [r for r in rules if any(r.code.startswith(p) for p in prefixes)]
    if family:
        wanted = family.strip().lower()
        letters = {letter for letter, (_module, title) in FAMILIES.items()
                   if wanted in (letter.lower(), title.lower())}
        if not letters:
            from difflib import get_close_matches

            names = ", ".join(f"{letter} ({title})" for letter, (_m, title) in FAMILIES.items())
            titles = {title.lower(): title for _m, title in FAMILIES.values()}
            # The family titles and their first words (`rotor` -> Rotors, `controler` ->
            # Controller cross-check), as the selectors' did-you-mean does for codes.
            words = {**titles, **{t.split()[0]: full for t, full in titles.items()}}
            close = get_close_matches(wanted, list(words), n=1, cutoff=0.6)
            guess = f"did you mean '{words[close[0]].lower()}'? " if close else ""
            raise ReedtoolError(f"unknown rule family '{family}'",
                                hint=f"{guess}families: {names}")
        rules = [r for r in rules if r.code[0] in letters]
    if severity:
        rules = [r for r in rules if r.severity == severity]
    return rules


@click.command(name="rules")
@click.argument("selectors", nargs=-1, metavar="[CODE|PREFIX|NAME]...")
@click.option("--family", metavar="NAME", help="Only this family: S/structure, I/inertia, "
                                               "R/rotors, C/controller cross-check.")
@click.option("--severity", type=click.Choice(["error", "warning", "info"]),
              help="Only rules of this default severity.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
def command(selectors: tuple[str, ...], family: str | None, severity: str | None,
            fmt: str) -> int:
    """List validate's rules: code, name, default severity, family and summary.

    `reedtool validate --explain CODE` prints one rule's full documentation.
    """
    rules = select_rules(selectors, family, severity)
    if fmt == "json":
        from reedtool.report.json_format import envelope

        doc = {**envelope(SCHEMA), "rules": [
            {"code": r.code, "slug": r.slug, "severity": r.severity, "family": r.family,
             "summary": r.summary, "clause": r.clause, "stack": r.stack,
             "lifecycle": r.lifecycle, "explanation": r.explanation}
            for r in rules]}
        click.echo(json.dumps(doc, indent=2, ensure_ascii=False))
        return 0
    if not rules:
        click.echo("no rule matches")
        return 0
    width = max(len(r.slug) for r in rules)
    for r in rules:
        click.echo(f"{r.code}  {r.slug:<{width}}  {r.severity:<7}  {r.summary}")
    return 0
