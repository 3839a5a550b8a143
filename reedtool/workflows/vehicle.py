"""A loaded robot -> the vehicle that hovers: its rotors, whole-robot mass properties, the
hover trim validate judges by, and the simulator's parameters.

Only `lift` rotors hold a hover (a VTOL's pusher or a plane's puller stays off); every
rotor is kept for the tables and the resource checks.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

from reedtool.errors import ReedtoolError

# The robustness batch flies all vehicles at once as (k, N) float64 arrays: about 200 state,
# command and bookkeeping values per vehicle plus ~20 per rotor (measured: 10^7 quads took
# 22 GB). Estimated before allocating, against --max-memory.
BATCH_BYTES_PER_VEHICLE = 8 * 200
BATCH_BYTES_PER_VEHICLE_ROTOR = 8 * 20
DEFAULT_MAX_MEMORY_MB = 2048
# Real multirotors have 3 to 16 rotors; a model with hundreds is generated wrongly, and its
# (rotors x rotors) allocation work is what ran out of memory at 2000.
MAX_ROTORS = 64


def batch_memory_bytes(samples: int, n_rotors: int) -> int:
    """Estimated peak memory of flying `samples` perturbed vehicles together."""
    return samples * (BATCH_BYTES_PER_VEHICLE + n_rotors * BATCH_BYTES_PER_VEHICLE_ROTOR)


def check_batch_resources(every_rotor, samples: int | None, max_memory_bytes: int) -> None:
    """Refuse, before anything is allocated, a model or batch this machine cannot fly."""
    from reedtool.physics.rotors import lift_rotors

    if len(every_rotor) > MAX_ROTORS:
        source = every_rotor[0].loc.file if every_rotor else None
        raise ReedtoolError(f"{len(every_rotor)} rotors: more than the {MAX_ROTORS} a multirotor "
                            "hover test handles", file=source,
                            hint="is the model generated wrongly? real multirotors have 3 to "
                                 "16 rotors")
    n_lift = len(lift_rotors(every_rotor))
    if samples:
        need = batch_memory_bytes(samples, n_lift)
        if need > max_memory_bytes:
            fit = max_memory_bytes // batch_memory_bytes(1, n_lift)
            raise ReedtoolError(f"--samples {samples} needs about {need / 2**20:,.0f} MB for "
                                f"{n_lift} rotors, more than --max-memory "
                                f"{max_memory_bytes // 2**20} MB",
                                hint=f"use --samples {fit} or fewer (a few hundred give the "
                                     "pass rate to a few percent), or raise --max-memory")


@dataclass
class Vehicle:
    """One robot as a vehicle. Mass properties and trim are computed when first asked for."""

    robot: object                 # reedtool.model.Robot
    every_rotor: list             # every motor the model declares, lift or not
    rotors: list                  # the lift rotors, in the model's order

    @classmethod
    def of(cls, robot) -> "Vehicle":
        from reedtool.physics.rotors import discover_rotors, lift_rotors

        every_rotor = discover_rotors(robot)
        return cls(robot, every_rotor, lift_rotors(every_rotor))

    @cached_property
    def props(self):
        """Whole-robot mass properties (Pinocchio), base frame, joints at zero."""
        from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

        return whole_robot_pinocchio(self.robot)

    @cached_property
    def omnidirectional(self) -> bool:
        from reedtool.physics.rotors import is_omnidirectional

        return is_omnidirectional(self.rotors)

    @cached_property
    def trim(self):
        """The static hover trim validate judges by (checks.context): the 6-DoF allocation
        for an omnidirectional frame, whose reversible rotors may push down."""
        from reedtool.physics.trim import solve_trim, solve_trim_6dof

        props = self.props
        solve = solve_trim_6dof if self.omnidirectional else solve_trim
        trim = solve(props.mass_kg, props.com_m, self.rotors)
        if self.every_rotor and not self.rotors:
            # A fixed-wing's puller (or a glider with a pusher): motors exist, none lifts.
            roles = ", ".join(f"{r.name} is {r.role}" for r in self.every_rotor)
            trim = dataclasses.replace(trim, message=(
                f"the model has no lift rotors ({roles}: its thrust axis is horizontal); "
                "a fixed-wing cannot hover"))
        return trim


@dataclass
class FlyingVehicle:
    """What the simulator flies: the parameters, and the rotors with any derived response."""

    params: object                # reedtool.sim.params.VehicleParams
    rotors: list
    derived: list                 # one line per value derived rather than read


def prepare_flight(vehicle: Vehicle) -> FlyingVehicle:
    """The simulator's parameters of a trimmed vehicle, or a one-line refusal of what the
    simulator cannot fly (an omnidirectional frame, unusable motor dynamics, an inertia
    that is not positive definite)."""
    import numpy as np

    from reedtool.sim.params import VehicleParams, check_rotor_dynamics

    robot, props = vehicle.robot, vehicle.props
    if vehicle.omnidirectional:
        raise ReedtoolError(
            f"{robot.name}: {vehicle.trim.message}; hover-test's flight controller cannot fly "
            "an omnidirectional frame (reversible or many-direction rotors): it commands "
            "thrust and three torques from rotors that push one way",
            file=robot.source_file,
            hint="`reedtool validate` checks this frame's 6-DoF hover trim and allocation")
    rotors, derived = ardupilot_motor_response(robot, vehicle.rotors)
    check_rotor_dynamics(rotors)
    if props.mass_kg <= 0 or not np.all(np.linalg.eigvalsh(props.inertia_kg_m2) > 0):
        raise ReedtoolError("the whole-robot inertia is not positive definite, nothing can "
                            "be simulated", file=robot.source_file,
                            hint="run `reedtool inertia` on the model")
    params = VehicleParams.from_rotors(props.mass_kg, props.com_m, props.inertia_kg_m2, rotors)
    return FlyingVehicle(params, rotors, derived)


def ardupilot_motor_response(robot, rotors):
    """ArduPilotPlugin rotors carry no time constants: derive them from the joint's
    velocity PID and the rotor's inertia, or refuse with the reason (one line)."""
    from reedtool.physics.rotors import ardupilot_time_constant

    out, derived = [], []
    for rotor in rotors:
        if rotor.kind != "ardupilot":
            out.append(rotor)
            continue
        found = ardupilot_time_constant(robot, rotor)
        if not found.time_constant_s > 0:
            raise ReedtoolError(
                f"rotor {rotor.name}: the ArduPilotPlugin gives no motor time constant "
                f"({found.explanation}), and hover-test simulates the motor response",
                file=rotor.loc.file, line=rotor.loc.line,
                hint="`reedtool validate` checks their hover trim from the LiftDrag estimate")
        out.append(dataclasses.replace(rotor, time_constant_up_s=found.time_constant_s,
                                       time_constant_down_s=found.time_constant_s))
        derived.append(f"{rotor.name}: {found.explanation}")
    return out, derived
