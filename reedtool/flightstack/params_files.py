"""Autopilot parameter files named on the command line -> the tables flightstack rules read."""

from __future__ import annotations

from pathlib import Path
from typing import Iterable

from reedtool.errors import ReedtoolError

# Where the flight stacks keep the files these options take, for a name given without a
# path (`--airframe 4001_gz_x500`): PX4's SITL airframes (gz and classic), ArduPilot's
# SITL frame parameters.
PX4_AIRFRAMES_DIR = "ROMFS/px4fmu_common/init.d-posix/airframes/"
ARDUPILOT_PARAMS_DIR = "Tools/autotest/default_params/"


def _check_named_file(path: Path, option: str) -> None:
    """A missing file given by bare name is most likely a flight stack's own name for it."""
    if path.exists() or len(path.parts) != 1:
        return     # a path: the reader says what is wrong with it
    if option == "--airframe":
        raise ReedtoolError(
            f"no such file; PX4 keeps its airframes as files in PX4-Autopilot, under "
            f"{PX4_AIRFRAMES_DIR} (SITL) and ROMFS/px4fmu_common/init.d/airframes/ (boards)",
            file=path, hint=f"pass the file's path, e.g. --airframe PX4-Autopilot/"
                            f"{PX4_AIRFRAMES_DIR}{path.name}")
    raise ReedtoolError(
        f"no such file; ArduPilot keeps its SITL frame parameters in ardupilot/"
        f"{ARDUPILOT_PARAMS_DIR} (e.g. copter.parm), or save yours from a ground station",
        file=path, hint=f"pass the file's path, e.g. --autopilot-params ardupilot/"
                        f"{ARDUPILOT_PARAMS_DIR}{path.name}")


def load_flight_params(px4_files: Iterable[Path] = (), ardupilot_files: Iterable[Path] = ()
                       ) -> list:
    """PX4 airframes/parameter files first, then ArduPilot .parm files, in the order given."""
    out: list = []
    px4_files, ardupilot_files = list(px4_files), list(ardupilot_files)
    for path in px4_files:
        _check_named_file(Path(path), "--airframe")
    for path in ardupilot_files:
        _check_named_file(Path(path), "--autopilot-params")
    if px4_files:
        from reedtool.flightstack.px4 import load_px4_params

        out += [load_px4_params(path) for path in px4_files]
    if ardupilot_files:
        from reedtool.flightstack.ardupilot import load_parm

        out += [load_parm(path) for path in ardupilot_files]
    return out


def agreement_line(params, rotor_count: int, model: str) -> str:
    """What a clean cross-check compared, in one line (a silent pass looks like no check)."""
    name = Path(params.file).name
    if params.kind == "px4":
        last = rotor_count - 1
        compared = [f"CA_ROTOR0..{last}" if last > 0 else "CA_ROTOR0"]
        if params.uses_gz_outputs:
            compared.append("SIM_GZ_EC_*")
        elif any(name.startswith("PWM_MAIN_FUNC") for name in params.values):
            compared.append("PWM_MAIN_FUNC")
    else:
        compared = ["FRAME_CLASS/FRAME_TYPE", "SERVOn_FUNCTION"]
    rotors = f"{rotor_count} rotor" + ("s" if rotor_count != 1 else "")
    return f"flight stack: {rotors} of {model} agree with {name} ({', '.join(compared)})"
