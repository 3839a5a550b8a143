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
