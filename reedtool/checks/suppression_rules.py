"""Rules on the suppressions themselves (S142, S143), as ruff checks its noqa comments.

A suppression that names no rule (`ignore[I2O4]`, the letter O for a zero) silences
nothing and says nothing, so the finding it was written for comes back unexplained; one
that silences nothing any more hides the next finding on its line. S142 reads the
comments of the files a robot was read from; S143 is judged over the whole run, since a
comment in a macro file several models share is needed when any of them needs it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import get_rule, rule, suggest_selector
from reedtool.checks.suppressions import source_files, unknown_names, unused
from reedtool.model import SourceLoc


@rule("S142", "suppression-code-unknown", "warning",
      "An inline suppression names no rule code or rule name, so it silences nothing.",
      clause="suspicious")
def suppression_code_unknown(ctx: CheckContext) -> Iterator[Issue]:
    """`<!-- reedtool: ignore[I2O4] -->` (a letter O typed for a zero), `ignore[I2]` (a
    prefix) or `ignore[inertia-triangle]` (half a rule name) silence nothing: a suppression
    names whole codes or rule names, as ruff's `# noqa:` names whole codes. Without this
    rule the typo passes silently, and the finding it was meant for stays reported with no
    word on why the comment did not work. The finding points at the comment and suggests
    the nearest code or rule name.

    Severity (warning: suspicious, the model itself is unaffected): the comment does
    nothing, which is rarely what its author meant.
    """
    for file, shown in sorted(source_files(ctx.robot).items()):
        for line, name in unknown_names(file):
            guess = suggest_selector(name)
            if guess is not None and get_rule(guess) is None:
                guess = None     # a prefix: a suppression needs a whole code
            yield Issue(f"suppression names '{name}', which is no rule code or rule name; "
                        "it silences nothing", loc=SourceLoc(shown, line), subject=name,
                        hint=(f"did you mean '{guess}'? " if guess else "")
                        + "a suppression names whole codes (I204) or rule names; "
                          "`reedtool rules` lists them")


@dataclass
class SuppressionUse:
    """What one checked model tells the run about suppressions: the files it was read from,
    the comment entries that silenced one of its findings, the rules that ran on it."""

    files: dict[str, str] = field(default_factory=dict)    # resolved -> as shown
    used: set[tuple[str, int, str]] = field(default_factory=set)
    enabled: frozenset[str] = frozenset()


@rule("S143", "suppression-unused", "info",
      "An inline suppression silenced no finding in this run.", clause="ambiguous",
      run_level=True)
def suppression_unused(uses: list[SuppressionUse]) -> Iterator[Issue]:
    """A `<!-- reedtool: ignore[...] -->` comment whose rules found nothing on its line (or
    the next) in any model of the run: the mistake it excused was fixed, or the element
    moved. Left in place it silences the next finding on that line without anyone having
    looked at it, as ruff's RUF100 warns for unused noqa comments. A comment in a file
    several models of the run include is unused only when none of them needed it; a name of
    a rule the run did not select (`--select`) is not judged.

    Severity (info, reedtool cannot tell a convention from a mistake): the comment may serve
    a model or an argument variant this run did not check (pre-commit passes only the
    changed files). Raise it with `[tool.reedtool.severity] S143 = "warning"`.
    """
    files = set().union(*(set(use.files) for use in uses)) if uses else set()
    used = set().union(*(use.used for use in uses)) if uses else set()
    enabled = frozenset().union(*(use.enabled for use in uses)) if uses else frozenset()
    for file, line, name in unused(files, used, lambda code: code in enabled):
        what = "every rule" if name == "*" else f"'{name}'"
        yield Issue(f"suppression of {what} silenced no finding in this run",
                    loc=SourceLoc(file, line), subject=name,
                    hint="remove it (or the name) if the finding it excused is fixed")
