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
from cellstress.sim import scene
from cellstress.sim.build import Layout

CAST_RANGE = 0.5  # m: the farthest a backing surface is looked for (a clamping gap is centimetres)
# Surroundings are measured for closest points at most this far apart: the largest distance tolerance a criterion
# may have (criteria.base.CriterionRecord). Farther apart (the reward's look at every action end) the contact has
# no backing: the search's severity there is the free contact's.
CONTACT_RANGE = 0.1  # m
AXIS_SAMPLES = 9  # points along each robot capsule's axis where a hand in a reach volume may be pinned
TRAVEL_SAMPLES = 16  # path times sampled over the remaining motion (the largest advance of the point is kept)
# The robot's travel is measured only behind a gap this small (no criterion calls a wider gap clamping: iso15066's
# is 20 mm); behind a wider one it is reported as 0 (the contact is free, the travel plays no part).
TRAVEL_GAP = 0.1  # m
_EPS = 1e-12


def _cross_2d(o: np.ndarray, d: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """(m, e): ray parameter t >= 0 where each ray o[i] + t d[i] (3-D, unit d) crosses the vertical plane of each
    floor segment p0[j]-p1[j] within the segment; inf where parallel or missed."""
    ex, ey = (p1[:, 0] - p0[:, 0])[None, :], (p1[:, 1] - p0[:, 1])[None, :]
    dx, dy = d[:, 0:1], d[:, 1:2]
    den = dx * ey - dy * ex
    ok = np.abs(den) > _EPS
    den = np.where(ok, den, 1.0)
    wx, wy = p0[None, :, 0] - o[:, 0:1], p0[None, :, 1] - o[:, 1:2]
    t = (wx * ey - wy * ex) / den
    u = (wx * dy - wy * dx) / den
    return np.where(ok & (t >= 0.0) & (u >= -1e-9) & (u <= 1.0 + 1e-9), t, math.inf)


class FixedSurfaces:
    """The cell's fixed surfaces as the simulator has them (see the module docstring), named for reports. Every
    prism side and every panel is a vertical rectangle over a floor segment; the rays are cast against all of them
    at once (numpy), the prisms' top faces and insides by a crossing-number test per prism."""

    def __init__(self, layout: Layout):
        P = layout.params
        doors, pallets = {int(f) for f in P.door_fence}, {int(f) for f in P.panel_fence}
        kinds = ["door" if i in doors else "pallet" if i in pallets else "fence" for i in range(len(P.fences))]
        prisms = [(o.name, np.asarray(o.footprint(), dtype=float), float(o.height)) for o in layout.obstacles]
        self.names = ("floor", *(name for name, _, _ in prisms),
                      *(f"{k} panel {kinds[:i + 1].count(k)}" for i, k in enumerate(kinds)))
        n_prisms = len(prisms)
        starts, ends, lo, hi, owner = [], [], [], [], []
        for p, (_, foot, h) in enumerate(prisms):
            for i in range(len(foot)):
                starts.append(foot[i - 1])
                ends.append(foot[i])
                lo.append(0.0)
                hi.append(h)
                owner.append(1 + p)
        for i, row in enumerate(np.asarray(P.fences, dtype=float).reshape(-1, 6)):
            starts.append(row[0:2])
            ends.append(row[2:4])
            lo.append(row[4])
            hi.append(row[5])
            owner.append(1 + n_prisms + i)
        self.p0 = np.asarray(starts, dtype=float).reshape(-1, 2)
        self.p1 = np.asarray(ends, dtype=float).reshape(-1, 2)
        self.lo, self.hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        self.owner = np.asarray(owner, dtype=np.int64)
        self.heights = np.asarray([h for _, _, h in prisms], dtype=float)
        # (prism edges, prisms): which prism each of the first edges bounds, for the crossing-number parity
        n_edges = sum(len(f) for _, f, _ in prisms)
        self.of_prism = np.zeros((n_edges, n_prisms))
        self.of_prism[np.arange(n_edges), self.owner[:n_edges] - 1] = 1.0

    def _inside(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """(m, prisms): is point (x[i, p], y[i, p]) inside prism p's footprint (crossing number)."""
        n = self.of_prism.shape[0]
        if not n:
            return np.zeros(x.shape, dtype=bool)
        cols = self.owner[:n] - 1
        px, py = x[:, cols], y[:, cols]  # each edge against its own prism's point
        (xi, yi), (xj, yj) = self.p1[:n].T, self.p0[:n].T
        flat = yi == yj
        dy = np.where(flat, 1.0, yj - yi)
        crosses = ((yi > py) != (yj > py)) & (px < xi + (py - yi) * (xj - xi) / dy) & ~flat
        return (crosses.astype(float) @ self.of_prism) % 2.0 == 1.0

    def distances(self, origins, directions) -> np.ndarray:
        """(m, surfaces): distance along each ray (origins, unit directions: (m, 3)) to each surface, in the
        order of ``names`` (0 from inside a solid or below the floor; inf where missed)."""
        o = np.asarray(origins, dtype=float).reshape(-1, 3)
        d = np.asarray(directions, dtype=float).reshape(-1, 3)
        m, n_prisms = len(o), len(self.heights)
        out = np.full((m, len(self.names)), math.inf)
        falling = d[:, 2] < -_EPS
        out[:, 0] = np.where(o[:, 2] <= 0.0, 0.0, np.where(falling, -o[:, 2] / np.where(falling, d[:, 2], -1.0),
                                                           math.inf))
        # the sides of prisms and the panels: vertical rectangles
        t = _cross_2d(o, d, self.p0, self.p1)
        z = o[:, 2:3] + np.where(np.isfinite(t), t, 0.0) * d[:, 2:3]
        t = np.where((z >= self.lo[None, :]) & (z <= self.hi[None, :]), t, math.inf)
        for col in np.unique(self.owner):
            out[:, col] = np.min(t[:, self.owner == col], axis=1)
        if n_prisms:
            h = self.heights[None, :]
            down = falling[:, None] & (o[:, 2:3] > h)  # the top faces
            tt = np.where(down, (h - o[:, 2:3]) / np.where(down, d[:, 2:3], -1.0), 0.0)
            top = down & self._inside(o[:, 0:1] + tt * d[:, 0:1], o[:, 1:2] + tt * d[:, 1:2])
            prisms = out[:, 1:1 + n_prisms]
            prisms = np.where(top & (tt < prisms), tt, prisms)
            within = (o[:, 2:3] >= 0.0) & (o[:, 2:3] <= h) & self._inside(
                np.repeat(o[:, 0:1], n_prisms, axis=1), np.repeat(o[:, 1:2], n_prisms, axis=1))
            out[:, 1:1 + n_prisms] = np.where(within, 0.0, prisms)
        return out

    def nearest(self, origin, direction, reach: float = CAST_RANGE) -> tuple[str, float] | None:
        """(name, distance) of the first fixed surface on the ray from ``origin`` along the unit ``direction``
        within ``reach`` [m] (distance 0: the origin is inside a solid or below the floor), or None."""
        which, dist = self.nearest_many(origin, direction, reach)
        return None if which[0] < 0 else (self.names[int(which[0])], float(dist[0]))

    def nearest_many(self, origins, directions, reach: float = CAST_RANGE) -> tuple[np.ndarray, np.ndarray]:
        """For each ray: the index into ``names`` of its first surface within ``reach`` (-1: none; the first in
        ``names``' order on a tie) and the distance (inf: none)."""
        t = self.distances(origins, directions)
        k = np.argmin(t, axis=1)
        dist = t[np.arange(len(t)), k]
        found = dist <= reach
        return np.where(found, k, -1), np.where(found, dist, math.inf)


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
        sigma = scene.time_scaling(layout, row)
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
        left = scene.time_scaling(layout, row) * T if phase == L.PHASE_BRAKING else T
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


def robot_surface_points(layout: Layout, row: np.ndarray) -> tuple[np.ndarray, ...]:
    """Where a hand that may be anywhere in the worker's reach volumes can be pinned by the robot: points on robot
    0's capsules (``AXIS_SAMPLES`` along each axis, each moved out by the radius along its own direction of motion,
    the capsule's leading side) inside the worker's envelope at the row's pose (``kernels.worker_point_distances``:
    reach volumes, fences respected, and body capsules), with their unit direction of motion, speed [m/s] and kernel
    joint. Capsules on the fixed base and points at rest are left out. (points, directions, speeds, joints)."""
    P = layout.params
    n_caps = P.cap_joint.shape[0]
    nj = P.placements.shape[0]
    tau, h = float(row[L.M_TAU]), 1e-6
    sigma = scene.time_scaling(layout, row)
    q, qd = np.zeros(nj), np.zeros(nj)
    rot, pos = np.zeros((nj, 3, 3)), np.zeros((nj, 3))
    ends = []
    for t in (tau, tau + h):
        K.joint_trajectory(P, t, 1.0, q, qd)
        K.forward_kinematics(P, q, rot, pos)
        ra, rb = np.zeros((n_caps, 3)), np.zeros((n_caps, 3))
        K.robot_capsules(P, rot, pos, ra, rb)
        ends.append((ra, rb))
    (a0, b0), (a1, b1) = ends
    s = np.linspace(0.0, 1.0, AXIS_SAMPLES)[None, :, None]
    p0 = a0[:, None, :] + s * (b0 - a0)[:, None, :]
    vel = sigma * (a1[:, None, :] + s * (b1 - a1)[:, None, :] - p0) / h
    speed = np.linalg.norm(vel, axis=2)
    keep = (speed > 1e-6) & (P.cap_joint[:, None] >= 0)
    dirs = np.where(keep[..., None], vel / np.where(keep, speed, 1.0)[..., None], 0.0)
    lead = p0 + np.asarray(P.cap_r, dtype=float)[:, None, None] * dirs
    caps = np.broadcast_to(np.arange(n_caps)[:, None], keep.shape)
    lead, dirs, speed, caps = lead[keep], dirs[keep], speed[keep], caps[keep]
    if not len(lead):
        return lead, dirs, speed, np.zeros(0, dtype=np.int64)
    dist = np.empty((1, len(lead)))
    K.worker_point_distances(P, np.ascontiguousarray(L.row_pose(row)[None, :]),
                             np.ascontiguousarray(lead[None, :, :]), dist)
    inside = dist[0] <= 0.0
    return lead[inside], dirs[inside], speed[inside], P.cap_joint[caps[inside]].astype(np.int64)
