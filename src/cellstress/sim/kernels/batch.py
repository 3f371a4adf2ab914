"""Whole episodes: one, many in parallel, and one action at a time from Python through a handle."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import List, njit, prange
from cellstress.sim.geometry import NO_REFCOUNT
from cellstress.sim.kernels.params import make_work
from cellstress.sim.kernels.step import sense_and_measure, step_action
from cellstress.sim.layout import M_D, M_V, NM, S_K, S_UNSAFE

BATCH_CHUNK = 32  # episodes per work-array set in run_batch

# Integer constants handed to the non-inlined step kernels are np.int64(...): numba types a bare constant as a
# literal and compiles the callee once more for it (a cold start spent ~28 s on a second sense_and_measure and
# ~28 s on two more step_actions that way).


@njit(cache=True, error_model="numpy")
def run_episode(P, s0, actions, out):
    """Play ``actions`` from s0; out[0] is the initial row. Returns the number of rows written."""
    W = make_work(P)
    state = s0.copy()
    sense_and_measure(P, state, W, out[0], np.int64(-1))
    n = np.int64(1)
    for a in range(actions.shape[0]):
        n += step_action(P, state, actions[a], W, out, n)
        if state[S_UNSAFE] != 0.0:
            break
    return n


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _batch_episode(P, s0, actions, e, W, state, rows, d_end, v_end, unsafe_step, min_d):
    """Episode e of run_batch, on the given work arrays."""
    n_act = actions.shape[1]
    for i in range(s0.shape[0]):
        state[i] = s0[i]
    unsafe_step[e] = -1
    lo = np.inf
    for k in range(n_act):
        n = step_action(P, state, actions[e, k], W, rows, np.int64(0))
        for i in range(n):
            if rows[i, M_D] < lo:
                lo = rows[i, M_D]
        d_end[e, k] = rows[n - 1, M_D]
        v_end[e, k] = rows[n - 1, M_V]
        if state[S_UNSAFE] != 0.0:
            unsafe_step[e] = int(state[S_K])
            for kk in range(k + 1, n_act):
                d_end[e, kk] = np.nan
                v_end[e, kk] = np.nan
            break
    min_d[e] = lo


@njit(cache=True, error_model="numpy", parallel=True)
def run_batch(P, s0, actions, d_end, v_end, unsafe_step, min_d):
    """Many episodes from the same s0. For episode e and action k: d_HR and v_R at the action's end
    (d_end[e, k], v_end[e, k]; NaN after an unsafe end), unsafe_step[e] the first unsafe time step or -1,
    min_d[e] the smallest d_HR seen."""
    n_ep, n_act = actions.shape
    spa = P.spa
    # Work arrays per chunk of episodes, not per episode: an episode's results do not depend on what the
    # arrays held before (Simulator.step reuses one set for every call), and allocating them costs ~3 %.
    n_chunks = (n_ep + BATCH_CHUNK - 1) // BATCH_CHUNK
    for chunk in prange(n_chunks):
        W = make_work(P)
        state = s0.copy()
        rows = np.empty((spa, NM))
        for e in range(chunk * BATCH_CHUNK, min(n_ep, (chunk + 1) * BATCH_CHUNK)):
            _batch_episode(P, s0, actions, e, W, state, rows, d_end, v_end, unsafe_step, min_d)


# Calling a compiled function types every argument: SimParams and Work hold about 50 arrays, which costs
# ~9 us per call, more than an action's physics. A typed list holding both is typed in one look-up.
@njit(cache=True)
def make_handle(P, W):
    h = List()
    h.append((P, W))
    return h


@njit(cache=True, error_model="numpy")
def step_with_handle(h, state, action, out):
    """step_action(P, state, action, W, out, 0) for the (P, W) in handle h."""
    P, W = h[0]
    return step_action(P, state, action, W, out, np.int64(0))
