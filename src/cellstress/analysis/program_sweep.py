"""A robot program's capsules swept over its cycle against the cell's solids: the second failure of the robot
program check (``analysis.program_check``).

A moving link passes through the robot's own pedestal, the table, an obstacle, a fence or the floor when its
collision capsule's axis (the core line inside the link's geometry; the capsule's radius only encloses it) goes
more than ``DEPTH`` into the solid (below the floor; for a fence panel, which has no thickness, a point of it
within ``DEPTH`` of the panel). A link that only touches a surface is not:
the baseline's gripper capsule ends exactly on the table top. The robot's fixed links (its base) are not
tested, and the links its first joint alone carries are not tested against its own pedestal: they turn on
the base by design (the SO-100's shoulder axis lies 19 mm inside the outline of its base).

Sampling, and why it cannot miss a pass: on each move the capsules are posed by the simulator's own kernels
(``kernels.robot_live``, as ``sim.scene.robot_capsules`` poses them) at path times at most ``step / v`` apart,
where ``v`` bounds the speed of every point of every capsule axis on that move (``point_speed_bounds``: each
joint's peak speed times its largest lever arm to the point, summed along the chain; an axis point is a convex
combination of the axis's ends, so it is no faster than the faster end); a dwell is a pose at rest, the move's
first sample. Along each axis the depth is read at points at most ``step`` apart. ``step`` is ``DEPTH``
(``sample_spacing`` widens it only for a program that would need more than ``MAX_POINTS`` axis points, a
cycle of minutes at high speed, and the header prints the spacing used). Depth inside a solid is 1-Lipschitz
in the point, so an axis point that at any instant lies ``DEPTH + step`` deep (20 mm) is, at the nearest
sample (``step / 2`` of travel away) and the nearest point along the axis (``step / 2``), still more than
``DEPTH`` deep, and is reported; nothing shallower than ``DEPTH`` is. An axis that crosses a fence panel has,
at the nearest sample, a point within ``step`` of it, and is reported. A solid thinner than
``2 (DEPTH + step)`` (40 mm) could let a pass go unreported; fences are tested as panels for that reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.plane import distance_to_polyline, points_in_polygon
from cellstress.robot.model import REVOLUTE, RobotModel
from cellstress.robot.trajectory import Trajectory
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.build import PEDESTAL, Layout, RobotPart

DEPTH = 0.01  # m: a capsule axis this far inside a solid (or this near a fence panel) passes through it
CHUNK_POINTS = 400_000  # axis points measured at once (memory)
MAX_POINTS = 40_000_000  # axis points over a robot's cycle, at most (time)


@dataclass(frozen=True)
class PassThrough:
    """A link's capsule axis inside a solid during a move: the deepest sample of that (move, link, solid)."""

    move: int
    link: str
    solid: str  # 'the floor', 'robot-pedestal', 'table', an obstacle's name, 'fence F panel P'
    depth: float  # m (a fence panel: DEPTH minus the axis's distance from it)
    t: float  # path time [s] of the deepest sample, in [0, cycle)


# ---- the speed bound ---------------------------------------------------------------------------------------
def peak_joint_speeds(traj: Trajectory) -> np.ndarray:
    """(moves, joints): each joint's peak speed on each move [rad/s or m/s] (a minimum-jerk move peaks at 15/8 of
    its mean speed; a linear one runs at its mean)."""
    w = traj.waypoints
    d = np.abs(np.roll(w, -1, axis=0) - w)
    return (1.0 if traj.linear else 1.875) * d / traj.move_times[:, None]


def lever_arms(robot: RobotModel, joint: int, point: np.ndarray) -> np.ndarray:
    """(joints,): for each joint j that carries ``point`` (fixed in ``joint``'s frame) a bound on the speed the
    point gains per unit of joint j's speed in every configuration, 0 for the others: 1 for a prismatic joint;
    for a revolute one the point's distance from the joint's origin, bounded by the lengths of the joint
    placements between them, each prismatic joint's largest travel and the point's own distance, added."""
    out = np.zeros(robot.n_joints)
    length = float(np.linalg.norm(point))
    j = joint
    while j >= 0:  # from the point's joint towards the base
        out[j] = length if robot.kinds[j] == REVOLUTE else 1.0
        length += float(np.linalg.norm(robot.placements[j][:3, 3]))
        if robot.kinds[j] != REVOLUTE:
            length += float(max(abs(robot.lower[j]), abs(robot.upper[j])))
        j = int(robot.parents[j])
    return out


def point_speed_bounds(part: RobotPart) -> np.ndarray:
    """(moves,): a bound [m/s] on the speed of every point of the robot's capsule axes on each move: per axis
    end, each joint's peak speed times its lever arm, summed along the chain."""
    robot, peak = part.model, peak_joint_speeds(part.trajectory)
    best = np.zeros(len(peak))
    for c in part.capsules:
        if c.joint < 0:
            continue
        for p in (c.p0, c.p1):
            best = np.maximum(best, peak @ lever_arms(robot, c.joint, np.asarray(p, float)))
    return best


# ---- capsules over the cycle -------------------------------------------------------------------------------
def robot_params(layout: Layout, r: int):
    """``SimParams`` in which robot r's arrays stand where robot 0's do, so ``kernels.robot_live`` poses robot r
    (its capsules in the first rows of ``Work.ra``): the arrays ``kernels.other_robots`` hands to the same
    compiled function for it."""
    P = layout.params
    if r == 0:
        return P
    x = r - 1
    return P._replace(scal=P.x_scal[x], base=P.x_base[x], parents=P.x_parents[x], placements=P.x_placements[x],
                      axes=P.x_axes[x], jtype=P.x_jtype[x], anc=P.x_anc[x], wp=P.x_wp[x],
                      seg_start=P.x_seg_start[x], seg_move=P.x_seg_move[x], seg_dwell=P.x_seg_dwell[x],
                      cap_joint=P.x_cap_joint[x], cap_a=P.x_cap_a[x], cap_b=P.x_cap_b[x])


def capsule_axes(layout: Layout, r: int, taus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Robot r's capsule axis ends (a, b: (times, capsules, 3)) at path times ``taus``, posed by the kernels as
    the simulator poses them (``kernels.robot_live``, before any stop)."""
    P = robot_params(layout, r)
    W = K.make_work(P)
    n = len(layout.robots[r].capsules)
    phase = float(P.scal[L.C_PHASE0])
    a, b = np.empty((len(taus), n, 3)), np.empty((len(taus), n, 3))
    for k, tau in enumerate(taus):
        K.robot_live(P, float(tau) - phase, np.inf, W)
        a[k], b[k] = W.ra[:n], W.rb[:n]
    return a, b


def capsule_grid(layout: Layout, r: int, t0: float, dt: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``capsule_axes`` at the n path times t0 + k dt, in one compiled loop: ``kernels.robot_table`` (the
    pre-stop table the simulator fills the same way) with the phase at t0 and the time step dt."""
    P = robot_params(layout, r)
    scal = P.scal.copy()
    scal[L.C_PHASE0], scal[L.C_DT] = t0, dt
    P = P._replace(scal=scal, x_scal=np.zeros((0, scal.shape[0])))  # the other robots are not posed
    nc = P.cap_r.shape[0]
    a, b = np.empty((n, nc, 3)), np.empty((n, nc, 3))
    K.robot_table(P, n, a, b, np.empty(n), np.empty(n), np.empty((n, 0)), np.empty((n, 0)))
    m = len(layout.robots[r].capsules)
    return a[:, :m], b[:, :m]


def sample_spacing(part: RobotPart, bounds: np.ndarray) -> float:
    """The capsule travel [m] between samples and between points along an axis: DEPTH, unless that needs more
    than MAX_POINTS axis points over the cycle (a cycle of minutes at high speed), then as much more as keeps
    them within it (the work, and the time ``check`` takes, stay bounded; the header says the spacing used)."""
    traj = part.trajectory
    moving = [c for c in part.capsules if c.joint >= 0]
    lengths = np.array([float(np.linalg.norm(np.subtract(c.p1, c.p0))) for c in moving])

    def points(step: float) -> float:
        samples = float(sum(n for _, _, n in sample_grids(traj, bounds, step)))
        return samples * float(np.sum(np.ceil(lengths / step) + 1))

    step = DEPTH
    if moving and points(step) > MAX_POINTS:
        step *= math.sqrt(points(step) / MAX_POINTS)
        while points(step) > MAX_POINTS:  # (the ceilings: a few percent more at most)
            step *= 1.05
    return step


def sample_grids(traj: Trajectory, bounds: np.ndarray, step: float = DEPTH) -> list[tuple[float, float, int]]:
    """(first path time, time step, samples) of each stretch sampled evenly: each move of a waypoint program
    from its start to its end (the robot rests through each dwell, so a move's first sample stands for it); a
    trajectory file's rows, short moves without dwells, as one stretch over the cycle. Samples lie at most
    ``step`` / bound apart."""
    if traj.linear:
        n = max(1, math.ceil(traj.cycle * float(bounds.max()) / step))
        return [(0.0, traj.cycle / n, n + 1)]
    n = np.maximum(1, np.ceil(traj.move_times * bounds / step)).astype(np.int64)
    begin = traj.starts + traj.dwells
    return [(float(begin[i]), float(traj.move_times[i] / n[i]), int(n[i]) + 1) for i in range(len(n))]


def move_of(traj: Trajectory, taus: np.ndarray) -> np.ndarray:
    """The move each path time belongs to (a waypoint's dwell counts to the move after it; the cycle's end to
    the last move)."""
    return np.clip(np.searchsorted(traj.starts, np.minimum(taus, traj.cycle), side="right") - 1, 0,
                   traj.n_segments - 1)


def sample_times(traj: Trajectory, bounds: np.ndarray, step: float = DEPTH) -> tuple[np.ndarray, np.ndarray]:
    """The path times of ``sample_grids`` and the move of each."""
    taus = np.concatenate([t0 + np.arange(n) * dt for t0, dt, n in sample_grids(traj, bounds, step)])
    return taus, move_of(traj, taus)


def _axis_points(a: np.ndarray, b: np.ndarray, step: float) -> np.ndarray:
    """(times, points, 3): points along each sample's axis, at most ``step`` apart."""
    length = float(np.max(np.linalg.norm(b - a, axis=-1))) if len(a) else 0.0
    u = np.linspace(0.0, 1.0, max(2, math.ceil(length / step) + 1))
    return a[:, None, :] + u[None, :, None] * (b - a)[:, None, :]


def _prism_depth(pts: np.ndarray, poly: np.ndarray, height: float) -> np.ndarray:
    """Depth [m] of each point inside the prism raising ``poly`` from the floor to ``height`` (-inf outside or
    within DEPTH of its surface)."""
    depth = np.full(len(pts), -np.inf)
    lo, hi = poly.min(axis=0) + DEPTH, poly.max(axis=0) - DEPTH
    near = np.flatnonzero((pts[:, 0] > lo[0]) & (pts[:, 0] < hi[0]) & (pts[:, 1] > lo[1]) & (pts[:, 1] < hi[1])
                          & (pts[:, 2] > DEPTH) & (pts[:, 2] < height - DEPTH))
    if len(near) == 0:
        return depth
    px, py, pz = pts[near, 0], pts[near, 1], pts[near, 2]
    inside = points_in_polygon(px, py, poly)
    plan = distance_to_polyline(px, py, poly, closed=True)
    depth[near] = np.where(inside, np.minimum(plan, np.minimum(pz, height - pz)), -np.inf)
    return depth


def _fence_panels(layout: Layout) -> tuple[list[str], np.ndarray]:
    """The fence panels' names and (x0, y0, x1, y1, bottom, top) rows."""
    names, rects = [], []
    for f, fence in enumerate(layout.cell.spec.fences):
        for p, (s, e) in enumerate(zip(fence.points, fence.points[1:], strict=False)):
            names.append(f"fence {f + 1} panel {p + 1}")
            rects.append((s[0], s[1], e[0], e[1], fence.bottom, fence.top))
    return names, np.asarray(rects, dtype=float).reshape(-1, 6)


def panel_distances(pts: np.ndarray, rect: np.ndarray) -> np.ndarray:
    """Distance [m] of each point from the vertical rectangle over the floor segment (x0, y0)-(x1, y1) between
    heights bottom and top."""
    x0, y0, x1, y1, zlo, zhi = rect
    d = np.array([x1 - x0, y1 - y0])
    w2 = float(d @ d)
    t = np.clip(((pts[:, 0] - x0) * d[0] + (pts[:, 1] - y0) * d[1]) / w2, 0.0, 1.0) if w2 > 0 else 0.0
    dx, dy = pts[:, 0] - (x0 + t * d[0]), pts[:, 1] - (y0 + t * d[1])
    dz = pts[:, 2] - np.clip(pts[:, 2], zlo, zhi)
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def own_pedestal(layout: Layout, r: int) -> int:
    """The index in ``layout.obstacles`` of robot r's own pedestal (``sim.build.pedestal``: after the cell's
    obstacles, one per robot that has one, in robot order), or -1."""
    first = len(layout.cell.spec.solid_obstacles())
    name = PEDESTAL if len(layout.robots) == 1 else f"{layout.robots[r].name}-pedestal"
    return next((i for i in range(first, len(layout.obstacles)) if layout.obstacles[i].name == name), -1)


def passes_through(layout: Layout, r: int, bounds: np.ndarray, step: float = DEPTH) -> tuple[PassThrough, ...]:
    """Every (move, link, solid) where robot r's capsule axes go more than DEPTH into a solid (for a fence
    panel: an axis point within DEPTH of it), sampled along each move at most ``step`` of capsule travel apart,
    with points at most ``step`` apart along each axis; the deepest sample of each."""
    part = layout.robots[r]
    solids = [(o.name, np.asarray(o.footprint(), float), float(o.height)) for o in layout.obstacles]
    own = own_pedestal(layout, r)
    panel_names, rects = _fence_panels(layout)
    best: dict[tuple[int, str, str], tuple[float, float]] = {}

    def note(moves: np.ndarray, taus: np.ndarray, link: str, solid: str, depth: np.ndarray, over: float) -> None:
        hit = np.flatnonzero(depth > over)
        for move in np.unique(moves[hit]):  # the deepest sample of each move
            k = hit[moves[hit] == move]
            k = int(k[np.argmax(depth[k])])
            key = (int(move), link, solid)
            if key not in best or depth[k] > best[key][0]:
                best[key] = (float(depth[k]), float(taus[k]))

    per_sample = sum(max(2, math.ceil(float(np.linalg.norm(np.subtract(c.p1, c.p0))) / step) + 1)
                     for c in part.capsules)
    chunk = max(2, CHUNK_POINTS // per_sample)
    for t0, dt, n in sample_grids(part.trajectory, bounds, step):
        for k0 in range(0, n, chunk):  # bounded memory
            m = min(chunk, n - k0)
            taus = t0 + (k0 + np.arange(m)) * dt
            moves = move_of(part.trajectory, taus)
            a, b = capsule_grid(layout, r, t0 + k0 * dt, dt, m)
            for c, cap in enumerate(part.capsules):
                if cap.joint < 0:  # the robot's fixed links stand on its pedestal
                    continue
                pts = _axis_points(a[:, c], b[:, c], step)  # (times, points, 3)
                flat = pts.reshape(-1, 3)
                note(moves, taus, cap.name, "the floor", -pts[:, :, 2].min(axis=1), DEPTH)
                for i, (name, poly, height) in enumerate(solids):
                    if i == own and part.model.parents[cap.joint] < 0:  # the first link turns on its base by design
                        continue
                    depth = _prism_depth(flat, poly, height).reshape(pts.shape[:2]).max(axis=1)
                    note(moves, taus, cap.name, name, depth, DEPTH)
                lo, hi = flat.min(axis=0) - DEPTH, flat.max(axis=0) + DEPTH
                near = np.flatnonzero((np.maximum(rects[:, 0], rects[:, 2]) >= lo[0])
                                      & (np.minimum(rects[:, 0], rects[:, 2]) <= hi[0])
                                      & (np.maximum(rects[:, 1], rects[:, 3]) >= lo[1])
                                      & (np.minimum(rects[:, 1], rects[:, 3]) <= hi[1])
                                      & (rects[:, 5] >= lo[2]) & (rects[:, 4] <= hi[2]))
                for i in near:
                    gap = panel_distances(flat, rects[i]).reshape(pts.shape[:2]).min(axis=1)
                    note(moves, taus, cap.name, panel_names[i], DEPTH - gap, -1e-12)
    return tuple(PassThrough(m, link, solid, round(d, 4), round(t, 3))
                 for (m, link, solid), (d, t) in sorted(best.items(), key=lambda kv: (kv[0][0], kv[1][1], kv[0][1:])))
