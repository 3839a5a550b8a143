"""Whole-robot mass properties from Pinocchio: an oracle reedtool did not write.

The model is built with a FREE-FLYER root joint. With a fixed base Pinocchio welds the
root link to its `universe` body, and computeTotalMass, which sums the bodies of real
joints, would leave the root link's mass out. With a free-flyer at its neutral
configuration (identity pose) the root link frame coincides with the world frame, so
every world-frame quantity is in the base (root link) frame, which is where
reedtool.physics.inertia.whole_robot works too. All joints sit at their neutral (zero) position.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.model import Robot
from reedtool.physics.inertia import MassProperties, parallel_axis_term


def build_model(robot: Robot):
    """(pinocchio Model, Data) of the robot's URDF text, with a free-flyer root joint."""
    import pinocchio as pin

    if not robot.urdf_xml:
        raise ReedtoolError(f"robot '{robot.name}' has no URDF text to give Pinocchio",
                            file=robot.source_file)
    hint = "run `reedtool validate` on the model first"
    with _captured_stderr() as captured:
        try:
            model = pin.buildModelFromXML(robot.urdf_xml, pin.JointModelFreeFlyer())
        except Exception as exc:  # noqa: BLE001 - Pinocchio raises bare RuntimeError and others
            model, failure = None, exc
    complaints = _urdfdom_errors(captured.text)
    if model is None:
        reason = "; ".join(complaints) or " ".join(str(failure).split())
        raise ReedtoolError(f"Pinocchio cannot build the model: {reason}",
                            file=robot.source_file, hint=hint) from failure
    if complaints:
        # urdfdom skipped an element it could not read (an <inertial>, a <visual>) and went
        # on: the model it built is not the one written, so nothing computed from it holds.
        raise ReedtoolError(f"Pinocchio's URDF parser skipped part of the model: "
                            f"{'; '.join(complaints)}", file=robot.source_file, hint=hint)
    return model, model.createData()


class _Captured:
    text = ""


@contextlib.contextmanager
def _captured_stderr():
    """Collect what C++ code writes to file descriptor 2 (urdfdom's console_bridge), so it
    becomes part of a one-line error instead of raw lines on the user's terminal."""
    captured = _Captured()
    sys.stderr.flush()
    with tempfile.TemporaryFile() as sink:
        saved = os.dup(2)
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            captured.text = sink.read().decode("utf-8", "replace")


def _urdfdom_errors(text: str) -> list[str]:
    """urdfdom's 'Error:' lines (without the 'at line N in file.cpp' that follows each)."""
    return [" ".join(line.split(":", 1)[1].split()) for line in text.splitlines()
            if line.startswith("Error:")]


def whole_robot_pinocchio(robot: Robot) -> MassProperties:
    """Total mass, COM and composite inertia about the COM, in the base frame, by Pinocchio."""
    import pinocchio as pin

    model, data = build_model(robot)
    q0 = pin.neutral(model)
    mass_kg = float(pin.computeTotalMass(model))
    if mass_kg <= 0.0:
        return MassProperties(0.0, np.zeros(3), np.zeros((3, 3)))
    com_m = np.array(pin.centerOfMass(model, data, q0), dtype=float)
    # The free-flyer's 6x6 block of the joint-space inertia matrix is the whole robot's
    # spatial inertia about the root frame origin, in root axes: [[m E, m [c]x^T],
    # [m [c]x, I_origin]] (Pinocchio orders velocities linear first, in the local frame).
    # crba fills the upper triangle only; the 3x3 angular block is on the diagonal.
    M = pin.crba(model, data, q0)
    I_origin = np.triu(M[3:6, 3:6]) + np.triu(M[3:6, 3:6], 1).T
    # Back from the root origin to the COM (parallel-axis theorem, subtracted).
    I_com = I_origin - parallel_axis_term(mass_kg, com_m)
    return MassProperties(mass_kg, com_m, I_com)
