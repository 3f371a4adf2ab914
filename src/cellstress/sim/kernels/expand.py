"""Every child of many states at once: each state stepped by each of the worker's actions (``verify``'s
exhaustive expansion of the action tree).

A child is exactly what ``step_action`` makes of its parent: the same compiled step that ``run_episode`` and
``run_batch`` play, so a child's state is bit-identical to the state reached by playing its action prefix.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit, prange
from cellstress.sim.geometry import NO_REFCOUNT
from cellstress.sim.kernels.params import make_work
from cellstress.sim.kernels.step import step_action
from cellstress.sim.layout import M_D, NM, NS

EXPAND_CHUNK = 64  # children per work-array set in expand_pairs


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _expand_one(P, states, p, a, c, W, state, rows, children, last, d_min):
    """Child c = states[p] after action a, on the given work arrays."""
    for i in range(state.shape[0]):
        state[i] = states[p, i]
    n = step_action(P, state, np.int64(a), W, rows, np.int64(0))
    for i in range(state.shape[0]):
        children[c, i] = state[i]
    lo = np.inf
    for i in range(n):
        if rows[i, M_D] < lo:
            lo = rows[i, M_D]
    d_min[c] = lo
    for i in range(rows.shape[1]):
        last[c, i] = rows[n - 1, i] if n > 0 else np.nan


def expand_states(P, states, n_act, children, last, d_min):
    """children[i * n_act + a]: states[i] after action a (n_act actions, 0..n_act-1); last: the metric row of
    the child's last step, d_min: the least d_HR over the action's steps (NaN / inf for a parent that was
    already unsafe, which does not move). (``expand_pairs`` over every (parent, action) pair in that order.)"""
    parent = np.repeat(np.arange(states.shape[0]), n_act)
    action = np.tile(np.arange(n_act), states.shape[0])
    expand_pairs(P, states, parent, action, children, last, d_min)


@njit(cache=True, error_model="numpy", parallel=True)
def expand_pairs(P, states, parent, action, children, last, d_min):
    """children[i]: states[parent[i]] after action[i]; last and d_min as for ``expand_states``."""
    n_child = parent.shape[0]
    spa = P.spa
    # One work-array set per chunk of children, as run_batch does: a step's results do not depend on what the
    # arrays held before.
    n_chunks = (n_child + EXPAND_CHUNK - 1) // EXPAND_CHUNK
    for chunk in prange(n_chunks):
        W = make_work(P)
        state = np.empty(NS)
        rows = np.empty((spa, NM))
        for c in range(chunk * EXPAND_CHUNK, min(n_child, (chunk + 1) * EXPAND_CHUNK)):
            _expand_one(P, states, parent[c], action[c], c, W, state, rows, children, last, d_min)
