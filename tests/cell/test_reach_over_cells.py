"""The built-in reach-over cells (issue 20): a 1.4 m panel too close to the robot for ISO 13857's Table 2, reached
over by the articulated worker, and its twin with the table's distance met (docs/cells.md)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cellstress.cell.load import builtin_text, load_cell
from cellstress.core.iso13857 import reach_over_distance
from cellstress.sim.simulator import Simulator

WITNESS = ("walk+reach-side,walk+reach-side,turn-right-45+reach-over,side-right+bend-forward,"
           "turn-right-45+stand-up")  # docs/cells.md: found by plan
ZONE_FRONT = 1.111  # m: the swept zone's front edge, the baseline's (docs/cells.md, ISO 13855 arithmetic)


def _panel(name: str) -> tuple[float, float]:
    """(y, top) of the cell's low panel."""
    (panel,) = [f for f in load_cell(name).spec.fences if f.top < 2.0]
    assert panel.points[0][1] == panel.points[1][1] and panel.bottom == 0.0
    return panel.points[0][1], panel.top


def test_the_twins_differ_only_in_where_the_panel_stands() -> None:
    a, b = (yaml.safe_load(builtin_text(n)) for n in ("reach-over", "reach-over-ok"))
    for key in ("name", "description", "fences", "human"):
        a.pop(key), b.pop(key)
    assert a == b
    ha, hb = load_cell("reach-over").spec.human, load_cell("reach-over-ok").spec.human
    assert (ha.model, ha.body) == (hb.model, hb.body) == ("articulated", "p95-male")
    assert ha.start.xy[1] - _panel("reach-over")[0] == pytest.approx(hb.start.xy[1] - _panel("reach-over-ok")[0])


def test_the_panel_is_too_close_in_one_and_far_enough_in_the_other() -> None:
    (y_flaw, top), (y_ok, top_ok) = _panel("reach-over"), _panel("reach-over-ok")
    assert top == top_ok == 1.4
    need = max(reach_over_distance(a, 1000 * top) for a in range(0, 2800, 50)) / 1000  # any hazard height
    assert need == 1.1
    assert y_flaw - ZONE_FRONT < need <= y_ok - ZONE_FRONT


def test_the_witness_reaches_over_the_panel_and_not_over_the_twins() -> None:
    sim = Simulator("reach-over")
    trace = sim.run(WITNESS.split(","))
    assert trace.unsafe
    rec = trace.record(trace.unsafe_row)
    assert rec.body_part.endswith("hand") and rec.stop_phase == "running" and rec.v_R > 0.5
    y_panel, top = _panel("reach-over")
    assert rec.y - 0.2 >= y_panel - 1e-9  # the body stays in front of the panel ...
    assert rec.human_point[1] < y_panel - 0.5 and rec.human_point[2] < top  # ... the hand is over and behind it
    twin = Simulator("reach-over-ok").run(WITNESS.split(","))
    assert not twin.unsafe and min(r.d_HR for r in twin.records()) > 0.5


def test_random_episodes_find_the_hazard_only_in_the_flawed_cell() -> None:
    for name, unsafe in (("reach-over", True), ("reach-over-ok", False)):
        sim = Simulator(name)
        acts = np.random.default_rng(0).integers(0, sim.n_actions, (3000, sim.actions_per_episode))
        assert bool(sim.run_batch(acts).unsafe.any()) is unsafe
