"""Rules on how a model is invoked: the xacro arguments given to it (S140-S149).

These rules look at `CheckContext.arguments` (reedtool.io.xacro_args.ArgumentUse), which
`validate` fills from the command line, the configuration and `--launch`; without it
(a URDF, or a library call) they find nothing.
"""

from __future__ import annotations

from difflib import get_close_matches
from typing import Iterator

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule


@rule("S140", "xacro-argument-unknown", "warning",
      "A name:=value argument names no argument the model declares or reads.", clause="suspicious")
def argument_unknown(ctx: CheckContext) -> Iterator[Issue]:
    """xacro ignores an argument that no file of the model declares (`<xacro:arg>`) or
    reads (`$(arg ...)`), so a misspelt `mav_nmae:=hex` leaves the default in place without
    a word, and the model is simulated with a value nobody chose. The finding points at
    where the argument was written (the launch file line, the configuration file) and
    suggests the nearest name the model knows.

    It is a warning, not an error: a launch file may pass the same arguments to several
    models that read different subsets. Not reported when an include of the model could
    not be followed statically (its arguments are then unknown).
    """
    use = ctx.arguments
    if use is None or not use.complete:
        return
    for name in sorted(use.given):
        if name in use.declared:
            continue
        close = get_close_matches(name, sorted(use.declared), n=1, cutoff=0.6)
        origin = use.origins.get(name)
        where = f" (from {origin})" if origin else ""
        hint = (f"did you mean '{close[0]}'?" if close else
                "the model declares " + (", ".join(sorted(use.declared)) or "no arguments"))
        yield Issue(f"argument '{name}'{where} is not declared or read by the model; xacro "
                    "ignores it", loc=use.given[name], subject=name, hint=hint)
