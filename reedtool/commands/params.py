"""Options shared by the commands, declared once here so every command spells and
reads them the same way.

- `model_inputs`: the model paths (files, directories, globs, ROS packages) with their
  xacro `name:=value` words, `--package-path`, `--model` and `--launch`; `[tool.reedtool]
  args` of the nearest configuration are added when the model is loaded (workflows/).
- `validation_options`: `--ignore CODE` and `--ignore-validation`, for the commands that
  run validate's rules before they compute.

click's FloatRange lets `nan` through (every comparison with NaN is false), and `inf`
through an open upper bound; an option that feeds a computation wants neither.
"""

from __future__ import annotations

import math
from pathlib import Path

import click


class FiniteFloatRange(click.FloatRange):
    """A FloatRange that refuses NaN and infinities."""

    name = "finite float range"

    def convert(self, value, param, ctx):
        number = click.FLOAT.convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return super().convert(number, param, ctx)


def model_option(command):
    """`--model NAME`: the model of an SDF world (or any SDF file) a command reads."""
    return click.option(
        "--model", "model_name", metavar="NAME", default=None,
        help="In an SDF world holding several models, the one to read (by its name).",
    )(command)


def package_path_option(command):
    return click.option("--package-path", "package_paths", multiple=True, metavar="DIR",
                        type=click.Path(path_type=Path, file_okay=False),
                        help="Directory to search for ROS packages first (repeatable).")(command)


def launch_option(command):
    return click.option("--launch", "launch_file", metavar="FILE",
                        type=click.Path(path_type=Path, dir_okay=False),
                        help="Read the model and its xacro arguments from a roslaunch XML or "
                             "ROS 2 (XML or Python) launch file.")(command)


def model_inputs(metavar: str = "MODEL [NAME:=VALUE]..."):
    """The model words (paths and NAME:=VALUE), --package-path, --model and --launch."""
    def decorate(command):
        for option in reversed((click.argument("inputs", nargs=-1, metavar=metavar),
                                package_path_option, model_option, launch_option)):
            command = option(command)
        return command
    return decorate


def ignore_option(command):
    return click.option("--ignore", multiple=True, metavar="CODE,...",
                        help="Skip validate's rules whose code starts with these prefixes "
                             "(or these rule names).")(command)


def validation_options(command):
    """--ignore CODE and --ignore-validation: how a computing command treats validate's
    errors (workflows/validation.py says which ones it refuses on)."""
    command = click.option(
        "--ignore-validation", is_flag=True,
        help="Compute even when validate reports an error that makes the result "
             "meaningless (by default the model is refused: exit 1).")(command)
    return ignore_option(command)


def note_model_files(inputs) -> None:
    """The model files named on the command line are inputs of this run: no output of it
    (a picture, a plot, a CSV) may overwrite one."""
    from reedtool.io.fileio import note_input

    for word in inputs:
        if Path(word).is_file():
            note_input(Path(word))


def one_model_request(command_name: str, inputs, package_paths, model_name, launch_file,
                      ignore=()):
    """The command line of a single-model command -> (model path, ModelRequest)."""
    from reedtool.workflows.robots import one_model, request_from_words

    paths, request = request_from_words(inputs, package_paths=package_paths,
                                        model_name=model_name, launch_file=launch_file,
                                        ignore=ignore)
    if not paths:
        raise click.UsageError("missing argument 'MODEL'")
    return one_model(paths, request, command_name), request
