"""Predictive risk: can the robot, on its own programmed path, reach the worker's pose before it stops?

ISO 13855 sizes a safeguard by asking whether a person approaching at speed K reaches the hazard within
T, the time the machine needs to stop after the person is seen. ``lookahead_gaps`` asks that question of a
simulated episode, at every 50 ms time step k: keep the worker in the pose of step k (time t_k) and move the
robot on along its path to the times t_k + tau, tau = 0, dt, ..., ``horizon`` (the cycle is deterministic, and
the stop model is the simulator's: if a stop has been requested by step k the robot brakes as it did, else it
runs on unstopped). The gap of step k is

    g_k = min over those tau with v_R(t_k + tau) > speed tolerance of  d_HR(worker at k, robot at t_k + tau) - K tau

(d_HR as the simulator measures it: body capsules and reach volumes, fences respected). g_k <= 0 means that a
worker who kept moving towards the robot at K could meet it while it still moves; a large g_k means the
robot is far, stopped, or about to stop. Poses at which the robot stands still (in a dwell, or stopped) do not
count: contact with a still robot is not a hazard (contact-while-moving; under iso15066, which has no speed
tolerance, every pose with v_R > 0 counts). A step with no moving pose in its
window has gap +inf.

The default window is ISO 13855's T for the fastest device, its response time plus the robot's stopping time
(0.05 + 0.15 = 0.2 s in the reference cells): the shortest time for which the robot moves on after the worker
is first seen, whichever device sees them. The default K is ISO 13855's 1.6 m/s.

It is a *score* for searchers, not part of the simulation: the episode, its metric rows and its outcome are
unchanged, and no episode is played. The extra work is (horizon / dt + 1) robot poses and separations per time
step (5 for the default 0.2 s at 50 ms), done by the same compiled functions as the simulator's
(``kernels.robot_live``, ``kernels.human_pose``, ``kernels.near_fences``, ``kernels.separation``) on a Work of
its own; the kernels are not changed.

Why it helps: a closeness score measured at the same instant cannot tell a worker who stands at a light
curtain while the robot dwells from one who stands there just before the arm moves on (docs/results.md, S2).
The gap does: only the second has a moving robot within reach inside the window.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim import kernels as K
from cellstress.sim import layout as L


@njit(cache=True, error_model="numpy")
def lookahead_gaps(P, W, rows, t_stop, horizon, speed, n_tau, out):
    """g_k (module docstring) for each metric row of ``rows`` into ``out``.

    ``t_stop``: the time the robot's stop takes effect, as latched in the state after these rows (inf: none);
    it applies to the rows whose stop phase is not "running" (the phase of a row says whether a stop had been
    requested by then). The window [t_k, t_k + horizon] is sampled at n_tau + 1 equally spaced times.
    """
    scal = P.scal
    vtol = scal[L.C_VTOL]
    if not vtol < np.inf:  # a criterion without a speed tolerance (iso15066): any motion counts
        vtol = 0.0
    arm_len = P.body[L.B_ARM_LEN]
    origin, grid_h = scal[L.C_REACH_ORIGIN], scal[L.C_REACH_H]
    scratch = np.zeros(L.NM)
    pose = np.zeros(L.N_POSE)
    for i in range(rows.shape[0]):
        t0 = rows[i, L.M_T]
        ts = np.inf if rows[i, L.M_PHASE] == L.PHASE_RUNNING else t_stop
        for k in range(5):
            pose[k] = rows[i, L.M_X + k]
        for k in range(11):
            pose[L.POSE_EXT + k] = rows[i, L.M_DROP + k]
        K.human_pose(P, pose, W)
        n_near = K.near_fences(P, W, arm_len + 0.05)  # as sense_and_measure collects them
        best = np.inf
        for j in range(n_tau + 1):
            tau = horizon * j / n_tau if n_tau > 0 else 0.0
            v, _, _ = K.robot_live(P, t0 + tau, ts, W)
            if not v > vtol:
                continue
            d = K.separation(P.cap_r, P.reach, origin, grid_h, arm_len, P.fences, W.near, W.ra, W.rb, W.sh, W.tr,
                             W.ha, W.hb, W.hr, W.lbs, W.ts, W.best_r, n_near, scratch, L.N_BODY_CAPSULES)
            g = (d if d > 0.0 else 0.0) - speed * tau
            if g < best:
                best = g
        out[i] = best


def default_horizon(params) -> float:
    """T of ISO 13855 for the fastest device: its response time plus the robot's controller delay and braking
    time [s], the shortest time for which the robot moves on after a worker is first seen."""
    resp = float(np.min(params.dev_resp)) if params.dev_resp.size else 0.0
    return resp + float(params.scal[L.C_STOP_DELAY]) + float(params.scal[L.C_STOP_TIME])


class Lookahead:
    """``lookahead_gaps`` for one simulator, with its own Work (the simulator's is left alone).

    ``horizon`` [s]: the window (None: ``default_horizon``); ``speed`` [m/s]: K, the worker's approach speed
    (ISO 13855's 1.6 m/s for walking); the window is sampled every ``step`` seconds (None: the simulator's dt).
    """

    def __init__(self, params, horizon: float | None = None, speed: float = 1.6, step: float | None = None):
        if params.x_scal.shape[0]:  # several robots: the gap is robot 0's (its capsules only; the others unposed)
            params = params._replace(cap_r=np.ascontiguousarray(params.cap_r[:params.cap_joint.shape[0]]),
                                     cap_speed=np.ascontiguousarray(params.cap_speed[:params.cap_joint.shape[0]]))
        self.params = params
        self.horizon = default_horizon(params) if horizon is None else float(horizon)
        if not self.horizon >= 0.0 or not speed >= 0.0:
            raise ValueError("horizon and speed must be >= 0")
        self.speed = float(speed)
        dt = float(params.scal[L.C_DT]) if step is None else float(step)
        self.n_tau = max(0, int(round(self.horizon / dt)))
        self._work = K.make_work(params)

    def gaps(self, rows: np.ndarray, t_stop: float) -> np.ndarray:
        """g_k for each metric row (see the module docstring); ``t_stop`` from the state after the rows."""
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        out = np.empty(rows.shape[0])
        lookahead_gaps(self.params, self._work, rows, float(t_stop), self.horizon, self.speed, self.n_tau, out)
        return out
