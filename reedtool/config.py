"""Project configuration for reedtool: `[tool.reedtool]` in pyproject.toml, or reedtool.toml.

The nearest configuration above the model wins, found by walking up from the model's
directory: in each directory a reedtool.toml (top-level keys) is taken first, then a
pyproject.toml that has a `[tool.reedtool]` table (one without it is skipped, as ruff
does). Keys:

    select = ["S", "I", "R"]          # code prefixes to run (default: all)
    ignore = ["I205"]                 # code prefixes to skip
    strict = false                    # warnings fail the run too
    [tool.reedtool.severity]          # or [severity] in reedtool.toml
    I204 = "error"                    # per-prefix severity overrides
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path

from reedtool.errors import ReedtoolError

KEYS = ("select", "ignore", "severity", "strict")


@dataclass(frozen=True)
class Config:
    path: Path | None = None
    select: tuple[str, ...] | None = None     # None: not configured
    ignore: tuple[str, ...] = ()
    severity: dict[str, str] = field(default_factory=dict)
    strict: bool = False


def _load_toml(path: Path) -> dict:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - exercised on 3.10 only
        import tomli as tomllib
    from reedtool.io.fileio import open_regular_input

    try:
        with open_regular_input(path, what="config file", max_bytes=1 << 20) as handle:
            return tomllib.load(handle)
    except UnicodeDecodeError:
        raise ReedtoolError("not a text file (bytes that are not UTF-8)", file=path,
                            hint="is this the right file? save it as UTF-8 text") from None
    except OSError as exc:
        raise ReedtoolError(f"cannot read config: {exc.strerror}", file=path) from exc
    except tomllib.TOMLDecodeError as exc:
        raise ReedtoolError(f"invalid TOML: {exc}", file=path,
                            hint="fix the syntax or remove the file") from exc


def find_config(start: Path) -> tuple[Path, dict] | None:
    """The nearest reedtool configuration at or above `start` and its table."""
    directory = start if start.is_dir() else start.parent
    for folder in [directory.resolve(), *directory.resolve().parents]:
        candidate = folder / "reedtool.toml"
        if candidate.is_file():
            return candidate, _load_toml(candidate)
        candidate = folder / "pyproject.toml"
        if candidate.is_file():
            table = _load_toml(candidate).get("tool", {}).get("reedtool")
            if table is not None:
                return candidate, table
    return None


def _string_list(value, key: str, path: Path) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ReedtoolError(f"'{key}' must be a list of rule codes or prefixes", file=path)
    return tuple(value)


def parse_config(table: dict, path: Path) -> Config:
    unknown = sorted(set(table) - set(KEYS))
    if unknown:
        raise ReedtoolError(f"unknown reedtool setting '{unknown[0]}'", file=path,
                            hint=f"known settings: {', '.join(KEYS)}")
    severity = table.get("severity", {})
    if not isinstance(severity, dict):
        raise ReedtoolError("'severity' must be a table of CODE = \"error|warning|info\"",
                            file=path)
    strict = table.get("strict", False)
    if not isinstance(strict, bool):
        raise ReedtoolError("'strict' must be true or false", file=path)
    return Config(
        path=path,
        select=_string_list(table["select"], "select", path) if "select" in table else None,
        ignore=_string_list(table.get("ignore", []), "ignore", path),
        severity={str(k): str(v) for k, v in severity.items()},
        strict=strict,
    )


def load_config(model_path: Path) -> Config:
    """The configuration that applies to `model_path`; defaults when there is none."""
    found = find_config(Path(model_path))
    if found is None:
        return Config()
    path, table = found
    if not isinstance(table, dict):
        raise ReedtoolError("[tool.reedtool] must be a table", file=path)
    return parse_config(table, path)
