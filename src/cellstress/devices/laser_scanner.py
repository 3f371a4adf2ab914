"""A horizontal laser scanner's protective field: a polygon at the scan-plane height.

It sees only what crosses its scan plane inside the field (in practice the legs, at the usual 0.3 m), so a
worker outside the field may lean over it. ISO 13855:2010, detection zone parallel to the direction of approach:
S = 1600 mm/s * T + (1200 mm - 0.4 H), with C = 1200 - 0.4 H not below 850 mm.

An optional ``warning`` field (a second polygon at the same height, as real scanners switch field sets) cuts the
robot to ``reduced_speed`` of its path speed instead of stopping it, ramped over the braking time. The
protective field behind it may then count with the reduced speed's stopping time (braking from a fraction r
of full speed at the same deceleration takes r times the stopping time): T = response + r * stopping time. That
holds only if the reduction has taken full effect before the worker reaches the protective field, so the
warning field needs a lead of K * (response + (1 - r) * stopping time) in front of that distance.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from cellstress.core.fields import Polygon, PositiveTime, Record
from cellstress.core.iso13855 import K_WALK, horizontal_c_mm, mm
from cellstress.core.plane import polygon_outside_point
from cellstress.core.records import Channel, IsoDistance, ScanPlane
from cellstress.devices.base import DeviceRecord, Restart


class WarningField(Record):
    """A laser scanner's warning field: seeing the worker there cuts the robot's speed instead of stopping it."""

    polygon: Polygon
    """The warning field's outline on the floor [m] (usually around the protective field)."""
    reduced_speed: Annotated[float, Field(gt=0.0, lt=1.0)] = 0.25
    """The fraction of its path speed the robot slows to, ramped over the stopping time."""
    restart: Restart = "manual"
    """How the reduction is released: ``manual`` (for the rest of the episode) or ``{automatic: CLEAR_TIME}``
    (full speed again once the warning field has not seen the worker for CLEAR_TIME seconds)."""
    speed_limit: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)] | None = None
    """The robot speed [m/s] the reduced speed was laid out for (e.g. the speed the risk assessment allows near
    the protective field); ``check`` fails where ``reduced_speed`` times the robot's real top speed on its
    program exceeds it. Absent: not checked."""


def _c(height_mm: float) -> float:
    return horizontal_c_mm(height_mm)


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
    resolution_mm: Annotated[float, Field(ge=10.0, le=200.0, allow_inf_nan=False)] = 70.0
    """Detection capability d [mm] of the field (ISO 13855: the scan plane must lie at least 15 (d - 50) mm above
    the floor, which ``check`` tests). Absent: 70 mm, the usual setting for detecting a person's legs, whose
    lowest plane is 300 mm."""
    warning: WarningField | None = None
    """An optional warning field (same height and response time) that reduces the robot's speed."""

    detection_phrase: ClassVar[str] = "walks into the field of the laser scanner"
    color: ClassVar[str] = "#f2c300"

    @model_validator(mode="after")
    def _warning_around_protective(self) -> LaserScanner:
        # the protective field's distance counts on the reduced speed having taken effect when the worker reaches
        # it (module docstring): only true if the worker crosses the warning field first, everywhere
        if self.warning is not None:
            p = polygon_outside_point(self.polygon, self.warning.polygon)
            if p is not None:
                raise ValueError(f"warning.polygon must contain the protective field (polygon): the protective "
                                 f"field's point ({p[0]:.3f}, {p[1]:.3f}) lies outside the warning field")
        return self

    def primitives(self) -> tuple[ScanPlane, ...]:
        return (ScanPlane(tuple(self.polygon), self.height),)

    @property
    def warning_name(self) -> str:
        return f"{self.name}:warning"

    def channels(self) -> tuple[Channel, ...]:
        chans = super().channels()
        w = self.warning
        if w is None:
            return chans
        clear = float("inf") if w.restart == "manual" else float(w.restart.automatic)
        return chans + (Channel(ScanPlane(tuple(w.polygon), self.height), self.warning_name, float(w.reduced_speed),
                                self.response_time, clear),)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        return self.stop_distance(0.0, stopping_time)

    def stop_distance(self, delay: float, braking: float) -> IsoDistance:
        """S = 1600 T + C; behind a warning field the robot brakes from the reduced speed r, in r * braking (its
        controller's delay stays whole)."""
        stopping_time = braking
        height_mm = self.height * 1000.0
        c = _c(height_mm)
        c_text = (f"(1200 - 0.4*{mm(height_mm)})" if c == 1200.0 - 0.4 * height_mm else
                  "850 (C = 1200 - 0.4 H is below 850)")
        if self.warning is not None:  # behind a warning field: the robot brakes from the reduced speed
            r = self.warning.reduced_speed
            T = self.response_time + delay + r * stopping_time
            s = K_WALK * T + c
            wait = f" + {delay:g}" if delay > 0.0 else ""
            return IsoDistance(K_WALK, T, c, s, f"at the reduced speed {r:g}: S = 1600*({self.response_time:g}"
                                                f"{wait} + {r:g}*{stopping_time:g}) + {c_text} = {mm(s)} mm")
        T = self.response_time + delay + stopping_time
        s = K_WALK * T + c
        return IsoDistance(K_WALK, T, c, s, f"S = 1600*{T:.2f} + {c_text} = {mm(s)} mm")

    def warning_distance(self, stopping_time: float) -> IsoDistance | None:
        return self.warning_stop_distance(0.0, stopping_time)

    def warning_stop_distance(self, delay: float, braking: float) -> IsoDistance | None:
        """The warning field's distance: the protective field's S at the reduced speed plus the lead the
        reduction needs to take full effect, K * (response + delay + (1 - r) * braking)."""
        if self.warning is None:
            return None
        r = self.warning.reduced_speed
        prot = self.stop_distance(delay, braking)
        lead_t = self.response_time + delay + (1.0 - r) * braking
        s = prot.S + K_WALK * lead_t
        wait = f" + {delay:g}" if delay > 0.0 else ""
        return IsoDistance(K_WALK, prot.T + lead_t, prot.C, s,
                           f"S = {mm(prot.S)} (protective, reduced speed) + 1600*({self.response_time:g}{wait} + "
                           f"(1 - {r:g})*{braking:g}) = {mm(s)} mm")

    def describe(self) -> str:
        text = f"{len(self.polygon)}-point field at {self.height:g} m, {self.resolution_mm:g} mm"
        if self.warning is not None:
            text += f", warning field ({len(self.warning.polygon)} points) to {self.warning.reduced_speed:g} speed"
        return text + ("" if self.restart == "manual" else f", automatic restart after {self.clear_time:g} s")

    def draw(self, ax):
        from matplotlib.patches import Patch, Polygon

        if self.warning is not None:  # drawn under the protective field, dotted, lighter
            ax.add_patch(Polygon(self.warning.polygon, closed=True, fill=False, edgecolor=self.color, lw=1.2,
                                 ls=":", zorder=2.55))
        ax.add_patch(Polygon(self.polygon, closed=True, facecolor=self.color, alpha=0.22, edgecolor="none",
                             zorder=2.5))
        ax.add_patch(Polygon(self.polygon, closed=True, fill=False, edgecolor=self.color, lw=1.5, ls="--",
                             zorder=2.6))
        return Patch(facecolor=self.color, alpha=0.4, edgecolor=self.color, ls="--",
                     label=f"scanner field '{self.name}' ({self.height:g} m, {self.response_time:g} s)"
                     + ("" if self.warning is None else f", warning field dotted ({self.warning.reduced_speed:g})")
                     + ("" if self.restart == "manual" else f", restarts by itself after {self.clear_time:g} s"))
