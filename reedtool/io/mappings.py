"""`name:=value` arguments: the one place every model-loading command parses them."""

from __future__ import annotations

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
            raise ReedtoolError(f"cannot read argument '{arg}'",
                                hint="xacro arguments are written name:=value, one per word, "
                                     "after the model")
        mappings[name] = value
    return mappings

