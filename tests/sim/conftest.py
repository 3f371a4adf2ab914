"""Fixtures of the simulator's tests."""

from __future__ import annotations

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
        assert again.tobytes() == nxt.tobytes(), a
        state = nxt
        if sim.is_unsafe(state):
            break
    return state


@pytest.fixture(scope="session")
def replay_latches():
    return _replay_latches
