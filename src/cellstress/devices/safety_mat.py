"""A pressure-sensitive safety mat (ISO 13856-1): presence on its area stops the robot.

The worker's legs stand on the floor, so a horizontal detection plane a little above it (``SENSING_HEIGHT``,
5 cm) over the mat's polygon sees exactly the feet that stand on the mat; the body above does not press it (a
worker leaning over the mat from its edge is not detected, as with a real mat). ISO 13855:2010 for
pressure-sensitive mats: S = 1600 mm/s * T + 1200 mm, T = the mat's response time + the robot's stopping time.
"""

from __future__ import annotations

from typing import ClassVar, Literal

from cellstress.core.fields import Polygon, PositiveTime
from cellstress.core.iso13855 import C_MAT, K_WALK, mm
from cellstress.core.records import IsoDistance, ScanPlane
from cellstress.devices.base import DeviceRecord

SENSING_HEIGHT = 0.05  # m: the legs' capsules cross it where a foot stands; nothing else reaches so low


class SafetyMat(DeviceRecord):
    """``polygon``: the mat's area on the floor [m]; ``response_time`` [s] from a step on it to the stop signal."""

    type: Literal["safety-mat"]
    """A pressure-sensitive safety mat on the floor."""
    polygon: Polygon
    """The mat's area on the floor [m] (one mat or a joined row of mats)."""
    response_time: PositiveTime = 0.1
    """Time [s] from a step on the mat to the stop signal."""

    detection_phrase: ClassVar[str] = "steps on the safety mat"
    color: ClassVar[str] = "#2a9d8f"

    def primitives(self) -> tuple[ScanPlane, ...]:
        return (ScanPlane(tuple(self.polygon), SENSING_HEIGHT),)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        T = self.response_time + stopping_time
        s = K_WALK * T + C_MAT
        return IsoDistance(K_WALK, T, C_MAT, s, f"S = 1600*{T:.2f} + 1200 (pressure-sensitive mat) = {mm(s)} mm")

    def describe(self) -> str:
        text = f"{len(self.polygon)}-point mat"
        return text + ("" if self.restart == "manual" else f", automatic restart after {self.clear_time:g} s")

    def draw(self, ax):
        from matplotlib.patches import Patch, Polygon

        ax.add_patch(Polygon(self.polygon, closed=True, facecolor=self.color, alpha=0.25, edgecolor=self.color,
                             lw=1.2, hatch="..", zorder=2.4))
        return Patch(facecolor=self.color, alpha=0.4, edgecolor=self.color, hatch="..",
                     label=f"safety mat '{self.name}' ({self.response_time:g} s)")
