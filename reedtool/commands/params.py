"""Option types shared by the commands.

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


def model_arguments(command):
    """MODEL, its xacro NAME:=VALUE arguments, --package-path and --model: what every
    command that loads one model takes, spelt the same everywhere."""
    for decorate in reversed((
            click.argument("model", type=click.Path(path_type=Path, dir_okay=False)),
            click.argument("mappings", nargs=-1),
            click.option("--package-path", "package_paths", multiple=True, metavar="DIR",
                         type=click.Path(path_type=Path, file_okay=False),
                         help="Directory to search for ROS packages first (repeatable)."),
            model_option)):
        command = decorate(command)
    return command
