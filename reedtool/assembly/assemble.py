"""One model path -> a robot that can be computed on -> its vehicle and validate's errors:
the call every analysing or flying command makes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from reedtool.assembly.models import ModelRequest, model_arguments
from reedtool.assembly.vehicle import Vehicle, check_batch_resources


@dataclass
class Assembled:
    """A model loaded with its arguments, sound enough to compute on."""

    model: Path
    robot: object                          # reedtool.model.Robot
    mappings: dict[str, str]               # the xacro arguments it was expanded with
    vehicle: Vehicle
    errors: list = field(default_factory=list)   # validate's error findings


def load_robot_for(model: Path, request: ModelRequest, *, require_sound: bool = True):
    """The one robot of `model`, expanded with its arguments (configuration, --launch,
    name:=value), refused (one line, exit 2) when it is not a sound tree to compute on
    (unless the caller checks that itself, after its own refusals)."""
    from reedtool.checks.preflight import require_sound_model
    from reedtool.config import load_config
    from reedtool.io.loader import load_robot

    mappings = model_arguments(model, load_config(model), request)[0]
    robot = load_robot(model, mappings, list(request.package_paths),
                       model_name=request.model_name)
    if require_sound:
        require_sound_model(robot)
    return robot, mappings


def assemble(model: Path, request: ModelRequest, *, samples: int | None = None,
             max_memory_bytes: int | None = None, validate: bool = True) -> Assembled:
    """Load `model`, build its vehicle and (with `validate`) find validate's errors on it.

    A model with more rotors than a hover test handles (or a batch of `samples` larger
    than `max_memory_bytes`) is refused before any rule runs on it.
    """
    from reedtool.assembly.validation import validation_errors

    robot, mappings = load_robot_for(model, request)
    vehicle = Vehicle.of(robot)
    if max_memory_bytes is not None:
        check_batch_resources(vehicle.every_rotor, samples, max_memory_bytes)
    errors = validation_errors(model, robot) if validate else []
    return Assembled(model, robot, mappings, vehicle, errors)
