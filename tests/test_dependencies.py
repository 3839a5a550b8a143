"""Every install requirement earns its place: the product imports it (issue 22).

A requirement only the tests use belongs in the `test` extra; one nothing uses is dead
weight every user installs. Each requirement of `[project] dependencies` must be imported
by a module of the reedtool package (lazy imports included), and carry a comment saying
why beside it in pyproject.toml.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import reedtool

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = Path(reedtool.__file__).resolve().parent
# distribution name -> the module it installs, where they differ
IMPORT_NAME = {"pin": "pinocchio", "pyyaml": "yaml"}


def _pyproject() -> dict:
    if sys.version_info >= (3, 11):
        import tomllib
    else:
        import tomli as tomllib
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def _distribution(requirement: str) -> str:
    return re.match(r"[A-Za-z0-9_.-]+", requirement).group(0).lower()


def _imported_modules() -> set[str]:
    found = set()
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                found.add(node.module.split(".")[0])
    return found


def test_every_install_requirement_is_imported_by_the_product():
    imported = _imported_modules()
    unused = [req for req in _pyproject()["project"]["dependencies"]
              if IMPORT_NAME.get(_distribution(req), _distribution(req).replace("-", "_"))
              not in imported]
    assert unused == []


def test_every_install_requirement_says_why_it_stays():
    text = (ROOT / "pyproject.toml").read_text()
    block = text.split("dependencies = [", 1)[1].split("]\n", 1)[0]
    lines = block.splitlines()
    silent = []
    for number, line in enumerate(lines):
        match = re.match(r'\s*"([^"]+)"', line)
        if not match:
            continue
        name = _distribution(match.group(1))
        same_line = "#" in line.split('"', 2)[2]
        comment_above = any(lines[k].strip().startswith("#") and name in lines[k].lower()
                            for k in range(max(0, number - 4), number))
        if not (same_line or comment_above):
            silent.append(name)
    assert silent == []
