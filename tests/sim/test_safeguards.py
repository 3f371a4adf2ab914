"""The safeguards of issue 18 in the simulator: automatic restart, a warning field's reduced speed, the safety mat.

Each test plays a built-in scenario and checks a behaviour on the rows: the robot resumes exactly where it stood,
only after the clear time without detection, a new detection latches a new stop, the speed under a warning field
is the reduced fraction of the path speed, and every way of playing gives the same bits.
"""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.records import STOP_PHASES
from cellstress.sim.simulator import Simulator

INTO_BAY = ["walk+upright"] * 7 + ["walk+bend-forward"]  # through the curtain, up to the table's base
RUNNING, PENDING, BRAKING, STOPPED, REDUCED = (L.PHASE_RUNNING, L.PHASE_PENDING, L.PHASE_BRAKING, L.PHASE_STOPPED,
                                              L.PHASE_REDUCED)


@pytest.fixture(scope="module")
def auto():
    return Simulator("restart-auto")


def _release_row(rows) -> int:
    """The first row after a stop at which the robot runs again."""
    stopping = np.isin(rows[:, L.M_PHASE], (PENDING, BRAKING, STOPPED))
    return next(i for i in range(1, len(rows)) if stopping[i - 1] and not stopping[i])


def test_stops_latch_flag():
    assert Simulator("baseline").layout.stops_latch
    assert Simulator("restart-manual").layout.stops_latch
    assert not Simulator("warning-field-ok").layout.stops_latch


def test_restart_after_clear_time_resumes_where_it_stood(auto):
    rows = auto.run(INTO_BAY).rows
    curtain = 1 << auto.layout.device_names.index("bay-curtain")
    i = _release_row(rows)
    last_seen = max(k for k in range(i) if int(rows[k, L.M_SEEN]) & curtain)
    clear = auto.layout.cell.spec.devices[1].clear_time
    dt = auto.dt
    # released at the first step at least CLEAR_TIME after the curtain last saw the worker, not before
    assert rows[i, L.M_T] - rows[last_seen, L.M_T] >= clear - 1e-9
    assert rows[i - 1, L.M_T] - rows[last_seen, L.M_T] < clear - 1e-9
    assert rows[i - 1, L.M_PHASE] == STOPPED and rows[i - 1, L.M_V] == 0.0
    # it resumes from the standstill pose: the path time at release is the standstill's, then it ramps up
    assert rows[i, L.M_TAU] == rows[i - 1, L.M_TAU]
    assert rows[i + 1, L.M_TAU] > rows[i, L.M_TAU]
    # the ramp: sigma rises at 1/T per second, so tau(t) = tau_r + d^2 / (2 T) for d < T
    T = auto.layout.cell.spec.robot.stopping_time
    d = dt
    assert rows[i + 1, L.M_TAU] == pytest.approx(rows[i, L.M_TAU] + d * d / (2 * T), abs=1e-12)
    # and it is unsafe: the worker in the bay is within reach of the moving robot
    assert auto.run(INTO_BAY).unsafe


def test_manual_twin_stays_stopped():
    sim = Simulator("restart-manual")
    trace = sim.run(INTO_BAY + ["walk+bend-forward"] * 8)
    rows = trace.rows
    first_stop = int(np.argmax(rows[:, L.M_PHASE] == STOPPED))
    assert np.all(rows[first_stop:, L.M_PHASE] == STOPPED)
    assert np.all(rows[first_stop:, L.M_V] == 0.0)
    assert not trace.unsafe


def test_a_second_detection_latches_a_new_stop(auto):
    # into the curtain, back out behind it (the curtain clears, the robot restarts), and in again
    acts = ["walk+upright"] * 4 + ["turn-left-90+upright"] * 2 + ["walk+upright"] * 4 + \
        ["turn-left-90+upright"] * 2 + ["walk+upright"] * 4
    state, parts = auto.reset(), []
    for a in acts:
        state, rows = auto.step(state, a)
        parts.append(rows)
    rows = np.concatenate(parts)
    phases = rows[:, L.M_PHASE]
    starts = [k for k in range(1, len(rows)) if phases[k] == PENDING and phases[k - 1] not in (PENDING, BRAKING,
                                                                                                STOPPED)]
    assert len(starts) >= 2, [STOP_PHASES[int(p)] for p in phases]
    assert state[L.S_RESTARTS] >= 1
    assert state[L.S_LIVE] == 1.0


def test_warning_field_cuts_speed_to_fraction():
    sim = Simulator("warning-field-ok")
    rows = sim.run(["walk+upright"] * 3).rows
    r = sim.layout.cell.spec.devices[0].warning.reduced_speed
    reduced = np.flatnonzero(rows[:, L.M_PHASE] == REDUCED)
    assert len(reduced)
    dt, T = sim.dt, sim.layout.cell.spec.robot.stopping_time
    k = reduced[0]
    resp = sim.layout.cell.spec.devices[0].response_time
    # after the response time and the ramp ((1 - r) T), the path time advances at r per second
    late = [j for j in range(len(rows) - 1) if rows[j, L.M_T] >= rows[k, L.M_T] + resp + (1 - r) * T + 1e-9]
    assert late
    P, W = sim.params, K.make_work(sim.params)
    for j in late:
        slope = (rows[j + 1, L.M_TAU] - rows[j, L.M_TAU]) / dt
        assert slope == pytest.approx(r, abs=1e-9)
        # v_R is r times the speed of the robot at full speed at the same path time
        v_full, _, _ = K.robot_live(P, rows[j, L.M_TAU] - P.scal[L.C_PHASE0], np.inf, W)
        assert rows[j, L.M_V] == pytest.approx(r * v_full, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("cell", ["restart-auto", "warning-field-short", "mat-short"])
def test_every_way_of_playing_agrees(cell):
    sim = Simulator(cell)
    seqs = np.random.default_rng(7).integers(0, 30, (20, sim.actions_per_episode)).tolist()
    seqs.append([0] * sim.actions_per_episode)  # walk straight ahead: the restart (or the reduction) happens
    assert check_determinism(sim, seqs) == len(seqs)


def test_mat_sees_the_feet_only():
    sim = Simulator("mat-ok")
    mat = 1 << sim.layout.device_names.index("front-mat")
    rows = sim.run(["walk+upright"] * 2).rows
    assert any(int(s) & mat for s in rows[:, L.M_SEEN])
    # leaning over the mat's front edge from outside is not seen: standing still, bent forward, at the start
    rows = sim.run(["turn-left-45+bend-forward", "turn-right-45+bend-forward"]).rows
    assert not any(int(s) & mat for s in rows[:, L.M_SEEN])


@pytest.mark.parametrize("cell, acts", [
    ("restart-auto", INTO_BAY + ["walk+bend-forward"] * 4),
    ("warning-field-ok", ["walk+upright"] * 8),
])
def test_replayed_latches_match_the_kernel(cell, acts, replay_latches):
    """A criterion that judges contacts may end an action early; the simulator then replays the latches from the
    rows (``_state_at``). Replayed over a whole action, they must give the kernel's own state, bit for bit: the
    stop, the reduction, the release and its anchor. (restart-auto: the action with the release ends at the
    contact.)"""
    state = replay_latches(Simulator(cell), acts)
    assert state[L.S_LIVE] == 1.0
