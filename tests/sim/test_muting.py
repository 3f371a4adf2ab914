"""Muting at a conveyor opening (issue 18): the pallet blocks the opening while it passes, the muted curtain sees
nothing within its window and sees again after it; a person following the pallet passes unseen only where the
muting outlasts the pallet; every way of playing gives the same bits."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.devices.light_curtain import LightCurtain
from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.simulator import Simulator

STRAIGHT = ["walk+upright"] * 16  # from the start, 0.9 m in front of the opening, straight through it
OPENING_Y = -1.6


@pytest.fixture(scope="module")
def long():
    return Simulator("muting-long")


@pytest.fixture(scope="module")
def ok():
    return Simulator("muting-ok")


def _clock(sim, t):
    return (float(sim.params.scal[L.C_PHASE0]) + t) % float(sim.params.scal[L.C_CYCLE])


def test_the_pallet_blocks_the_opening_while_it_passes(long):
    rows = long.run(STRAIGHT).rows
    muting = long.layout.cell.spec.devices[0].muting
    radius = long.layout.params.body[L.B_BODY_RADIUS]
    blocked = next(i for i in range(1, len(rows)) if rows[i, L.M_Y] == rows[i - 1, L.M_Y])
    moved = next(i for i in range(blocked, len(rows)) if rows[i, L.M_Y] != rows[i - 1, L.M_Y])
    # held in front of the pallet until it has passed: the first step that moves on starts once the clock is past
    # the pallet's window (the kernel's test: IN <= clock <= OUT), the step before it within it
    assert np.all(rows[:moved, L.M_Y] <= OPENING_Y - radius + 1e-9)
    k = int(rows[moved, L.M_STEP]) - 1  # the step the move started from, its time k * dt as the kernel's
    t_from = k * long.dt
    assert not muting.pallet[0] <= _clock(long, t_from) <= muting.pallet[1]
    assert muting.pallet[0] <= _clock(long, (k - 1) * long.dt) <= muting.pallet[1]
    assert _clock(long, t_from) == pytest.approx(muting.pallet[1], abs=long.dt + 1e-9)


def test_following_the_pallet_unseen_while_muted(long, ok):
    hit = long.run(STRAIGHT)
    assert hit.unsafe
    assert not np.any(hit.rows[:, L.M_SEEN])  # the muted curtain never saw the worker pass
    assert hit.rows[-1, L.M_PHASE] == L.PHASE_RUNNING
    # with the muting ended as the pallet clears, the same walk is seen in the opening and stopped in time
    safe = ok.run(STRAIGHT)
    assert not safe.unsafe
    seen = np.flatnonzero(safe.rows[:, L.M_SEEN])
    assert len(seen) and _clock(ok, safe.rows[seen[0], L.M_T]) > ok.layout.cell.spec.devices[0].muting.until


def test_muting_record_checks():
    base = {"type": "light-curtain", "name": "c", "start": (0, 0), "end": (1, 0)}
    with pytest.raises(ValueError, match="before the pallet has passed"):
        LightCurtain.model_validate({**base, "muting": {"pallet": (1.0, 2.0), "until": 1.5}})
    with pytest.raises(ValueError, match="arrive before"):
        LightCurtain.model_validate({**base, "muting": {"pallet": (2.0, 1.0), "until": 3.0}})
    c = LightCurtain.model_validate({**base, "muting": {"pallet": (1.0, 2.0), "until": 2.5}})
    assert c.channels()[0].muted == (1.0, 2.5)
    assert c.timed_panels()[0].t_out == 2.0
    assert LightCurtain.model_validate(base).channels()[0].muted is None


@pytest.mark.parametrize("cell", ["muting-long", "muting-ok"])
def test_every_way_of_playing_agrees(cell):
    sim = Simulator(cell)
    seqs = np.random.default_rng(7).integers(0, 30, (20, sim.actions_per_episode)).tolist()
    seqs.append([0] * sim.actions_per_episode)
    assert check_determinism(sim, seqs) == len(seqs)


def test_worker_paths_follow_the_pallet(long):
    acts = np.zeros((2, long.actions_per_episode), dtype=np.int64)
    acts[1, 8:] = 1
    paths = long.worker_paths(acts)
    for e in range(len(acts)):
        rows = long.run(acts[e]).rows[1:]
        assert np.array_equal(paths[e, : len(rows)], rows[:, list(L.POSE_ROW)])
    assert not long.layout.static_fences
