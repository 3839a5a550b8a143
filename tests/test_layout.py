"""The package layout shows the pipeline: every import points down it, and no cycles.

Stages, lowest first. A module may import its own stage and any stage below it; two
stages of the same rank (checks and sim) are siblings and may not import each other.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import reedtool

PACKAGE = Path(reedtool.__file__).resolve().parent

CORE = {"", "errors", "model", "frames"}         # reedtool/__init__ and what every stage shares
RANK = {
    "": 0,
    "resolve": 1,
    "io": 2,
    "physics": 3,
    "flightstack": 4,
    "checks": 5, "sim": 5,
    "port": 6,
    "generate": 7,
    "report": 8, "config": 8,
    "workflows": 9,
    "commands": 10,
    "cli": 11,
}
# What the commands share that is not itself a command (click option types).
COMMANDS_SHARED = {"reedtool.commands", "reedtool.commands.params"}
MAX_LOOSE_MODULES = 8


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _stage(module: str) -> str:
    parts = module.split(".")
    stage = parts[1] if len(parts) > 1 else ""
    return "" if stage in CORE else stage


def _imports(path: Path, module: str) -> set[str]:
    """Absolute names of the reedtool modules `path` imports (lazy imports included)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            if name.split(".")[0] == "reedtool":
                found.add(name)
                found.update(f"{name}.{a.name}" for a in node.names
                             if (PACKAGE.parent / f"{name}.{a.name}".replace(".", "/")).with_suffix(".py").exists()
                             or (PACKAGE.parent / f"{name}.{a.name}".replace(".", "/") / "__init__.py").exists())
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == "reedtool")
    return found


DATA_DIRS = {"_data", "ros_packages"}   # bundled files (an installed wheel's templates), not code


@functools.cache           # parsed once for the five tests that read it; none changes it
def _graph() -> dict[str, set[str]]:
    return {_module_name(p): _imports(p, _module_name(p)) for p in PACKAGE.rglob("*.py")
            if not DATA_DIRS & set(p.relative_to(PACKAGE).parts)}


def test_every_import_points_down_the_pipeline():
    wrong = []
    for module, imported in _graph().items():
        here = _stage(module)
        for target in imported:
            there = _stage(target)
            if there == here:
                continue
            if RANK[there] > RANK[here] or (RANK[there] == RANK[here] and there != ""):
                wrong.append(f"{module} -> {target}")
    assert wrong == []


def _stage_edges(graph: dict[str, set[str]]) -> set[tuple[str, str]]:
    """(importing stage, imported stage) for every import across stages."""
    return {(_stage(module), _stage(target)) for module, imported in graph.items()
            for target in imported if _stage(module) != _stage(target)}


def test_stages_run_in_pipeline_order():
    """The workflows stage sits between the output stage and the commands, checks and sim below
    it: read from the package's imports, not from RANK. The workflows stage builds on checks, sim
    and report, the commands on it, and no stage below reaches up to them."""
    edges = _stage_edges(_graph())
    assert {("workflows", "checks"), ("workflows", "sim"), ("workflows", "report"),
            ("commands", "workflows")} <= edges
    below = {"", "resolve", "io", "physics", "flightstack", "checks", "sim", "port", "generate", "report",
             "config"}
    upward = sorted(f"{low} -> {high}" for low, high in edges
                    if low in below and high in ("workflows", "commands", "cli"))
    assert upward == []


def _command_to_command(graph: dict[str, set[str]]) -> list[str]:
    wrong = []
    for module, imported in graph.items():
        if _stage(module) != "commands" or module in COMMANDS_SHARED:
            continue
        wrong += [f"{module} -> {target}" for target in sorted(imported)
                  if _stage(target) == "commands" and target not in COMMANDS_SHARED
                  and target != module]
    return wrong


def test_no_command_imports_another_command():
    """Each command is options -> one call -> report -> exit code; what two commands share
    lives below them (workflows/, report/), never in one of them."""
    assert _command_to_command(_graph()) == []


def test_command_to_command_imports_are_found():
    """The check above can fail: hover-test importing validate (as it once did) is caught,
    the shared option types are not."""
    graph = {"reedtool.commands.hover_test": {"reedtool.commands.validate",
                                              "reedtool.commands.params",
                                              "reedtool.workflows.flight"}}
    assert _command_to_command(graph) == ["reedtool.commands.hover_test -> "
                                          "reedtool.commands.validate"]


def test_every_module_belongs_to_a_known_stage():
    assert sorted({_stage(m) for m in _graph()} - set(RANK)) == []


def test_no_import_cycles_between_modules():
    graph = _graph()
    # Module-to-module edges only (a package __init__ importing its own modules is fine).
    edges = {m: {t for t in ts if t in graph and t != m and not m == t.rpartition(".")[0]}
             for m, ts in graph.items()}
    state: dict[str, int] = {}
    cycles = []

    def visit(node, stack):
        state[node] = 1
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 1:
                cycles.append(" -> ".join(stack[stack.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            visit(node, [node])
    assert cycles == []


def test_few_modules_stay_loose_at_the_top():
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(loose) <= MAX_LOOSE_MODULES, loose
