"""Brute force for the verifier's cross-checks: every action prefix played, none merged, none pruned.

The tree of all n^h sequences (n: the worker's actions per decision, 30 or 119) is walked layer by layer with
the same compiled step the simulator plays (``expand_states``): a prefix's children are its state stepped by
each action, an unsafe child ends its episode (all n^r completions hazardous), and nothing else is assumed.
Only the merging and the bounds of ``verifier.tree`` are left out, which is what these checks test; the step
itself is checked against ``Simulator.run_batch`` elsewhere.
"""

from __future__ import annotations

import numpy as np

from cellstress.sim import layout as L
from cellstress.sim.kernels.expand import expand_states

CHUNK = 2048  # parents per expansion (memory: CHUNK * n children)


def brute_force(sim, horizon: int) -> int:
    """The number of hazardous sequences of ``horizon`` actions from ``sim``'s start (its reset state)."""
    n_act = sim.n_actions
    s0 = sim.reset()
    if s0[L.S_UNSAFE] != 0.0:
        return n_act ** horizon
    assert sim.contacts is None, "brute force plays the kernel test only"
    states = s0[None, :].copy()
    hazardous = 0
    for depth in range(1, horizon + 1):
        weight = n_act ** (horizon - depth)
        alive = []
        for i0 in range(0, len(states), CHUNK):
            parents = states[i0:i0 + CHUNK]
            n = len(parents) * n_act
            children, last, d_min = np.empty((n, L.NS)), np.empty((n, L.NM)), np.empty(n)
            expand_states(sim.params, parents, n_act, children, last, d_min)
            unsafe = children[:, L.S_UNSAFE] != 0.0
            hazardous += int(np.count_nonzero(unsafe)) * weight
            if depth < horizon:
                alive.append(children[~unsafe])
        if depth < horizon:
            states = np.concatenate(alive) if alive else np.zeros((0, L.NS))
    return hazardous
