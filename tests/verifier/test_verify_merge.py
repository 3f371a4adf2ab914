"""verify's merge key: derived from the declarations of the state layout (every slot says how it merges), and
what it merges has the same future.

Two properties are played out on cells of every kind (automatic restart, warning field, speed and separation
monitoring, guard door, muting, several robots, a prismatic joint): a reachable state whose slots declared
free are set to anything plays on bit for bit as before; and reachable states that share a key (different
action prefixes that end in the same place) meet the unsafe set at the same step under random actions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cellstress.core.vector_spec import EXACT, Merge, StateSpec
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator
from cellstress.verifier.phases import start_points
from cellstress.verifier.tree import KEY_COLUMNS, merge_keys

CELLS = Path(__file__).parent / "cells"
# (cell, arrival phase): built-in cells with each feature, and the test cells where it matters within 3-4 actions
CASES = [
    ("restart-auto", None), ("warning-field-short", None), ("ssm-latency", None), ("door-unlocked", None),
    ("muting-long", None), ("two-robots", None), ("restart-fast", 0.0), ("warning-trunk", 4.35),
    ("ssm-near", 1.0), ("door-near", 0.0), ("muting-near", 4.0), ("two-near", 0.0), ("linear-axis", 0.0),
]


def _sim(cell: str, phase: float | None) -> Simulator:
    sim = Simulator(cell if phase is None else str(CELLS / f"{cell}.yaml"))
    if phase is None:
        return sim
    return sim.with_start(start_points(sim.cell)[0].pose, phase)


def _play(sim: Simulator, state: np.ndarray, actions) -> tuple[np.ndarray, np.ndarray]:
    """The rows of playing ``actions`` from ``state`` until the episode ends, and the last state."""
    rows = []
    for a in actions:
        state, r = sim.step(state, int(a))
        rows.append(r)
        if sim.is_unsafe(state):
            break
    return (np.concatenate(rows) if rows else np.zeros((0, L.NM))), state


def _reachable(sim: Simulator, rng: np.random.Generator, n: int, most: int) -> list[np.ndarray]:
    """Living states after random prefixes of 1..``most`` actions, actions drawn mostly from a few so that
    different prefixes end in the same place."""
    few = rng.choice(30, 8, replace=False)
    out = []
    for _ in range(n):
        length = int(rng.integers(1, most + 1))
        acts = rng.choice(few, length) if rng.random() < 0.7 else rng.integers(0, 30, length)
        state = sim.reset()
        for a in acts:
            state, _ = sim.step(state, int(a))
            if sim.is_unsafe(state):
                break
        else:
            out.append(state)
    return out


def test_every_slot_declares_how_it_merges() -> None:
    assert isinstance(L.STATE, StateSpec) and len(L.STATE.merges) == L.NS
    with pytest.raises(ValueError, match="does not declare"):
        StateSpec.of("s", (("A", "a", EXACT), ("B", "b")))
    # the key holds exactly the slots not declared free, in layout order
    assert [c[0] for c in KEY_COLUMNS] == [i for i, g in enumerate(L.STATE.merges) if g.kind != "free"]
    # and what decides where the robot will be is among them, bit for bit
    for name in ("TSTOP", "A_TAU", "A_SIG", "TSLOW", "SLOW", "STOP_CLEAR", "SEP_Q3", "DOOR0_OPEN", "XTSTOP1"):
        assert L.STATE.merge(name).kind == "exact", name


def test_a_declaration_says_enough() -> None:
    with pytest.raises(ValueError, match="one of"):
        Merge("within")
    with pytest.raises(ValueError, match="says why"):
        Merge("free")
    with pytest.raises(ValueError, match="free_while"):
        Merge("free", reason="x", free_while="A", free_value=0.0)
    with pytest.raises(ValueError, match="no slot"):
        StateSpec.of("s", (("A", "a", Merge("exact", reason="x", free_while="B", free_value=0.0)),))


def _scramble(state: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``state`` with every slot that is free there set to a random value."""
    out = state.copy()
    for i, g in enumerate(L.STATE.merges):
        free = g.kind == "free" or (g.free_while is not None and state[L.STATE.index(g.free_while)] == g.free_value)
        if free:
            out[i] = rng.uniform(-5.0, 50.0)
    return out


@pytest.mark.parametrize(("cell", "phase"), CASES)
def test_slots_declared_free_do_not_reach_the_future(cell, phase) -> None:
    sim = _sim(cell, phase)
    rng = np.random.default_rng(7)
    changed = 0
    for state in _reachable(sim, rng, 60, 3):
        other = _scramble(state, rng)
        assert merge_keys(state)[0] == merge_keys(other)[0]
        changed += int(not np.array_equal(state, other))
        for acts in rng.integers(0, 30, size=(4, 4)):
            rows_a, end_a = _play(sim, state, acts)
            rows_b, end_b = _play(sim, other, acts)
            assert np.array_equal(rows_a, rows_b), (cell, acts)
            # and the states they end in differ at most where they may: in slots free there
            assert np.array_equal(merge_keys(end_a), merge_keys(end_b)), (cell, acts)
    assert changed > 20


def _merged_pairs(sim: Simulator, rng: np.random.Generator) -> list[tuple[np.ndarray, np.ndarray]]:
    """Pairs of different reachable states that share a merge key."""
    states = _reachable(sim, rng, 400, 3)
    keys = merge_keys(np.array(states))
    first: dict[bytes, int] = {}
    pairs = []
    for i, k in enumerate(keys):
        j = first.setdefault(bytes(k), i)
        if j != i and not np.array_equal(states[i], states[j]):
            pairs.append((states[j], states[i]))
    return pairs


@pytest.mark.parametrize(("cell", "phase"), CASES)
def test_merged_states_meet_the_same_future(cell, phase) -> None:
    sim = _sim(cell, phase)
    rng = np.random.default_rng(11)
    for a, b in _merged_pairs(sim, rng):
        for acts in rng.integers(0, 30, size=(6, 5)):
            rows_a, end_a = _play(sim, a, acts)
            rows_b, end_b = _play(sim, b, acts)
            assert np.array_equal(rows_a, rows_b), (cell, acts)
            assert merge_keys(end_a)[0] == merge_keys(end_b)[0]


def test_reachable_states_do_merge_though_they_differ() -> None:
    # different prefixes reach states that differ only in slots declared free (the first detection's time, the
    # last time a device saw the worker while no release can come), so the test above is not vacuous
    sim = _sim("warning-trunk", 4.35)
    assert len(_merged_pairs(sim, np.random.default_rng(11))) > 0


def test_a_micrometre_can_decide_a_stride() -> None:
    # why no slot merges within a tolerance: in warning-trunk the worker stands where a stride to the right ends
    # exactly at the fence; 0.06 um to the left, the same stride clears it
    sim = _sim("warning-trunk", 4.35)
    walk_right = sim.action_index("turn-left-90+upright")  # heading -90 deg + 90: along +x
    state, _ = sim.step(sim.reset(), walk_right)
    state, _ = sim.step(state, sim.action_index("walk+upright"))
    nudged = state.copy()
    nudged[L.S_X] -= 6e-8
    _, a = _play(sim, state, [sim.action_index("walk+upright")])
    _, b = _play(sim, nudged, [sim.action_index("walk+upright")])
    assert abs((b[L.S_X] - nudged[L.S_X]) - (a[L.S_X] - state[L.S_X])) > 0.05
