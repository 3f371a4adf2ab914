"""analysis/worker_reach.py: beside a reach-over row that fails, whether the simulated worker can get there at all
(issue 34: check and search agree)."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from cellstress.analysis import worker_reach as W
from cellstress.analysis.check_rows import check_rows
from cellstress.analysis.iso13855 import check_cell
from cellstress.api import search
from cellstress.cell.load import builtin_text, parse_cell
from cellstress.core.iso13857 import TABLE_2
from cellstress.human.anthropometry import BODY_SIZES
from cellstress.sim.simulator import Simulator

ROOT = Path(__file__).resolve().parents[2]
ZONE_FRONT = 1.111  # m: reach-over's swept zone, its front edge at 1.09 m (tests/cell/test_reach_over_cells.py)


def _reach_over(top: float, behind: float, model: str = "articulated"):
    """reach-over with its front panel of height ``top`` placed ``behind`` in front of the zone (the walls' ends
    and the start with it); ``model`` paper: the paper's worker instead."""
    d = yaml.safe_load(builtin_text("reach-over"))
    y = round(ZONE_FRONT + behind, 3)
    d["fences"][0].update(top=top, points=[[-1.5, y], [1.5, y]])
    d["fences"][1]["points"][0] = [-1.5, y]
    d["fences"][2]["points"][0] = [1.5, y]
    d["human"]["start"]["xy"] = [0.0, round(y + 0.75, 3)]
    if model == "paper":
        d["human"] = {k: v for k, v in d["human"].items() if k not in ("model", "body")}
    d["name"] = f"ro-{top}-{behind}-{model}"
    return parse_cell(yaml.safe_dump(d, sort_keys=False), d["name"], None)


def _row(cell):
    static = check_cell(cell)
    (row,) = [r for r in check_rows(static) if r.name == "reach-over"]
    return static, row


def test_the_stored_table_covers_every_body_on_table_2s_grid():
    data = json.loads((ROOT / "src" / "cellstress" / "analysis" / W.TABLE).read_text())
    assert data["a_mm"] == list(TABLE_2.a_mm) and data["b_mm"] == list(TABLE_2.b_mm)
    assert sorted(data["bodies"]) == sorted(BODY_SIZES)
    for rows in data["bodies"].values():
        c = np.asarray(rows)
        assert c.shape == (len(TABLE_2.a_mm), len(TABLE_2.b_mm)) and (c >= 0.0).all()
        # the worker never gets further than the standard's distance (issue 20: 0 cells "beyond" at p95)
        assert (c <= np.asarray(TABLE_2.c_mm) + 100.0).all()


def test_a_band_takes_the_larger_row_and_the_column_at_or_below_the_top():
    t = W.SearchTable((0.0, 200.0, 400.0), (1000.0, 1400.0), np.array([[0.5, 0.1], [0.7, 0.2], [0.6, 0.3]]))
    assert t.reach(-np.inf, 0.2, 1.0) == 0.7
    assert t.reach(0.2, 0.4, 1.3) == 0.7  # 1.3 m: the 1.0 m column (a lower top is reached over at least as far)
    assert t.reach(0.2, 0.4, 1.4) == 0.3
    assert t.reach(0.2, 0.4, 0.9) == np.inf  # below the table: nothing claimed


@pytest.mark.parametrize("behind", [0.2, 0.4, 0.6])
def test_a_1_6_m_panel_the_articulated_worker_does_not_get_over_names_its_limit(behind):
    """Table 2 asks 0.9 m behind 1.6 m at 1.09 m, the body bound says a p95 man could reach 0.73 m, but the
    articulated worker's arms get nothing beyond the face at 1.0-1.2 m (the stored search): the row says so."""
    static, row = _row(_reach_over(1.6, behind))
    assert not row.ok
    assert "articulated worker (p95-male) gets at most" in row.limit and "beam search" in row.limit
    assert row.limit in "\n".join(static.lines())
    # the undetected reach counted the arm over that panel: kept out of it, the arm path is met, and its row says so
    (reach,) = [r for r in check_rows(static) if r.name == "undetected-reach"]
    assert reach.ok or reach.limit.startswith("the arm comes that close only over fence 1 panel 1, which the "
                                              "simulated worker cannot reach over")
    assert reach.ok or reach.limit in "\n".join(static.lines())


@pytest.mark.parametrize("top, behind", [(1.4, 0.6), (1.0, 0.8)])
def test_where_the_worker_gets_there_no_limit_is_named_and_plan_finds_it(top, behind):
    cell = _reach_over(top, behind)
    static, row = _row(cell)
    assert not row.ok and row.limit == ""
    assert all(r.limit == "" for r in check_rows(static) if r.name == "undetected-reach")
    assert search(cell, "plan", 200, 0).found


def test_the_paper_worker_is_judged_by_the_bound_and_the_bound_holds():
    """The paper's worker (hip at standing height, reach volumes around the top edge) behind a 1.6 m panel with the
    zone 0.7 m behind (Table 2 asks 0.9 m): the bound says at most 0.62 m at 1.0-1.2 m, so the row names it; and
    no random episode touches the robot. At 1.2 m and 0.4 m the worker can reach, and the row names nothing."""
    far = _reach_over(1.6, 0.7, "paper")
    _, row = _row(far)
    assert not row.ok and row.limit.startswith("the simulated worker cannot reach over the panel")
    assert "a bound on its body" in row.limit
    close = _reach_over(1.2, 0.4, "paper")
    _, near = _row(close)
    assert not near.ok and near.limit == ""
    for cell, reached in ((far, False), (close, True)):  # the same random episodes touch the robot only where
        sim = Simulator(cell)                            # no limit is named
        acts = np.random.default_rng(0).integers(0, sim.n_actions, (3000, sim.actions_per_episode))
        assert bool(sim.run_batch(acts).unsafe.any()) is reached


def test_the_stored_column_is_what_the_search_gives_now():
    """The table depends on the worker model and the kernels: one column recomputed (p95-male, b = 1.6 m) equals
    the stored one (else: python scripts/build_reach_over_table.py)."""
    spec = importlib.util.spec_from_file_location("build_reach_over_table", ROOT / "scripts" /
                                                  "build_reach_over_table.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    stored = json.loads((ROOT / "src" / "cellstress" / "analysis" / W.TABLE).read_text())
    j = stored["b_mm"].index(1600.0)
    assert mod.column(mod._bench(), "p95-male", 1600.0) == [row[j] for row in stored["bodies"]["p95-male"]]
