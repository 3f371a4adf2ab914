"""Interlocked guard doors in the simulator (issue 18): the leaf blocks while closed, the push latches a stop after
the interlock's response time, the door lets the worker through only after its opening time, with guard locking
only once the robot is at rest; every way of playing gives the same bits."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.simulator import Simulator
from cellstress.verifier.tree import merge_keys

STRAIGHT = ["walk+upright"] * 16  # from the start, 0.9 m in front of the door, straight through it
DOOR_Y = -1.6


@pytest.fixture(scope="module")
def unlocked():
    return Simulator("door-unlocked")


@pytest.fixture(scope="module")
def locked():
    return Simulator("door-locked")


def _timeline(sim, acts):
    """(rows, time of the push = the interlock's first signal, time of the first step the worker moved on)."""
    rows = sim.run(acts).rows
    door = 1 << sim.layout.device_names.index("bay-door")
    seen = [int(s) & door != 0 for s in rows[:, L.M_SEEN]]
    push = next(i for i, s in enumerate(seen) if s)
    moved = next(i for i in range(push + 1, len(rows)) if rows[i, L.M_Y] != rows[i - 1, L.M_Y])
    return rows, push, moved


def test_the_push_stops_the_robot_after_the_interlock_response(unlocked):
    rows, push, _ = _timeline(unlocked, STRAIGHT)
    door = unlocked.layout.cell.spec.devices[0]
    tp = rows[push, L.M_T]
    assert rows[push - 1, L.M_PHASE] == L.PHASE_RUNNING
    pending = rows[(rows[:, L.M_T] > tp - 1e-9) & (rows[:, L.M_T] < tp + door.response_time - 1e-9)]
    braking = rows[rows[:, L.M_T] >= tp + door.response_time - 1e-9]
    assert np.all(pending[:, L.M_PHASE] == L.PHASE_PENDING)
    assert braking[0, L.M_PHASE] == L.PHASE_BRAKING
    # the interlock keeps signalling: the door stays open
    assert all(int(s) & 1 for s in rows[push:, L.M_SEEN])


def test_closed_door_blocks_and_opens_after_its_opening_time(unlocked):
    rows, push, moved = _timeline(unlocked, STRAIGHT)
    opening = unlocked.layout.cell.spec.devices[0].opening_time
    radius = unlocked.layout.params.body[L.B_BODY_RADIUS]
    tp, dt = rows[push, L.M_T], unlocked.dt
    # held at the leaf (the footprint does not cross it) until the door is passable ...
    assert np.all(rows[:moved, L.M_Y] <= DOOR_Y - radius + 1e-9)
    # ... and moving on at the first step taken once it is: from a state at least the opening time after the push
    t_from = rows[moved, L.M_T] - dt
    assert t_from - tp >= opening - 1e-9 > t_from - dt - tp
    assert rows[-1, L.M_Y] > DOOR_Y  # through it


def test_guard_locking_holds_the_door_until_the_robot_is_at_rest(locked):
    rows, push, moved = _timeline(locked, STRAIGHT)
    spec = locked.layout.cell.spec
    door = spec.devices[0]
    tp, dt = rows[push, L.M_T], locked.dt
    rest = tp + door.response_time + spec.robot.stopping_time
    at_rest = rows[rows[:, L.M_PHASE] == L.PHASE_STOPPED]
    assert at_rest[0, L.M_T] == pytest.approx(rest, abs=dt)
    # it starts to open only at rest, and is passable an opening time later: the worker moves no earlier
    assert rows[moved, L.M_T] - dt >= rest + door.opening_time - 1e-9
    assert np.all(rows[push:moved, L.M_Y] == rows[push, L.M_Y])
    assert not locked.run(STRAIGHT).unsafe


def test_without_locking_the_worker_meets_the_coasting_robot(unlocked, locked):
    # the same sequence ends in a hazard through the unlocked door and in none through the locked one
    acts = ["walk+bend-forward", "walk+bend-forward", "walk+bend-right", "walk+bend-right",
            "turn-right-90+bend-forward-left", "turn-left-45+bend-right", "walk+bend-forward-right",
            "walk+bend-forward-right", "walk+bend-forward-left"]  # plan's first hazard, seed 0
    hit = unlocked.run(acts)
    assert hit.unsafe
    assert hit.rows[-1, L.M_PHASE] == L.PHASE_BRAKING and hit.rows[-1, L.M_V] > 0.0
    assert not locked.run(acts).unsafe


def test_worker_paths_follow_an_unlocked_door(unlocked):
    # the open-loop motion opens a door without guard locking exactly as played
    rng = np.random.default_rng(3)
    acts = rng.integers(0, 6, size=(40, unlocked.actions_per_episode))
    acts[0] = 0
    paths = unlocked.worker_paths(acts)
    for e in range(len(acts)):
        rows = unlocked.run(acts[e]).rows[1:]
        assert np.array_equal(paths[e, : len(rows)], rows[:, list(L.POSE_ROW)]), e
    assert paths[0, -1, 1] > DOOR_Y


@pytest.mark.parametrize("cell", ["door-unlocked", "door-locked"])
def test_every_way_of_playing_agrees(cell):
    sim = Simulator(cell)
    seqs = np.random.default_rng(7).integers(0, 30, (20, sim.actions_per_episode)).tolist()
    seqs.append([0] * sim.actions_per_episode)
    seqs.append([0] * 8 + [1] * 8)
    assert check_determinism(sim, seqs) == len(seqs)


@pytest.mark.parametrize("cell", ["door-unlocked", "door-locked"])
def test_replayed_latches_match_the_kernel(cell, replay_latches):
    """``Simulator._state_at`` replays a cut action's rows: the door's push and opening included, bit for bit."""
    state = replay_latches(Simulator(cell), STRAIGHT)
    assert state[L.S_DOOR_REQ] < np.inf


def test_layout_and_verifier_know_the_doors(unlocked):
    assert Simulator("baseline").layout.static_fences
    assert not unlocked.layout.static_fences
    assert unlocked.layout.stops_latch  # a door's stop holds for the episode
    s0 = unlocked.reset()
    pushed = s0.copy()
    pushed[L.S_DOOR_REQ] = pushed[L.S_DOOR_OPEN] = 1.0
    keys = merge_keys(np.stack([s0, pushed]))
    assert keys[0] != keys[1]  # states that differ only in a door never merge
