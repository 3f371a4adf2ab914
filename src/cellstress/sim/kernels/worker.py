"""The worker's own motion and distances, without robot or devices: what ``plan`` predicts with
(``Simulator.worker_paths``, ``worker_distances``). Many candidate sequences per call, so both run their
episodes or poses in parallel, each chunk on work arrays of its own; and a path can resume from the state a
sequence's earlier actions led to, so a candidate that shares a played prefix does not walk it again."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.sim.geometry import segment_segment_xyz
from cellstress.sim.kernels.body import pose_body
from cellstress.sim.kernels.fences import collect_near_fences
from cellstress.sim.kernels.params import make_work
from cellstress.sim.kernels.reach import reach_value_at
from cellstress.sim.kernels.step import begin_action, move_worker
from cellstress.sim.layout import (
    B_ARM_LEN,
    B_N_CAPS,
    C_REACH_H,
    C_REACH_ORIGIN,
    NS,
    POSE_EXT,
    S_DROP,
    S_FWD,
    S_HEADING,
    S_K,
    S_LAT,
    S_X,
    S_Y,
)

PATH_CHUNK = 16  # episodes per work-array set (each walks actions * spa steps)
POSE_CHUNK = 256  # poses per work-array set


@njit(cache=True, error_model="numpy")
def worker_path(P, start, first, actions, W, state, out, ends):
    """One episode of ``worker_paths``: from ``start``, the state as action ``first`` begins, the poses of every
    step from then on (out[first * spa:], layout.POSE_STATE's order) and the state as each later action begins
    and as the last ends (ends[first + 1:]; ends[first] = start). Its own kernel, not inlined into the parallel
    loop (as ``batch.run_batch`` keeps ``step_action`` apart: ``dense.dense_episode`` says why)."""
    spa = P.spa
    for i in range(NS):
        state[i] = start[i]
        ends[first, i] = start[i]
    k = first * spa
    for a in range(first, actions.shape[0]):
        h0, f0, l0 = state[S_HEADING], state[S_FWD], state[S_LAT]
        begin_action(P, state, W)
        for j in range(1, spa + 1):
            move_worker(P, state, actions[a], h0, f0, l0, j / spa, W)
            state[S_K] += 1.0  # (a door pushed opens on the clock)
            out[k, 0], out[k, 1], out[k, 2] = state[S_X], state[S_Y], state[S_HEADING]
            out[k, 3], out[k, 4] = state[S_FWD], state[S_LAT]
            for i in range(11):
                out[k, POSE_EXT + i] = state[S_DROP + i]
            k += 1
        for i in range(NS):
            ends[a + 1, i] = state[i]


@njit(cache=True, error_model="numpy", parallel=True)
def worker_paths(P, starts, first, actions, out, ends):
    """The worker's poses at every time step of each episode of ``actions`` (n, n_actions), as if no contact
    ended it: the open-loop part of the simulation (``move_worker``), without robot, devices or measuring.
    Episode e starts from starts[e], the state as its action first[e] begins (the state s0 and 0 for a whole
    episode; else an ``ends`` row of an earlier call); out (n, n_actions * spa, N_POSE) gets the steps from
    then on, ends (n, n_actions + 1, NS) the state at each action's start from first[e] on, and at the end. A
    door without guard locking opens here as played; one with guard locking stays locked (the robot's rest is
    not simulated)."""
    n = actions.shape[0]
    for chunk in prange((n + PATH_CHUNK - 1) // PATH_CHUNK):
        W = make_work(P)
        state = np.empty(NS)
        for e in range(chunk * PATH_CHUNK, min(n, (chunk + 1) * PATH_CHUNK)):
            worker_path(P, starts[e], first[e], actions[e], W, state, out[e], ends[e])


@njit(cache=True, error_model="numpy")
def worker_pose_distances(P, W, pose, points, out):
    """out[j]: distance from the worker at ``pose`` (layout.POSE_STATE's order) to the point points[j], as
    ``separation`` measures the paper worker's side of d_HR: the nearer of the two reach volumes (fences
    respected) and the body capsules; inf for a NaN point. The robot plays no part. For the articulated worker
    the reach volumes are its conservative envelope: where its arms could be within the action that follows.
    Its own kernel, not inlined into the parallel loop (``worker_path``)."""
    arm, origin, grid_h = P.body[B_ARM_LEN], P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H]
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    n_caps = int(P.body[B_N_CAPS])
    pose_body(P.body, pose[0], pose[1], pose[2], pose[3], pose[4], pose, POSE_EXT, ha, hb, hr, sh, tr)
    n_near = collect_near_fences(P.fences, sh, W.near, arm + 0.05)
    for j in range(points.shape[0]):
        px, py, pz = points[j, 0], points[j, 1], points[j, 2]
        if np.isnan(px):
            out[j] = np.inf
            continue
        best = np.inf
        for side in range(2):
            best = min(best, reach_value_at(P.reach, origin, grid_h, arm, P.fences, W.near, sh, tr, side, n_near,
                                          px, py, pz))
        for c in range(n_caps):
            d2 = segment_segment_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     px, py, pz, px, py, pz)[0]
            best = min(best, np.sqrt(d2) - hr[c])
        out[j] = best


@njit(cache=True, error_model="numpy", parallel=True)
def worker_point_distances(P, poses, points, out):
    """out[i, j]: ``worker_pose_distances`` from poses[i] to points[i, j]."""
    n = poses.shape[0]
    for chunk in prange((n + POSE_CHUNK - 1) // POSE_CHUNK):
        W = make_work(P)
        for i in range(chunk * POSE_CHUNK, min(n, (chunk + 1) * POSE_CHUNK)):
            worker_pose_distances(P, W, poses[i], points[i], out[i])
