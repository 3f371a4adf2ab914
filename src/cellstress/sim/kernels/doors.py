"""Interlocked guard doors: when the worker pushes one, when it opens, and where its leaf blocks; and the
panels that block on the cell's clock (a pallet passing a muted curtain's opening), and the muting itself.

A door's leaf is a row of ``P.fences`` (``P.door_fence``). The kernels block with ``W.fences``, a copy of them in
which ``place_doors`` moves the leaf of every passable door out of the way for the state at hand, so the fence
code (walking, the trunk, the arms' detours) needs no change and a cell without doors uses the same panels.
A door's two state slots (``S_DOOR_REQ + i``, ``S_DOOR_OPEN + i``) hold when it was pushed and when it started to
open; nothing closes it again within an episode.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.geometry import point_segment_2d
from cellstress.sim.layout import C_CYCLE, C_PHASE0, C_STOP_TIME, S_DOOR_OPEN, S_DOOR_REQ, S_TSTOP, S_XTSTOP

FAR = 1.0e6  # m: where a passable door's leaf is put: a point this far off is near nothing


@njit(cache=True, error_model="numpy", inline="always")
def robots_at_rest(P, state, d, t):
    """Every robot channel d stops stands at t: its latched stop took effect at least its stopping time ago.
    Braking from full speed takes exactly that long (``robot.path_time``), from a reduced speed less, so this is
    never early."""
    mask = P.dev_robots[d]
    if mask & 1 and t - state[S_TSTOP] < P.scal[C_STOP_TIME]:
        return False
    for r in range(P.x_scal.shape[0]):
        if mask >> (r + 1) & 1 and t - state[S_XTSTOP + r] < P.x_scal[r, C_STOP_TIME]:
            return False
    return True


@njit(cache=True, error_model="numpy", inline="always")
def door_passable(P, state, i, t):
    """Door i is open wide enough for a person at t: its opening time has passed since it started to open."""
    return t - state[S_DOOR_OPEN + i] >= P.door_open[i]


@njit(cache=True, error_model="numpy", inline="always")
def door_signals(P, state, d, t):
    """The interlock of the door whose channel is d signals at t: the door has been pushed (by then)."""
    for i in range(P.door_dev.shape[0]):
        if P.door_dev[i] == d:
            return state[S_DOOR_REQ + i] <= t
    return False


@njit(cache=True, error_model="numpy", inline="always")
def on_clock(P, t, a, b):
    """The cell's clock at t, (phase + t) modulo the robot's cycle, lies in [a, b] (b may run past the cycle's
    end: the window then wraps to its start)."""
    c = (P.scal[C_PHASE0] + t) % P.scal[C_CYCLE]
    return (a <= c <= b) or (a <= c + P.scal[C_CYCLE] <= b)


@njit(cache=True, error_model="numpy", inline="always")
def muted(P, d, t):
    """Channel d is muted at t (it sees nothing): the cell's clock is in its muting window."""
    return P.dev_muted[d, 0] < np.inf and on_clock(P, t, P.dev_muted[d, 0], P.dev_muted[d, 1])


@njit(cache=True, error_model="numpy", inline="always")
def _place(P, fences, f, blocks):
    if blocks:
        for j in range(6):
            fences[f, j] = P.fences[f, j]
    else:
        fences[f, 0] = fences[f, 1] = fences[f, 2] = fences[f, 3] = FAR


@njit(cache=True, error_model="numpy", inline="always")
def place_doors(P, state, fences, t):
    """``fences`` (a copy of P.fences) for the state at t: each door's leaf where it is while it blocks, a
    point far off once it is passable; each timed panel (a pallet) in place only within its clock window."""
    for i in range(P.door_fence.shape[0]):
        _place(P, fences, P.door_fence[i], not door_passable(P, state, i, t))
    for i in range(P.panel_fence.shape[0]):
        _place(P, fences, P.panel_fence[i], on_clock(P, t, P.panel_win[i, 0], P.panel_win[i, 1]))


@njit(cache=True, error_model="numpy", inline="always")
def push_doors(P, state, r, x, y, t):
    """The worker tries to step to (x, y) (footprint radius r) at t: every door not yet pushed whose leaf the
    footprint touches is pushed now; without guard locking it starts to open at once."""
    for i in range(P.door_fence.shape[0]):
        f = P.door_fence[i]
        if state[S_DOOR_REQ + i] == np.inf and \
                point_segment_2d(x, y, P.fences[f, 0], P.fences[f, 1], P.fences[f, 2], P.fences[f, 3]) < r:
            state[S_DOOR_REQ + i] = t
            if P.door_lock[i] == 0.0:
                state[S_DOOR_OPEN + i] = t


@njit(cache=True, error_model="numpy", inline="always")
def unlock_doors(P, state, t):
    """Guard locking: a pushed door that is still locked starts to open at t if the robots it stops are at rest."""
    for i in range(P.door_dev.shape[0]):
        if state[S_DOOR_REQ + i] <= t and state[S_DOOR_OPEN + i] == np.inf and robots_at_rest(
                P, state, P.door_dev[i], t):
            state[S_DOOR_OPEN + i] = t


@njit(cache=True, error_model="numpy", inline="always")
def note_push(P, state, d, t):
    """Replaying rows (``step.latch_seen``): the door whose channel is d signals at t, so it was pushed by t: if
    the state does not know it yet, it was pushed at t (the push and the first signal share a time step)."""
    for i in range(P.door_dev.shape[0]):
        if P.door_dev[i] == d and state[S_DOOR_REQ + i] == np.inf:
            state[S_DOOR_REQ + i] = t
            if P.door_lock[i] == 0.0:
                state[S_DOOR_OPEN + i] = t
