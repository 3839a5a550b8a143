"""Autopilot parameter files named on the command line -> the tables flightstack rules read."""

from __future__ import annotations

from pathlib import Path
from typing import Iterable


def load_flight_params(px4_files: Iterable[Path] = (), ardupilot_files: Iterable[Path] = ()
                       ) -> list:
    """PX4 airframes/parameter files first, then ArduPilot .parm files, in the order given."""
    out: list = []
    px4_files, ardupilot_files = list(px4_files), list(ardupilot_files)
    if px4_files:
        from reedtool.flightstack.px4 import load_px4_params

        out += [load_px4_params(path) for path in px4_files]
    if ardupilot_files:
        from reedtool.flightstack.ardupilot import load_parm

        out += [load_parm(path) for path in ardupilot_files]
    return out
