"""`reedtool validate`: every static mistake that makes a model fail in Gazebo, with its line.

Many models per run (files, directories, globs, ROS packages, every multirotor of a
world), one report, one exit code over all: 0 clean, 1 findings at a failing severity,
2 when an input could not be read (the other models are still checked and reported), 3
when a rule failed internally (its finding says so; every other finding is reported).
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import click

from reedtool.workflows.robots import ModelRequest, model_arguments, targets_of
from reedtool.workflows.validation import selection_for
from reedtool.commands.params import ignore_option, model_inputs
from reedtool.errors import ReedtoolError

FORMATS = ("text", "json", "github", "sarif", "junit")


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

    request: ModelRequest = field(default_factory=ModelRequest)
    controllers: list = field(default_factory=list)
    flight_params: list = field(default_factory=list)   # --airframe / --autopilot-params
    diagram: Path | None = None           # --diagram: the rotor layout picture
    diagram_per_model: bool = False       # several models: NAME.svg -> NAME-MODEL.svg
    force: bool = False
    notes: list[str] = field(default_factory=list)   # one line per clean cross-check
    # (model name, SuppressionUse, S143 severity) per robot checked: the run's S143
    suppression_uses: list = field(default_factory=list)


@dataclass(frozen=True)
class Job:
    """One check of the run: a model path, with one argument variant of its config."""

    target: object                  # workflows.targets.Target
    variant: dict | None = None     # per-file-args variant; None: the model's arguments

    @property
    def name(self) -> str:
        from reedtool.workflows.robots import variant_label

        return self.target.name + (variant_label(self.variant) if self.variant else "")


def jobs_of(target, request: ModelRequest) -> list[Job]:
    """The checks of one target: one per argument variant it has (workflows.robots)."""
    from reedtool.workflows.robots import variants_of

    variants = variants_of(target.path, request)
    return [Job(target, v) for v in variants] if variants else [Job(target)]


def check_target(job: Job, options: RunOptions) -> tuple[list, list[str], list]:
    """check_model for a Job, the notes it made and its suppression uses (what --jobs
    hands each worker: a worker's changes to `options` do not come back, its return value
    does)."""
    from dataclasses import replace

    notes, uses, request = options.notes, options.suppression_uses, options.request
    options.notes, options.suppression_uses = [], []
    if job.variant is not None:
        # Each variant is its own robot: nothing loaded for another variant is reused.
        options.request = replace(request, variant=job.variant, preloaded={})
    try:
        results = check_model(job.name, job.target.path, options)
        return results, options.notes, options.suppression_uses
    finally:
        options.notes, options.suppression_uses, options.request = notes, uses, request


def check_model(name: str, model: Path, options: RunOptions) -> list:
    """The ModelResults of one model path (several for a world). Input errors of the
    model itself become a result with `error`; configuration errors raise."""
    from reedtool.workflows.validation import check_model_path
    from reedtool.report import ModelResult

    checked = check_model_path(model, options.request, controllers=options.controllers,
                               flight_params=options.flight_params)
    if checked.error is not None:
        exc = checked.error
        return [ModelResult(name, error=exc.one_line(), error_file=exc.file,
                            error_line=exc.line)]
    from reedtool.workflows.suppression_audit import suppression_use
    from reedtool.config import load_config

    selection = selection_for(load_config(model), options.request.select,
                              options.request.ignore)
    results = []
    for one in checked.models:
        results.append(ModelResult(name + one.suffix, one.findings,
                                   suppressed=len(one.suppressed)))
        options.suppression_uses.append((name + one.suffix,
                                         *suppression_use(one.robot, one.suppressed, selection)))
        if not one.suppressed:     # a silenced flight-stack finding is no agreement
            options.notes += _agreement_lines(model, one.robot, one.findings, options,
                                              name + one.suffix)
        if options.diagram is not None:
            _write_diagram(model, one.robot, one.findings, options,
                           several=len(checked.models) > 1)
    return results


def _agreement_lines(path: Path, robot, findings, options: RunOptions, model: str
                     ) -> list[str]:
    """One line per --airframe/--autopilot-params file the model agrees with: every rule
    of that flight stack ran and none found anything above information."""
    if not options.flight_params or any(f.code.startswith("S") and f.severity == "error"
                                        for f in findings):
        return []     # a broken tree: the flight-stack rules did not look
    from reedtool.checks.registry import all_rules
    from reedtool.config import load_config
    from reedtool.flightstack.params_files import agreement_line
    from reedtool.physics.rotors import discover_rotors

    selection = selection_for(load_config(path), options.request.select,
                              options.request.ignore)
    rotors = discover_rotors(robot)
    lines = []
    for params in options.flight_params:
        # The controller cross-check rules of this file's flight stack (code table metadata).
        rules = [r for r in all_rules() if r.code.startswith("C") and r.stack == params.kind]
        ran = all(selection.enabled(r.code) for r in rules)
        quiet = not any(f.code in {r.code for r in rules} and f.severity != "info"
                        for f in findings)
        counted = rotors if params.kind == "px4" else [r for r in rotors if r.role == "lift"]
        if rules and ran and quiet and counted:
            lines.append(agreement_line(params, len(counted), model))
    return lines


def _write_diagram(model: Path, robot, findings, options: RunOptions, several: bool) -> None:
    """One picture per model: FILE itself for a run of one model; else FILE-STEM.svg, STEM
    the model file's (and -ROBOT for each model of a world), so models that share a robot
    name (variants of one xacro, fixtures) do not overwrite each other's picture."""
    from reedtool.workflows.diagram import write_diagram
    from reedtool.physics.rotors import discover_rotors

    target = options.diagram
    if several or options.diagram_per_model:
        if not discover_rotors(robot):
            # A ground robot beside the multirotors has no layout; the run goes on.
            options.notes.append(f"reedtool: --diagram: {model}"
                                 + (f" [model {robot.name}]" if several else "")
                                 + ": no rotors, no layout drawn")
            return
        stem = model.name.split(".")[0] if model.is_file() else model.name
        name = f"{stem}-{robot.name}" if several else stem
        target = target.with_name(f"{target.stem}-{name}{target.suffix}")
    write_diagram(robot, target, findings, options.force)


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
        selection = selection_for(config, options.request.select, options.request.ignore)
        click.echo(f"  select: {', '.join(s or 'ALL' for s in selection.select)}")
        click.echo(f"  ignore: {', '.join(selection.ignore) or '-'}")
        click.echo("  severity: " + (", ".join(f"{k} = {v}" for k, v in selection.severity.items())
                                     or "-"))
        click.echo(f"  strict: {str(config.strict).lower()}")
        mappings, _, origins, _ = model_arguments(target.path, config, options.request)
        for name in sorted(mappings):
            click.echo(f"  arg {name}:={mappings[name]}  ({origins[name]})")
        ignores = config.ignores_for(target.path)
        if ignores:
            click.echo(f"  per-file-ignores: {', '.join(ignores)}")
        from reedtool.workflows.robots import variant_label

        for job in jobs_of(target, options.request):
            if job.variant is not None:
                click.echo(f"  variant:{variant_label(job.variant)}")
        from reedtool.config import DEFAULT_EXCLUDE

        exclude = DEFAULT_EXCLUDE if config.exclude is None else config.exclude
        click.echo(f"  exclude: {', '.join((*exclude, *config.extend_exclude)) or '-'}"
                   + (" (forced)" if config.force_exclude else ""))
        if config.baseline is not None:
            click.echo(f"  baseline: {relative_to_cwd(config.baseline)}")
    return 0


def _prepare_workers() -> None:
    """What every model's check imports, loaded once before --jobs forks its workers."""
    import reedtool.workflows.suppression_audit  # noqa: F401
    import reedtool.io.dae  # noqa: F401
    import reedtool.io.loader  # noqa: F401
    import reedtool.io.xacro_expand  # noqa: F401
    import reedtool.physics.inertia  # noqa: F401
    from reedtool.checks.registry import all_rules

    all_rules()


def _write_baseline(results, path: Path, force: bool) -> int:
    """--write-baseline: every finding of the run recorded; exit 0 (2 when a model could
    not be read: a baseline without its findings would not be the run's)."""
    from reedtool.workflows.baseline import baseline_text
    from reedtool.io.fileio import atomic_write_text
    from reedtool.report import render

    unread = [r for r in results if r.error is not None]
    if unread:
        click.echo(render(unread, "text"), nl=False)
        raise ReedtoolError(f"{len(unread)} model(s) could not be read; baseline not written",
                            file=path, hint="fix or exclude them, then write the baseline")
    text, count = baseline_text(results, path)
    atomic_write_text(path, text, force=force)
    checked = sum(1 for r in results if r.skipped is None)
    click.echo(f"reedtool: wrote {count} finding(s) of {checked} model(s) to {path}")
    return 0


# ------------------------------------------------------------------ the command

@click.command(name="validate")
@model_inputs(metavar="[MODEL|DIR|GLOB|PACKAGE]... [NAME:=VALUE]...")
@click.option("--format", "fmt", type=click.Choice(FORMATS), default="text",
              show_default=True, help="Output format.")
@click.option("--output-file", "-o", "output_file", type=click.Path(path_type=Path,
                                                                    dir_okay=False),
              help="Write the report to FILE instead of standard output.")
@click.option("--force", is_flag=True,
              help="Overwrite an existing --output-file or --diagram file.")
@click.option("--select", multiple=True, metavar="CODE,...",
              help="Run only rules whose code starts with these prefixes (or these rule names).")
@ignore_option
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
              help="RotorS-style vehicle parameter YAML to cross-check against the model, "
                   "and RotorS Lee gain files (lee_controller_NAME.yaml) with it "
                   "(repeatable).")
@click.option("--airframe", "airframe_files", multiple=True, metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="PX4 airframe script or parameter file to cross-check (repeatable).")
@click.option("--autopilot-params", "autopilot_files", multiple=True, metavar="FILE.parm",
              type=click.Path(path_type=Path, dir_okay=False),
              help="ArduPilot .parm file to cross-check (FRAME_CLASS/TYPE, SERVOn_FUNCTION).")
@click.option("--diagram", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Also draw the rotor layout (.svg/.png), rotors named by findings in red.")
@click.option("--force-exclude", is_flag=True,
              help="Apply the configuration's exclude to files named on the command line too "
                   "(as pre-commit passes them; the config's `force-exclude`).")
@click.option("--baseline", "baseline_file", type=click.Path(path_type=Path, dir_okay=False),
              help="Report only findings not recorded in this baseline file (default: the "
                   "config's `baseline`).")
@click.option("--write-baseline", "write_baseline", metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="Record every finding of this run in FILE as accepted and exit 0 "
                   "(--force to replace it).")
@click.option("--jobs", "-j", type=click.IntRange(min=0), default=1, show_default=True,
              metavar="N", help="Check the models in N processes (0: one per available "
                                "CPU); the report keeps the models' order.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, fmt: str, output_file: Path | None, force: bool,
            select: tuple[str, ...], ignore: tuple[str, ...], explain_code: str | None,
            strict: bool | None, exit_zero: bool, show_statistics: bool, show_settings: bool,
            no_color: bool, controller_files: tuple[Path, ...] = (),
            airframe_files: tuple[Path, ...] = (), autopilot_files: tuple[Path, ...] = (),
            diagram: Path | None = None, jobs: int = 1, force_exclude: bool = False,
            baseline_file: Path | None = None, write_baseline: Path | None = None) -> int:
    """Check models (.urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world files,
    directories, globs, ROS packages, or a changed pyproject.toml/reedtool.toml: the
    models it configures) for mistakes; NAME:=VALUE words are xacro arguments for every
    model.

    Exit 0 when there is no error, 1 when there are errors (or warnings with --strict),
    2 on bad usage or when a model could not be read, 3 when a rule failed internally (a
    reedtool bug: that rule's finding says so, the rest of the report is complete).
    """
    if explain_code:
        return explain(explain_code)

    from reedtool.workflows.robots import request_from_words
    from reedtool.resolve.packages import shared_crawls

    context = click.get_current_context(silent=True)
    if context is not None:       # every model of the run resolves against the same roots
        context.with_resource(shared_crawls())
    paths, request = request_from_words(inputs, package_paths=package_paths,
                                        model_name=model_name, launch_file=launch_file,
                                        select=select, ignore=ignore)
    request.force_exclude = force_exclude
    from reedtool.resolve.mappings import suggest_mapping

    for word in paths:
        if not Path(word).exists() and suggest_mapping(word) is not None:
            # `mav_name=foo` names no file: an argument missing its `:`, not a model.
            raise ReedtoolError(f"'{word}' is not a file; xacro arguments are written "
                                "name:=value", hint=f"did you mean '{suggest_mapping(word)}'?")
    options = RunOptions(request=request, diagram=diagram, force=force)
    if not paths:
        raise click.UsageError("missing argument 'MODEL' (or use --explain CODE)")
    if len(paths) == 1 and not Path(paths[0]).exists() and not re.search(r"[*?\[]", paths[0]):
        # One model that is not there: the one-line error of every command, exit 2.
        from reedtool.workflows.targets import not_found_message

        message = not_found_message(paths[0])
        raise ReedtoolError(message, file=paths[0],
                            hint=None if message != "file not found" else "check the model path")

    targets = targets_of(paths, request)
    if show_settings:
        return print_settings(targets, options)
    if controller_files:
        from reedtool.flightstack.rotors_lee import load_controller_files

        options.controllers = load_controller_files(controller_files)
    if airframe_files or autopilot_files:
        from reedtool.flightstack.params_files import load_flight_params

        options.flight_params = load_flight_params(airframe_files, autopilot_files)
    options.diagram_per_model = len(targets) > 1

    import functools

    from reedtool.workflows.parallel import map_models
    from reedtool.config import load_config
    from reedtool.report import ModelResult, render

    checkable = [job for t in targets if t.skipped is None and t.path is not None
                 for job in jobs_of(t, request)]
    outcomes = map_models(functools.partial(check_target, options=options), checkable, jobs,
                          prepare=_prepare_workers)
    checked: dict[int, list] = {}
    for job, outcome in zip(checkable, outcomes):
        checked.setdefault(id(job.target), []).append(outcome)
    results = []
    failing_of = []      # (result, the severities that fail its model)
    suppression_uses: list = []
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
        model_results = []
        for one_results, notes, uses in checked[id(target)]:
            model_results += one_results
            options.notes += notes
            suppression_uses += uses
        if target.checked_for is not None:
            for result in model_results:
                if result.error is not None:
                    # The failure is this model's; name the file it was checked for.
                    result.error += (f" [checked for {target.checked_for}, which it includes; "
                                     f"give {target.checked_for} its arguments (name:=value) "
                                     "to validate it as a model of its own]")
        results.extend(model_results)
        if len(targets) == 1 and results[-1].error is not None:
            # One model: its input error is the one-line error of every command.
            raise ReedtoolError(results[-1].error)
        # Each model fails by its own configuration's `strict`, unless the command line says.
        model_strict = load_config(target.path).strict if strict is None else strict
        strict_any = strict_any or model_strict
        model_failing = {"error", "warning"} if model_strict else {"error"}
        failing_of += [(r, model_failing) for r in model_results]
    from reedtool.workflows.suppression_audit import unused_suppressions

    # S143 over the whole run: a comment in a shared file is unused only if no model needed it.
    unused = unused_suppressions(suppression_uses)
    for result in results:
        if unused.get(result.name):
            from reedtool.checks.finding import Finding

            result.findings = sorted(result.findings + unused.pop(result.name),
                                     key=Finding.sort_key)
    if write_baseline is not None:
        return _write_baseline(results, write_baseline, force)
    from reedtool.workflows.baseline import apply_run_baselines
    from reedtool.config import relative_to_cwd

    baselines, missing = apply_run_baselines(
        results, [(t.name, t.path) for t in targets if t.path is not None], baseline_file)
    failed = any(f.severity in model_failing for r, model_failing in failing_of
                 for f in r.findings)
    for path in missing:
        options.notes.append(f"reedtool: the configuration's baseline {relative_to_cwd(path)} "
                             "does not exist yet, so every finding is reported; write it with "
                             f"`reedtool validate --write-baseline {relative_to_cwd(path)}`")
    for baseline in baselines:
        if baseline.stale():
            options.notes.append(f"reedtool: {relative_to_cwd(baseline.path)}: "
                                 f"{baseline.stale()} accepted finding(s) no longer occur in "
                                 "this run; `--write-baseline` records the findings of now")
    failing = frozenset({"error", "warning"} if strict_any else {"error"})   # junit
    color = _use_color(no_color) and output_file is None
    text = render(results, fmt, color=color, show_statistics=show_statistics, failing=failing)
    if output_file is not None:
        from reedtool.io.fileio import atomic_write_text

        atomic_write_text(output_file, text, force=force)
    else:
        click.echo(text, nl=False, color=color)
    for note in options.notes:
        # Text on the terminal carries it; machine formats and files stay as they are.
        click.echo(note, err=fmt != "text" or output_file is not None)
    if any(r.error is not None for r in results):
        return 2
    from reedtool.checks.runner import has_internal_errors

    if has_internal_errors(f for r in results for f in r.findings):
        return 3        # even with --exit-zero: the report misses what that rule checks
    if exit_zero:
        return 0
    return 1 if failed else 0

