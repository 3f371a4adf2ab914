"""Fixtures of the simulator's tests."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.simulator import _state_at


def _replay_latches(sim, acts):
    """Play ``acts``; after each action rebuild its latches from the rows (``_state_at``, as the simulator does
    when a criterion ends an action early) and require the kernel's own state, bit for bit. Returns the last
    state (the play stops at the first unsafe one)."""
    state = sim.reset()
    for a in acts:
        nxt, rows = sim.step(state, a)
        again = nxt.copy()
        again[L.S_TSTOP:L.S_UNSAFE] = 0.0
        again[L.S_LIVE:] = 0.0
        _state_at(again, state, rows, sim.params)
        if rows[-1, L.M_SWEPT] != 0.0:  # a contact within the step: its end pose continued from the contact's
            pose = list(L.POSE_STATE)  # (to the rounding of that division, not bit for bit)
            np.testing.assert_allclose(again[pose], nxt[pose], rtol=0.0, atol=1e-9)
            again[pose] = nxt[pose]
        if rows[-1, L.M_SWEPT] != 0.0 or rows[-1, L.M_D] <= 0.0:  # (the row's d_HR is clipped at 0, and a
            again[L.S_D_SEP] = nxt[L.S_D_SEP]  # contact row's is its own moment's: _state_at's comment)
        assert again.tobytes() == nxt.tobytes(), a
        state = nxt
        if sim.is_unsafe(state):
            break
    return state


@pytest.fixture(scope="session")
def replay_latches():
    return _replay_latches
