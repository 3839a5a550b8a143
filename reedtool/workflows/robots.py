"""A model path and what the command line, a launch file and the configuration say about
it -> the xacro arguments it is expanded with -> its robots.

Arguments come from three places, later ones winning: `[tool.reedtool] args` (and
`per-file-args`) of the nearest configuration, `--launch FILE`, and `name:=value` words.
Every command resolves them here, so a model means the same robot to each of them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from reedtool.errors import ReedtoolError

_NOT_XACRO = {".urdf", ".sdf", ".world"}


@dataclass
class ModelRequest:
    """What the command line says about the models of a run."""

    mappings: dict[str, str] = field(default_factory=dict)
    package_paths: list[Path] = field(default_factory=list)
    model_name: str | None = None         # --model: one model of an SDF world
    launch: object | None = None          # reedtool.io.launch.LaunchCall
    launch_file: Path | None = None
    select: tuple[str, ...] = ()
    ignore: tuple[str, ...] = ()
    # One argument variant of the configuration's per-file-args (validate runs each
    # separately); None: the model's first variant, if it has any.
    variant: dict | None = None
    force_exclude: bool = False           # --force-exclude: `exclude` named files too
    # Models loaded while deciding what a named file means (workflows.targets), kept so the
    # check does not expand them twice: resolved path -> load_models pairs.
    preloaded: dict = field(default_factory=dict)


def _config_line(path: Path | None, name: str) -> int | None:
    """The line of the configuration file that sets argument `name` (best effort)."""
    if path is None:
        return None
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError:
        return None
    pattern = re.compile(r"(^|[{,\s])[\"']?" + re.escape(name) + r"[\"']?\s*=")
    return next((n for n, line in enumerate(lines, 1) if pattern.search(line)), None)


def model_arguments(model: Path, config, request: ModelRequest):
    """The xacro arguments for `model` (configuration, then --launch, then the command
    line, later ones winning) and their ArgumentUse for the argument rules."""
    from reedtool.config import relative_to_cwd
    from reedtool.model import SourceLoc

    mappings: dict[str, str] = {}
    given: dict[str, SourceLoc | None] = {}
    origins: dict[str, str] = {}
    checked: set[str] = set()        # the names rule S140 looks at
    config_args, _ = config.args_for(model)
    for name, value in config_args.items():
        mappings[name] = value
        line = _config_line(config.path, name)
        given[name] = SourceLoc(relative_to_cwd(config.path), line) if config.path else None
        origins[name] = f"config {relative_to_cwd(config.path)}"
        if name not in config.args:   # per-file-args name this model on purpose
            checked.add(name)
    variants = config.variants_for(model)
    variant = request.variant if request.variant is not None else \
        (variants[0] if variants else {})
    for name, value in variant.items():
        mappings[name] = value
        given[name] = SourceLoc(relative_to_cwd(config.path), _config_line(config.path, name))
        origins[name] = f"config {relative_to_cwd(config.path)} (variant)"
        checked.add(name)
    launch = request.launch
    if launch is not None:
        for name, value in launch.mappings.items():
            mappings[name] = value
            given[name] = launch.locs.get(name, launch.loc)
            origins[name] = f"--launch {relative_to_cwd(request.launch_file)}"
            checked.add(name)
    for name, value in request.mappings.items():
        mappings[name] = value
        given[name] = SourceLoc(str(model))     # the model, no line: it was typed
        origins[name] = "command line"
        checked.add(name)
    return mappings, given, origins, checked


def model_mappings(model: Path, request: ModelRequest) -> dict[str, str]:
    """The xacro arguments `model` is expanded with (configuration, --launch, command line)."""
    from reedtool.config import load_config

    return model_arguments(model, load_config(model), request)[0]


def argument_use(model: Path, mappings, given, origins, checked, config,
                 request: ModelRequest):
    """What rule S140 needs: the arguments the model declares against those it was given."""
    if model.is_dir() or model.suffix.lower() in _NOT_XACRO or not given:
        return None
    from reedtool.io.xacro_args import ArgumentUse, known_arguments

    declared, complete = known_arguments(model, mappings, request.package_paths)
    # The config's `args` apply to every model of a repository; they are checked for a
    # model that reads at least one of them (they are meant for it), so a plain xacro file
    # next to a RotorS model is not told about arguments it never wanted.
    if set(config.args) & declared:
        checked |= set(config.args)
    return ArgumentUse(declared=declared,
                       given={n: loc for n, loc in given.items() if n in checked},
                       origins={n: o for n, o in origins.items() if n in checked},
                       complete=complete)


def variants_of(model: Path, request: ModelRequest) -> list[dict[str, str]]:
    """The argument variants `model` is validated with: its configuration's lists of
    `per-file-args` tables. An argument typed or read from --launch wins over a variant's,
    as over every configured one; variants that then differ in nothing are checked once
    ([] when the model is checked once, with its arguments)."""
    from reedtool.config import load_config

    given = set(request.mappings) | (set(request.launch.mappings) if request.launch else set())
    variants: list[dict[str, str]] = []
    for variant in load_config(model).variants_for(model):
        left = {name: value for name, value in variant.items() if name not in given}
        if left and left not in variants:
            variants.append(left)
    return variants


def variant_label(variant: dict[str, str]) -> str:
    """How a model's argument variant is named in reports: ` [mav_name:=firefly]`."""
    return " [" + ", ".join(f"{name}:={value}" for name, value in variant.items()) + "]"


def load_models(model: Path, mappings, package_paths, model_name):
    """(display suffix, Robot) pairs of one model path: one, or each model of a world."""
    from reedtool.io.loader import load_robots

    robots = load_robots(model, mappings, list(package_paths), model_name=model_name)
    return [("" if len(robots) == 1 else f" [model {r.name}]", r) for r in robots]


def targets_of(paths: Sequence[str], request: ModelRequest):
    """The models that command-line paths (files, directories, globs, packages, a changed
    configuration) name; arguments mean "this model" (workflows.targets)."""
    from reedtool.config import find_config, load_config
    from reedtool.workflows.targets import expand_targets, include_globs_of, include_tree_of
    from reedtool.report import display_path

    def mappings_for(path: Path) -> dict[str, str]:
        try:
            config = load_config(path)
        except ReedtoolError:
            return dict(request.mappings)
        return model_arguments(path, config, request)[0]

    def glob_mappings_for(path: Path) -> dict[str, str]:
        """mappings_for without the names argument variants set (unless typed): a top file
        checked as firefly and as hummingbird includes `$(arg mav_name)_base.xacro` for
        each, so every file that name matches is a part of it, not a model."""
        mappings = mappings_for(path)
        try:
            variants = load_config(path).variants_for(path)
        except ReedtoolError:
            return mappings
        for name in {name for variant in variants for name in variant}:
            if name not in request.mappings:
                mappings.pop(name, None)
        return mappings

    def has_arguments(path: Path) -> bool:
        """Arguments meant for this file: typed, from --launch, or a per-file table.
        (The config's `args` reach every model of a repository, so they do not say the
        file is a model: whether it expands alone with them does.)"""
        if request.mappings or (request.launch is not None and request.launch.mappings):
            return True
        try:
            config = load_config(path)
        except ReedtoolError:
            return False
        return (set(config.args_for(path)[0].items()) != set(config.args.items())
                or bool(config.variants_for(path)))

    def stands_alone(path: Path) -> bool:
        """Loads alone into a robot with links; the robots are kept for the check."""
        key = path.resolve()
        if key in request.preloaded:
            return True
        try:
            pairs = load_models(path, mappings_for(path), request.package_paths,
                                request.model_name)
        except ReedtoolError:
            return False
        if not any(robot.links for _, robot in pairs):
            return False
        request.preloaded[key] = pairs
        return True

    def configures_models(path: Path) -> bool:
        found = find_config(path)
        return found is not None and found[0] == path.resolve()

    def excluded(path: Path, walked: Path | None) -> str | None:
        """Why the configuration leaves `path` out: always when found by a directory walk,
        when named only with `force-exclude` (ruff's rule: a file passed is checked)."""
        try:
            config = load_config(path)
        except ReedtoolError:
            return None       # the check of the file reports the configuration's error
        if walked is None and not (config.force_exclude or request.force_exclude):
            return None
        pattern = config.exclusion(path, walked)
        if pattern is None:
            return None
        from reedtool.config import relative_to_cwd

        if pattern in config.extend_exclude:
            where = f"extend-exclude in {relative_to_cwd(config.path)}"
        elif config.exclude is not None:
            where = f"exclude in {relative_to_cwd(config.path)}"
        else:
            where = "reedtool's default exclude"
        return f"excluded by '{pattern}' ({where})"

    return expand_targets(paths, include_tree_of(mappings_for, request.package_paths),
                          display=lambda p: display_path(str(p)) or str(p),
                          include_globs=include_globs_of(glob_mappings_for,
                                                         request.package_paths),
                          has_arguments=has_arguments, stands_alone=stands_alone,
                          configures_models=configures_models, excluded=excluded)


def request_from_words(words: Sequence[str], *, package_paths: Sequence[Path] = (),
                       model_name: str | None = None, launch_file: Path | None = None,
                       select: Sequence[str] = (), ignore: Sequence[str] = ()):
    """The command line's words (paths and name:=value) and model options -> (paths,
    ModelRequest). With --launch and no path, the launch file's model is the path."""
    from reedtool.resolve.mappings import MAPPING_SEPARATOR, parse_mappings

    if any(not w.strip() for w in words):
        # `reedtool validate "$MODEL"` with MODEL unset: read as ".", it would check every
        # model under the working directory and could pass without seeing the one meant.
        raise ReedtoolError("an empty word where a model path or NAME:=VALUE belongs",
                            hint="check the shell variable that should name the model")
    request = ModelRequest(mappings=parse_mappings([w for w in words if MAPPING_SEPARATOR in w]),
                           package_paths=list(package_paths), model_name=model_name,
                           launch_file=launch_file, select=tuple(select), ignore=tuple(ignore))
    paths = [w for w in words if MAPPING_SEPARATOR not in w]
    if launch_file is not None:
        from reedtool.io.launch import read_launch

        request.launch = read_launch(launch_file, package_paths=list(package_paths))
        if not paths:
            if request.launch.model is None:
                raise ReedtoolError("the launch file's xacro call names no model reedtool "
                                    "can evaluate", file=launch_file,
                                    hint="pass the model path before the options")
            paths = [str(request.launch.model)]
    return paths, request


_GLOB_CHARS = re.compile(r"[*?\[]")


def one_model(paths: Sequence[str], request: ModelRequest, command: str) -> Path:
    """The one model a single-model command reads from its paths (a file, a directory,
    a glob or a ROS package naming exactly one model), or a one-line refusal naming the
    models found."""
    for n, word in enumerate(paths):
        if Path(word).exists() or _GLOB_CHARS.search(word):
            continue
        if n == 0 and "=" not in word:
            from reedtool.workflows.targets import suggest_path

            nearby = suggest_path(word)
            raise ReedtoolError("model file not found", file=word,
                                hint=f"did you mean '{nearby}'?" if nearby else
                                "pass a model file (.urdf, .xacro, .sdf, .gazebo, "
                                ".world), a directory or a ROS package")
        # A word after the model that names nothing is a mistyped argument.
        from reedtool.resolve.mappings import suggest_mapping

        suggestion = suggest_mapping(word)
        raise ReedtoolError(f"cannot read argument '{word}'",
                            hint=(f"did you mean '{suggestion}'? " if suggestion else "")
                            + "xacro arguments are written name:=value, one per word, "
                              "after the model")
    if len(paths) == 1 and not _GLOB_CHARS.search(paths[0]):
        path = Path(paths[0])
        if not path.is_dir() or (path / "model.sdf").is_file():
            return path      # itself, as every command always read a named file
    targets = targets_of(paths, request)
    problem = next((t for t in targets if t.error is not None), None)
    if problem is not None:
        raise ReedtoolError(problem.error, file=problem.name)
    models = [t for t in targets if t.path is not None]
    if not models:
        first = next((t for t in targets if t.skipped is not None), None)
        if first is None:
            raise ReedtoolError("no model given", hint=f"reedtool {command} MODEL")
        raise ReedtoolError(f"nothing to read: {first.skipped}", file=first.name)
    if len(models) > 1:
        shown = ", ".join(t.name for t in models[:5]) + (", ..." if len(models) > 5 else "")
        raise ReedtoolError(f"{len(models)} models found ({shown}); {command} reads one "
                            "model at a time", file=", ".join(paths),
                            hint=f"name one of them, or run `reedtool {command}` once per "
                                 "model (`reedtool validate` checks them all in one run)")
    return models[0].path
