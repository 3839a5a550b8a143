"""One model path -> a robot that can be computed on -> validate's errors on it, split by
the refusal policy (workflows/validation.py) -> its vehicle: the call every analysing or
flying command makes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from reedtool.workflows.robots import ModelRequest, model_mappings
from reedtool.workflows.validation import Verdict, judge
from reedtool.workflows.vehicle import Vehicle, check_batch_resources


@dataclass
class Assembled:
    """A model loaded with its arguments, sound enough to compute on."""

    model: Path
    robot: object                          # reedtool.model.Robot
    mappings: dict[str, str]               # the xacro arguments it was expanded with
    vehicle: Vehicle
    verdict: Verdict = field(default_factory=Verdict)   # validate's errors, split

    @property
    def errors(self) -> list:
        return self.verdict.errors


def load_robot_for(model: Path, request: ModelRequest, *, require_sound: bool = True):
    """The one robot of `model`, expanded with its arguments (configuration, --launch,
    name:=value), refused (one line, exit 2) when it is not a sound tree to compute on
    (unless the caller checks that itself, after its own refusals)."""
    from reedtool.checks.preflight import require_sound_model
    from reedtool.io.loader import load_robot

    mappings = model_mappings(model, request)
    robot = load_robot(model, mappings, list(request.package_paths),
                       model_name=request.model_name)
    if require_sound:
        require_sound_model(robot)
    return robot, mappings


def assemble(model: Path, request: ModelRequest, command: str, *,
             samples: int | None = None, max_memory_bytes: int | None = None,
             require_sound: bool = True) -> Assembled:
    """Load `model`, build its vehicle and judge validate's errors on it for `command`
    (a key of COMMAND_NEEDS).

    A model with more rotors than a hover test handles (or a batch of `samples` larger
    than `max_memory_bytes`) is refused before any rule runs on it.
    """
    robot, mappings = load_robot_for(model, request, require_sound=require_sound)
    vehicle = Vehicle.of(robot)
    if max_memory_bytes is not None:
        check_batch_resources(vehicle.every_rotor, samples, max_memory_bytes)
    verdict = judge(model, robot, request, command)
    return Assembled(model, robot, mappings, vehicle, verdict)
