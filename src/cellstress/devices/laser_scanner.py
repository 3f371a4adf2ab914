"""A horizontal laser scanner's protective field: a polygon at the scan-plane height.

It sees only what crosses its scan plane inside the field (in practice the legs, at the usual 0.3 m), so a
worker outside the field may lean over it. ISO 13855:2010, detection zone parallel to the direction of approach:
S = 1600 mm/s * T + (1200 mm - 0.4 H), with C = 1200 - 0.4 H not below 850 mm.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field

from cellstress.core.fields import Polygon, PositiveTime
from cellstress.core.iso13855 import K_WALK, MIN_C_BODY, mm
from cellstress.core.records import IsoDistance, ScanPlane
from cellstress.devices.base import DeviceRecord


class LaserScanner(DeviceRecord):
    """``polygon``: the protective field [m]; ``height``: the scan plane above the floor [m];
    ``response_time`` [s] from detection to the stop signal."""

    type: Literal["laser-scanner"]
    """A horizontal laser scanner's protective field."""
    polygon: Polygon
    """The protective field's outline on the floor [m]."""
    height: Annotated[float, Field(ge=0.0, le=1.0)] = 0.3
    """Height of the scan plane above the floor [m]; it sees what crosses the plane inside the field."""
    response_time: PositiveTime = 0.35
    """Time [s] from detection to the stop signal."""

    detection_phrase: ClassVar[str] = "walks into the field of the laser scanner"
    color: ClassVar[str] = "#f2c300"

    def primitives(self) -> tuple[ScanPlane, ...]:
        return (ScanPlane(tuple(self.polygon), self.height),)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        T = self.response_time + stopping_time
        height_mm = self.height * 1000.0
        c = max(MIN_C_BODY, 1200.0 - 0.4 * height_mm)
        s = K_WALK * T + c
        formula = f"S = 1600*{T:.2f} + (1200 - 0.4*{mm(height_mm)}) = {mm(s)} mm"
        if c > 1200.0 - 0.4 * height_mm:
            formula = f"S = 1600*{T:.2f} + 850 (C = 1200 - 0.4 H is below 850) = {mm(s)} mm"
        return IsoDistance(K_WALK, T, c, s, formula)

    def describe(self) -> str:
        return f"{len(self.polygon)}-point field at {self.height:g} m"

    def draw(self, ax):
        from matplotlib.patches import Patch, Polygon

        ax.add_patch(Polygon(self.polygon, closed=True, facecolor=self.color, alpha=0.22, edgecolor="none",
                             zorder=2.5))
        ax.add_patch(Polygon(self.polygon, closed=True, fill=False, edgecolor=self.color, lw=1.5, ls="--",
                             zorder=2.6))
        return Patch(facecolor=self.color, alpha=0.4, edgecolor=self.color, ls="--",
                     label=f"scanner field '{self.name}' ({self.height:g} m, {self.response_time:g} s)")
