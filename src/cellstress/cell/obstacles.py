"""Obstacles in a cell file: a footprint (a polygon or a box) raised from the floor to a height."""

from __future__ import annotations

import math

from pydantic import model_validator

from cellstress.core.fields import Angle, Height, Length, Name, Point2, Polygon, Record


class BoxFootprint(Record):
    """A rectangle on the floor."""

    center: Point2
    """Centre [m]."""
    size: tuple[Length, Length]
    """Length along its own x axis and width [m]."""
    yaw_deg: Angle = 0.0
    """Rotation about the vertical axis [deg], counter-clockwise seen from above."""

    def corners(self) -> tuple[Point2, ...]:
        c, s = math.cos(math.radians(self.yaw_deg)), math.sin(math.radians(self.yaw_deg))
        hx, hy = self.size[0] / 2.0, self.size[1] / 2.0
        return tuple((self.center[0] + c * u - s * v, self.center[1] + s * u + c * v)
                     for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)))


class ObstacleSpec(Record):
    """A static solid standing on the floor (a conveyor, a pallet, a machine, a pedestal): a footprint raised to
    a height. The worker cannot walk into it and cannot lean the trunk or head into it."""

    name: Name
    """Its name in outputs and pictures."""
    polygon: Polygon | None = None
    """Its footprint [m], a simple polygon; give this or ``box``."""
    box: BoxFootprint | None = None
    """Its footprint as a rectangle; give this or ``polygon``."""
    height: Height
    """Height of its top above the floor [m]."""

    @model_validator(mode="after")
    def _one_footprint(self) -> ObstacleSpec:
        if (self.polygon is None) == (self.box is None):
            raise ValueError("give exactly one of polygon and box")
        return self

    def footprint(self) -> tuple[Point2, ...]:
        """The footprint's corners [m]."""
        return self.polygon if self.polygon is not None else self.box.corners()
