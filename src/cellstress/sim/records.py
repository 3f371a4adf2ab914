"""The cell simulator's per-step record: one metric row with names and units, as ``result.json`` stores it.

A frozen pydantic record, so the same type is made from a row (``Trace.records``, no validation: the row is
ours) and checked when a result file someone else sent is read (strict types, bounded sizes).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_serializer

from cellstress.core.fields import Record

STOP_PHASES = ("running", "stop-pending", "braking", "stopped", "reduced-speed")
Name = Annotated[str, Field(max_length=200)]
Coordinate = tuple[float, float, float]


class StepRecord(Record):
    """One 50 ms time step: the worker's pose, d_HR [m], v_R [m/s], the devices that see the worker, the robot's
    stop phase, and the closest robot link, body part and points; row 0 is the start (no action yet)."""

    step: Annotated[int, Field(ge=0, le=1_000_000)]
    t: float
    action: Name | None
    x: float
    y: float
    heading_deg: float
    forward_flexion_deg: float
    lateral_flexion_deg: float
    d_HR: float | None  # None only where a file held a non-finite number
    v_R: float | None
    devices: Annotated[tuple[Name, ...], Field(max_length=64)]
    stop_phase: Literal["running", "stop-pending", "braking", "stopped", "reduced-speed"]
    robot_link: Name | None
    body_part: Name | None
    robot_point: Coordinate
    human_point: Coordinate
    unsafe: bool
    limbs: Annotated[tuple[float, ...], Field(min_length=11, max_length=11)] | None = None
    """The articulated worker's hip drop [m] and arm joints [deg] (left arm's five, then the right's, in
    human.reach's order); absent for the paper's worker."""

    @model_serializer(mode="wrap")
    def _without_absent_limbs(self, handler):
        # (the paper worker's records stay as they were: no "limbs": null in every step of a result file)
        doc = handler(self)
        if isinstance(doc, dict) and doc.get("limbs") is None:
            doc.pop("limbs", None)
        return doc
