"""Speed and separation monitoring (ISO/TS 15066:2016, 5.5.4): a sensing area that measures where the worker is
and a controller that scales the robot's speed so that the separation never falls below the protective
separation distance

    S_p(v_r) = v_h (T_r + T_s) + v_r T_r + S_s(v_r) + C + Z_d + Z_r,    S_s(v_r) = v_r T_s / 2,

v_h the worker's speed, v_r the robot's speed towards the worker (taken as its maximum speed scaled by the
commanded fraction s), T_r the reaction time (sensor latency + controller), T_s the robot's stopping time,
S_s the robot's stopping distance (a linear ramp from v_r over the full stopping time: an upper bound, since
braking from a lower speed at the same deceleration is shorter), C the intrusion distance, Z_d and Z_r the
position uncertainties of the sensor and the robot. The controller commands the largest s in [0, 1] with
S_p(s v_max) <= S (s = 0: a protective stop). It computes with the times the integrator CONFIGURED
(``reaction_time``, ``stopping_time``); the robot answers with its real ones (this record's ``response_time``,
the robot's own stopping time). A configured time shorter than the real one underestimates S_p: the flaw.

The sensing area is a scan plane (like a laser scanner's field): the worker is measured while a body part
crosses it. The separation S is the horizontal distance from the detected body to the robot; the static check
takes the least distance from the area's open edges to the hazard zone (what the area guarantees).
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from cellstress.core.fields import Polygon, PositiveTime
from cellstress.core.iso13855 import MIN_C_BODY, mm
from cellstress.core.records import Channel, IsoDistance, ScanPlane, SeparationRule
from cellstress.devices.base import DeviceRecord

Speed = Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)]
Allowance = Annotated[float, Field(ge=0.0, le=5.0, allow_inf_nan=False)]


def intrusion_for_height(height: float) -> float:
    """ISO 13855:2010's intrusion allowance for a horizontal detection zone at ``height`` [m]: C = 1200 - 0.4 H
    [mm], not below 850 mm; returned in m."""
    return max(MIN_C_BODY, 1200.0 - 0.4 * height * 1000.0) / 1000.0


def protective_separation(v_h: float, v_r: float, t_r: float, t_s: float, rest: float) -> float:
    """S_p [m] for the robot speed ``v_r`` [m/s] (``rest`` = C + Z_d + Z_r [m])."""
    return v_h * (t_r + t_s) + v_r * t_r + v_r * t_s / 2.0 + rest


def speed_fraction(separation: float, v_h: float, v_max: float, t_r: float, t_s: float, rest: float) -> float:
    """The largest s in [0, 1] with S_p(s v_max) <= ``separation`` (S_p is linear in s)."""
    free = separation - v_h * (t_r + t_s) - rest
    per_unit = v_max * (t_r + t_s / 2.0)
    return min(1.0, max(0.0, free / per_unit))


class SpeedSeparation(DeviceRecord):
    """``polygon``: the sensing area [m] at ``height``; ``response_time`` [s]: the REAL time from a measurement
    to the robot's new speed command; ``reaction_time`` and ``stopping_time``: what the controller was
    configured with."""

    type: Literal["speed-separation"]
    """Speed and separation monitoring (ISO/TS 15066:2016, 5.5.4)."""
    polygon: Polygon
    """The sensing area's outline on the floor [m]: the worker's position is measured inside it."""
    height: Annotated[float, Field(ge=0.0, le=1.0)] = 0.3
    """Height of the sensing plane above the floor [m]; it sees what crosses the plane inside the area."""
    response_time: PositiveTime = 0.1
    """The real reaction time T_r [s] (sensor latency + controller): after it a new speed command takes effect."""
    reaction_time: PositiveTime
    """The reaction time T_r [s] the controller computes S_p with (configured by the integrator)."""
    stopping_time: PositiveTime
    """The robot's stopping time T_s [s] the controller computes S_p with (configured by the integrator; the
    robot brakes with its own ``robot.stopping_time``)."""
    max_speed: Speed
    """The robot's maximum speed towards the worker v_max [m/s]; the command scales it by s in [0, 1]."""
    human_speed: Speed = 1.6
    """The worker's approach speed v_h [m/s] (ISO 13855:2010: 1600 mm/s)."""
    intrusion: Allowance | None = None
    """Intrusion distance C [m]; absent: ISO 13855's allowance for the sensing height, 1.2 - 0.4 H (>= 0.85)."""
    z_d: Allowance = 0.0
    """Position uncertainty of the sensing system Z_d [m] (its measurement tolerance)."""
    z_r: Allowance = 0.0
    """Position uncertainty of the robot Z_r [m] (from its position measurement)."""

    detection_phrase: ClassVar[str] = "walks into the speed and separation monitoring area"
    color: ClassVar[str] = "#8e44ad"

    @model_validator(mode="after")
    def _restart_is_the_speed_command(self):
        if self.restart != "manual":  # the speed follows the separation both ways: nothing to restart
            raise ValueError("a speed-separation device sets the speed from the separation, up and down; it takes "
                             "no restart field")
        return self

    @property
    def c(self) -> float:
        """The intrusion distance C [m] in use."""
        return intrusion_for_height(self.height) if self.intrusion is None else float(self.intrusion)

    @property
    def allowance(self) -> float:
        """C + Z_d + Z_r [m]: the part of S_p that does not grow with time."""
        return self.c + self.z_d + self.z_r

    def primitives(self) -> tuple[ScanPlane, ...]:
        return (ScanPlane(tuple(self.polygon), self.height),)

    def channels(self) -> tuple[Channel, ...]:
        """One channel: the sensing area, whose measurement sets the speed (never a latched stop)."""
        rule = SeparationRule(float(self.human_speed), float(self.max_speed), float(self.reaction_time),
                              float(self.stopping_time), float(self.allowance))
        return (Channel(self.primitives()[0], self.name, 1.0, self.response_time, float("inf"), separation=rule),)

    def configured_separation(self) -> float:
        """S_p at full speed [m] with the configured times: what the controller believes it needs."""
        return protective_separation(self.human_speed, self.max_speed, self.reaction_time, self.stopping_time,
                                     self.allowance)

    def fraction(self, separation: float) -> float:
        """The speed fraction the controller commands at the measured ``separation`` [m]."""
        return speed_fraction(separation, self.human_speed, self.max_speed, self.reaction_time,
                              self.stopping_time, self.allowance)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        return self.stop_distance(0.0, stopping_time)

    def stop_distance(self, delay: float, braking: float) -> IsoDistance:
        """S_p at full speed with the REAL times (T_r: this record's response time and the robot's controller
        delay; T_s: the robot's braking time), as an assessor computes it: K = v_h, T = T_r + T_s,
        C = v_max (T_r + T_s / 2) + C + Z_d + Z_r [mm]."""
        t_r, v_h, v, stopping_time = self.response_time + delay, self.human_speed, self.max_speed, braking
        s = protective_separation(v_h, v, t_r, stopping_time, self.allowance)
        rest = s - v_h * (t_r + stopping_time)
        text = (f"S_p = {v_h:g}*({t_r:g} + {stopping_time:g}) + {v:g}*{t_r:g} + {v:g}*{stopping_time:g}/2 + "
                f"{mm(self.c * 1000.0)} + {mm(self.z_d * 1000.0)} + {mm(self.z_r * 1000.0)} = {mm(s * 1000.0)} mm")
        return IsoDistance(v_h * 1000.0, t_r + stopping_time, rest * 1000.0, s * 1000.0, text)

    def static_check(self, distance: float, stopping_time: float) -> tuple[float, str]:
        return self.stop_check(distance, 0.0, stopping_time)

    def stop_check(self, distance: float, delay: float, braking: float) -> tuple[float, str]:
        """This kind's part of the static check (analysis.iso13855 asks any device that has it): full speed is
        allowed down to the controller's own S_p, so the separation guaranteed is the lesser of the area's
        ``distance`` and that (docs/cells.md); the note names the configured times."""
        return min(distance, self.configured_separation()), self.configured_note(braking, delay)

    def configured_note(self, stopping_time: float, delay: float = 0.0) -> str:
        """The controller's own S_p at full speed, and which configured time is shorter than the real one (T_r:
        the response time and the robot's controller delay; T_s: its braking time)."""
        short = [f"{what} {cfg:g} s < real {real:g} s" for what, cfg, real in
                 (("T_r", self.reaction_time, self.response_time + delay),
                  ("T_s", self.stopping_time, stopping_time))
                 if cfg < real - 1e-12]
        head = (f"configured: T_r {self.reaction_time:g} s, T_s {self.stopping_time:g} s: full speed down to "
                f"S_p = {mm(self.configured_separation() * 1000.0)} mm (the actual separation is the lesser of it "
                "and the area's)")
        return head + (f" (underestimated: {', '.join(short)})" if short else "")

    def describe(self) -> str:
        return (f"{len(self.polygon)}-point area at {self.height:g} m, v_max {self.max_speed:g} m/s, configured "
                f"T_r {self.reaction_time:g} s, T_s {self.stopping_time:g} s")

    def draw(self, ax):
        from matplotlib.patches import Patch, Polygon

        ax.add_patch(Polygon(self.polygon, closed=True, facecolor=self.color, alpha=0.12, edgecolor=self.color,
                             lw=1.2, ls="-.", hatch="//", zorder=2.45))
        return Patch(facecolor=self.color, alpha=0.3, edgecolor=self.color, hatch="//", ls="-.",
                     label=f"speed & separation '{self.name}' (T_r set {self.reaction_time:g} s, real "
                           f"{self.response_time:g} s)")
