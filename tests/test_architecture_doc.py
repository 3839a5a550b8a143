"""docs/architecture.md lists every module of the package in a row of its own, and no
module that is gone (HELPERS: 'one row each'; it drifted when stages were added)."""

from pathlib import Path

# The checkout's sources and docs (CI tests an installed wheel, which carries no docs).
ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "reedtool"
DOC = ROOT / "docs" / "architecture.md"
BUNDLED = {"ros_packages"}     # data shipped with the package, not code


def _modules() -> set[str]:
    out = set()
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        if rel.parts[0] in BUNDLED:
            continue
        # A package's __init__ is its face; only one that holds code of its own gets a row.
        if path.name == "__init__.py" and path.parent.name != "report":
            continue
        out.add(rel.as_posix())
    return out


def _rows() -> list[str]:
    cells = []
    for line in DOC.read_text(encoding="utf-8").splitlines():
        parts = [c.strip() for c in line.split("|")]
        if line.startswith("|") and len(parts) >= 4 and parts[2].startswith("`"):
            cells.append(parts[2].strip("`"))
    return cells


def test_every_module_has_one_row():
    rows = _rows()
    modules = _modules()
    assert sorted(m for m in modules if rows.count(m) != 1) == []
    assert sorted(set(rows) - modules) == []


def _stage_of_row() -> dict[str, str]:
    """module -> the stage its row sits under (a blank stage cell continues the one above)."""
    stages, current = {}, ""
    for line in DOC.read_text(encoding="utf-8").splitlines():
        parts = [c.strip() for c in line.split("|")]
        if line.startswith("|") and len(parts) >= 4 and parts[2].startswith("`"):
            current = parts[1] or current
            stages[parts[2].strip("`")] = current
    return stages


def test_every_row_sits_under_its_folder():
    """A module's row names the stage its folder is (report/ is the output stage, the loose
    modules are core, config or cli), so the table cannot keep a folder's old name."""
    loose = {"errors.py": "core", "model.py": "core", "frames.py": "core",
             "config.py": "output", "cli.py": "cli"}
    wrong = {module: stage for module, stage in _stage_of_row().items()
             if stage != loose.get(module, {"report": "output"}.get(module.split("/")[0],
                                                                    module.split("/")[0]))}
    assert wrong == {}
