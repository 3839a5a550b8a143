"""`name:=value` arguments: the one place every model-loading command parses them."""

from __future__ import annotations

import re
from typing import Sequence

from reedtool.errors import ReedtoolError

MAPPING_SEPARATOR = ":="


def parse_mappings(args: Sequence[str]) -> dict[str, str]:
    """`name:=value` command-line arguments, as roslaunch and xacro take them.

    Shared by every command that loads a model, so all of them accept and refuse the same
    arguments. A second `:=` is refused, as xacro does, rather than guessing which is meant.
    """
    mappings: dict[str, str] = {}
    for arg in args:
        name, sep, value = arg.partition(MAPPING_SEPARATOR)
        name = name.strip()
        if not sep or not name or MAPPING_SEPARATOR in value or any(c.isspace() for c in name):
            suggestion = suggest_mapping(arg) if not sep else None
            raise ReedtoolError(f"cannot read argument '{arg}'",
                                hint=(f"did you mean '{suggestion}'? " if suggestion else "")
                                + "xacro arguments are written name:=value, one per word, "
                                  "after the model")
        mappings[name] = value
    return mappings



_MISTYPED = re.compile(r"^([A-Za-z_][A-Za-z0-9_.-]*)=(.*)$")


def suggest_mapping(word: str) -> str | None:
    """`name:=value` for a word written `name=value` (a path never looks like that here:
    the caller asks only about words that name no file)."""
    match = _MISTYPED.match(word.strip())
    return f"{match.group(1)}{MAPPING_SEPARATOR}{match.group(2)}" if match else None
