"""A command is options -> one call -> a report object -> a formatter in report/ -> an exit
code (issue 29, docs/architecture.md): no function of reedtool/commands/ grows past about a
screen, so product logic and formatting cannot settle there again."""

from __future__ import annotations

import ast
from pathlib import Path

import reedtool

COMMANDS = Path(reedtool.__file__).resolve().parent / "commands"
# A screen: option parsing, one call, the formatter and the exit code fit well inside it.
MAX_FUNCTION_LINES = 60


def _long_functions(source: str, name: str) -> list[str]:
    """'file:function (N lines)' for each function (methods and nested ones included) longer
    than MAX_FUNCTION_LINES, counted from its `def` line (decorators excluded) to its last."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            length = node.end_lineno - node.lineno + 1
            if length > MAX_FUNCTION_LINES:
                out.append(f"{name}:{node.name} ({length} lines)")
    return out


def test_no_function_in_commands_is_over_a_screen():
    long = [found for path in sorted(COMMANDS.glob("*.py"))
            for found in _long_functions(path.read_text(encoding="utf-8"), path.name)]
    assert long == []


def test_a_long_function_is_found():
    """The walk above can fail: a 61-line function (and one nested in a class) is caught, a
    60-line one is not."""
    def body(n):
        return "\n".join(["    x = 0"] * (n - 1))
    source = (f"def ok():\n{body(60)}\n\ndef long():\n{body(61)}\n\n"
              f"class C:\n    def m(self):\n    {body(61).replace(chr(10), chr(10) + '    ')}\n")
    assert _long_functions(source, "x.py") == ["x.py:long (61 lines)", "x.py:m (61 lines)"]
