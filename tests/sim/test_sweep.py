"""Contact in continuous time (kernels.sweep): the swept test misses no contact that sampling the same motion
ten times as finely finds, finds contacts that fall between the steps, records their own time, and stays
deterministic; the verifier's distance bound prunes only above the distance where it may still count one."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.kernels.dense import dense_batch
from cellstress.sim.kernels.sweep import _moving_time, flag_distance
from cellstress.sim.simulator import Simulator


def _unswept(sim: Simulator) -> Simulator:
    scal = sim.params.scal.copy()
    scal[L.C_SWEEP] = 0.0
    return Simulator(dataclasses.replace(sim.layout, params=sim.params._replace(scal=scal)), start=sim.start)


@pytest.fixture(scope="module")
def s3():
    sim = Simulator("s3-fence-gap")
    acts = np.random.default_rng(0).integers(0, sim.n_actions, size=(4000, sim.actions_per_episode))
    return sim, acts, sim.run_batch(acts).unsafe_step


@pytest.mark.parametrize("cell", ["s3-fence-gap", "s1-scanner-width"])
def test_no_contact_of_the_fine_samples_is_missed(cell, s3) -> None:
    sim = s3[0] if cell == "s3-fence-gap" else Simulator(cell)
    acts = np.random.default_rng(1).integers(0, sim.n_actions, size=(800, sim.actions_per_episode))
    swept = sim.run_batch(acts).unsafe_step
    fine = np.empty(len(acts), dtype=np.int64)
    dense_batch(sim.params, sim.reset(), np.ascontiguousarray(acts), 10, fine)
    hit = fine >= 0
    assert np.all((swept[hit] >= 0) & (swept[hit] <= fine[hit]))
    if cell == "s3-fence-gap":
        assert hit.sum() > 3  # and the check is not vacuous


def test_contacts_between_the_steps_are_found_with_their_time(s3) -> None:
    sim, acts, swept = s3
    flat = _unswept(sim)
    sampled = flat.run_batch(acts).unsafe_step
    between = np.flatnonzero((swept >= 0) & (sampled < 0))
    assert len(between) > 0  # the sampled model misses these
    kinds = set()
    for e in between[:10]:
        row = sim.run(acts[e]).rows[-1]
        assert row[L.M_UNSAFE] == 1.0 and row[L.M_SWEPT] in (1.0, 2.0)
        kinds.add(int(row[L.M_SWEPT]))
        assert row[L.M_T] - sim.dt <= row[L.M_TC] < row[L.M_T]  # its own time, within the step
        rec = sim.run(acts[e]).records()[-1]  # and the record says so, with that time
        assert rec.between == ("contact" if row[L.M_SWEPT] == 1.0 else "not-ruled-out")
        assert rec.contact_t == rec.moment and rec.t - sim.dt <= rec.contact_t < rec.t
        # bit for bit again
        assert np.array_equal(sim.run(acts[e]).rows, sim.run(acts[e]).rows)
    # a contact at a step's own sample records that step's time
    own = [sim.run(acts[e]).rows[-1] for e in np.flatnonzero((sampled >= 0) & (swept == sampled))]
    own = [row for row in own if row[L.M_SWEPT] == 0.0]
    assert own and all(row[L.M_TC] == row[L.M_T] for row in own)
    rec = sim.run(acts[np.flatnonzero((sampled >= 0) & (swept == sampled))[0]]).records()[-1]
    if rec.between is None:  # a step's own contact: the record is as it always was
        assert "between" not in rec.model_dump() and "contact_t" not in rec.model_dump() and rec.moment == rec.t


def test_the_flag_distance_is_a_few_millimetres() -> None:
    P = Simulator("baseline").params
    extra = flag_distance(P) - float(P.scal[L.C_DTOL])
    assert 0.0 < extra < 0.02


def test_moving_time_leaves_out_the_dwells() -> None:
    """_moving_time against counting 0.1 ms samples of the same path (dwell then move per segment, cyclic,
    a padded row of another robot included)."""
    starts = np.array([0.0, 1.0, 1.5, 3.0, np.inf])
    dwell = np.array([0.4, 0.0, 0.5, 0.0, 0.0])
    move = np.array([0.6, 0.5, 1.0, 1.0, 1.0])
    cycle = 4.0
    rng = np.random.default_rng(3)

    def moving(t):
        tc = t % cycle
        i = int(np.searchsorted(starts[:4], tc, side="right")) - 1
        return tc >= starts[i] + dwell[i]

    for _ in range(200):
        a = float(rng.uniform(-3.0, 9.0))
        b = a + float(rng.choice([rng.uniform(0.0, 0.05), rng.uniform(0.0, 3.99)]))
        got = _moving_time(cycle, starts, move, dwell, a, b)
        n = max(1, int(round((b - a) / 1e-4)))
        ts = a + (np.arange(n) + 0.5) * (b - a) / n
        want = (b - a) * np.mean([moving(t) for t in ts]) if b > a else 0.0
        assert abs(got - want) <= 2e-4 + 1e-9 and got == _moving_time(cycle, starts, move, dwell, b, a)
    assert _moving_time(cycle, starts, move, dwell, 0.1, 0.3) == 0.0  # inside the first dwell
    assert _moving_time(cycle, starts, move, dwell, 1.0, 6.0) == 5.0  # a cycle or more: all of it (an upper bound)
