"""validate's findings on a model, as every command sees them: the nearest configuration's
selection, severities and suppressions, then the command line's `--select`/`--ignore`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from reedtool.assembly.models import ModelRequest, argument_use, load_models, model_arguments
from reedtool.errors import ReedtoolError


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


def _ignores_for(config, model: Path):
    from reedtool.checks.runner import parse_selectors

    origin = str(config.path) if config.path else "config"

    def ignores_for(file: str | None) -> tuple[str, ...]:
        return parse_selectors(config.ignores_for(file or model), origin=origin)

    return ignores_for


@dataclass
class CheckedModel:
    """One robot of a model path with validate's findings on it."""

    suffix: str                  # "" or " [model NAME]" for each model of a world
    robot: object                # reedtool.model.Robot
    findings: list = field(default_factory=list)     # kept after suppressions
    suppressed: list = field(default_factory=list)


@dataclass
class CheckedPath:
    """What one model path gave: its robots with findings, or the input error that
    stopped it (the other paths of a run are still checked)."""

    models: list[CheckedModel] = field(default_factory=list)
    error: ReedtoolError | None = None


def check_model_path(model: Path, request: ModelRequest, *, controllers=(),
                     flight_params=()) -> CheckedPath:
    """Load `model` with its arguments and run validate's rules on each of its robots.

    A model that cannot be read gives its error in the result; a bad configuration (or
    --select) raises before anything is loaded.
    """
    from reedtool.checks.runner import apply_suppressions, run_checks
    from reedtool.config import load_config

    config = load_config(model)
    selection = selection_for(config, request.select, request.ignore)
    ignores_for = _ignores_for(config, model)
    ignores_for(model)   # a bad per-file-ignores selector is a config error, raised now
    mappings, given, origins, checked = model_arguments(model, config, request)
    try:
        arguments = argument_use(model, mappings, given, origins, checked, config, request)
        pairs = (request.preloaded.pop(model.resolve(), None)
                 or load_models(model, mappings, request.package_paths, request.model_name))
    except ReedtoolError as exc:
        return CheckedPath(error=exc)
    out = CheckedPath()
    for suffix, robot in pairs:
        findings = run_checks(robot, selection, controllers=list(controllers),
                              flight_params=list(flight_params), arguments=arguments)
        kept, dropped = apply_suppressions(findings, ignores_for)
        out.models.append(CheckedModel(suffix, robot, kept, dropped))
    return out


def validation_errors(model: Path, robot) -> list:
    """The error findings `validate` reports for an already loaded robot (its config's
    selection, severities and suppressions): what hover-test refuses to fly."""
    from reedtool.checks.runner import apply_suppressions, run_checks
    from reedtool.config import load_config

    config = load_config(model)
    findings = run_checks(robot, selection_for(config))
    kept, _ = apply_suppressions(findings, _ignores_for(config, model))
    return [f for f in kept if f.severity == "error"]
