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
    between: Literal["contact", "not-ruled-out"] | None = None
    """A contact the swept test found between the previous step and this one ("contact"), or one it could not
    rule out at its finest sub-step ("not-ruled-out": the bodies came within ``kernels.sweep.flag_distance``);
    the pose, points and speeds are then those of that moment. Absent: the step's own sample."""
    contact_t: float | None = None
    """The moment of that contact [s] (between t - dt and t); absent with ``between``."""

    @property
    def moment(self) -> float:
        """When the row's contact (or closest approach) happens: ``contact_t`` if it lies between the steps."""
        return self.t if self.contact_t is None else self.contact_t

    @model_serializer(mode="wrap")
    def _without_absent_fields(self, handler):
        # (records stay as they were: no "limbs": null for the paper worker, no "between": null at every step)
        doc = handler(self)
        if isinstance(doc, dict):
            for key in ("limbs", "between", "contact_t"):
                if doc.get(key) is None:
                    doc.pop(key, None)
        return doc
