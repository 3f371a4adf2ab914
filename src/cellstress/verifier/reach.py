"""The distance bound: where the worker cannot come near anything the robot can occupy in the time left.

**The worker.** Every point of the worker lies within the kernel's radius of the hip pivot (x, y, hip height
plus the stance's drop): the legs hang from it, the trunk, head and shoulders turn rigidly about it
(``kernels.body.pose_body``; lying prone too), the arms hang or reach from the shoulders and the reach volumes
lie within the arm's length of them (fences only shorten a reach). The reach field is a grid, so ``REACH_SLACK``
grid spacings are added for its interpolation. The field is measured from H = (x, y, z_H): the articulated
worker's stance moves the pivot between the lowest and the highest drop of its action table (prone to tiptoe),
so z_H is the middle of that range and half the range is added to the radius (the paper's worker has no stance:
z_H is its hip height, nothing is added). H moves only when the worker walks, side-steps, steps back or
crawls, by at most one stride (walking speed x dt x the action table's largest walking fraction; crawling is
slower) per step; turning, bending, a change of stance and the arms do not move it.

**The robot.** Its pose is always its path's pose at the path time tau the state holds (``kernels.robot``:
``path_time``, ``live_path_time``), and tau advances at a rate sigma in [0, 1]: one second per second until a
stop takes effect, then slower; an automatic restart ramps sigma back up to 1 at most, a warning field or a
speed and separation monitor down to its fraction, never above 1, and nothing turns it back. So at a step k' after
step k, whatever the devices do, the robot's pose is its path's pose at some path time in
[tau_k, tau_k + (k' - k) dt], tau_k the state's own (tau0 + k dt until a stop takes effect).
The path is sampled every ``dt / SUB`` of path time; between samples no point of a capsule axis moves more than
``speed`` x half the spacing, where ``speed`` bounds every capsule point's speed along the path: the sum over the
joints that move it of the joint's peak speed (a minimum-jerk segment peaks at 1.875 times its mean speed) times
the point's distance from the joint's origin (at most the lengths of the links in between, the slides of the
prismatic joints in between, and the capsule's end), plus each prismatic joint's own peak speed.

**The field.** For each robot sample, the distance from every node of a floor grid (spacing ``GRID``, at hip
height) to the sample's capsules, less the sampling allowance and half a grid diagonal: the true distance from
any H to that sample's neighbourhood is at least its nearest node's value.

A state at step k is safe when, for every later step k' of the episode, the least of those values over the
samples of path times [tau_k, tau_k + (k' - k) dt] at its pivot's node, less (k' - k) strides and the worker's
radius, exceeds the criterion's contact distance. With several robots, each has its own field (its capsules,
its speed bound) and its own path time, and the bound is the least over them.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.human.actions import A_DROP, A_WALK
from cellstress.sim import layout as L
from cellstress.sim.kernels.body import worker_radius as body_radius
from cellstress.sim.kernels.robot import live_path_time, path_time
from cellstress.sim.kernels.sweep import flag_distance
from cellstress.sim.scene import robot_capsules
from cellstress.sim.speeds import capsule_speeds

GRID = 0.05  # m: floor grid of the field
SUB = 4  # robot samples per time step


def drop_range(params) -> tuple[float, float]:
    """The lowest and the highest the stance puts the hip pivot relative to standing [m] (0, 0 for the paper's
    worker): the action table's drop targets, and standing itself, which every stance moves linearly between."""
    drops = np.asarray(params.act[:, A_DROP], dtype=float)
    return min(float(drops.min(initial=0.0)), 0.0), max(float(drops.max(initial=0.0)), 0.0)


def field_height(params) -> float:
    """z_H, the height the distance field is measured at: the middle of the pivot's heights (see the module)."""
    low, high = drop_range(params)
    return float(params.body[L.B_HIP_Z]) + (low + high) / 2.0


def worker_radius(params) -> float:
    """A radius about (x, y, z_H) that holds every point of the worker, in every pose and stance (see the module):
    the kernel's radius about the hip pivot at the highest stance (``kernels.body.worker_radius``, the one the
    swept contact test uses too), plus the farthest the stance takes the pivot from z_H."""
    low, high = drop_range(params)
    return float(body_radius(params.body, high, float(params.scal[L.C_REACH_H]))) + (high - low) / 2.0


def worker_stride(params) -> float:
    """The farthest the hip pivot's (x, y) moves in one time step: walking speed x dt x the largest walking
    fraction of the worker's actions (crawling is slower still: ``kernels.step.move_worker``)."""
    walks = np.abs(np.asarray(params.act[:, A_WALK], dtype=float)).max(initial=0.0)
    return float(params.body[L.B_WALK_SPEED]) * float(params.scal[L.C_DT]) * float(walks)


def robot_point_speed(layout, robot: int = 0) -> float:
    """An upper bound on the speed of any point of any of one robot's capsule axes per second of path time."""
    return float(capsule_speeds(layout.robots[robot]).max(initial=0.0))


class SweptField:
    """The distance bound of one simulator (cell and phase) for episodes of ``horizon`` actions."""

    def __init__(self, sim, horizon: int):
        P = sim.params
        self.dt = float(P.scal[L.C_DT])
        self.spa = P.spa
        # each robot's own constants (robot 0's, then the others'): its phase, stopping time, stop category
        self.scal = np.ascontiguousarray(np.vstack([P.scal[None, :], P.x_scal]) if len(P.x_scal) else P.scal[None, :])
        # a step may count as unsafe up to this d_HR: the contact distance, or where the swept test between the
        # steps cannot rule a contact out (kernels.sweep.flag_distance)
        self.dtol = flag_distance(P) if P.scal[L.C_SWEEP] != 0.0 else float(P.scal[L.C_DTOL])
        self.stride = worker_stride(P)
        self.radius = worker_radius(P)
        self.hip = field_height(P)
        steps = horizon * self.spa
        delta = self.dt / SUB
        tau0 = self.scal[:, L.C_PHASE0]
        n = steps * SUB + 2
        ra = np.empty((n, len(P.cap_r), 3))
        rb = np.empty_like(ra)
        for i in range(n):  # every robot at its own path time (its phase + i delta)
            ra[i], rb[i] = robot_capsules(sim.layout, tau0 + i * delta)
        fl = P.floor
        self.x0, self.y0 = float(fl[0]), float(fl[2])
        nx = int(np.ceil((fl[1] - fl[0]) / GRID)) + 1
        ny = int(np.ceil((fl[3] - fl[2]) / GRID)) + 1
        self.samples = np.empty((len(self.scal), n, nx, ny))
        # each robot's capsule axes at every sample, their radii, and how far a capsule point moves between a
        # sample and the next half-way (kept for the last action's bound, verifier.last_action)
        self.robots: list[tuple[np.ndarray, np.ndarray, np.ndarray, float]] = []
        for r in range(len(self.scal)):
            own = np.flatnonzero(P.cap_robot == r)
            self.robots.append((np.ascontiguousarray(ra[:, own]), np.ascontiguousarray(rb[:, own]),
                                np.ascontiguousarray(P.cap_r[own]), robot_point_speed(sim.layout, r) * delta / 2.0))
            _sample_field(*self.robots[r][:3], self.x0, self.y0, GRID, self.hip, self.samples[r])
            self.samples[r] -= self.robots[r][3] + GRID * np.sqrt(0.5)

    def lower_bound(self, states: np.ndarray, steps_left: int) -> np.ndarray:
        """A lower bound, over the next ``steps_left`` steps after each of ``states``, on the distance from the
        hip pivot (started at the state's (x, y), walking a stride a step) to the robots: for each later step k'
        and each robot, the least distance to its samples of path times [tau_k, tau_k + (k' - k) dt] (its own
        path time tau_k; one more sample each side, for rounding), less the strides walked by then."""
        states = np.ascontiguousarray(states)
        out = np.empty(len(states))
        _window_bound(self.samples, self.x0, self.y0, GRID, SUB, self.dt, self.scal, int(steps_left), self.stride,
                      states, out)
        return out

    def safe(self, children: np.ndarray, steps_left: int) -> np.ndarray:
        """Children that no completion of ``steps_left`` steps brings within the contact distance."""
        if not len(children):
            return np.zeros(0, dtype=bool)
        return self.lower_bound(children, steps_left) - self.radius > self.dtol


@njit(cache=True, inline="always")
def window_start(scal, states, c, r, dt, sub):
    """Robot r's path time in state c less its phase, counted in samples of dt / sub (an exact whole number on
    the plain path before a stop). Only robot 0 leaves the plain path model (``S_LIVE``); the others stop for
    good."""
    k = states[c, L.S_K]
    t = k * dt
    t_stop = states[c, L.S_TSTOP] if r == 0 else states[c, L.S_XTSTOP + r - 1]
    if r == 0 and states[c, L.S_LIVE] != 0.0:
        return (live_path_time(scal[r], states[c], t)[0] - scal[r, L.C_PHASE0]) / (dt / sub)
    if t < t_stop:
        return k * sub  # (path_time: its phase + t)
    return (path_time(scal[r], t, t_stop)[0] - scal[r, L.C_PHASE0]) / (dt / sub)


@njit(cache=True)
def _window_bound(samples, x0, y0, g, sub, dt, scal, steps_left, stride, states, out):
    """``SweptField.lower_bound``: out[c] = min over robots r and j in 1..steps_left of (least value of robot r's
    samples at the hip pivot's grid node from its path time tau_c to tau_c + j dt, one more each side) -
    j * stride; tau_c robot r's path time in state c, counted in samples (``window_start``)."""
    nx, ny, n = samples.shape[2], samples.shape[3], samples.shape[1]
    for c in range(states.shape[0]):
        ix = min(max(int(np.rint((states[c, L.S_X] - x0) / g)), 0), nx - 1)
        iy = min(max(int(np.rint((states[c, L.S_Y] - y0) / g)), 0), ny - 1)
        best = np.inf
        for r in range(samples.shape[0]):
            start = window_start(scal, states, c, r, dt, sub)
            run = np.inf
            i = max(0, int(np.floor(start)) - 1)
            for j in range(1, steps_left + 1):
                hi = min(int(np.ceil(start + j * sub)) + 1, n - 1)
                while i <= hi:
                    v = samples[r, i, ix, iy]
                    if v < run:
                        run = v
                    i += 1
                b = run - j * stride
                if b < best:
                    best = b
        out[c] = best


@njit(cache=True, inline="always")
def point_axis_distance(px, py, pz, ax, ay, az, ux, uy, uz):
    """Distance from p to the capsule axis a + t u, t in [0, 1] (the capsule's surface is its radius closer)."""
    den = ux * ux + uy * uy + uz * uz
    t = 0.0
    if den > 0.0:
        t = ((px - ax) * ux + (py - ay) * uy + (pz - az) * uz) / den
        t = min(1.0, max(0.0, t))
    dx, dy, dz = px - ax - t * ux, py - ay - t * uy, pz - az - t * uz
    return np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, parallel=True)
def _sample_field(ra, rb, cap_r, x0, y0, g, z, out):
    """out[s, i, j]: least distance from (x0 + i g, y0 + j g, z) to the capsules of robot sample s."""
    for s in prange(out.shape[0]):
        for i in range(out.shape[1]):
            px = x0 + i * g
            for j in range(out.shape[2]):
                py = y0 + j * g
                best = np.inf
                for c in range(cap_r.shape[0]):
                    ax, ay, az = ra[s, c, 0], ra[s, c, 1], ra[s, c, 2]
                    d = point_axis_distance(px, py, z, ax, ay, az, rb[s, c, 0] - ax, rb[s, c, 1] - ay,
                                            rb[s, c, 2] - az) - cap_r[c]
                    if d < best:
                        best = d
                out[s, i, j] = best
