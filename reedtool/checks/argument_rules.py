"""Rules on how a model is invoked: the xacro arguments given to it (S140-S149).

These rules look at `CheckContext.arguments` (reedtool.io.xacro_args.ArgumentUse), which
`validate` fills from the command line, the configuration and `--launch`; without it
(a URDF, or a library call) they find nothing.
"""

from __future__ import annotations

from typing import Iterator

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule


def _unknown_arguments(ctx: CheckContext):
    """(name, nearest declared name or None, where written, origin) per unknown argument."""
    use = ctx.arguments
    if use is None or not use.complete:
        return
    for name in sorted(use.given):
        if name in use.declared:
            continue
        from difflib import get_close_matches  # here: only an unknown argument needs it

        close = get_close_matches(name, sorted(use.declared), n=1, cutoff=0.6)
        yield name, (close[0] if close else None), use.given[name], use.origins.get(name)


def _message(name: str, origin) -> str:
    where = f" (from {origin})" if origin else ""
    return f"argument '{name}'{where} is not declared or read by the model; xacro ignores it"


@rule("S140", "xacro-argument-unknown", "warning",
      "A name:=value argument the model does not read is a near miss of one it does.",
      clause="suspicious")
def argument_unknown(ctx: CheckContext) -> Iterator[Issue]:
    """xacro ignores an argument that no file of the model declares (`<xacro:arg>`) or
    reads (`$(arg ...)`), so a misspelt `mav_nmae:=hex` leaves the default in place without
    a word, and the model is simulated with a value nobody chose. The finding points at
    where the argument was written (the launch file line, the configuration file) and
    suggests the nearest name the model knows.

    Severity (warning: suspicious, but the model loads and flies): only an argument close
    to a name the model knows (difflib ratio 0.6 or more) is a likely typo. Not reported
    when an include of the model could not be followed statically (its arguments are then
    unknown).
    """
    for name, close, loc, origin in _unknown_arguments(ctx):
        if close is not None:
            yield Issue(_message(name, origin), loc=loc, subject=name,
                        hint=f"did you mean '{close}'?")


@rule("S141", "xacro-argument-unused", "info",
      "A name:=value argument the model neither reads nor nearly names.", clause="ambiguous")
def argument_unused(ctx: CheckContext) -> Iterator[Issue]:
    """As S140, for an argument that is not near any name the model knows: a launch file
    passes one set of arguments to several models and nodes, each reading its own subset
    (CrazyS's launch files pass `enable_mellinger_controller` to every vehicle).

    Severity (information): reedtool cannot tell an argument meant for another part of the
    launch from a mistake, so it says what it sees.
    """
    use = ctx.arguments
    for name, close, loc, origin in _unknown_arguments(ctx):
        if close is None:
            yield Issue(_message(name, origin), loc=loc, subject=name,
                        hint="the model declares " + (", ".join(sorted(use.declared))
                                                      or "no arguments"))
