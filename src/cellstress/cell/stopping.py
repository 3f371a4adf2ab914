"""A robot's ``stopping`` block in the cell file: its stop category, its controller's delay and either its braking
time or its maker's stopping data (docs/robot.md, Stopping). The file is read and interpreted when the cell is
loaded (``cell.robot_stop``); this record only checks what the block itself can."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from cellstress.core.fields import MAX_TIME, PositiveTime, Record

Delay = Annotated[float, Field(ge=0.0, le=MAX_TIME, allow_inf_nan=False)]


class StoppingSpec(Record):
    """How the robot stops after a protective device's stop signal reaches it (docs/robot.md, Stopping)."""

    category: Literal[0, 1, 2] = 1
    """Stop category (IEC 60204-1:2016, 9.2.2): 0 removes power at once and each joint's brake stops it on its own
    (the arm may leave its path); 1 brakes along the path, then removes power; 2 brakes along the path and keeps
    power. The robot's manual says which its protective stop is."""
    controller_delay: Delay = 0.0
    """Time [s] from the stop signal reaching the robot's safety inputs until it begins to brake, not counted in
    the maker's data (e.g. a safety PLC or a network in between); the robot keeps its path speed meanwhile."""
    time: PositiveTime | None = None
    """Braking time [s]: from full speed, once braking begins (``controller_delay`` after the signal), to
    standstill. Give this or ``data``."""
    data: Annotated[str, Field(min_length=1, max_length=1000, pattern=r"^[^\x00]+$")] | None = None
    """The maker's stopping data (ISO 10218-1:2011, Annex B): a CSV file, relative to the cell file, with a row
    per published point: ``joint,category,speed_pct,payload_kg,extension_pct,distance,unit,time_s``
    (docs/robot.md, Stopping, shows one). Read conservatively: each joint at the next published point at or above
    the program's top speed of that joint, ``payload_kg`` and ``extension_pct``. At most 10,000 rows and 1 MB."""
    payload_kg: Annotated[float, Field(ge=0.0, le=10_000.0, allow_inf_nan=False)] | None = None
    """The payload the robot carries [kg] (its gripper and the heaviest part); required with ``data``."""
    extension_pct: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)] = 100.0
    """How far the arm reaches out on its program, in percent of its maximum extension (the maker's 33, 66, 100 %)
    [%]; with ``data``. 100 unless the program is known to stay closer in."""

    @model_validator(mode="after")
    def _time_or_data(self) -> StoppingSpec:
        if (self.time is None) == (self.data is None):
            raise ValueError("give exactly one of time (the braking time) and data (the maker's stopping data "
                             "file)" + (", not both" if self.time is not None else ""))
        if self.data is not None and self.payload_kg is None:
            raise ValueError("data needs payload_kg: the payload the robot carries [kg], to read the data at")
        if self.data is None and (self.payload_kg is not None or "extension_pct" in self.model_fields_set):
            raise ValueError("payload_kg and extension_pct are for reading stopping data; this block gives a time")
        return self


def stop_spec(rs) -> StoppingSpec:
    """A robot's (``cell.schema.RobotSpec``) ``stopping`` block; for one that gives ``stopping_time`` only, the block
    that says the same (category 1, no delay, that braking time)."""
    if rs.stopping is not None:
        return rs.stopping
    return StoppingSpec.model_construct(category=1, controller_delay=0.0, time=rs.stopping_time, data=None,
                                        payload_kg=None, extension_pct=100.0)
