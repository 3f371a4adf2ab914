"""Table arithmetic against a hand-computed example, and the paper's Table III as shipped data."""

from __future__ import annotations

import csv
import io
import math
import tomllib
from pathlib import Path

import pytest

from cellstress.campaign.paper import paper_table
from cellstress.campaign.plan import CampaignPlan, CellRef, SearcherRef
from cellstress.campaign.table import csv_text, markdown, summarize, t_interval, wilson

CELL = "s1-scanner-width"


def _rec(searcher: str, seed: int, episodes: int, found: bool, budget: int = 200) -> dict:
    return {"cell": CELL, "searcher": searcher, "seed": seed, "episodes": episodes, "found": found,
            "budget": budget}


# Hand-computed (z = 1.959964, t(0.975, 3) = 3.182446):
# random: episodes 20, 60, fail, fail -> 20, 60, 200, 200: mean 120, median (60 + 200) / 2 = 130,
#   s^2 = (100^2 + 60^2 + 80^2 + 80^2) / 3 = 8800, s = 93.808315; half = 3.182446 * 93.808315 / 2 = 149.2690
#   -> (-29.27, 269.27), clipped to (1, 200). Success 2/4: Wilson centre 0.5, half
#   z / (1 + z^2/4) * sqrt(0.25/4 + z^2/64) = 0.999795 * 0.350033 = 0.349961 -> (0.150039, 0.849961).
# mcts: 10, 20, 30, 40, all found: mean 25, median 25, s^2 = 500/3, s = 12.909944, half = 20.542603
#   -> (4.457397, 45.542603); ratio 25 / 120 = 0.208333. Success 4/4: centre (1 + z^2/8) / (1 + z^2/4)
#   = 0.755055, half 0.999795 * sqrt(z^2/64) = 0.244945 -> (0.510109, 1).
# Paper S1: random 3/10, 166.8; MCTS1 10/10, 70.0 -> ratio 70 / 166.8 = 0.419664.
RECORDS = ([_rec("random", 0, 20, True), _rec("random", 1, 60, True), _rec("random", 2, 200, False),
            _rec("random", 3, 200, False)]
           + [_rec("mcts", s, e, True) for s, e in enumerate((40, 30, 20, 10))])


def test_wilson_by_hand():
    ci = wilson(2, 4)
    assert ci.lo == pytest.approx(0.150039, abs=1e-6) and ci.hi == pytest.approx(0.849961, abs=1e-6)
    ci = wilson(4, 4)
    assert ci.lo == pytest.approx(0.510109, abs=1e-6) and ci.hi == 1.0
    ci = wilson(0, 10)  # the upper bound of 0/10 at 95 %: z^2 / (n + z^2)
    assert ci.lo == 0.0 and ci.hi == pytest.approx(1.959964**2 / (10 + 1.959964**2), abs=1e-6)


def test_t_interval_by_hand():
    ci = t_interval([10.0, 20.0, 30.0, 40.0], 1, 200)
    assert ci.lo == pytest.approx(4.457397, abs=1e-5) and ci.hi == pytest.approx(45.542603, abs=1e-5)
    assert t_interval([20.0, 60.0, 200.0, 200.0], 1, 200) == type(ci)(1, 200)  # clipped on both sides
    assert t_interval([7.0], 1, 200) is None
    same = t_interval([50.0, 50.0, 50.0], 1, 200)
    assert (same.lo, same.hi) == (50.0, 50.0)


def test_summarize_by_hand():
    rows = summarize(RECORDS, [CELL], ["random", "mcts"], 200)
    assert [(r.cell, r.searcher) for r in rows] == [(CELL, "random"), (CELL, "mcts")]
    rnd, mcts = rows
    assert (rnd.runs, rnd.found, rnd.success_rate) == (4, 2, 0.5)
    assert (rnd.mean_episodes, rnd.median_episodes, rnd.ratio_to_random) == (120.0, 130.0, 1.0)
    assert (rnd.mean_ci.lo, rnd.mean_ci.hi) == (1.0, 200.0)
    assert (mcts.runs, mcts.found, mcts.mean_episodes, mcts.median_episodes) == (4, 4, 25.0, 25.0)
    assert mcts.ratio_to_random == pytest.approx(0.208333, abs=1e-6)
    assert mcts.mean_ci.lo == pytest.approx(4.457397, abs=1e-5)
    assert mcts.success_ci.lo == pytest.approx(0.510109, abs=1e-6)
    assert (mcts.paper.found, mcts.paper.runs, mcts.paper.mean_episodes) == (10, 10, 70.0)
    assert mcts.paper_ratio_to_random == pytest.approx(0.419664, abs=1e-6)
    assert rnd.paper_ratio_to_random == 1.0


def test_a_failed_run_counts_as_the_budget_even_if_its_episodes_say_otherwise():
    # with until=first a failed run has used the whole budget; the rule does not rely on that
    rows = summarize([_rec("mcts", 0, 37, False, budget=50), _rec("mcts", 1, 10, True, budget=50)], [CELL],
                     ["mcts"], 50)
    assert rows[0].mean_episodes == 30.0


def test_paper_numbers_only_at_the_papers_budget():
    recs = [dict(r, budget=50, episodes=min(r["episodes"], 50)) for r in RECORDS]
    rows = summarize(recs, [CELL], ["random", "mcts"], 50)
    assert all(r.paper is None and r.paper_ratio_to_random is None for r in rows)
    assert rows[1].ratio_to_random == pytest.approx(25 / ((20 + 50 + 50 + 50) / 4))


def test_no_random_no_ratio_and_unknown_pairs_have_no_paper_numbers():
    recs = [dict(r, cell="baseline") for r in RECORDS if r["searcher"] == "mcts"]
    (row,) = summarize(recs, ["baseline"], ["mcts"], 200)
    assert row.ratio_to_random is None and row.paper is None and row.paper_ratio_to_random is None


def _plan() -> CampaignPlan:
    return CampaignPlan((CellRef(CELL, CELL, "0" * 64, "contact-while-moving: unsafe when touched"),),
                        (SearcherRef("random", ()), SearcherRef("mcts", ())), 4, 200, "0")


def test_markdown_and_csv_rows():
    rows = summarize(RECORDS, [CELL], ["random", "mcts"], 200)
    md = markdown(rows, _plan())
    lines = md.splitlines()
    assert ("| s1-scanner-width | mcts | 4/4 | 1.00 (0.51–1.00) | 25.0 (4.5–45.5) | 25.0 | 0.21 | 10/10 | 70.0 "
            "| 0.42 |") in lines
    assert ("| s1-scanner-width | random | 2/4 | 0.50 (0.15–0.85) | 120.0 (1.0–200.0) | 130.0 | 1.00 | 3/10 "
            "| 166.8 | 1.00 |") in lines
    assert "Huck" in md and "Wilson" in md and "Student-t" in md
    assert f"Criterion of {CELL}: contact-while-moving: unsafe when touched." in lines
    table = list(csv.DictReader(io.StringIO(csv_text(rows))))
    assert table[1]["searcher"] == "mcts"
    assert float(table[1]["mean_episodes"]) == 25.0 and float(table[1]["ratio_to_random"]) == pytest.approx(0.208333)
    assert float(table[0]["success_ci_lo"]) == pytest.approx(0.150039, abs=1e-6)
    assert table[1]["paper_found"] == "10" and table[1]["paper_mean_episodes"] == "70"


def test_paper_table3_as_published():
    p = paper_table()
    want = {  # Huck et al. 2020, Table III (also docs/results.md and DESIGN.md)
        "s1-scanner-width": [(3, 166.8), (10, 70.0), (10, 49.7)],
        "s2-elbow-intrusion": [(3, 150.4), (8, 63.3), (9, 80.4)],
        "s3-fence-gap": [(8, 81.1), (10, 34.9), (10, 38.0)],
    }
    for cell, values in want.items():
        for searcher, (found, mean) in zip(("random", "mcts", "mcts-commit"), values, strict=True):
            row = p.get(cell, searcher)
            assert (row.found, row.runs, row.mean_episodes, row.budget) == (found, 10, mean, 200)
    assert len(p.rows) == 9 and "Huck" in p.citation and "Table III" in p.citation
    assert p.get("baseline", "mcts") is None
    # failures count 200: a mean can never be below what the failures alone contribute
    for (_, _), row in p.rows:
        assert row.mean_episodes >= (row.runs - row.found) * row.budget / row.runs - 1e-9
    assert math.isclose(sum(r.found for _, r in p.rows), 71)


def test_the_data_file_ships_with_the_package():
    root = Path(__file__).resolve().parents[2]
    data = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["cellstress"]
    assert "campaign/*.json" in data
    assert (root / "src" / "cellstress" / "campaign" / "paper_table3.json").is_file()
