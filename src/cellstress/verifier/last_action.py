"""The last action's bound: a child of the last layer is safe when no pose its action can take comes near the robot.

The distance bound (``verifier.reach``) has to take every pose the worker can reach in the actions left, so it
grows the hip pivot by the worker's whole radius. In the last layer the action is known, and so is every pose it
can pass through. For the paper's worker (``kernels.step.move_worker``) an action moves its heading, forward and
lateral flexion linearly from the state's to their targets over the action, and a step that is blocked keeps
the step before's; so every pose of the action, and every pose on the straight lines between its steps that
the swept contact test looks at, has its (heading, flexions) on the line q(s), s in [0, 1], from the state's to
the action's targets. Its position lies on the segment from the state's along the walking direction, as long
as a stride (blocked strides stay) when the action does not turn, or within that far of it when it does.

**Key points.** Every point of the worker lies within a radius of one of its key points (``key_points``): the
points along each leg, the trunk and the head (spaced at most ``KEY_SPACING``; radius: the capsule's, plus half
the spacing), and the two shoulders (radius: the arm's length plus the largest arm radius and the reach field's
slack, as in the worker's radius: the hanging arms and the reach volumes lie within it). A key point k offset
from the pivot moves with s at a speed of at most |k| |dh| + (|k0| + 2 |k1| + |k2|) |df| + (|k1| + |k2|) |dl|
(the trunk frame's derivatives; ``key_speed`` takes the largest over the key points), so sampling q at
``POSTURES`` + 1 values of s, each sample stands for its neighbourhood less half a spacing times that speed.
The position is sampled at the middle of ``SPOTS`` equal pieces of the segment, less half a piece.

**The robot** over the action is at a path time in [tau_k, tau_k + spa dt] (``reach.window_start``, one more
sample each side), sampled every dt / 4 as for the distance bound. For each window a 3-D grid (``GRID3``) holds
the least distance from each node to the robot's capsules at those samples, less how far a capsule point moves
between samples, computed the first time a node is read (most of the grid never is); a key point's value is its
nearest node's less the distance to it. Two spheres per pose (the legs; the trunk, head, arms and reach about
the shoulders' middle) are tried first, and the key points only for a child they do not clear.

A child is safe when, for every robot, the least over its sampled poses and key points of (value - radius)
less the two sampling allowances exceeds the largest distance at which the swept contact test may still count a
contact (``kernels.sweep.flag_distance``). Such a child is not played: its sequences are counted safe.
``tests/verifier/test_verify_last_action.py`` checks the key points against the worker's distance function, the
key-point speed against densely sampled actions, and the bound against the d_HR the played children measure.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.human.actions import A_DIR, A_FWD, A_LAT, A_SET_TRUNK, A_TURN, A_WALK
from cellstress.sim import layout as L
from cellstress.sim.kernels.body import REACH_SLACK, pose_body
from cellstress.verifier.reach import SUB, point_axis_distance, window_start

GRID3 = 0.1  # m: the 3-D grid of the window fields
KEY_SPACING = 0.1  # m: the largest gap between key points along a leg or the trunk
POSTURES = 12  # pieces of the posture line sampled per action
SPOTS = 4  # pieces of the walking segment sampled per action


def applies(sim) -> bool:
    """The bound is written for the paper's worker (its poses: heading and two flexions on a line per action)."""
    return float(sim.params.body[L.B_MODEL]) == 0.0


class LastAction:
    """The last action's bound of one simulator; built from its ``reach.SweptField`` (the robot's samples)."""

    def __init__(self, sim, swept):
        P = sim.params
        self.params = P
        self.swept = swept
        b = P.body
        self.r_shoulder = float(b[L.B_ARM_LEN] + max(b[L.B_R_ARM], b[L.B_R_UPPER], b[L.B_R_FORE], b[L.B_R_HAND])
                                + REACH_SLACK * P.scal[L.C_REACH_H])
        fl = P.floor
        self.x0, self.y0, self.z0 = float(fl[0]), float(fl[2]), 0.0
        self.nx = int(np.ceil((fl[1] - fl[0]) / GRID3)) + 1
        self.ny = int(np.ceil((fl[3] - fl[2]) / GRID3)) + 1
        top = float(b[L.B_HIP_Z] + max(b[L.B_HEAD_RISE] + b[L.B_R_HEAD], b[L.B_TRUNK_TOP] + b[L.B_R_TRUNK],
                                       b[L.B_SHOULDER_RISE]))
        self.nz = int(np.ceil(top / GRID3)) + 1
        # every robot's capsules at every sample in one array (a robot with fewer capsules is padded with
        # capsules of radius -inf, which are never the nearest)
        n_caps = max(len(cr) for _, _, cr, _ in swept.robots)
        n_samples = swept.robots[0][0].shape[0]
        self.ra = np.zeros((len(swept.robots), n_samples, n_caps, 3))
        self.rb = np.zeros_like(self.ra)
        self.cap_r = np.full((len(swept.robots), n_caps), -np.inf)
        self.allowance = np.array([allow for _, _, _, allow in swept.robots])
        for r, (ra, rb, cr, _) in enumerate(swept.robots):
            self.ra[r, :, :len(cr)], self.rb[r, :, :len(cr)], self.cap_r[r, :len(cr)] = ra, rb, cr
        # the window fields, filled node by node as the bound reads them (NaN: not yet), and which robot and
        # samples each one is of
        self._index: dict[tuple[int, int, int], int] = {}
        self._fields = np.full((4, self.nx, self.ny, self.nz), np.nan)
        self._meta = np.zeros((4, 3), dtype=np.int64)

    def _field(self, r: int, lo: int, hi: int) -> int:
        """The index of robot r's window field over samples lo..hi."""
        key = (r, lo, hi)
        i = self._index.get(key)
        if i is None:
            i = self._index[key] = len(self._index)
            if i == len(self._fields):  # grow, keeping the nodes filled so far
                more = np.full_like(self._fields, np.nan)
                self._fields = np.concatenate([self._fields, more])
                self._meta = np.concatenate([self._meta, np.zeros_like(self._meta)])
            self._meta[i] = (r, lo, hi)
        return i

    def safe(self, parents: np.ndarray) -> np.ndarray:
        """(n parents, n actions): the children no pose of their action brings within the flag distance."""
        return self.lower_bound(parents, stop=True) > self.swept.dtol

    def lower_bound(self, parents: np.ndarray, stop: bool = False) -> np.ndarray:
        """(n parents, n actions): a lower bound on d_HR over each child's action (module docstring); ``stop``:
        only whether it exceeds the flag distance matters (where it does not, the value is only at most that)."""
        P, sw = self.params, self.swept
        parents = np.ascontiguousarray(parents)
        n_rob = len(sw.scal)
        n_samples = sw.samples.shape[1]
        starts = np.empty((len(parents), n_rob))
        _starts(sw.scal, sw.dt, SUB, parents, starts)
        which = np.empty((len(parents), n_rob), dtype=np.int64)
        for c in range(len(parents)):
            for r in range(n_rob):
                lo = max(0, int(np.floor(starts[c, r])) - 1)
                hi = min(int(np.ceil(starts[c, r] + P.spa * SUB)) + 1, n_samples - 1)
                which[c, r] = self._field(r, lo, hi)
        out = np.empty((len(parents), P.act.shape[0]))
        robots = (self.ra, self.rb, self.cap_r, self.allowance, self._meta)
        _children_bound(P.body, P.act, P.spa, float(P.body[L.B_WALK_SPEED]) * sw.dt, self.r_shoulder, parents,
                        self._fields, robots, which, self.x0, self.y0, self.z0, GRID3, sw.dtol if stop else -np.inf,
                        out)
        return out


@njit(cache=True)
def _starts(scal, dt, sub, states, out):
    for c in range(states.shape[0]):
        for r in range(out.shape[1]):
            out[c, r] = window_start(scal, states, c, r, dt, sub)


@njit(cache=True, inline="always")
def _node(robots, f, px, py, pz):
    """Field f's value at a node: the least distance from it to its robot's capsules at its samples, less how far
    a capsule point moves between samples."""
    ra, rb, cap_r, allowance, meta = robots
    r, lo, hi = meta[f, 0], meta[f, 1], meta[f, 2]
    best = np.inf
    for s in range(lo, hi + 1):
        for c in range(cap_r.shape[1]):
            ax, ay, az = ra[r, s, c, 0], ra[r, s, c, 1], ra[r, s, c, 2]
            d = point_axis_distance(px, py, pz, ax, ay, az, rb[r, s, c, 0] - ax, rb[r, s, c, 1] - ay,
                                    rb[r, s, c, 2] - az) - cap_r[r, c]
            if d < best:
                best = d
    return best - allowance[r]


@njit(cache=True, inline="always")
def _value(fields, robots, f, x0, y0, z0, g, px, py, pz):
    """A lower bound on the distance from p to field f's robot: its nearest node's value (computed the first time
    it is read; threads that race write the same value) less the way there."""
    i = min(max(int(np.rint((px - x0) / g)), 0), fields.shape[1] - 1)
    j = min(max(int(np.rint((py - y0) / g)), 0), fields.shape[2] - 1)
    m = min(max(int(np.rint((pz - z0) / g)), 0), fields.shape[3] - 1)
    nx, ny, nz = x0 + i * g, y0 + j * g, z0 + m * g
    v = fields[f, i, j, m]
    if np.isnan(v):
        v = _node(robots, f, nx, ny, nz)
        fields[f, i, j, m] = v
    dx, dy, dz = px - nx, py - ny, pz - nz
    return v - np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True)
def key_speed(b, dh, df, dl):
    """How far any key point (a leg's, the trunk's, the head's, a shoulder's) moves per unit of s when the
    heading turns by dh, the forward flexion by df and the lateral by dl over the action (module docstring)."""
    best = 0.0
    # offsets from the pivot in the trunk frame (forward, left, up): the legs' ends, the trunk's top, the head,
    # a shoulder; the legs turn with the heading only (they stay plumb)
    for k0, k1, k2, plumb in ((0.0, b[L.B_LEG_HALF], b[L.B_HIP_Z], 1.0), (0.0, 0.0, b[L.B_TRUNK_TOP], 0.0),
                              (0.0, 0.0, b[L.B_HEAD_RISE], 0.0),
                              (0.0, b[L.B_SHOULDER_HALF], b[L.B_SHOULDER_RISE], 0.0)):
        norm = np.sqrt(k0 * k0 + k1 * k1 + k2 * k2)
        v = norm * abs(dh)
        if plumb == 0.0:
            v += (abs(k0) + 2.0 * abs(k1) + abs(k2)) * abs(df) + (abs(k1) + abs(k2)) * abs(dl)
        if v > best:
            best = v
    return best


@njit(cache=True, inline="always")
def _key_points(b, ha, hb, hr, sh, kp, kr):
    """The key points of a posed paper worker (posed at x = y = 0) into kp, their radii into kr; returns how many:
    points along the legs, the trunk and the head (capsules 0-3), each with the capsule's radius plus half the
    spacing, and the two shoulders with the arm's reach (kr[-2:] set by the caller)."""
    n = 0
    for k in range(4):
        length = np.sqrt((hb[k, 0] - ha[k, 0]) ** 2 + (hb[k, 1] - ha[k, 1]) ** 2 + (hb[k, 2] - ha[k, 2]) ** 2)
        m = max(1, int(np.ceil(length / KEY_SPACING)))
        for i in range(m):
            f = (i + 0.5) / m
            for d in range(3):
                kp[n, d] = ha[k, d] + f * (hb[k, d] - ha[k, d])
            kr[n] = hr[k] + 0.5 * length / m
            n += 1
    for k in range(2):
        for d in range(3):
            kp[n, d] = sh[k, d]
        n += 1
    return n


@njit(cache=True, parallel=True)
def _children_bound(b, act, spa, stride, r_shoulder, states, fields, robots, which, x0, y0, z0, g, stop_at, out):
    """out[c, a]: the last action's lower bound on d_HR for parent c and action a (module docstring); where it
    falls to ``stop_at`` or below, the search stops and out[c, a] is only at most ``stop_at`` (-inf: never)."""
    n_caps = int(b[L.B_N_CAPS])
    # the two coarse spheres: the plumb legs about the middle of their height, and about the shoulders' middle
    # the shoulders' reach (r_shoulder past either shoulder), the trunk down to the hip and the head
    legs_z = 0.5 * b[L.B_HIP_Z]
    legs_r = np.sqrt(legs_z * legs_z + b[L.B_LEG_HALF] ** 2) + b[L.B_R_LEG]
    upper_r = max(b[L.B_SHOULDER_HALF] + r_shoulder, b[L.B_SHOULDER_RISE] + b[L.B_R_TRUNK],
                  abs(b[L.B_TRUNK_TOP] - b[L.B_SHOULDER_RISE]) + b[L.B_R_TRUNK],
                  abs(b[L.B_HEAD_RISE] - b[L.B_SHOULDER_RISE]) + b[L.B_R_HEAD])
    for c in prange(states.shape[0]):
        ha, hb, hr = np.empty((n_caps, 3)), np.empty((n_caps, 3)), np.empty(n_caps)
        sh, tr, ext = np.empty((2, 3)), np.empty((3, 3)), np.zeros(16)
        kp, kr = np.empty((64, 3)), np.empty(64)
        x, y = states[c, L.S_X], states[c, L.S_Y]
        h0, f0, l0 = states[c, L.S_HEADING], states[c, L.S_FWD], states[c, L.S_LAT]
        for a in range(act.shape[0]):
            dh = act[a, A_TURN]
            df = (act[a, A_FWD] - f0) if act[a, A_SET_TRUNK] != 0.0 else 0.0
            dl = (act[a, A_LAT] - l0) if act[a, A_SET_TRUNK] != 0.0 else 0.0
            length = abs(act[a, A_WALK]) * stride * spa  # how far the pivot can walk over the action
            spots = SPOTS if length > 0.0 and dh == 0.0 else 1
            ux, uy = np.cos(h0 + act[a, A_DIR]), np.sin(h0 + act[a, A_DIR])
            # a straight walk: the middle of each piece less half a piece; a turning walk: anywhere within length
            slack = 0.5 * length / spots if dh == 0.0 else length
            speed = key_speed(b, dh, df, dl)
            n_q = 0 if speed == 0.0 else POSTURES  # (a posture that does not move: its one pose)
            if n_q:
                slack += 0.5 * speed / n_q
            # first two spheres per pose (the legs; the trunk, head, arms and reach about the shoulders'
            # middle): enough for most children; the key points only where they are not
            coarse = np.inf
            for q in range(n_q + 1):
                s = q / n_q if n_q else 0.0
                pose_body(b, 0.0, 0.0, h0 + dh * s, f0 + df * s, l0 + dl * s, ext, 0, ha, hb, hr, sh, tr)
                for p in range(spots):
                    off = (p + 0.5) / spots * length if dh == 0.0 else 0.0
                    px, py = x + off * ux, y + off * uy
                    for r in range(which.shape[1]):
                        f = which[c, r]
                        v = _value(fields, robots, f, x0, y0, z0, g, px, py, legs_z) - legs_r
                        if v < coarse:
                            coarse = v
                        mx, my, mz = (sh[0, 0] + sh[1, 0]) / 2, (sh[0, 1] + sh[1, 1]) / 2, (sh[0, 2] + sh[1, 2]) / 2
                        v = _value(fields, robots, f, x0, y0, z0, g, px + mx, py + my, mz) - upper_r
                        if v < coarse:
                            coarse = v
            if coarse - slack > stop_at and stop_at > -np.inf:
                out[c, a] = coarse - slack
                continue
            best = np.inf
            for q in range(n_q + 1):
                s = q / n_q if n_q else 0.0
                pose_body(b, 0.0, 0.0, h0 + dh * s, f0 + df * s, l0 + dl * s, ext, 0, ha, hb, hr, sh, tr)
                n_key = _key_points(b, ha, hb, hr, sh, kp, kr)
                kr[n_key - 2] = r_shoulder
                kr[n_key - 1] = r_shoulder
                for p in range(spots):
                    off = (p + 0.5) / spots * length if dh == 0.0 else 0.0
                    px, py = x + off * ux, y + off * uy
                    for r in range(which.shape[1]):
                        f = which[c, r]
                        for k in range(n_key):
                            v = _value(fields, robots, f, x0, y0, z0, g, px + kp[k, 0], py + kp[k, 1], kp[k, 2]) - kr[k]
                            if v < best:
                                best = v
                    if best - slack <= stop_at:
                        break
                if best - slack <= stop_at:
                    break
            out[c, a] = best - slack
