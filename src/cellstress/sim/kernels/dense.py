"""The swept contact test's cross-check: episodes whose contact is tested at every step and at evenly spaced
moments between the steps, on the same continuous motion (``kernels.sweep``: the worker on the straight line
between its sampled poses, the robot on its path), with no bound and no halving. ``benchmarks/sweep_check.py``
compares it with the swept test."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.sim.kernels.params import make_work
from cellstress.sim.kernels.step import begin_action, move_worker, sense_and_measure
from cellstress.sim.kernels.sweep import _possible, _sample
from cellstress.sim.layout import C_DT, C_DTOL, NM, NS, S_FWD, S_HEADING, S_K, S_LAT


@njit(cache=True, error_model="numpy")
def dense_episode(P, s0, actions, n_sub):
    """The first step of the episode ``actions`` (played from s0 with ``P``'s swept test off) at which the kernel
    test holds at the step's sample or at one of the ``n_sub - 1`` moments evenly between it and the previous
    step, in a pose the worker can be in (``sweep._possible``); -1: none. Its own kernel, not inlined into
    ``dense_batch``'s parallel loop: compiled there (the step's inlined functions under the parallel
    transforms), it reported contacts the same code called step by step does not (reach-over, numba 0.68), as
    ``batch.run_batch`` keeps ``step_action`` apart too."""
    spa = P.spa
    dt = P.scal[C_DT]
    W = make_work(P)
    state = s0.copy()
    prev = np.empty(NS)
    row = np.empty(NM)
    srow = np.empty(NM)
    for a in range(actions.shape[0]):
        action = actions[a]
        h0, f0, l0 = state[S_HEADING], state[S_FWD], state[S_LAT]
        begin_action(P, state, W)
        for j in range(1, spa + 1):
            for i in range(NS):
                prev[i] = state[i]
            move_worker(P, state, action, h0, f0, l0, j / spa, W)
            state[S_K] += 1.0
            unsafe = sense_and_measure(P, state, W, row, action)
            t0 = state[S_K] * dt - dt
            for m in range(1, n_sub):
                if unsafe:
                    break
                d, moving, _ = _sample(P, prev, state, W, m / n_sub, t0, srow)
                unsafe = d <= P.scal[C_DTOL] and moving and _possible(P, W)
            if unsafe:
                return int(state[S_K])
    return -1


@njit(cache=True, error_model="numpy", parallel=True)
def dense_batch(P, s0, actions, n_sub, unsafe_step):
    """unsafe_step[e]: ``dense_episode`` of episode e (actions[e])."""
    for e in prange(actions.shape[0]):
        unsafe_step[e] = dense_episode(P, s0, actions[e], n_sub)
