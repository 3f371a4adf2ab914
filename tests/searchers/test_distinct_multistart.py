"""Several start points (the first decision picks one, recorded as start:NAME) and the distinct-hazards mode."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from cellstress.cell.load import load_cell
from cellstress.core.errors import ActionError
from cellstress.searchers import search
from cellstress.searchers.distinct import hazard_class
from cellstress.searchers.multistart import MultiStartProblem
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator


@pytest.fixture(scope="module")
def af():
    return Simulator("all-flaws")


def test_all_flaws_cell_has_the_three_start_points(af):
    starts = af.cell.spec.human.starts
    assert [s.name for s in starts] == ["upper-end", "lower-end", "lower-end-right"]
    assert starts[0].xy == (0.7, 3.35) and starts[1].xy == (0.0, -2.5)


def test_start_token_replays_exactly(af):
    p = MultiStartProblem(af)
    assert p.actions_per_episode == 9 and p.choices(0) == 3 and p.choices(1) == 30
    state, rows = p.step(p.reset(), 4)  # 4 % 3 = start 1
    assert state[0] == 1 and rows[0, L.M_X] == 0.0 and rows[0, L.M_Y] == -2.5
    parts = [rows]
    for a in (0, 6, 12):
        state, r = p.step(state, a)
        parts.append(r)
    names = p.names([4, 0, 6, 12])
    assert names[0] == "start:lower-end"
    trace = af.run(names)
    assert np.array_equal(trace.rows, np.concatenate(parts))
    with pytest.raises(ActionError, match="unknown start 'nowhere'"):
        af.run(["start:nowhere", "walk+upright"])


@pytest.mark.parametrize("searcher", ["random", "mcts"])
def test_multistart_search_is_deterministic(af, searcher):
    a = search(af, searcher, 40, 3, until="budget")
    b = search(af, searcher, 40, 3, until="budget")
    assert a.to_json() == b.to_json()
    assert all(t.actions[0].startswith("start:") for t in a.top)
    assert "distinct" not in a.to_dict()


def test_distinct_mode_lists_each_class_once_with_a_replay(af):
    res = search(af, "mcts", 400, 0, until="budget", distinct=True)
    assert res.distinct, "expected at least one hazard class in 400 episodes"
    keys = [tuple(map(str, d.klass.model_dump().values())) for d in res.distinct]
    assert len(set(keys)) == len(keys)
    # worst first (searchers.severity: creeping last, then by contact speed), ties in the order found
    order = [(d.severity.creeping, -d.severity.v_R, d.episode) for d in res.distinct]
    assert order == sorted(order)
    for d in res.distinct:
        trace = af.run(d.actions)
        assert trace.unsafe
        hit = trace.records()[trace.unsafe_row]
        assert (hit.step, hit.robot_link) == (d.step, d.klass.robot_link)
    assert len(res.hazards) >= len(res.distinct)


def test_hazard_class_key(af):
    sim = af.with_start((0.0, -2.5, 90.0))
    # the S2 witness (docs/cells.md): the lower end of all-flaws is S2 itself (same robot, same phase)
    seq = ["walk+bend-right", "walk+bend-left", "turn-right-45+upright", "walk+bend-forward-left"]
    state = sim.reset()
    for a in seq:
        state, rows = sim.step(state, a)
        if sim.is_unsafe(state):
            break
    assert sim.is_unsafe(state)
    device, link, region, cx, cy = hazard_class(sim, state, rows[-1])
    assert (device, link, region, cx, cy) == ("bay-curtain", "forearm_link", "hands", 0, -4)


def test_distinct_needs_until_budget(tmp_path):
    out = subprocess.run([sys.executable, "-m", "cellstress", "search", "all-flaws", "--distinct", "--out",
                          str(tmp_path / "x")], capture_output=True, text=True)
    assert out.returncode == 2 and out.stderr.strip() == "error: --distinct needs --until budget"
    with pytest.raises(Exception, match="distinct needs"):
        search(load_cell("all-flaws"), "mcts", 10, 0, distinct=True)


def test_root_causes_group_the_classes_and_links_split_the_chain_in_thirds() -> None:
    """One safeguard and one body area are one root cause, whatever the link, the hand or forearm and the floor
    cell; the UR10's links fall into the thirds of its chain from the base."""
    from cellstress.searchers.distinct import link_group, root_cause
    from cellstress.searchers.result import HazardClass
    from cellstress.sim.simulator import Simulator

    layout = Simulator("baseline").layout
    thirds = {c.name: link_group(layout, c.name) for c in layout.capsules}
    assert thirds["base_link"] == thirds["shoulder_link"] == thirds["upper_arm_link"] == "base side"
    assert thirds["forearm_link"] == thirds["wrist_1_link"] == "middle"
    assert thirds["wrist_2_link"] == thirds["wrist_3_link"] == "wrist and tool"

    def klass(device, link, region, x):
        return HazardClass(device=device, robot_link=link, body_region=region, approach_cell=(x, 0.0, x + 0.5, 0.5))

    same = [klass("bay-curtain", "forearm_link", "hands", 0.0), klass("bay-curtain", "upper_arm_link", "forearms", 0.5)]
    assert root_cause(same[0]) == root_cause(same[1]) == ("bay-curtain", "upper limbs")
    assert root_cause(klass("bay-curtain", "forearm_link", "chest", 0.0)) == ("bay-curtain", "trunk")
    assert root_cause(klass("none", "forearm_link", "hands", 0.0)) != root_cause(same[0])
