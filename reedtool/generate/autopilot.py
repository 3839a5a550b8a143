"""new-package --autopilot: the PX4 airframe or ArduPilot .parm of a generated multirotor.

Both files are written from the frame catalogue entry the model is rendered from
(reedtool.generate.airframes), so the package is consistent by construction:

* PX4 (`px4/airframe_gz_<name>`): CA rotor i is the rotor with the i-th smallest motor
  number, at its position about the model's centre of mass in FRD, KM = ±momentConstant
  (+ for ccw), SIM_GZ_EC_FUNC(actuator+1) = 101 + i, SIM_GZ_EC_MIN 0 and SIM_GZ_EC_MAX =
  maxRotVelocity, MPC_THR_HOVER = hover speed / maxRotVelocity (THR_MDL_FAC 0: PX4's thrust
  model linear in the command, as the gz bridge maps the command to rad/s linearly).
* ArduPilot (`ardupilot/<name>.parm`): the first AP_MotorsMatrix frame whose motors sit at
  the frame's bearings with its spins, and SERVO(actuator+1)_FUNCTION = the motor of that
  bearing. PX4's octorotor X spins every rotor the other way from ArduPilot's octa X; for
  ArduPilot the catalogue frame is used with its spins reversed (a mirror-image prop set),
  and the model is generated with those spins too.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import PurePosixPath

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.generate.airframes import Airframe

AUTOPILOTS = ("px4", "ardupilot")
# ArduPilot bearings from add_motor_raw factors (Y6) are atan2 of rounded factors: 63.4°
# for a 60° arm. Within this, a catalogue rotor and an ArduPilot motor are the same place.
AP_BEARING_TOL_DEG = 10.0


def _spins(frame: Airframe) -> list[int]:
    return [1 if slot.direction == "ccw" else -1 for slot in frame.rotors]


def ardupilot_frame(frame: Airframe) -> tuple[Airframe, int, int, list[int]]:
    """(the frame to generate, FRAME_CLASS, FRAME_TYPE, AP motor number per catalogue rotor)."""
    from reedtool.flightstack.ardupilot import match_frame

    bearings = [slot.bearing_deg for slot in frame.rotors]
    found = match_frame(bearings, _spins(frame), AP_BEARING_TOL_DEG)
    if found is not None:
        return frame, *found
    reversed_frame = dataclasses.replace(frame, rotors=tuple(
        dataclasses.replace(slot, direction="cw" if slot.direction == "ccw" else "ccw")
        for slot in frame.rotors), reference=frame.reference + "; spins reversed for ArduPilot")
    found = match_frame(bearings, _spins(reversed_frame), AP_BEARING_TOL_DEG)
    if found is None:
        raise ReedtoolError(f"no ArduPilot frame has the rotor layout of '{frame.name}'",
                            hint="use --autopilot px4 for this frame")
    return reversed_frame, *found


def prepare_spec(spec, autopilot: str | None):
    """The spec to render for an autopilot (ArduPilot may need the spins of its frame).

    ArduPilot SITL reaches a Gazebo model only through ardupilot_gazebo's ArduPilotPlugin,
    which is built for Gazebo Sim (Garden and later, ArduPilot/ardupilot_gazebo README); a
    RotorS package (Gazebo Classic, ROS 1) could carry no plugin ArduPilot talks to, so
    it is refused rather than written with a .parm nothing reads."""
    if autopilot == "ardupilot" and spec.kind == "multirotor" and spec.sim != "gz":
        raise ReedtoolError(
            "--autopilot ardupilot needs Gazebo Sim: ArduPilot SITL drives a Gazebo model "
            "through ardupilot_gazebo's ArduPilotPlugin, which supports Gazebo Garden and "
            f"later, and a {'ROS 1 ' if spec.ros == 1 else ''}RotorS package runs on Gazebo "
            "Classic, where the model would have no plugin ArduPilot talks to",
            hint="use --ros 2 --sim gz --autopilot ardupilot: the model then carries the "
                 "ArduPilotPlugin and its LiftDrag blades")
    if autopilot == "ardupilot" and spec.kind == "multirotor":
        spec.frame = ardupilot_frame(spec.frame)[0]
    return spec


def _com_m(spec, positions: np.ndarray) -> np.ndarray:
    """Whole-model COM: the body's at its COM (a CAD body's, else the origin), sensors at
    the origin, each rotor's mass at its hub."""
    from reedtool.generate.package_spec import body_com_m, total_mass_estimate_kg

    moment = spec["mass"] * np.array(body_com_m(spec)) + spec["mass_rotor"] * positions.sum(axis=0)
    return moment / total_mass_estimate_kg(spec)


def autopilot_files(spec, autopilot: str | None, rendered=()):
    """The RenderedFiles for `--autopilot`, or [] without it. PX4 on gz: the airframe and
    the model in PX4-gazebo-models' layout under px4/ (port.px4_gz_contract), ported
    from the package's own model (`rendered`, the package's files)."""
    from reedtool.generate.render import RenderedFile

    if autopilot is None:
        return []
    if spec.kind != "multirotor":
        raise ReedtoolError("--autopilot applies to multirotor frames only",
                            hint="drop --autopilot for a ground robot")
    frame: Airframe = spec.frame
    from reedtool.generate.package_spec import rotor_positions_m

    positions = rotor_positions_m(spec)
    if autopilot == "px4":
        from reedtool.flightstack.px4 import RotorSpec, px4_airframe_text, px4_hover_throttle
        from reedtool.generate.package_spec import STANDARD_GRAVITY_M_S2, total_mass_estimate_kg

        com = _com_m(spec, positions)
        rotors = [RotorSpec(slot.motor_number, position - com,
                            1 if slot.direction == "ccw" else -1, spec["moment_constant"],
                            spec["max_rot_velocity"])
                  for slot, position in zip(frame.rotors, positions)]
        weight_N = total_mass_estimate_kg(spec) * STANDARD_GRAVITY_M_S2
        hover_rad_s = np.sqrt(weight_N / (frame.rotor_count * spec["motor_constant"]))
        throttle = px4_hover_throttle([hover_rad_s] * len(rotors),
                                      [spec["max_rot_velocity"]] * len(rotors))
        if spec.sim == "gz":
            from reedtool.port.px4_gz_contract import airframe_path, package_px4_files

            text = px4_airframe_text(spec.name, rotors, hover_throttle=throttle, world=spec.name)
            return [RenderedFile(PurePosixPath("px4", *airframe_path(spec.name).parts),
                                 text.encode("utf-8"), 0o644),
                    *(RenderedFile(PurePosixPath("px4", *path.parts), data, 0o644)
                      for path, data in package_px4_files(spec.name, rendered))]
        # Gazebo Classic (RotorS): PX4's simulator_mavlink outputs, no gz bridge.
        text = px4_airframe_text(spec.name, rotors, hover_throttle=throttle,
                                 simulator="classic")
        path = PurePosixPath("px4", f"airframe_gazebo-classic_{spec.name}")
    else:
        from reedtool.flightstack.ardupilot import parm_text

        _frame, frame_class, frame_type, motors = ardupilot_frame(frame)
        outputs = {slot.motor_number + 1: motor for slot, motor in zip(frame.rotors, motors)}
        text = parm_text(spec.name, frame_class, frame_type, outputs)
        path = PurePosixPath("ardupilot", f"{spec.name}.parm")
    return [RenderedFile(path, text.encode("utf-8"), 0o644)]


def autopilot_context(spec, autopilot: str | None) -> dict:
    """Template variables for --autopilot: `ardupilot_block`, the ArduPilotPlugin and its
    LiftDrag blades for a gz-sim multirotor (port.ardupilot_gz); `px4` and PX4's gz
    contract (port.px4_gz_contract: the sensors, the world's spherical coordinates)."""
    context = {"ardupilot_block": "", "px4": False}
    if autopilot == "ardupilot" and spec.kind == "multirotor" and spec.sim == "gz":
        from reedtool.generate.package_spec import rotor_positions_m

        positions = rotor_positions_m(spec)
        block = _ardupilot_block(spec, positions, _com_m(spec, positions))
        context["ardupilot_block"] = block
        # The README says where SITL must send its servo outputs: what the block says.
        context["ardupilot_fdm"] = {tag: re.search(f"<{tag}>([^<]*)</{tag}>", block).group(1)
                                    for tag in ("fdm_addr", "fdm_port_in")}
    if autopilot == "px4" and spec.kind == "multirotor" and spec.sim == "gz":
        from reedtool.port.px4_gz_contract import (
            MAGNETIC_FIELD_T,
            PX4_SENSORS,
            SPHERICAL_COORDINATES,
            px4_sensor_element,
        )
        from reedtool.port.sdf_writer import elements_text

        sensors = []
        for sensor in PX4_SENSORS:
            body = [c for c in px4_sensor_element(sensor).children
                    if c.tag not in ("always_on", "update_rate")]
            sensors.append({"name": sensor.name, "type": sensor.type,
                            "update_rate_hz": sensor.update_rate_hz,
                            "xml": elements_text(body, indent=6)})
        context.update(px4=True, px4_sensors=sensors, px4_spherical=SPHERICAL_COORDINATES,
                       px4_magnetic_field=MAGNETIC_FIELD_T)
    return context


def _ardupilot_block(spec, positions: np.ndarray, com: np.ndarray) -> str:
    """new-package --sim gz --autopilot ardupilot: the <gazebo> content (XML text) for the
    generated frame (rotor hubs at `positions`, the whole model's COM at `com`), rotors
    named as the template names them (rotor_N, rotor_N_joint, N the motor number = the
    channel), the body IMU as base_link::imu."""
    from reedtool.generate.package_spec import ROTOR_BLADE_THICKNESS_M, ROTOR_BLADE_WIDTH_M
    from reedtool.physics.inertia import box_inertia
    from reedtool.port.ardupilot_gz import ApRotor, ardupilot_elements
    from reedtool.port.sdf_writer import elements_text

    frame = spec.frame
    # The template's rotor inertia: a blade box of mass_rotor * slowdown (RotorS), its
    # origin at the joint: izz is the moment about the joint axis.
    blade = (spec["radius_rotor"], ROTOR_BLADE_WIDTH_M, ROTOR_BLADE_THICKNESS_M)
    izz = float(box_inertia(spec["mass_rotor"] * spec["rotor_velocity_slowdown_sim"], blade)[2, 2])
    rotors = [ApRotor(joint=f"rotor_{slot.motor_number}_joint", link=f"rotor_{slot.motor_number}",
                      channel=slot.motor_number,
                      turning_sign=1 if slot.direction == "ccw" else -1,
                      position_com_flu_m=np.asarray(position) - com,
                      joint_axis_link=np.array([0.0, 0.0, 1.0]),
                      thrust_axis_link=np.array([0.0, 0.0, 1.0]),
                      motor_constant=spec["motor_constant"],
                      moment_constant=spec["moment_constant"],
                      max_rot_velocity_rad_s=spec["max_rot_velocity"],
                      prop_radius_m=spec["radius_rotor"], inertia_axis_kg_m2=izz,
                      time_constant_s=spec["time_constant_up"])
              for slot, position in zip(frame.rotors, positions)]
    plugins, _controls = ardupilot_elements(rotors, "base_link::imu")
    return elements_text(plugins, indent=4)
