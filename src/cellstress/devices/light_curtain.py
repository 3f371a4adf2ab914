"""A vertical light curtain across an opening: a rectangle over a floor segment.

It sees any body capsule that touches its rectangle. Our worker model's devices never see an outstretched arm
(docs/architecture.md), so every curtain acts as a body detector: the distance required is ISO 13855's
S = 1600 mm/s * T + 850 mm, or the nominal value for its resolution d if that is larger (d <= 40 mm:
S = 2000 T + 8 (d - 14), and above 500 mm S = 1600 T + 8 (d - 14), at least 500 mm).
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from cellstress.core.fields import Elevation, Height, Point2, PositiveTime, Record
from cellstress.core.iso13855 import K_HAND, K_WALK, MIN_C_BODY, mm
from cellstress.core.records import Channel, IsoDistance, TimedPanel, VerticalField
from cellstress.devices.base import DeviceRecord

ClockTime = Annotated[float, Field(ge=0.0, le=3600.0, allow_inf_nan=False)]


class Muting(Record):
    """Muting at a conveyor opening: a pallet fills the opening while the cell's clock, (phase + t) modulo the
    robot's cycle, lies in ``pallet``; the curtain is muted from the pallet's arrival until ``until``."""

    pallet: tuple[ClockTime, ClockTime]
    """When the pallet fills the opening [s of the cell's clock]: it arrives, it has passed."""
    until: ClockTime
    """When the muting ends [s of the cell's clock]: at the earliest when the pallet has passed (IEC 62046:
    muting ends as soon as the material has cleared the opening)."""
    pallet_height: Height = 1.2
    """Height of the pallet with its load [m]: it blocks the opening from the floor up to there."""

    @model_validator(mode="after")
    def _order(self) -> Muting:
        t_in, t_out = self.pallet
        if not t_in < t_out:
            raise ValueError(f"the pallet must arrive before it has passed (pallet: [{t_in}, {t_out}])")
        if self.until < t_out:
            raise ValueError(f"until ({self.until}) ends the muting before the pallet has passed ({t_out})")
        return self


def nominal_distance(T: float, resolution_mm: float) -> IsoDistance:
    """ISO 13855:2010, detection zone orthogonal to the approach (vertical field), detection capability d."""
    d = resolution_mm
    if d <= 40.0:
        c = 8.0 * (d - 14.0)
        s = K_HAND * T + c
        text = f"S = 2000*{T:.2f} + 8*({mm(d)} - 14) = {mm(s)} mm"
        if s < 100.0:
            return IsoDistance(K_HAND, T, c, 100.0, text + " < 100, so 100 mm")
        if s <= 500.0:
            return IsoDistance(K_HAND, T, c, s, text)
        s2 = K_WALK * T + c
        text += f" > 500, so 1600*{T:.2f} + {mm(c)} = {mm(s2)} mm"
        if s2 < 500.0:
            return IsoDistance(K_WALK, T, c, 500.0, text + " -> minimum 500 mm")
        return IsoDistance(K_WALK, T, c, s2, text)
    s = K_WALK * T + MIN_C_BODY
    return IsoDistance(K_WALK, T, MIN_C_BODY, s, f"S = 1600*{T:.2f} + 850 = {mm(s)} mm (d > 40 mm)")


class LightCurtain(DeviceRecord):
    """``start``-``end``: the curtain's line on the floor [m]; beams from ``bottom`` to ``top`` [m];
    ``resolution_mm``: detection capability d; ``response_time`` [s]."""

    type: Literal["light-curtain"]
    """A vertical light curtain across an opening."""
    start: Point2
    """One end of the curtain's line on the floor [m]."""
    end: Point2
    """The other end [m]."""
    bottom: Elevation = 0.2
    """Height of the lowest beam [m]."""
    top: Height = 1.8
    """Height of the highest beam [m]."""
    response_time: PositiveTime = 0.05
    """Time [s] from detection to the stop signal."""
    resolution_mm: Annotated[float, Field(gt=0.0, le=200.0)] = 30.0
    """Detection capability d [mm] (ISO 13855: the reach-through allowance C grows with it)."""
    muting: Muting | None = None
    """Muting for a conveyor opening: the pallet's passage and when the muting ends (absent: never muted)."""

    detection_phrase: ClassVar[str] = "breaks the light curtain"
    color: ClassVar[str] = "#7b2cbf"

    @model_validator(mode="after")
    def _shape(self) -> LightCurtain:
        if self.start == self.end:
            raise ValueError("start and end are the same point")
        if self.top <= self.bottom:
            raise ValueError(f"top ({self.top}) must be above bottom ({self.bottom})")
        return self

    def primitives(self) -> tuple[VerticalField, ...]:
        return (VerticalField(tuple(self.start), tuple(self.end), self.bottom, self.top),)

    def channels(self) -> tuple[Channel, ...]:
        muted = None if self.muting is None else (float(self.muting.pallet[0]), float(self.muting.until))
        return tuple(Channel(p, self.name, 0.0, self.response_time, self.clear_time, muted)
                     for p in self.primitives())

    def timed_panels(self) -> tuple[TimedPanel, ...]:
        """The pallet across the opening while it passes (none without muting)."""
        if self.muting is None:
            return ()
        m = self.muting
        return (TimedPanel(tuple(self.start), tuple(self.end), 0.0, float(m.pallet_height), float(m.pallet[0]),
                           float(m.pallet[1])),)

    def nominal_distance(self, stopping_time: float) -> IsoDistance:
        return nominal_distance(self.response_time + stopping_time, self.resolution_mm)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        T = self.response_time + stopping_time
        nominal = nominal_distance(T, self.resolution_mm)
        s = K_WALK * T + MIN_C_BODY
        if nominal.S > s:
            return nominal
        return IsoDistance(K_WALK, T, MIN_C_BODY, s, f"ISO for d = {nominal.formula}; body-only sensing: "
                                                     f"S = 1600*{T:.2f} + 850 = {mm(s)} mm")

    def describe(self) -> str:
        (x0, y0), (x1, y1) = self.start, self.end
        restart = "" if self.restart == "manual" else f", automatic restart after {self.clear_time:g} s"
        muting = "" if self.muting is None else \
            f", muted {self.muting.pallet[0]:g}..{self.muting.until:g} s (pallet until {self.muting.pallet[1]:g} s)"
        return (f"({x0:g}, {y0:g})-({x1:g}, {y1:g}), {self.bottom:g}..{self.top:g} m, "
                f"{self.resolution_mm:g} mm{restart}{muting}")

    def draw(self, ax):
        from matplotlib.lines import Line2D

        (x0, y0), (x1, y1) = self.start, self.end
        # a muted curtain dotted (it lets the pallet, and whoever follows it, through)
        style = "-" if self.muting is None else (0, (1, 1))
        ax.plot([x0, x1], [y0, y1], color=self.color, lw=5, ls=style, solid_capstyle="butt", zorder=4.5)
        restart = "" if self.restart == "manual" else f", restarts by itself after {self.clear_time:g} s"
        if self.muting is not None:
            restart += f", muted {self.muting.pallet[0]:g}-{self.muting.until:g} s of the cycle"
        return Line2D([], [], color=self.color, lw=5, ls=style, label=f"light curtain '{self.name}' "
                      f"({self.bottom:g}-{self.top:g} m, {self.response_time:g} s{restart})")
