"""What ``check`` says about how the robot stops and how fast it really moves: the stopping data as read
(``robot.stopping``), category 0's grown capsules, and every speed a device is configured with against the robot's
real top speed on its program (a speed and separation monitor's ``max_speed``; a warning field's reduced speed
where it gives the limit it was laid out for).

**The robot's top speed.** The largest speed of any end of any capsule axis of robot 0 (its links, its tool and
what the cell adds) over one cycle, from the kernel's own forward kinematics (``kernels.robot_live``): poses
``SAMPLE_DT`` apart in path time, each differenced over ``H`` (a central difference of a smooth path; the
minimum-jerk moves are polynomials). A device configured for less than this is configured for a robot slower
than the one it guards: its distances and speed commands are too small, and the check fails.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.devices.laser_scanner import LaserScanner
from cellstress.devices.speed_separation import SpeedSeparation
from cellstress.robot.model import RobotModel
from cellstress.robot.stopping import FASTER, SLOWER, RobotStop, hold_radii
from cellstress.sim import kernels as K
from cellstress.sim import layout as L

SAMPLE_DT = 0.005  # s of path time between poses
H = 1e-4  # s: the half-step of the central difference
_READING = {FASTER: "stops faster than a linear ramp from the signal: braking taken over the whole time (more "
                    "distance than published)",
            SLOWER: "travels more than at full speed for the whole time: full speed for the time, then braking "
                    "(later than published)"}


def stop_lines(stop: RobotStop, robot: RobotModel, capsules) -> list[str]:
    """How the robot's stopping was read: each joint's published point and the profile that follows; for
    category 0, how much the capsules grew."""
    out = []
    for j in stop.joints:
        unit, per = ("rad", "rad/s") if j.angular else ("m", "m/s")
        sp, pl, ex = j.point
        read = _READING.get(j.profile.reading, "distance and time matched")
        out.append(f"  {j.joint}: {j.program_speed_pct:.0f} % of its top speed on the program; published point "
                   f"{sp:g} %, {pl:g} kg, {ex:g} % (row {j.row}): {j.distance:.3g} {unit} in {j.time:.3g} s from "
                   f"{j.speed:.3g} {per}: delay {j.profile.delay:.3g} s, braking {j.profile.braking:.3g} s ({read})")
    if stop.hold:
        grown = [(c.name, g) for c, g in zip(capsules, _growth(stop, robot, capsules), strict=True)]
        name, most = max(grown, key=lambda x: x[1])
        out.append(f"  held where the stop takes effect; each capsule grown for the joints' own braking, by up to "
                   f"{most:.3f} m ({name})")
    return out


def _growth(stop: RobotStop, robot: RobotModel, capsules) -> np.ndarray:
    return hold_radii(robot, np.asarray([c.joint for c in capsules], dtype=np.int64),
                      np.asarray([c.p0 for c in capsules], dtype=float).reshape(-1, 3),
                      np.asarray([c.p1 for c in capsules], dtype=float).reshape(-1, 3), np.asarray(stop.travel))


@dataclass(frozen=True)
class TopSpeed:
    """Robot 0's top speed [m/s] over its cycle, where (its capsule) and when (path time in the cycle [s])."""

    speed: float
    capsule: str
    tau: float


def top_speed(layout) -> TopSpeed:
    """The largest speed of any capsule axis end of robot 0 over one cycle (see the module docstring)."""
    P = layout.params
    W = K.make_work(P)
    cycle = float(layout.trajectory.cycle)
    n0 = len(layout.robots[0].capsules) if layout.robots else P.cap_joint.shape[0]
    phase = float(P.scal[L.C_PHASE0])
    best, where, when = 0.0, 0, 0.0
    for tau in np.arange(0.0, cycle, SAMPLE_DT):
        K.robot_live(P, tau - phase - H, np.inf, W)
        a0, b0 = W.ra[:n0].copy(), W.rb[:n0].copy()
        K.robot_live(P, tau - phase + H, np.inf, W)
        v = np.maximum(np.linalg.norm(W.ra[:n0] - a0, axis=1), np.linalg.norm(W.rb[:n0] - b0, axis=1)) / (2.0 * H)
        k = int(np.argmax(v))
        if v[k] > best:
            best, where, when = float(v[k]), k, float(tau)
    return TopSpeed(best, layout.capsules[where].name, when)


@dataclass(frozen=True)
class SpeedCheck:
    """A speed a device is configured with against the robot's real top speed."""

    device: str
    what: str  # which of its speeds
    configured: float  # m/s
    real: float  # m/s: what the robot really reaches where that speed applies
    top: TopSpeed

    @property
    def ok(self) -> bool:
        return self.configured >= self.real - 1e-6

    def line(self) -> str:
        verdict = "ok" if self.ok else "FAIL: the device is configured for a slower robot than the one it guards"
        return (f"{self.device}: {self.what} {self.configured:.3g} m/s >= the robot's {self.real:.3g} m/s? "
                f"{verdict} (top speed {self.top.speed:.3g} m/s: {self.top.capsule} at {self.top.tau:.2f} s of "
                "its cycle)")


def speed_checks(layout) -> tuple[SpeedCheck, ...]:
    """Every configured speed of the cell's devices against robot 0's top speed (``top_speed``)."""
    devices = layout.cell.spec.devices
    wanted = [d for d in devices if isinstance(d, SpeedSeparation)
              or (isinstance(d, LaserScanner) and d.warning is not None and d.warning.speed_limit is not None)]
    if not wanted:
        return ()
    top = top_speed(layout)
    out = []
    for d in wanted:
        if isinstance(d, SpeedSeparation):
            out.append(SpeedCheck(d.name, "max_speed", float(d.max_speed), top.speed, top))
        else:
            r = float(d.warning.reduced_speed)
            out.append(SpeedCheck(d.warning_name, f"speed_limit (reduced speed {r:g} of the path's)",
                                  float(d.warning.speed_limit), r * top.speed, top))
    return tuple(out)
