"""`validate` over a run: the command line's words -> the models to check (files,
directories, globs, ROS packages, argument variants) -> each checked (across processes
with --jobs) -> one list of results with the run's S143, baselines and notes, and the
exit code over all. Also the settings each model gets (--show-settings). The caller
renders the results (report.render) and the settings (report.settings_text); nothing
here prints.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

from reedtool.errors import ReedtoolError
from reedtool.workflows.robots import ModelRequest, model_arguments, targets_of
from reedtool.workflows.validation import selection_for

# The rule families (checks.registry.FAMILIES titles) the flight-stack agreement reads.
STRUCTURE_FAMILY = "Structure"
CONTROLLER_FAMILY = "Controller cross-check"


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


# ------------------------------------------------------------------ the words -> the models

def read_words(inputs, *, package_paths=(), model_name=None, launch_file=None, select=(),
               ignore=(), force_exclude: bool = False) -> tuple[list[str], ModelRequest]:
    """The model words of the command line and the request every model of the run gets;
    `mav_name=foo` (an argument missing its `:`) is refused, naming the fix."""
    from reedtool.resolve.mappings import suggest_mapping
    from reedtool.workflows.robots import request_from_words

    paths, request = request_from_words(inputs, package_paths=package_paths,
                                        model_name=model_name, launch_file=launch_file,
                                        select=select, ignore=ignore)
    request.force_exclude = force_exclude
    for word in paths:
        if not Path(word).exists() and suggest_mapping(word) is not None:
            # `mav_name=foo` names no file: an argument missing its `:`, not a model.
            raise ReedtoolError(f"'{word}' is not a file; xacro arguments are written "
                                "name:=value", hint=f"did you mean '{suggest_mapping(word)}'?")
    return paths, request


def find_targets(paths: list[str], request: ModelRequest) -> list:
    """The models the paths name (workflows.targets); one model that is not there is the
    one-line error of every command."""
    if len(paths) == 1 and not Path(paths[0]).exists() and not re.search(r"[*?\[]", paths[0]):
        from reedtool.workflows.targets import not_found_message

        message = not_found_message(paths[0])
        raise ReedtoolError(message, file=paths[0],
                            hint=None if message != "file not found" else "check the model path")
    return targets_of(paths, request)


# ------------------------------------------------------------------ one model

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
    from reedtool.config import load_config
    from reedtool.report import ModelResult
    from reedtool.workflows.suppression_audit import suppression_use
    from reedtool.workflows.validation import check_model_path

    checked = check_model_path(model, options.request, controllers=options.controllers,
                               flight_params=options.flight_params)
    if checked.error is not None:
        exc = checked.error
        return [ModelResult(name, error=exc.one_line(), error_file=exc.file,
                            error_line=exc.line)]
    selection = selection_for(load_config(model), options.request.select,
                              options.request.ignore)
    results = []
    for one in checked.models:
        results.append(ModelResult(name + one.suffix, one.findings,
                                   suppressed=len(one.suppressed)))
        options.suppression_uses.append((name + one.suffix,
                                         *suppression_use(one.robot, one.suppressed, selection)))
        if not one.suppressed:     # a silenced flight-stack finding is no agreement
            options.notes += agreement_lines(model, one.robot, one.findings, options,
                                             name + one.suffix)
        if options.diagram is not None:
            write_model_diagram(model, one.robot, one.findings, options,
                                several=len(checked.models) > 1)
    return results


def agreement_lines(path: Path, robot, findings, options: RunOptions, model: str
                    ) -> list[str]:
    """One line per --airframe/--autopilot-params file the model agrees with: every
    controller cross-check rule of that flight stack (the registry's family and stack)
    ran and none found anything above information."""
    from reedtool.checks.registry import all_rules, get_rule

    def family(code: str) -> str | None:
        rule = get_rule(code)
        return rule.family if rule is not None else None

    if not options.flight_params or any(f.severity == "error"
                                        and family(f.code) == STRUCTURE_FAMILY
                                        for f in findings):
        return []     # a broken tree: the flight-stack rules did not look
    from reedtool.config import load_config
    from reedtool.flightstack.params_files import agreement_line
    from reedtool.physics.rotors import discover_rotors

    selection = selection_for(load_config(path), options.request.select,
                              options.request.ignore)
    rotors = discover_rotors(robot)
    lines = []
    for params in options.flight_params:
        rules = [r for r in all_rules()
                 if r.family == CONTROLLER_FAMILY and r.stack == params.kind]
        ran = all(selection.enabled(r.code) for r in rules)
        quiet = not any(f.code in {r.code for r in rules} and f.severity != "info"
                        for f in findings)
        counted = rotors if params.kind == "px4" else [r for r in rotors if r.role == "lift"]
        if rules and ran and quiet and counted:
            lines.append(agreement_line(params, len(counted), model))
    return lines


def write_model_diagram(model: Path, robot, findings, options: RunOptions,
                        several: bool) -> None:
    """One picture per model: FILE itself for a run of one model; else FILE-STEM.svg, STEM
    the model file's (and -ROBOT for each model of a world), so models that share a robot
    name (variants of one xacro, fixtures) do not overwrite each other's picture."""
    from reedtool.physics.rotors import discover_rotors
    from reedtool.workflows.diagram import write_diagram

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


def prepare_workers() -> None:
    """What every model's check imports, loaded once before --jobs forks its workers."""
    import reedtool.io.dae  # noqa: F401
    import reedtool.io.loader  # noqa: F401
    import reedtool.io.xacro_expand  # noqa: F401
    import reedtool.physics.inertia  # noqa: F401
    import reedtool.workflows.suppression_audit  # noqa: F401
    from reedtool.checks.registry import all_rules

    all_rules()


# ------------------------------------------------------------------ the run

@dataclass
class ValidateRun:
    """A run's results in the order given, the notes to show, and what fails it."""

    results: list
    notes: list[str]
    failed: bool = False                 # a finding at a severity its model fails on
    strict_any: bool = False             # some model is checked --strict

    @property
    def failing(self) -> frozenset[str]:
        """The severities that fail the run (JUnit marks them failures)."""
        return frozenset({"error", "warning"} if self.strict_any else {"error"})

    @property
    def unread(self) -> list:
        return [r for r in self.results if r.error is not None]

    def exit_code(self, exit_zero: bool = False) -> int:
        """2 when a model could not be read, 3 when a rule failed internally (even with
        --exit-zero: the report misses what that rule checks), else 1 on a failing
        finding (0 with --exit-zero)."""
        from reedtool.checks.runner import has_internal_errors

        if self.unread:
            return 2
        if has_internal_errors(f for r in self.results for f in r.findings):
            return 3
        if exit_zero:
            return 0
        return 1 if self.failed else 0


def _check_all(targets: list, options: RunOptions, jobs: int) -> dict[int, list]:
    """Every job of every checkable target, across `jobs` processes: id(target) -> its
    (results, notes, suppression uses) per job."""
    import functools

    from reedtool.workflows.parallel import map_models

    checkable = [job for t in targets if t.skipped is None and t.path is not None
                 for job in jobs_of(t, options.request)]
    outcomes = map_models(functools.partial(check_target, options=options), checkable, jobs,
                          prepare=prepare_workers)
    checked: dict[int, list] = {}
    for job, outcome in zip(checkable, outcomes):
        checked.setdefault(id(job.target), []).append(outcome)
    return checked


def _target_results(target, outcomes: list, options: RunOptions, uses: list) -> list:
    """A checked target's results (its notes and suppression uses gathered), an input
    error naming the file it was checked for."""
    model_results = []
    for one_results, notes, one_uses in outcomes:
        model_results += one_results
        options.notes += notes
        uses += one_uses
    if target.checked_for is not None:
        for result in model_results:
            if result.error is not None:
                # The failure is this model's; name the file it was checked for.
                result.error += (f" [checked for {target.checked_for}, which it includes; "
                                 f"give {target.checked_for} its arguments (name:=value) "
                                 "to validate it as a model of its own]")
    return model_results


def _collect(targets: list, checked: dict[int, list], options: RunOptions,
             strict: bool | None) -> tuple[list, list, list, bool]:
    """(results, (result, the severities that fail its model) pairs, suppression uses,
    any model strict), in the order of the targets."""
    from reedtool.config import load_config
    from reedtool.report import ModelResult

    results, failing_of, uses, strict_any = [], [], [], False
    for target in targets:
        if target.skipped is not None:
            results.append(ModelResult(target.name, skipped=target.skipped))
            continue
        if target.path is None:
            if len(targets) == 1:
                raise ReedtoolError(target.error, file=target.name)
            results.append(ModelResult(target.name, error=target.error, error_file=target.name))
            continue
        model_results = _target_results(target, checked[id(target)], options, uses)
        results.extend(model_results)
        if len(targets) == 1 and results[-1].error is not None:
            # One model: its input error is the one-line error of every command.
            raise ReedtoolError(results[-1].error)
        # Each model fails by its own configuration's `strict`, unless the command line says.
        model_strict = load_config(target.path).strict if strict is None else strict
        strict_any = strict_any or model_strict
        model_failing = {"error", "warning"} if model_strict else {"error"}
        failing_of += [(r, model_failing) for r in model_results]
    return results, failing_of, uses, strict_any


def _baseline_notes(baselines, missing) -> list[str]:
    from reedtool.config import relative_to_cwd

    notes = []
    for path in missing:
        notes.append(f"reedtool: the configuration's baseline {relative_to_cwd(path)} "
                     "does not exist yet, so every finding is reported; write it with "
                     f"`reedtool validate --write-baseline {relative_to_cwd(path)}`")
    for baseline in baselines:
        if baseline.stale():
            notes.append(f"reedtool: {relative_to_cwd(baseline.path)}: "
                         f"{baseline.stale()} accepted finding(s) no longer occur in "
                         "this run; `--write-baseline` records the findings of now")
    return notes


def run_validate(targets: list, options: RunOptions, *, jobs: int = 1,
                 strict: bool | None = None, baseline_file: Path | None = None,
                 apply_baselines: bool = True) -> ValidateRun:
    """Check every target; S143 over the whole run; the baselines applied (unless the run
    is to write one, `apply_baselines` False)."""
    from reedtool.checks.finding import Finding
    from reedtool.workflows.suppression_audit import unused_suppressions

    options.diagram_per_model = len(targets) > 1
    checked = _check_all(targets, options, jobs)
    results, failing_of, uses, strict_any = _collect(targets, checked, options, strict)
    # S143 over the whole run: a comment in a shared file is unused only if no model needed it.
    unused = unused_suppressions(uses)
    for result in results:
        if unused.get(result.name):
            result.findings = sorted(result.findings + unused.pop(result.name),
                                     key=Finding.sort_key)
    run = ValidateRun(results, options.notes, strict_any=strict_any)
    if not apply_baselines:
        return run
    from reedtool.workflows.baseline import apply_run_baselines

    baselines, missing = apply_run_baselines(
        results, [(t.name, t.path) for t in targets if t.path is not None], baseline_file)
    run.failed = any(f.severity in model_failing for r, model_failing in failing_of
                     for f in r.findings)
    run.notes += _baseline_notes(baselines, missing)
    return run


def load_cross_checks(options: RunOptions, controller_files=(), airframe_files=(),
                      autopilot_files=()) -> None:
    """--controller, --airframe and --autopilot-params read into `options` (once a run)."""
    if controller_files:
        from reedtool.flightstack.rotors_lee import load_controller_files

        options.controllers = load_controller_files(controller_files)
    if airframe_files or autopilot_files:
        from reedtool.flightstack.params_files import load_flight_params

        options.flight_params = load_flight_params(airframe_files, autopilot_files)


def write_run_baseline(run: ValidateRun, path: Path, force: bool) -> tuple[int, int]:
    """--write-baseline: every finding of the run recorded; (findings, models checked).
    Refused when a model could not be read: a baseline without its findings would not be
    the run's."""
    from reedtool.io.fileio import atomic_write_text
    from reedtool.workflows.baseline import baseline_text

    if run.unread:
        raise ReedtoolError(f"{len(run.unread)} model(s) could not be read; baseline not "
                            "written", file=path,
                            hint="fix or exclude them, then write the baseline")
    text, count = baseline_text(run.results, path)
    atomic_write_text(path, text, force=force)
    return count, sum(1 for r in run.results if r.skipped is None)


# ------------------------------------------------------------------ --show-settings

@dataclass
class ModelSettings:
    """The configuration and settings one model of the run gets, as they are shown."""

    name: str
    skipped: str | None = None
    error: str | None = None
    config: str | None = None             # the configuration file used (relative)
    also_found: list[str] = field(default_factory=list)
    select: tuple[str, ...] = ()
    ignore: tuple[str, ...] = ()
    severity: dict = field(default_factory=dict)
    strict: bool = False
    arguments: list[tuple[str, str, str]] = field(default_factory=list)  # name, value, origin
    per_file_ignores: list[str] = field(default_factory=list)
    variants: list[str] = field(default_factory=list)
    exclude: list[str] = field(default_factory=list)
    force_exclude: bool = False
    baseline: str | None = None


def settings_of(targets: list, request: ModelRequest) -> Iterator[ModelSettings]:
    """--show-settings: what each target is checked with, one target at a time (shown as
    it comes: a bad configuration further down stops the run there)."""
    from reedtool.config import DEFAULT_EXCLUDE, load_config, relative_to_cwd
    from reedtool.workflows.robots import variant_label

    for target in targets:
        if target.skipped is not None or target.path is None:
            yield ModelSettings(target.name, skipped=target.skipped, error=target.error)
            continue
        config = load_config(target.path)
        selection = selection_for(config, request.select, request.ignore)
        mappings, _, origins, _ = model_arguments(target.path, config, request)
        exclude = DEFAULT_EXCLUDE if config.exclude is None else config.exclude
        yield ModelSettings(
            target.name,
            config=relative_to_cwd(config.path) if config.path is not None else None,
            also_found=[relative_to_cwd(other) for other in config.candidates[1:]],
            select=selection.select, ignore=selection.ignore, severity=selection.severity,
            strict=config.strict,
            arguments=[(name, mappings[name], origins[name]) for name in sorted(mappings)],
            per_file_ignores=list(config.ignores_for(target.path) or ()),
            variants=[variant_label(job.variant) for job in jobs_of(target, request)
                      if job.variant is not None],
            exclude=[*exclude, *config.extend_exclude], force_exclude=config.force_exclude,
            baseline=relative_to_cwd(config.baseline) if config.baseline is not None else None)
