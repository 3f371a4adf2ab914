"""Contact in continuous time (kernels.sweep): the swept test misses no contact that sampling the same motion
ten times as finely finds, finds contacts that fall between the steps, records their own time, and stays
deterministic; the verifier's distance bound prunes only above the distance where it may still count one."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numba import njit

from cellstress.sim import layout as L
from cellstress.sim.geometry import segment_segment_xyz
from cellstress.sim.kernels.dense import dense_batch
from cellstress.sim.kernels.params import make_work
from cellstress.sim.kernels.reach import reach_field_at
from cellstress.sim.kernels.sweep import CERT_STEP, REACH_SLOPE, _certified, _moving_time, _sample, flag_distance
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


@njit(cache=False)
def _fine_minimum(P, W, spacing):
    """The smallest distance between the robot and the worker posed in W, sampled every ``spacing`` along each
    robot capsule's axis (the reach fields, fences ignored) and exact for the body capsules: the true distance is
    at most this."""
    best = np.inf
    for c in range(P.cap_r.shape[0]):
        r = P.cap_r[c]
        a, b = W.ra[c], W.rb[c]
        for k in range(int(P.body[L.B_N_CAPS])):
            d2 = segment_segment_xyz(a[0], a[1], a[2], b[0], b[1], b[2], W.ha[k, 0], W.ha[k, 1], W.ha[k, 2],
                                     W.hb[k, 0], W.hb[k, 1], W.hb[k, 2])[0]
            best = min(best, np.sqrt(d2) - r - W.hr[k])
        n = max(1, int(np.ceil(np.sqrt(((b - a) ** 2).sum()) / spacing)))
        for i in range(n + 1):
            p = a + (i / n) * (b - a)
            for side in range(2):
                f = reach_field_at(P.reach, P.scal[L.C_REACH_ORIGIN], P.scal[L.C_REACH_H], W.sh, W.tr, side, p[0],
                                   p[1], p[2])
                best = min(best, f - r)
    return best


def test_the_certified_bound_lies_below_the_distance_and_within_a_piece_of_it() -> None:
    """``_certified`` skips whole runs of an axis (``_axis_bound``): on random poses of the worker around the
    robot, at random moments of its cycle (no fences: the field alone), its value never exceeds the distance
    sampled every 0.1 mm, and lies within a 1 mm piece's slack of it."""
    sim = Simulator("baseline")
    P = sim.params._replace(fences=np.zeros((0, sim.params.fences.shape[1])))
    W = make_work(P)
    rng = np.random.default_rng(3)
    state = sim.reset()
    near = 0
    for _ in range(300):
        state[L.S_K] = float(rng.integers(1, 400))
        t0 = (state[L.S_K] - 1) * sim.dt
        _sample(P, state, state, W, 0.5, t0, W.srow)
        c = int(rng.integers(P.cap_r.shape[0]))  # beside a random robot capsule, facing any way
        angle, dist = rng.uniform(0, 2 * np.pi), rng.uniform(0.3, 1.3)
        state[L.S_X] = 0.5 * (W.ra[c, 0] + W.rb[c, 0]) + dist * np.cos(angle)
        state[L.S_Y] = 0.5 * (W.ra[c, 1] + W.rb[c, 1]) + dist * np.sin(angle)
        state[L.S_HEADING] = rng.uniform(-np.pi, np.pi)
        state[L.S_FWD], state[L.S_LAT] = rng.uniform(0.0, 1.0), rng.uniform(-0.4, 0.4)
        _sample(P, state, state, W, 0.5, t0, W.srow)
        bound, fine = _certified(P, W), _fine_minimum(P, W, 1e-4)
        assert bound <= fine + 1e-12
        assert bound >= fine - REACH_SLOPE * 0.5 * CERT_STEP - REACH_SLOPE * 1e-4
        near += 0.0 < fine < 0.1
    assert near > 10  # poses near the robot, where the bound is refined, were among them
