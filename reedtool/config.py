"""Project configuration for reedtool: `[tool.reedtool]` in pyproject.toml, or reedtool.toml.

The nearest configuration above the model wins, found by walking up from the model's
directory: in each directory a reedtool.toml (top-level keys) is taken first, then a
pyproject.toml that has a `[tool.reedtool]` table (one without it is skipped, as ruff
does). Configurations further up are not merged; `--show-settings` lists every one found
and says which won. Keys:

    select = ["S", "I", "R"]          # codes, prefixes or rule names to run (default: all)
    ignore = ["I205"]                 # codes, prefixes or rule names to skip
    strict = false                    # warnings fail the run too
    args = {mav_name = "reed_quad_x"} # xacro name:=value arguments for every model
    [tool.reedtool.severity]          # or [severity] in reedtool.toml
    I204 = "error"                    # per-prefix severity overrides
    [tool.reedtool.per-file-args]     # more xacro arguments for models matching a glob
    "urdf/*.gazebo" = {namespace = "reed_quad_x"}
    # a list of tables: the model is validated once per table (argument variants)
    "urdf/mav_generic_odometry_sensor.gazebo" = [{mav_name = "firefly"},
                                                 {mav_name = "hummingbird"}]
    [tool.reedtool.per-file-ignores]  # rules to skip for findings in files matching a glob
    "urdf/legacy_*.xacro" = ["S120"]
    exclude = ["build", "install"]    # files and directories a directory walk skips
    extend-exclude = ["urdf/old/*"]   # more of them, on top of `exclude`'s (or the default)
    force-exclude = false             # skip excluded files even when named (pre-commit)
    baseline = "reedtool-baseline.json"  # accepted findings; only new ones are reported

Globs are matched against the path relative to the directory of the configuration file;
a glob without a `/` also matches the file name alone (`"*.gazebo"`). As in ruff, an
`exclude` pattern without a `/` matches any file or directory of that name below the
directory walked, one with a `/` the path relative to the configuration file; `exclude`
replaces the default (DEFAULT_EXCLUDE: the build trees of catkin and colcon, which hold
copies of the models), `extend-exclude` adds to it.
"""

from __future__ import annotations

import fnmatch
import os
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

from reedtool.errors import ReedtoolError

KEYS = ("select", "ignore", "severity", "strict", "args", "per-file-args", "per-file-ignores",
        "exclude", "extend-exclude", "force-exclude", "baseline")
# What a directory walk skips unless `exclude` says otherwise: catkin's and colcon's build,
# install and log trees beside `src/` hold copies of the package's models.
DEFAULT_EXCLUDE = ("build", "devel", "install", "log")


@dataclass(frozen=True)
class Config:
    path: Path | None = None
    select: tuple[str, ...] | None = None     # None: not configured
    ignore: tuple[str, ...] = ()
    severity: dict[str, str] = field(default_factory=dict)
    strict: bool = False
    args: dict[str, str] = field(default_factory=dict)
    per_file_args: dict[str, dict[str, str]] = field(default_factory=dict)
    per_file_ignores: dict[str, tuple[str, ...]] = field(default_factory=dict)
    # per-file-args given as a list of tables: glob -> one argument table per variant
    per_file_variants: dict[str, tuple[dict[str, str], ...]] = field(default_factory=dict)
    exclude: tuple[str, ...] | None = None      # None: DEFAULT_EXCLUDE
    extend_exclude: tuple[str, ...] = ()
    force_exclude: bool = False
    baseline: Path | None = None                # resolved against the config's directory
    # Every configuration found walking up from the model, nearest first (path[0] won).
    candidates: tuple[Path, ...] = ()

    @property
    def root(self) -> Path | None:
        return self.path.parent if self.path else None

    def matches(self, pattern: str, file: str | Path) -> bool:
        """Does `file` match a per-file glob of this configuration?"""
        path = Path(file).resolve()
        if self.root is not None:
            try:
                relative = path.relative_to(self.root.resolve()).as_posix()
            except ValueError:
                relative = path.as_posix()
        else:
            relative = path.as_posix()
        if fnmatch.fnmatchcase(relative, pattern):
            return True
        return "/" not in pattern and fnmatch.fnmatchcase(path.name, pattern)

    def args_for(self, model: str | Path) -> tuple[dict[str, str], list[str]]:
        """The xacro arguments for `model`: `args`, then every matching `per-file-args` table.

        Also returns where each came from, for the unknown-argument warning and
        --show-settings.
        """
        out = dict(self.args)
        origins = [f"{self.path} args"] if self.args else []
        for pattern, table in self.per_file_args.items():
            if self.matches(pattern, model):
                out.update(table)
                origins.append(f"{self.path} per-file-args \"{pattern}\"")
        return out, origins

    def exclusion(self, path: Path, walked: Path | None = None) -> str | None:
        """The `exclude`/`extend-exclude` pattern that excludes `path`, or None.

        A pattern without a `/` matches a file or directory name below `walked` (the
        directory being searched; the file's own name when it was named); one with a `/`
        matches the path relative to the configuration's directory, or a directory above
        the file in it."""
        patterns = (DEFAULT_EXCLUDE if self.exclude is None else self.exclude) \
            + self.extend_exclude
        resolved = Path(os.path.abspath(path))
        names: tuple[str, ...] = (resolved.name,)
        if walked is not None:
            try:
                names = resolved.relative_to(Path(os.path.abspath(walked))).parts
            except ValueError:
                pass
        relative: tuple[str, ...] = ()
        if self.root is not None:
            try:
                relative = resolved.relative_to(Path(os.path.abspath(self.root))).parts
            except ValueError:
                relative = ()
        for raw in patterns:
            pattern = raw.strip().rstrip("/")
            pattern = pattern[2:] if pattern.startswith("./") else pattern
            if not pattern:
                continue
            if "/" not in pattern:
                if any(fnmatch.fnmatchcase(name, pattern) for name in names):
                    return raw
            elif any(fnmatch.fnmatchcase("/".join(relative[:n]), pattern)
                     for n in range(1, len(relative) + 1)):
                return raw
        return None

    def variants_for(self, model: str | Path) -> list[dict[str, str]]:
        """The argument variants `model` is validated with (every matching list of
        `per-file-args` tables, in order); [] when it is validated once."""
        return [dict(table) for pattern, tables in self.per_file_variants.items()
                if self.matches(pattern, model) for table in tables]

    def ignores_for(self, file: str | Path) -> tuple[str, ...]:
        found: list[str] = []
        for pattern, selectors in self.per_file_ignores.items():
            if self.matches(pattern, file):
                found.extend(selectors)
        return tuple(found)


# Every model of a run asks for its configuration (selection, arguments, exclude, strict):
# a file is parsed once per version of it (path, size, mtime).
_parsed: dict[tuple, dict] = {}


def _load_toml(path: Path) -> dict:
    try:
        st = os.stat(path)
        key = (os.path.abspath(path), st.st_size, st.st_mtime_ns)
    except OSError:
        key = None
    if key is not None and key in _parsed:
        return _parsed[key]
    table = _read_toml(path)
    if key is not None:
        if len(_parsed) >= 64:
            _parsed.pop(next(iter(_parsed)))
        _parsed[key] = table
    return table


def _read_toml(path: Path) -> dict:
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


def find_configs(start: Path) -> list[tuple[Path, dict]]:
    """Every reedtool configuration at or above `start`, nearest first, with its table."""
    directory = start if start.is_dir() else start.parent
    found: list[tuple[Path, dict]] = []
    for folder in [directory.resolve(), *directory.resolve().parents]:
        candidate = folder / "reedtool.toml"
        if candidate.is_file():
            found.append((candidate, _load_toml(candidate)))
            continue      # in one directory, reedtool.toml shadows pyproject.toml
        candidate = folder / "pyproject.toml"
        if candidate.is_file():
            table = _load_toml(candidate).get("tool", {}).get("reedtool")
            if table is not None:
                found.append((candidate, table))
    return found


def find_config(start: Path) -> tuple[Path, dict] | None:
    """The nearest reedtool configuration at or above `start` and its table."""
    found = find_configs(start)
    return found[0] if found else None


def _string_list(value, key: str, path: Path) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ReedtoolError(f"'{key}' must be a list of rule codes or prefixes", file=path)
    return tuple(value)


def _patterns(value, key: str, path: Path) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ReedtoolError(f"'{key}' must be a list of file or directory globs", file=path,
                            hint=f'e.g. {key} = ["build", "urdf/old/*"]')
    return tuple(value)


def _scalar(value) -> str | None:
    # TOML booleans become xacro's spelling; numbers keep their text.
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (str, int, float)):
        return str(value)
    return None


def _args_table(value, key: str, path: Path) -> dict[str, str]:
    if not isinstance(value, dict):
        raise ReedtoolError(f"'{key}' must be a table of name = value xacro arguments",
                            file=path, hint='e.g. args = {mav_name = "reed_quad_x"}')
    out: dict[str, str] = {}
    for name, raw in value.items():
        text = _scalar(raw)
        if text is None:
            raise ReedtoolError(f"xacro argument '{name}' in '{key}' must be a string, number "
                                "or boolean", file=path)
        out[str(name)] = text
    return out


def _glob_table(value, key: str, path: Path) -> dict:
    if not isinstance(value, dict):
        raise ReedtoolError(f"'{key}' must be a table keyed by file glob", file=path,
                            hint=f'e.g. [tool.reedtool.{key}] "urdf/*.xacro" = ...')
    return value


def parse_config(table: dict, path: Path) -> Config:
    unknown = sorted(set(table) - set(KEYS))
    if unknown:
        from difflib import get_close_matches

        close = get_close_matches(unknown[0], KEYS, n=1)
        hint = (f"did you mean '{close[0]}'? " if close else "") + \
            f"known settings: {', '.join(KEYS)}"
        raise ReedtoolError(f"unknown reedtool setting '{unknown[0]}'", file=path, hint=hint)
    severity = table.get("severity", {})
    if not isinstance(severity, dict):
        raise ReedtoolError("'severity' must be a table of CODE = \"error|warning|info\"",
                            file=path)
    strict = table.get("strict", False)
    if not isinstance(strict, bool):
        raise ReedtoolError("'strict' must be true or false", file=path)
    per_file_args: dict[str, dict[str, str]] = {}
    per_file_variants: dict[str, tuple[dict[str, str], ...]] = {}
    for glob, args in _glob_table(table.get("per-file-args", {}), "per-file-args",
                                  path).items():
        key = f"per-file-args \"{glob}\""
        if isinstance(args, list):
            if not args:
                raise ReedtoolError(f"'{key}' is an empty list of variants", file=path,
                                    hint='give one table per variant, e.g. '
                                         '[{mav_name = "firefly"}, {mav_name = "pelican"}]')
            per_file_variants[str(glob)] = tuple(_args_table(a, f"{key} variant {n + 1}", path)
                                                 for n, a in enumerate(args))
        else:
            per_file_args[str(glob)] = _args_table(args, key, path)
    per_file_ignores = {str(glob): _string_list(codes, f"per-file-ignores \"{glob}\"", path)
                        for glob, codes in _glob_table(table.get("per-file-ignores", {}),
                                                       "per-file-ignores", path).items()}
    force_exclude = table.get("force-exclude", False)
    if not isinstance(force_exclude, bool):
        raise ReedtoolError("'force-exclude' must be true or false", file=path)
    baseline = table.get("baseline")
    if baseline is not None and (not isinstance(baseline, str) or not baseline.strip()):
        raise ReedtoolError("'baseline' must be a file name", file=path,
                            hint='e.g. baseline = "reedtool-baseline.json"')
    return Config(
        path=path,
        exclude=(_patterns(table["exclude"], "exclude", path) if "exclude" in table
                 else None),
        extend_exclude=_patterns(table.get("extend-exclude", []), "extend-exclude", path),
        force_exclude=force_exclude,
        baseline=(path.parent / baseline) if baseline is not None else None,
        select=_string_list(table["select"], "select", path) if "select" in table else None,
        ignore=_string_list(table.get("ignore", []), "ignore", path),
        severity={str(k): str(v) for k, v in severity.items()},
        strict=strict,
        args=_args_table(table.get("args", {}), "args", path),
        per_file_args=per_file_args,
        per_file_variants=per_file_variants,
        per_file_ignores=per_file_ignores,
    )


def load_config(model_path: Path) -> Config:
    """The configuration that applies to `model_path`; defaults when there is none."""
    found = find_configs(Path(model_path))
    if not found:
        return Config()
    path, table = found[0]
    if not isinstance(table, dict):
        raise ReedtoolError("[tool.reedtool] must be a table", file=path)
    config = parse_config(table, path)
    return replace(config, candidates=tuple(p for p, _ in found))


def relative_to_cwd(path: Path) -> str:
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)
