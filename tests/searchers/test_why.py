"""Why a hazard was not prevented: the timeline in result.json agrees with the trace's own stop phases, and the
words name the safeguard and its ISO 13855 shortfall."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.replay import check_result
from cellstress.analysis.shortfall import shortfall
from cellstress.searchers import search
from cellstress.searchers.result import SearchResult
from cellstress.searchers.why import explain
from cellstress.sim.simulator import Simulator


@pytest.fixture(scope="module")
def s1():
    return Simulator("s1-scanner-width")


def test_undetected_hazard(tmp_path):
    res = search(Simulator("s3-fence-gap"), "plan", budget=200, seed=0)
    why = res.hazard.why
    assert not why.detected and why.stopped_by is None and why.late_by_s is None
    assert all(t.saw_at_s is None for t in why.devices)
    words = shortfall(why, check_cell(Simulator("s3-fence-gap").cell))
    assert words.startswith("undetected") and "short by" in words


def test_detected_too_late(s1):
    res = search(s1, "plan", budget=200, seed=0)
    why, h = res.hazard.why, res.hazard
    assert why.detected and why.stopped_by == "front-scanner"
    first = next(t for t in why.devices if t.device == why.stopped_by)
    assert first.stop_at_s == pytest.approx(first.saw_at_s + 0.35)
    assert why.standstill_at_s == pytest.approx(first.stop_at_s + s1.cell.spec.robot.stopping_time)
    assert why.contact_at_s == h.time_s and why.late_by_s > 0
    words = shortfall(why, check_cell(s1.cell))
    assert "front-scanner saw the worker at 0.50 s" in words and "ISO 13855 requires S = 1.88 m" in words


@pytest.mark.parametrize("cell", ["s1-scanner-width", "s2-elbow-intrusion", "all-flaws"])
def test_timeline_agrees_with_the_trace(cell):
    sim = Simulator(cell)
    rng = np.random.default_rng(7)
    acts = rng.integers(0, 30, size=(3000, 8))
    unsafe = np.flatnonzero(sim.run_batch(acts).unsafe)
    assert len(unsafe) > 0
    for e in unsafe[:40]:
        trace = sim.run(acts[e].tolist())
        recs = trace.records()
        why = explain(sim.layout, recs, trace.unsafe_row)
        hit = recs[trace.unsafe_row]
        braking = [r.t for r in recs if r.stop_phase in ("braking", "stopped")]
        if not why.detected:
            assert hit.stop_phase == "running" and not any(r.devices for r in recs)
            continue
        # the stop the timeline names is the one the simulator applied
        if braking:  # the first step sampled braking: at the moment braking begins, or the next step when that
            # moment lies a float's rounding after its step (the sample there says "stop-pending")
            assert why.braking_from_s - 1e-9 <= braking[0] < why.braking_from_s + sim.dt + 1e-9
        else:
            assert why.braking_from_s >= hit.t - 1e-9
        assert hit.stop_phase != "stopped" or why.late_by_s <= 1e-9


def test_old_files_without_the_timeline_still_replay(s1, tmp_path):
    res = search(s1, "plan", budget=200, seed=0)
    doc = json.loads(res.to_json())
    del doc["hazard"]["why"]
    path = tmp_path / "result.json"
    path.write_text(json.dumps(doc))
    old = SearchResult.load(path)
    assert old.hazard.why is None
    check = check_result(old, search_again=True)
    assert check.reproduced, check.problems


def test_automatic_restart_in_words(tmp_path):
    """restart-auto: the curtain stopped the robot in time, and the words say it restarted while the worker stood
    unseen; the result file keeps the words and replays; the static check names the restart."""
    sim = Simulator("restart-auto")
    res = search(sim, "plan", budget=200, seed=0)
    why = res.hazard.why
    assert why.detected and why.stopped_by == "bay-curtain" and why.late_by_s < 0
    assert "restarted automatically" in why.safeguards and "while no device saw the worker" in why.safeguards
    static = check_cell(sim.cell)
    assert "bay-curtain-restart" in static.failures()
    assert "then restarted" in shortfall(why, static)
    path = res.write(tmp_path)
    assert json.loads(path.read_text())["hazard"]["why"]["safeguards"] == why.safeguards
    check = check_result(SearchResult.load(path), search_again=True)
    assert check.reproduced, check.problems


def test_warning_field_in_words():
    sim = Simulator("warning-field-short")
    res = search(sim, "evolve", budget=200, seed=0)
    why = res.hazard.why
    assert why.stopped_by == "front-scanner"
    assert "front-scanner:warning saw the worker" in why.safeguards and "0.25 of its speed" in why.safeguards
    words = shortfall(why, check_cell(sim.cell))
    assert "requires S = 1.70 m" in words and "short by 0.31 m" in words


def test_guard_door_in_words(tmp_path):
    """door-unlocked: the door let the worker through before the robot was at rest, by how much; the static
    check's shortfall; the result replays (the door's slots included)."""
    sim = Simulator("door-unlocked")
    res = search(sim, "plan", budget=200, seed=0)
    why = res.hazard.why
    assert why.detected and why.stopped_by == "bay-door" and why.late_by_s > 0
    assert ("bay-door opened at 0.70 s without guard locking and let the worker through from 1.30 s, 0.45 s before "
            "the robot was at rest (1.75 s)") in why.safeguards
    words = shortfall(why, check_cell(sim.cell))
    assert "requires S = 1.57 m" in words and "short by 0.20 m" in words
    check = check_result(SearchResult.load(res.write(tmp_path)), search_again=True)
    assert check.reproduced, check.problems


def test_muting_in_words():
    """muting-long: nobody saw the worker, the curtain was muted at the contact, and the words say by how much the
    muting outlasted the pallet."""
    sim = Simulator("muting-long")
    res = search(sim, "plan", budget=200, seed=0)
    why = res.hazard.why
    assert not why.detected
    assert "bay-curtain was muted from 0.10 s to" in why.safeguards and "still muted at the contact" in why.safeguards
    assert "stayed muted 1.50 s after the pallet had cleared the opening" in shortfall(why, check_cell(sim.cell))


def test_no_safeguard_words_in_old_results(s1):
    """A cell without the new safeguards writes no ``safeguards`` key: its result files keep their bytes."""
    res = search(s1, "plan", budget=200, seed=0)
    assert res.hazard.why.safeguards is None
    assert "safeguards" not in res.hazard.why.model_dump()


def test_speed_separation_in_words(tmp_path):
    """ssm-latency: no device stops the robot (the monitor commands speeds); the words say when it measured and
    when its first cut took effect, and the static check's S_p with the real times against what the controller
    allowed; the result replays (the command queue included)."""
    sim = Simulator("ssm-latency")
    res = search(sim, "plan", budget=200, seed=0)
    why = res.hazard.why
    assert not why.detected and why.stopped_by is None
    assert "ssm measured the worker from" in why.safeguards and "first speed cut took effect at" in why.safeguards
    words = shortfall(why, check_cell(sim.cell))
    assert words.startswith("no device stopped the robot before the contact")
    assert "requires S_p = 2.25 m" in words and "real reaction time 0.3 s" in words
    assert "allowed full speed down to 1.55 m (short by 0.70 m)" in words
    check = check_result(SearchResult.load(res.write(tmp_path)), search_again=True)
    assert check.reproduced, check.problems
