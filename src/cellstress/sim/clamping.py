"""What surrounds a contact, for criteria that judge contacts (``core.surroundings``): the fixed surface behind the
body region, how far the robot still pushes towards it until it stands, and the worker's own speed.

* **Fixed surfaces** are the simulator's own: the floor (z = 0), every prism of ``Layout.obstacles`` (the tables,
  the cell's obstacles, the robots' pedestals: footprint from the floor to its height) and every row of the
  kernel's ``fences`` array (fence panels, door leaves, pallets; a door leaf or a pallet counts as if it were
  always there, which can only make more contacts clamping). A ray from the body's contact point along the push
  direction finds the nearest one (``FixedSurfaces.nearest``).
* **Travel until standstill** (``travel``): how far the robot point still advances along the push direction, on
  the robot's own path (the kernel's trajectory and forward kinematics), until the robot stands still: while it
  brakes along its path, for the rest of its braking; while it runs (or a stop is pending), as if the contact
  itself made it stop, with its stop data (delay, then braking); a category 0 stop holds its pose and the joints
  brake independently, so the point's speed along the direction falling linearly to 0 (docs/criteria.md).
* **The worker's speed** (``body_point_velocity``): the velocity of the body's contact point between the pose of
  the step before and the contact's pose (the same body functions the kernel and the pictures pose the worker
  with).

Everything here is Python, outside the hot loop: contacts are rare.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.human.body import CAPSULE_PART, BodyPose
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.build import Layout

CAST_RANGE = 0.5  # m: the farthest a backing surface is looked for (a clamping gap is centimetres)
TRAVEL_SAMPLES = 32  # path times sampled over the remaining motion (the largest advance of the point is kept)
_EPS = 1e-12


def _inside(x: float, y: float, foot: np.ndarray) -> bool:
    """Crossing-number point-in-polygon test."""
    inside = False
    n = len(foot)
    for i in range(n):
        (xi, yi), (xj, yj) = foot[i], foot[i - 1]
        if (yi > y) != (yj > y) and x < xi + (y - yi) * (xj - xi) / (yj - yi):
            inside = not inside
    return inside


def _ray_segment_2d(o: np.ndarray, d: np.ndarray, p0, p1) -> float | None:
    """Ray parameter t >= 0 where o + t d (3-D, unit d) crosses the vertical plane of floor segment p0-p1 within
    the segment, or None (parallel or missed)."""
    ex, ey = p1[0] - p0[0], p1[1] - p0[1]
    den = d[0] * ey - d[1] * ex
    if abs(den) <= _EPS:
        return None
    wx, wy = p0[0] - o[0], p0[1] - o[1]
    t = (wx * ey - wy * ex) / den
    u = (wx * d[1] - wy * d[0]) / den
    return t if t >= 0.0 and -1e-9 <= u <= 1.0 + 1e-9 else None


def ray_prism(o: np.ndarray, d: np.ndarray, foot: np.ndarray, height: float) -> float:
    """Distance along the ray o + t d to a prism (footprint ``foot``, floor to ``height``): 0 inside, inf missed."""
    if 0.0 <= o[2] <= height and _inside(o[0], o[1], foot):
        return 0.0
    best = math.inf
    if d[2] < -_EPS and o[2] > height:  # the top face
        t = (height - o[2]) / d[2]
        if _inside(o[0] + t * d[0], o[1] + t * d[1], foot):
            best = t
    for i in range(len(foot)):  # the side faces
        t = _ray_segment_2d(o, d, foot[i - 1], foot[i])
        if t is not None and t < best and 0.0 <= o[2] + t * d[2] <= height:
            best = t
    return best


def ray_panel(o: np.ndarray, d: np.ndarray, rect) -> float:
    """Distance along the ray to a vertical panel x0 y0 x1 y1 bottom top (the kernel's fence row), inf missed."""
    t = _ray_segment_2d(o, d, rect[0:2], rect[2:4])
    if t is None or not rect[4] <= o[2] + t * d[2] <= rect[5]:
        return math.inf
    return t


def ray_floor(o: np.ndarray, d: np.ndarray) -> float:
    if o[2] <= 0.0:
        return 0.0
    return -o[2] / d[2] if d[2] < -_EPS else math.inf


class FixedSurfaces:
    """The cell's fixed surfaces as the simulator has them (see the module docstring), named for reports."""

    def __init__(self, layout: Layout):
        self.prisms = tuple((o.name, np.asarray(o.footprint(), dtype=float), float(o.height))
                            for o in layout.obstacles)
        P = layout.params
        doors, pallets = {int(f) for f in P.door_fence}, {int(f) for f in P.panel_fence}
        kinds = ["door" if i in doors else "pallet" if i in pallets else "fence" for i in range(len(P.fences))]
        self.panels = tuple((f"{k} panel {kinds[:i + 1].count(k)}", np.asarray(row, dtype=float))
                            for i, (k, row) in enumerate(zip(kinds, P.fences, strict=True)))

    def nearest(self, origin, direction, reach: float = CAST_RANGE) -> tuple[str, float] | None:
        """(name, distance) of the first fixed surface on the ray from ``origin`` along the unit ``direction``
        within ``reach`` [m] (distance 0: the origin is inside a solid or below the floor), or None."""
        o, d = np.asarray(origin, dtype=float), np.asarray(direction, dtype=float)
        best: tuple[str, float] | None = None
        hits = [("floor", ray_floor(o, d))]
        hits += [(name, ray_prism(o, d, foot, h)) for name, foot, h in self.prisms]
        hits += [(name, ray_panel(o, d, rect)) for name, rect in self.panels]
        for name, t in hits:  # the first in this order wins a tie: deterministic
            if t <= reach and (best is None or t < best[1]):
                best = (name, float(t))
        return best


def body_thickness(layout: Layout, part: int, pose: BodyPose) -> float:
    """The body region's thickness at a contact [m]: its capsule's diameter; for a reach volume (a hand that may be
    anywhere in it) the hand's."""
    if part in (L.PART_LEFT_REACH, L.PART_RIGHT_REACH):
        return 2.0 * float(layout.params.body[L.B_R_HAND])
    return 2.0 * float(pose.r[CAPSULE_PART.index(part)])


def body_point_velocity(part: int, point, pose: BodyPose, before: BodyPose, dt: float) -> np.ndarray:
    """Velocity [m/s] of the body's contact point between the pose ``before`` (one step of ``dt`` earlier) and
    ``pose``. On a capsule: its axis point at the same fraction of the axis (the capsule's own spin about its axis
    is left out: under a centimetre per step at these radii); in a reach volume: the point carried rigidly with
    the shoulder and the trunk frame."""
    p = np.asarray(point, dtype=float)
    if part in (L.PART_LEFT_REACH, L.PART_RIGHT_REACH):
        side = part - L.PART_LEFT_REACH
        local = pose.trunk.T @ (p - pose.shoulders[side])
        then = before.shoulders[side] + before.trunk @ local
        return (p - then) / dt
    c = CAPSULE_PART.index(part)
    a, ab = pose.a[c], pose.b[c] - pose.a[c]
    den = float(ab @ ab)
    s = 0.0 if den <= _EPS else min(1.0, max(0.0, float((p - a) @ ab) / den))
    now = a + s * ab
    then = before.a[c] + s * (before.b[c] - before.a[c])
    return (now - then) / dt


def time_scaling(layout: Layout, row: np.ndarray) -> float:
    """The robot's time scaling sigma at a metric row: 1 running, falling linearly to 0 while braking, 0 stopped.
    The same arithmetic as ``scene.joint_state`` (kept there unchanged: scene.py's bytes key a compiled kernel in
    the shipped cache); tests/sim/test_clamping.py checks that the two agree."""
    P = layout.params
    T = float(P.scal[L.C_STOP_TIME])
    tau, t, phase = float(row[L.M_TAU]), float(row[L.M_T]), int(row[L.M_PHASE])
    if phase == L.PHASE_STOPPED:
        return 0.0
    if phase == L.PHASE_BRAKING and P.scal[L.C_STOP_HOLD] != 0.0:
        return max(0.0, 1.0 - (t - (tau - float(P.scal[L.C_PHASE0]))) / T)
    if phase == L.PHASE_BRAKING:
        d = float(np.sqrt(max(0.0, 2.0 * T * (t + float(P.scal[L.C_PHASE0]) - tau))))
        return max(0.0, 1.0 - d / T)
    return 1.0


def remaining_path_time(layout: Layout, row: np.ndarray) -> float:
    """Path time [s] the robot still advances until it stands, on its path (see the module docstring): braking,
    sigma^2 T / 2; otherwise delay + T / 2 (running at full path speed until its stop, made by the contact if
    none is under way, takes effect; the warning field's reduced speed is not credited); 0 stopped."""
    P = layout.params
    T, delay = float(P.scal[L.C_STOP_TIME]), float(P.scal[L.C_STOP_DELAY])
    phase = int(row[L.M_PHASE])
    if phase == L.PHASE_STOPPED:
        return 0.0
    if phase == L.PHASE_BRAKING:
        sigma = time_scaling(layout, row)
        return sigma * sigma * T / 2.0
    return delay + T / 2.0


def travel(layout: Layout, row: np.ndarray, joint: int, point, direction, v_push: float) -> float:
    """How far [m] the robot point ``point`` (fixed to kernel joint ``joint``) still advances along the unit
    ``direction`` until the robot stands still (>= 0). A category 0 stop holds the path: the point's speed
    ``v_push`` along the direction falls linearly to 0 over the rest of the stopping time."""
    P = layout.params
    phase = int(row[L.M_PHASE])
    if phase == L.PHASE_STOPPED or joint < 0:
        return 0.0
    T = float(P.scal[L.C_STOP_TIME])
    if P.scal[L.C_STOP_HOLD] != 0.0:
        left = time_scaling(layout, row) * T if phase == L.PHASE_BRAKING else T
        return max(0.0, v_push) * left / 2.0
    dtau = remaining_path_time(layout, row)
    if dtau <= 0.0:
        return 0.0
    nj = P.placements.shape[0]
    q, qd = np.zeros(nj), np.zeros(nj)
    rot, pos = np.zeros((nj, 3, 3)), np.zeros((nj, 3))
    tau = float(row[L.M_TAU])
    K.joint_trajectory(P, tau, 1.0, q, qd)
    K.forward_kinematics(P, q, rot, pos)
    local = rot[joint].T @ (np.asarray(point, dtype=float) - pos[joint])
    start = rot[joint] @ local + pos[joint]
    d = np.asarray(direction, dtype=float)
    best = 0.0
    for k in range(1, TRAVEL_SAMPLES + 1):
        K.joint_trajectory(P, tau + dtau * k / TRAVEL_SAMPLES, 1.0, q, qd)
        K.forward_kinematics(P, q, rot, pos)
        best = max(best, float(d @ (rot[joint] @ local + pos[joint] - start)))
    return best
