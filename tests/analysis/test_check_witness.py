"""``check --witness`` (analysis.witness): each failing row of the static check gets a simulated witness that
takes the row's own way in, the reason it cannot, or an honest "not reproduced"; the aim is the check's own
robot point, on the robot's surface at the row's moment."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import yaml

from cellstress.analysis.check_rows import CheckRow, check_rows
from cellstress.analysis.hazard_zone import SAMPLE_DT, robot_poses
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.analysis.witness import aim_of, aim_text, out_of_reach, takes_way, witness_searches
from cellstress.cell.load import builtin_text, parse_cell
from cellstress.searchers.plan import Plan
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator


@pytest.fixture(scope="module")
def s3():
    sim = Simulator("s3-fence-gap")
    return sim, check_rows(check_cell(sim.cell, sim.layout), check_programs(sim.layout))


def _row(rows, name: str) -> CheckRow:
    return next(r for r in rows if r.name == name)


def test_failing_rows_name_their_robot_point_and_way(s3) -> None:
    _, rows = s3
    scanner, reach = _row(rows, "front-scanner"), _row(rows, "undetected-reach")
    assert not scanner.ok and not reach.ok
    assert (scanner.way, scanner.device) == ("late", "front-scanner")
    assert (reach.way, reach.device) == ("unseen", "")
    assert scanner.point.part == "wrist_2_link" and scanner.point.t == pytest.approx(1.46)
    # the scanner row measures from the field's open edge x = 1.5
    assert scanner.point.toward[0][0] == pytest.approx(1.5)
    # every row the check makes has a way, but a program's own
    assert all(bool(r.way) != r.name.startswith("program") for r in rows)


def test_aim_is_on_the_capsule_surface_towards_the_worker(s3) -> None:
    """s3's scanner row names the wrist at 1.46 s, the end of a move: the robot creeps to a stop there (slower than
    the criterion's 1 mm/s), and a contact with a robot at rest is none, so the aim is the nearest point at a
    moment (of 10 ms samples) when the capsule still moves faster than that: 1.43 s."""
    sim, rows = s3
    row = _row(rows, "front-scanner")
    aim = aim_of(sim, row.point)
    ts, caps, ra, rb = robot_poses(sim.params, SAMPLE_DT, robot=0)[0]
    k = int(np.argmin(np.abs(ts - aim.time)))
    assert aim.time == pytest.approx(1.43) and aim.robot == 0
    p = np.asarray(aim.point)
    gaps = []
    for j in range(len(caps)):
        a, b = ra[k, j], rb[k, j]
        s = np.clip(np.dot(p - a, b - a) / max(float(np.dot(b - a, b - a)), 1e-18), 0.0, 1.0)  # (a ball: a = b)
        gaps.append(np.linalg.norm(p - (a + s * (b - a))) - float(sim.params.cap_r[caps[j]]))
    j = int(np.argmin(np.abs(gaps)))
    assert abs(gaps[j]) < 1e-9  # on a capsule's surface
    assert [c.name for c in sim.layout.capsules][caps[j]] == "wrist_2_link"
    v_tol = float(sim.params.scal[L.C_VTOL])
    assert np.linalg.norm(ra[k + 1, j] - ra[k, j]) / SAMPLE_DT > v_tol  # moving then
    assert np.linalg.norm(ra[k + 4, j] - ra[k + 3, j]) / SAMPLE_DT < v_tol  # at rest at the row's own moment
    # pushed out towards the worker's side (the scanner's edge at x = 1.5 lies in +x of the robot)
    assert p[0] > ra[k, j][0]
    assert Plan(aim=aim_text(aim)).aimed() is not None  # the text plan reads


def test_aim_moves_to_a_moment_an_episode_meets(s3) -> None:
    """s2-elbow-intrusion's curtain row names 1.72 s of the cycle; its episodes (fixed arrival) last 1.6 s, so the
    aim is the nearest point at a moment within them."""
    sim = Simulator("s2-elbow-intrusion")
    rows = check_rows(check_cell(sim.cell, sim.layout), check_programs(sim.layout))
    row = _row(rows, "bay-curtain")
    assert row.point.t > 1.6
    aim = aim_of(sim, row.point)
    assert 0.0 <= aim.time <= 1.6 + 1e-9


def test_s3_witnesses_take_each_rows_way(s3) -> None:
    """The scanner row's witness is seen by the scanner before the contact; the undetected reach's by no device;
    each replays unsafe. The first hazard the search meets is the unseen one, so the scanner row needs the
    budget run: its witness comes later in it."""
    sim, rows = s3
    got = {w.row: w for w in witness_searches(sim, rows, 200, 0)}
    assert set(got) == {"front-scanner", "undetected-reach"}
    for name, w in got.items():
        assert w.witness is not None, w.line()
        trace = sim.run(list(w.witness.actions))
        assert trace.unsafe
        records = trace.records()
        seen = {d for r in records[: trace.unsafe_row + 1] for d in r.devices}
        assert ("front-scanner" in seen) == (name == "front-scanner")
        assert takes_way(_row(rows, name), sim.layout, records, trace.unsafe_row)
        assert "FOUND at episode" in w.line() and w.aim is not None
    first = got["undetected-reach"].witness
    other = sim.run(list(first.actions))
    assert not takes_way(_row(rows, "front-scanner"), sim.layout, other.records(), other.unsafe_row)
    # the same again: a pure function of the seed
    again = {w.row: w for w in witness_searches(sim, rows, 200, 0)}
    assert {k: v.witness for k, v in again.items()} == {k: v.witness for k, v in got.items()}


def test_rows_with_a_limit_or_no_way_are_not_searched(s3) -> None:
    sim, _ = s3
    rows = (CheckRow("reach-over", "x", False, "", "", "cannot reach over a 1.6 m top", way="unseen"),
            CheckRow("program", "robot program", False, "", ""),
            CheckRow("fine", "x", True, "", "", way="any"))
    got = witness_searches(sim, rows, 5, 0)
    assert [w.row for w in got] == ["reach-over", "program"]
    assert all(w.result is None for w in got)
    assert got[0].line() == "reach-over: cannot reach over a 1.6 m top"
    assert "not searched" in got[1].line()


def test_not_reproduced_says_so(s3) -> None:
    """A row whose way no episode of a tiny budget takes: the line says the static verdict stands."""
    sim, rows = s3
    row = _row(rows, "front-scanner")
    got = witness_searches(sim, (row,), 1, 0)
    assert got[0].witness is None or got[0].witness.episode == 1
    if got[0].witness is None:
        assert "not reproduced in 1 episodes" in got[0].line() and "static verdict stands" in got[0].line()


def test_a_start_out_of_reach_is_named_not_searched(s3) -> None:
    """s3-fence-gap on a floor 40 m long, the worker starting 20 m away: 8 actions of 0.2 s at 1.6 m/s get 2.56 m
    plus a body's reach; every failing row says so, no search runs. At the cell's own start: nothing to say."""
    sim, rows = s3
    assert out_of_reach(sim) == ""
    d = yaml.safe_load(builtin_text("s3-fence-gap"))
    d["floor"]["ymax"] = 25.0
    d["human"]["start"]["xy"] = [0.0, 20.0]
    far = Simulator(parse_cell(yaml.safe_dump(d), "far", None))
    why = out_of_reach(far)
    assert why.startswith("the simulated worker cannot get there in one episode: the start is 1")
    got = witness_searches(far, rows, 200, 0)
    assert got and all(w.result is None and w.limit == why for w in got)


def test_a_row_about_one_robot_of_several_asks_for_a_contact_with_it() -> None:
    """two-robots: nothing stops robot b, so the undetected reach to b fails; its witness touches b. The same
    episode with its contact moved to robot a's capsule does not witness the row."""
    sim = Simulator("two-robots")
    rows = check_rows(check_cell(sim.cell, sim.layout), check_programs(sim.layout))
    row = _row(rows, "undetected-reach:b")
    (w,) = [w for w in witness_searches(sim, rows, 200, 0) if w.row == row.name]
    assert w.witness is not None, w.line()
    trace = sim.run(list(w.witness.actions))
    records, at = list(trace.records()), trace.unsafe_row
    assert records[at].robot_link.startswith("b:")
    assert takes_way(row, sim.layout, records, at)
    a_link = next(c.name for c in sim.layout.robots[0].capsules)
    records[at] = records[at].model_copy(update={"robot_link": a_link})
    assert not takes_way(row, sim.layout, records, at)


def test_a_row_takes_a_witness_another_rows_search_found() -> None:
    """s1-scanner-width's scanner row, and the same row without its point (searched unaimed), one episode each:
    the unaimed search finds nothing in its one episode, the aimed one its witness; the blind row takes that
    one (the same way in), from that search's result."""
    sim = Simulator("s1-scanner-width")
    rows = check_rows(check_cell(sim.cell, sim.layout), check_programs(sim.layout))
    row = _row(rows, "front-scanner")
    blind = replace(row, name="blind", point=None)
    lone = witness_searches(sim, (blind,), 1, 0)[0]
    assert lone.witness is None and "not reproduced in 1 episodes" in lone.line()
    got = {w.row: w for w in witness_searches(sim, (blind, row), 1, 0)}
    assert got["front-scanner"].witness is not None
    assert got["blind"].witness == got["front-scanner"].witness
    assert got["blind"].result is got["front-scanner"].result and got["blind"].aim is None
