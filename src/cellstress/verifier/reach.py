"""The distance bound: where the worker cannot come near anything the robot can occupy in the time left.

**The worker.** Every point of the worker lies within ``radius`` of the hip pivot H = (x, y, hip height): the
legs hang from it, the trunk, head and shoulders turn rigidly about it (``kernels.body.pose_body``), the arms
hang from the shoulders and the reach volumes lie within the arm's length of them (fences only shorten a
reach). The reach field is a grid, so ``REACH_SLACK`` grid spacings are added for its interpolation. H moves
only when the worker walks, by one stride (walking speed x dt) per step at most; turning and bending do not move
it.

**The robot.** Before its stop takes effect the robot's path time is tau0 + t; braking only slows it down
(``kernels.robot.path_time``), and a stop latched later takes effect later. So at a step k' after step k,
whatever the devices do, the robot's pose is its path's pose at some path time in [tau0 + k dt, tau0 + k' dt].
The path is sampled every ``dt / SUB`` of path time; between samples no point of a capsule axis moves more than
``speed`` x half the spacing, where ``speed`` bounds every capsule point's speed along the path: the sum over the
joints that move it of the joint's peak speed (a minimum-jerk segment peaks at 1.875 times its mean speed) times
the point's distance from the joint's origin (at most the lengths of the links in between, the slides of the
prismatic joints in between, and the capsule's end), plus each prismatic joint's own peak speed.

**The field.** For each robot sample, the distance from every node of a floor grid (spacing ``GRID``, at hip
height) to the sample's capsules, less the sampling allowance and half a grid diagonal: the true distance from
any H to that sample's neighbourhood is at least its nearest node's value.

A state at step k whose stop has not taken effect is safe when, for every later step k' of the episode, the
least of those values over the samples of path times [tau0 + k dt, tau0 + k' dt] at its pivot's node, less
(k' - k) strides and the worker's radius, exceeds the criterion's contact distance.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.sim import layout as L
from cellstress.sim.kernels.body import worker_radius as body_radius
from cellstress.sim.kernels.sweep import flag_distance
from cellstress.sim.scene import robot_capsules
from cellstress.sim.speeds import capsule_speeds

GRID = 0.05  # m: floor grid of the field
SUB = 4  # robot samples per time step


def worker_radius(body: np.ndarray, reach_spacing: float) -> float:
    """A radius about the hip pivot that holds every point of the paper's worker, in every pose (see the module:
    ``kernels.body.worker_radius``, the one the swept contact test uses too)."""
    return float(body_radius(body, 0.0, reach_spacing))


def robot_point_speed(layout) -> float:
    """An upper bound on the speed of any point of any of robot 0's capsule axes per second of path time."""
    return float(capsule_speeds(layout.robots[0]).max(initial=0.0))


class SweptField:
    """The distance bound of one simulator (cell and phase) for episodes of ``horizon`` actions."""

    def __init__(self, sim, horizon: int):
        P = sim.params
        self.dt = float(P.scal[L.C_DT])
        self.spa = P.spa
        # a step may count as unsafe up to this d_HR: the contact distance, or where the swept test between the
        # steps cannot rule a contact out (kernels.sweep.flag_distance)
        self.dtol = flag_distance(P) if P.scal[L.C_SWEEP] != 0.0 else float(P.scal[L.C_DTOL])
        self.stride = float(P.body[L.B_WALK_SPEED]) * self.dt
        self.radius = worker_radius(P.body, float(P.scal[L.C_REACH_H]))
        self.hip = float(P.body[L.B_HIP_Z])
        steps = horizon * self.spa
        delta = self.dt / SUB
        tau0 = float(P.scal[L.C_PHASE0])
        n = steps * SUB + 2
        ra = np.empty((n, len(P.cap_r), 3))
        rb = np.empty_like(ra)
        for i in range(n):
            ra[i], rb[i] = robot_capsules(sim.layout, tau0 + i * delta)
        self.allowance = robot_point_speed(sim.layout) * delta / 2.0
        fl = P.floor
        self.x0, self.y0 = float(fl[0]), float(fl[2])
        nx = int(np.ceil((fl[1] - fl[0]) / GRID)) + 1
        ny = int(np.ceil((fl[3] - fl[2]) / GRID)) + 1
        self.samples = np.empty((n, nx, ny))
        _sample_field(ra, rb, P.cap_r, self.x0, self.y0, GRID, self.hip, self.samples)
        self.samples -= self.allowance + GRID * np.sqrt(0.5)

    def lower_bound(self, step: int, steps_left: int, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """A lower bound, over the next ``steps_left`` steps after step ``step``, on the distance from the hip
        pivot (started at (x, y), walking a stride a step) to the robot: for each later step k, the least
        distance to the samples of path times [tau0 + step dt, tau0 + k dt] (one more sample each side, for
        rounding), less the strides walked by step k."""
        out = np.empty(len(x))
        _window_bound(self.samples, self.x0, self.y0, GRID, SUB, int(step), int(steps_left), self.stride,
                      np.ascontiguousarray(x), np.ascontiguousarray(y), out)
        return out

    def safe(self, children: np.ndarray, steps_left: int) -> np.ndarray:
        """Children (all at the same step) that no completion of ``steps_left`` steps brings within the contact
        distance; only those whose stop has not taken effect (the window assumes it)."""
        if not len(children):
            return np.zeros(0, dtype=bool)
        step = int(children[0, L.S_K])
        t = children[:, L.S_K] * self.dt
        d = self.lower_bound(step, steps_left, children[:, L.S_X], children[:, L.S_Y])
        return (t < children[:, L.S_TSTOP]) & (d - self.radius > self.dtol)


@njit(cache=True)
def _window_bound(samples, x0, y0, g, sub, step, steps_left, stride, xs, ys, out):
    """``SweptField.lower_bound``: out[c] = min over k in step+1..step+steps_left of (least sample value at the
    hip pivot's grid node over samples (step * sub - 1) .. (k * sub + 1)) - (k - step) * stride."""
    nx, ny, n = samples.shape[1], samples.shape[2], samples.shape[0]
    lo = max(0, step * sub - 1)
    for c in range(xs.shape[0]):
        ix = min(max(int(np.rint((xs[c] - x0) / g)), 0), nx - 1)
        iy = min(max(int(np.rint((ys[c] - y0) / g)), 0), ny - 1)
        best = np.inf
        run = np.inf
        i = lo
        for k in range(step + 1, step + steps_left + 1):
            hi = min(k * sub + 1, n - 1)
            while i <= hi:
                v = samples[i, ix, iy]
                if v < run:
                    run = v
                i += 1
            b = run - (k - step) * stride
            if b < best:
                best = b
        out[c] = best


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
                    ux, uy, uz = rb[s, c, 0] - ax, rb[s, c, 1] - ay, rb[s, c, 2] - az
                    den = ux * ux + uy * uy + uz * uz
                    f = 0.0
                    if den > 0.0:
                        f = ((px - ax) * ux + (py - ay) * uy + (z - az) * uz) / den
                        f = min(1.0, max(0.0, f))
                    dx, dy, dz = px - ax - f * ux, py - ay - f * uy, z - az - f * uz
                    d = np.sqrt(dx * dx + dy * dy + dz * dz) - cap_r[c]
                    if d < best:
                        best = d
                out[s, i, j] = best
