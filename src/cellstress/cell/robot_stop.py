"""A robot's stop from its cell entry (``stopping`` or ``stopping_time``), its URDF and its program: the times the
simulator brakes by, and for category 0 how far each joint may travel (``robot.stopping``). Every problem is a
CellError naming the cell file and the field (for the stopping data file also its row and column)."""

from __future__ import annotations

from pathlib import Path

from cellstress.cell.schema import RobotSpec
from cellstress.core.errors import CellError
from cellstress.robot.model import RobotModel
from cellstress.robot.stopping import (
    RobotStop,
    StoppingDataError,
    data_stop,
    given_stop,
    joint_stops,
    peak_joint_speeds,
)
from cellstress.robot.stopping_file import StoppingFileError, read_stopping_file
from cellstress.robot.trajectory import Trajectory


def stopping_data_path(ref: str, directory: Path | None) -> Path:
    """The stopping data file a cell names, relative to the cell file's folder."""
    path = Path(ref).expanduser()
    return directory / path if not path.is_absolute() and directory is not None else path


def robot_stop(src: str, where: str, rs: RobotSpec, robot: RobotModel, traj: Trajectory,
               directory: Path | None) -> RobotStop:
    """How robot ``rs`` stops; errors name ``where`` (robot or robots[i]) as the field's start."""
    st = rs.stop
    peaks = peak_joint_speeds(traj)
    if st.data is None:
        return given_stop(st.category, float(st.controller_delay), float(st.time), robot, peaks)
    field = f"{where}.stopping.data"
    path = stopping_data_path(st.data, directory)
    try:
        rows = read_stopping_file(path)
        joints = joint_stops(rows, st.category, robot, peaks, float(st.payload_kg), float(st.extension_pct))
    except (StoppingFileError, StoppingDataError) as exc:
        raise CellError(src, field, f"{path}: {exc}") from None
    return data_stop(st.category, float(st.controller_delay), joints, robot, peaks, st.data)
