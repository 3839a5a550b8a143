"""`reedtool validate`: every static mistake that makes a model fail in Gazebo, with its line.

Many models per run (files, directories, globs, ROS packages, every multirotor of a
world), one report, one exit code over all: 0 clean, 1 findings at a failing severity,
2 when an input could not be read (the other models are still checked and reported).
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import click

from reedtool.commands.params import model_option
from reedtool.errors import ReedtoolError

FORMATS = ("text", "json", "github", "sarif", "junit")
_NOT_XACRO = {".urdf", ".sdf", ".world"}


def explain(code: str) -> int:
    from reedtool.checks.registry import get_rule

    found = get_rule(code)
    if found is None:
        raise ReedtoolError(f"unknown rule '{code}'",
                            hint="`reedtool rules` lists every rule code and name")
    click.echo(f"{found.code} {found.slug} ({found.severity}, {found.family})\n")
    click.echo(f"{found.summary}\n")
    click.echo(found.explanation)
    click.echo(f"\nSeverity policy ({found.clause}): {found.policy}.")
    return 0


def _use_color(no_color: bool) -> bool:
    if no_color or os.environ.get("NO_COLOR"):
        return False
    return sys.stdout.isatty()


# ------------------------------------------------------------------ one model

@dataclass
class RunOptions:
    """What the command line says for every model of the run."""

    mappings: dict[str, str] = field(default_factory=dict)
    package_paths: list[Path] = field(default_factory=list)
    select: tuple[str, ...] = ()
    ignore: tuple[str, ...] = ()
    model_name: str | None = None
    launch: object | None = None          # reedtool.io.launch.LaunchCall
    launch_file: Path | None = None
    controllers: list = field(default_factory=list)
    flight_params: list = field(default_factory=list)   # --airframe / --autopilot-params
    diagram: Path | None = None           # --diagram: the rotor layout picture
    diagram_per_model: bool = False       # several models: NAME.svg -> NAME-MODEL.svg
    force: bool = False


def selection_for(config, select: Sequence[str] = (), ignore: Sequence[str] = ()):
    """The rule selection of a model: the command line over its configuration."""
    from reedtool.checks.runner import Selection, parse_selectors, parse_severity_overrides

    origin = str(config.path) if config.path else "config"
    if select and not parse_selectors(select, origin="--select"):
        # `--select ""` would run no rule and report a clean model.
        raise ReedtoolError("--select names no rule", hint="give a code, prefix or rule name "
                            "such as S, I203 or R; ALL selects every rule")
    return Selection(
        select=(parse_selectors(select, origin="--select") if select
                else parse_selectors(config.select, origin=origin) if config.select is not None
                else ("",)),
        ignore=(parse_selectors(config.ignore, origin=origin)
                + parse_selectors(ignore, origin="--ignore")),
        severity=parse_severity_overrides(config.severity, origin=origin),
    )


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


def model_arguments(model: Path, config, options: RunOptions):
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
    launch = options.launch
    if launch is not None:
        for name, value in launch.mappings.items():
            mappings[name] = value
            given[name] = launch.locs.get(name, launch.loc)
            origins[name] = f"--launch {relative_to_cwd(options.launch_file)}"
            checked.add(name)
    for name, value in options.mappings.items():
        mappings[name] = value
        given[name] = SourceLoc(str(model))     # the model, no line: it was typed
        origins[name] = "command line"
        checked.add(name)
    return mappings, given, origins, checked


def _argument_use(model: Path, mappings, given, origins, checked, config, options):
    from reedtool.io.xacro_args import ArgumentUse, known_arguments

    if model.is_dir() or model.suffix.lower() in _NOT_XACRO or not given:
        return None
    declared, complete = known_arguments(model, mappings, options.package_paths)
    # The config's `args` apply to every model of a repository; they are checked for a
    # model that reads at least one of them (they are meant for it), so a plain xacro file
    # next to a RotorS model is not told about arguments it never wanted.
    if set(config.args) & declared:
        checked |= set(config.args)
    return ArgumentUse(declared=declared,
                       given={n: loc for n, loc in given.items() if n in checked},
                       origins={n: o for n, o in origins.items() if n in checked},
                       complete=complete)


def load_models(model: Path, mappings, package_paths, model_name):
    """(display suffix, Robot) pairs of one model path: one, or each model of a world."""
    from reedtool.io.loader import load_robots

    robots = load_robots(model, mappings, list(package_paths), model_name=model_name)
    return [("" if len(robots) == 1 else f" [model {r.name}]", r) for r in robots]


def check_model(name: str, model: Path, options: RunOptions) -> list:
    """The ModelResults of one model path (several for a world). Input errors of the
    model itself become a result with `error`; configuration errors raise."""
    from reedtool.checks.runner import apply_suppressions, parse_selectors, run_checks
    from reedtool.config import load_config
    from reedtool.report import ModelResult

    config = load_config(model)
    selection = selection_for(config, options.select, options.ignore)
    origin = str(config.path) if config.path else "config"

    def ignores_for(file: str | None) -> tuple[str, ...]:
        return parse_selectors(config.ignores_for(file or model), origin=origin)

    ignores_for(model)   # a bad per-file-ignores selector is a config error, raised now
    mappings, given, origins, checked = model_arguments(model, config, options)
    try:
        arguments = _argument_use(model, mappings, given, origins, checked, config, options)
        pairs = load_models(model, mappings, options.package_paths, options.model_name)
    except ReedtoolError as exc:
        return [ModelResult(name, error=exc.one_line(), error_file=exc.file,
                            error_line=exc.line)]
    results = []
    for suffix, robot in pairs:
        findings = run_checks(robot, selection, controllers=options.controllers,
                              flight_params=options.flight_params, arguments=arguments)
        kept, dropped = apply_suppressions(findings, ignores_for)
        results.append(ModelResult(name + suffix, kept, suppressed=dropped))
        if options.diagram is not None:
            _write_diagram(robot, kept, options, several=len(pairs) > 1)
    return results


def _write_diagram(robot, findings, options: RunOptions, several: bool) -> None:
    from reedtool.commands.layout import write_diagram

    target = options.diagram
    if several or options.diagram_per_model:
        target = target.with_name(f"{target.stem}-{robot.name}{target.suffix}")
    write_diagram(robot, target, findings, options.force)


def validation_errors(model: Path, robot) -> list:
    """The error findings `validate` reports for an already loaded robot (its config's
    selection, severities and suppressions): what hover-test refuses to fly."""
    from reedtool.checks.runner import apply_suppressions, parse_selectors, run_checks
    from reedtool.config import load_config

    config = load_config(model)
    origin = str(config.path) if config.path else "config"
    findings = run_checks(robot, selection_for(config))
    kept, _ = apply_suppressions(
        findings, lambda file: parse_selectors(config.ignores_for(file or model), origin=origin))
    return [f for f in kept if f.severity == "error"]


def targets_of(paths: Sequence[str], options: RunOptions):
    from reedtool.config import load_config
    from reedtool.io.model_inputs import expand_targets, include_tree_of
    from reedtool.report import display_path

    def mappings_for(path: Path) -> dict[str, str]:
        try:
            config = load_config(path)
        except ReedtoolError:
            return dict(options.mappings)
        return model_arguments(path, config, options)[0]

    return expand_targets(paths, include_tree_of(mappings_for, options.package_paths),
                          display=lambda p: display_path(str(p)) or str(p))


def print_settings(targets, options: RunOptions) -> int:
    from reedtool.config import load_config, relative_to_cwd

    for target in targets:
        click.echo(f"{target.name}:")
        if target.skipped is not None:
            click.echo(f"  skipped: {target.skipped}")
            continue
        if target.path is None:
            click.echo(f"  error: {target.error}")
            continue
        config = load_config(target.path)
        if config.path is None:
            click.echo("  config: none found (defaults)")
        else:
            click.echo(f"  config: {relative_to_cwd(config.path)}")
            for other in config.candidates[1:]:
                click.echo(f"  also found (not used, the nearest wins): {relative_to_cwd(other)}")
        selection = selection_for(config, options.select, options.ignore)
        click.echo(f"  select: {', '.join(s or 'ALL' for s in selection.select)}")
        click.echo(f"  ignore: {', '.join(selection.ignore) or '-'}")
        click.echo("  severity: " + (", ".join(f"{k} = {v}" for k, v in selection.severity.items())
                                     or "-"))
        click.echo(f"  strict: {str(config.strict).lower()}")
        mappings, _, origins, _ = model_arguments(target.path, config, options)
        for name in sorted(mappings):
            click.echo(f"  arg {name}:={mappings[name]}  ({origins[name]})")
        ignores = config.ignores_for(target.path)
        if ignores:
            click.echo(f"  per-file-ignores: {', '.join(ignores)}")
    return 0


# ------------------------------------------------------------------ the command

@click.command(name="validate")
@click.argument("inputs", nargs=-1, metavar="[MODEL|DIR|GLOB]... [NAME:=VALUE]...")
@click.option("--package-path", "package_paths", multiple=True, metavar="DIR",
              type=click.Path(path_type=Path, file_okay=False),
              help="Directory to search for ROS packages first (repeatable).")
@model_option
@click.option("--launch", "launch_file", type=click.Path(path_type=Path, dir_okay=False),
              metavar="FILE", help="Read the model and its xacro arguments from a roslaunch "
                                   "XML or ROS 2 (XML or Python) launch file.")
@click.option("--format", "fmt", type=click.Choice(FORMATS), default="text",
              show_default=True, help="Output format.")
@click.option("--output-file", "-o", "output_file", type=click.Path(path_type=Path,
                                                                    dir_okay=False),
              help="Write the report to FILE instead of standard output.")
@click.option("--force", is_flag=True,
              help="Overwrite an existing --output-file or --diagram file.")
@click.option("--select", multiple=True, metavar="CODE,...",
              help="Run only rules whose code starts with these prefixes (or these rule names).")
@click.option("--ignore", multiple=True, metavar="CODE,...",
              help="Skip rules whose code starts with these prefixes (or these rule names).")
@click.option("--explain", "explain_code", metavar="CODE",
              help="Print the documentation of one rule (code or name) and exit.")
@click.option("--strict/--no-strict", default=None,
              help="Exit 1 on warnings as well as errors (default: the config's `strict`).")
@click.option("--exit-zero", is_flag=True,
              help="Exit 0 even when there are findings (input errors still exit 2).")
@click.option("--statistics", "show_statistics", is_flag=True,
              help="Add a count of findings per rule to the report.")
@click.option("--show-settings", is_flag=True,
              help="Print the configuration file and settings each model gets, and exit.")
@click.option("--no-color", is_flag=True, help="Never colour the text output.")
@click.option("--controller", "controller_files", multiple=True, metavar="FILE.yaml",
              type=click.Path(path_type=Path, dir_okay=False),
              help="RotorS-style vehicle parameter YAML to cross-check against the model "
                   "(repeatable).")
@click.option("--airframe", "airframe_files", multiple=True, metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="PX4 airframe script or parameter file to cross-check (repeatable).")
@click.option("--autopilot-params", "autopilot_files", multiple=True, metavar="FILE.parm",
              type=click.Path(path_type=Path, dir_okay=False),
              help="ArduPilot .parm file to cross-check (FRAME_CLASS/TYPE, SERVOn_FUNCTION).")
@click.option("--diagram", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Also draw the rotor layout (.svg/.png), rotors named by findings in red.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, fmt: str, output_file: Path | None, force: bool,
            select: tuple[str, ...], ignore: tuple[str, ...], explain_code: str | None,
            strict: bool | None, exit_zero: bool, show_statistics: bool, show_settings: bool,
            no_color: bool, controller_files: tuple[Path, ...] = (),
            airframe_files: tuple[Path, ...] = (), autopilot_files: tuple[Path, ...] = (),
            diagram: Path | None = None) -> int:
    """Check models (.urdf, .xacro or .sdf files, directories, globs, ROS packages) for
    mistakes; NAME:=VALUE words are xacro arguments for every model.

    Exit 0 when there is no error, 1 when there are errors (or warnings with --strict),
    2 on bad usage or when a model could not be read.
    """
    if explain_code:
        return explain(explain_code)

    from reedtool.io.mappings import MAPPING_SEPARATOR, parse_mappings

    mappings = parse_mappings([w for w in inputs if MAPPING_SEPARATOR in w])
    paths = [w for w in inputs if MAPPING_SEPARATOR not in w]
    options = RunOptions(mappings=mappings, package_paths=list(package_paths),
                         select=select, ignore=ignore, model_name=model_name,
                         launch_file=launch_file, diagram=diagram, force=force)
    if launch_file is not None:
        from reedtool.io.launch import read_launch

        options.launch = read_launch(launch_file, package_paths=list(package_paths))
        if not paths:
            if options.launch.model is None:
                raise ReedtoolError("the launch file's xacro call names no model reedtool "
                                    "can evaluate", file=launch_file,
                                    hint="pass the model path before the options")
            paths = [str(options.launch.model)]
    if not paths:
        raise click.UsageError("missing argument 'MODEL' (or use --explain CODE)")
    if len(paths) == 1 and not Path(paths[0]).exists() and not re.search(r"[*?\[]", paths[0]):
        # One model that is not there: the one-line error of every command, exit 2.
        raise ReedtoolError("file not found", file=paths[0], hint="check the model path")

    targets = targets_of(paths, options)
    if show_settings:
        return print_settings(targets, options)
    if controller_files:
        from reedtool.flightstack.controller_tables import load_controller_yaml

        options.controllers = [load_controller_yaml(path) for path in controller_files]
    if airframe_files or autopilot_files:
        from reedtool.flightstack.params_files import load_flight_params

        options.flight_params = load_flight_params(airframe_files, autopilot_files)
    options.diagram_per_model = len(targets) > 1

    from reedtool.config import load_config
    from reedtool.report import ModelResult, render

    results = []
    failed = False       # a finding at its model's failing severity
    strict_any = False
    for target in targets:
        if target.skipped is not None:
            results.append(ModelResult(target.name, skipped=target.skipped))
            continue
        if target.path is None:
            if len(targets) == 1:
                raise ReedtoolError(target.error, file=target.name)
            results.append(ModelResult(target.name, error=target.error, error_file=target.name))
            continue
        model_results = check_model(target.name, target.path, options)
        results.extend(model_results)
        if len(targets) == 1 and results[-1].error is not None:
            # One model: its input error is the one-line error of every command.
            raise ReedtoolError(results[-1].error)
        # Each model fails by its own configuration's `strict`, unless the command line says.
        model_strict = load_config(target.path).strict if strict is None else strict
        strict_any = strict_any or model_strict
        model_failing = {"error", "warning"} if model_strict else {"error"}
        failed = failed or any(f.severity in model_failing
                               for r in model_results for f in r.findings)
    failing = frozenset({"error", "warning"} if strict_any else {"error"})   # junit
    color = _use_color(no_color) and output_file is None
    text = render(results, fmt, color=color, show_statistics=show_statistics, failing=failing)
    if output_file is not None:
        from reedtool.io.fileio import atomic_write_text

        atomic_write_text(output_file, text, force=force)
    else:
        click.echo(text, nl=False, color=color)
    if any(r.error is not None for r in results):
        return 2
    if exit_zero:
        return 0
    return 1 if failed else 0

