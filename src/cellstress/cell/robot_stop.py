"""A robot's stop from its cell entry (``stopping`` or ``stopping_time``), its URDF and its program: the times the
simulator brakes by, and for category 0 how far each joint may travel (``robot.stopping``). Every problem is a
CellError naming the cell file and the field (for the stopping data file also its row and column)."""

from __future__ import annotations

from pathlib import Path

from cellstress.cell.schema import RobotSpec
from cellstress.cell.stopping import stop_spec
from cellstress.core.errors import CellError
from cellstress.core.protocols import Channels
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
    if rs.stopping is not None and "stopping_time" in rs.model_fields_set:
        raise CellError(src, where, "give stopping_time or a stopping block, not both (stopping.time is the braking "
                                    "time)")
    st = stop_spec(rs)
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


def check_hold(cell, where: str) -> None:
    """A category 0 stop removes power: the robot cannot follow a warning field's slower speed, a separation
    monitor's speed commands or an automatic restart back onto its path, which all assume a controlled stop."""
    for i, d in enumerate(cell.spec.devices):
        for c in (d.channels() if isinstance(d, Channels) else ()):
            if c.separation is not None or c.speed != 0.0 or c.clear_time != float("inf"):
                what = ("speed and separation monitoring" if c.separation is not None else
                        "a warning field" if c.speed != 0.0 else "an automatic restart")
                raise CellError(cell.source, f"{where}.stopping.category", f"is 0, but devices[{i}] has {what}, "
                                                                           "which needs a controlled stop (category "
                                                                           "1 or 2)")
