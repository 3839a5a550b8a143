"""`reedtool rules`: the rule catalogue, filtered by family, code prefix or name."""

from __future__ import annotations

import click


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
    from reedtool.report.rules_text import rules_json, rules_lines
    from reedtool.workflows.rule_catalogue import select_rules

    rules = select_rules(selectors, family, severity)
    if fmt == "json":
        click.echo(rules_json(rules))
    else:
        for line in rules_lines(rules):
            click.echo(line)
    return 0
