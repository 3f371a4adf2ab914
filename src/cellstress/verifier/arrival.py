"""Every arrival moment, not only the grid: the sub-tree of grid phase p stands for every arrival in [p - dt/2, p +
dt/2] when it is decided for a robot whose capsules are inflated by how far they can move in dt/2 of path time,
and any contact with a robot that is not standing counts.

**Why it holds.** In a cell where only the worker decides what the devices do (no speed and separation monitoring,
no muting window, no timed panel: those read the robot's clock or pose), the worker's motion and every detection
depend on the worker's actions alone; so every latch, release, speed reduction and door opening happens at the
same time whatever the arrival moment, and each robot's path time is tau(p', t) = p' + g(t) with the same g for
every p' (``kernels.robot``: the path time is the phase plus a function of the state; a cell of several robots
shifts every robot's phase together, ``build.with_phase``). An arrival delta later (|delta| <= dt/2) therefore
poses each robot where the grid phase's robot is at path time delta later. Each capsule moves rigidly with its
link and its axis points move by at most their endpoints' displacement, so every axis point of capsule c lies
within ``m_c`` (the largest endpoint displacement over any dt/2 of its robot's cycle, plus the sampling slack
below) of the grid phase's axis: the arrival's capsule lies inside the grid phase's capsule with radius r_c + m_c.
The distance to a body capsule can only shrink when a capsule grows into one containing it. The distance to a
reach volume is the reach field's value at the axis less the radius; the field interpolates a distance transform
trilinearly, so along each axis it changes by at most the distance moved, and in any direction by at most sqrt(3)
times it (``REACH_LIPSCHITZ``; measured: 1.33 over 50,000 random 4 mm steps), so the displacement is taken sqrt(3)
times; and the kernel's tracing finds the minimum along a capsule to within one grid spacing of the field, so one
spacing is added. So d_HR of the inflated model at p is at most d_HR at p' at every step. Its speed at p' is not
known (a dwell at p may be a move at p'), so the inflated model counts a contact as unsafe whenever the robot that
owns the nearest capsule is not standing (``layout.C_ANY_MOTION``); a robot standing at p stands at every p' (its
stop took full effect at a time that does not depend on p'). Both changes can only add unsafe steps, so no hazard
at any p' is missed; the bounds stay sound (the at-rest bound for the reason just given, the distance bound
because it reads the inflated capsules).

**What it costs.** False alarms: a contact of the inflated model that no arrival in the window has. Each hazardous
sequence it finds is replayed in the real model at arrival moments spread over the window (``CONFIRM_STEPS``); one
that is hazardous there is a real hazard, with its exact arrival moment as the witness; one that is not stays an
unconfirmed alarm, reported as such, and the verdict is not a proof.

**Sampling slack.** The displacement is measured on samples ``SAMPLE`` s apart, for lags that are multiples of it;
between samples and lags a point moves at most its capsule's speed bound (``reach.capsule_speeds``) times the
distance to the nearest sample at each end, so ``2 * speed * SAMPLE`` is added.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from cellstress.sim import layout as L
from cellstress.sim.build import Layout
from cellstress.sim.scene import robot_capsules
from cellstress.verifier.reach import capsule_speeds

SAMPLE = 1e-3  # s of path time between the samples the displacement is measured on
REACH_LIPSCHITZ = 3.0 ** 0.5  # the reach field's largest slope: a trilinear interpolant of a 1-Lipschitz grid
CONFIRM_STEPS = 11  # arrival moments across a window at which an alarm is replayed in the real model


@dataclass(frozen=True)
class ArrivalCover:
    """Whether a cell's grid sub-trees can stand for every arrival moment, and at what margin."""

    covered: bool  # False: the proof covers the grid moments only (``reason`` says why)
    reason: str
    half_window: float  # s: each grid phase stands for arrivals within this of it
    margins: tuple[float, ...]  # m per robot capsule (Layout.capsules' order); () when not covered

    @property
    def largest(self) -> float:
        return max(self.margins, default=0.0)


def clock_dependence(layout: Layout) -> str | None:
    """Why the devices or the worker's way depend on the robot's clock or pose in this cell (None: they do
    not)."""
    P = layout.params
    if np.any(P.dev_speed == L.SEPARATION):
        return "speed and separation monitoring slows the robot by its measured distance to the worker"
    if np.any(P.dev_muted[:, 0] < np.inf):
        return "a muted device's window runs on the robot's clock"
    if P.panel_fence.shape[0]:
        return "a timed panel (a pallet) blocks the worker on the robot's clock"
    return None


def arrival_cover(sim, contacts_judged: bool) -> ArrivalCover:
    """How verify covers the arrival moments between its grid phases in ``sim``'s cell (see the module)."""
    half = 0.5 * sim.dt
    why = clock_dependence(sim.layout)
    if why is None and contacts_judged:
        why = "the criterion judges each contact by the robot's speed and force at that moment"
    if why is not None:
        return ArrivalCover(False, why, half, ())
    return ArrivalCover(True, "", half, tuple(float(m) for m in capsule_margins(sim.layout, half)))


def capsule_margins(layout: Layout, half_window: float) -> np.ndarray:
    """For each robot capsule, the growth that covers ``half_window`` s of path time (every robot shifted
    together): how far any point of its axis can move, plus the sampling slack, times the reach field's slope,
    plus its tracing tolerance (see the module)."""
    lag = max(1, int(np.ceil(half_window / SAMPLE - 1e-9)))
    period = max(float(p.trajectory.cycle) for p in layout.robots)
    n = int(np.ceil(period / SAMPLE)) + lag + 1
    tau0 = float(layout.params.scal[L.C_PHASE0])
    a = np.empty((n, len(layout.capsules), 3))
    b = np.empty_like(a)
    for i in range(n):
        a[i], b[i] = robot_capsules(layout, tau0 + i * SAMPLE)
    moved = np.zeros(len(layout.capsules))
    for k in range(1, lag + 1):
        d = np.maximum(np.linalg.norm(a[k:] - a[:-k], axis=2), np.linalg.norm(b[k:] - b[:-k], axis=2))
        moved = np.maximum(moved, d.max(axis=0))
    speeds = np.concatenate([capsule_speeds(p) for p in layout.robots])
    return REACH_LIPSCHITZ * (moved + 2.0 * speeds * SAMPLE) + float(layout.params.scal[L.C_REACH_H])


def inflated(layout: Layout, cover: ArrivalCover) -> Layout:
    """The layout of the arrival-window model: capsules grown by their margins, any motion unsafe."""
    P = layout.params
    scal = P.scal.copy()
    scal[L.C_ANY_MOTION] = 1.0
    params = P._replace(cap_r=P.cap_r + np.asarray(cover.margins), scal=scal)
    return dataclasses.replace(layout, params=params)


def confirm_phases(phase: float, cover: ArrivalCover, cycle: float) -> tuple[float, ...]:
    """The arrival moments across the window of ``phase`` at which an alarm is replayed, nearest first, each
    within the cycle (a moment before 0 is the same moment of the cycle before), rounded to 1 ns as witnesses
    record them."""
    offsets = np.linspace(-cover.half_window, cover.half_window, CONFIRM_STEPS)
    order = np.argsort(np.abs(offsets), kind="stable")
    return tuple(dict.fromkeys(round((phase + float(o)) % cycle, 9) for o in offsets[order]))
