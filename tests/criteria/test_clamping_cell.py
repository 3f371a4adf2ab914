"""A search under iso15066 finds a clamping hazard that the transient-only judgement (before issue 34) passed: the
test cell cells/clamp-table.yaml, a slow UR5 picking parts from a table the worker reaches across."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import cellstress
from cellstress.cli import main
from cellstress.core.records import Contact
from cellstress.criteria.iso15066 import CREEP_SPEED, Iso15066
from cellstress.report.scope import strongest_contact
from cellstress.searchers.result import SearchResult
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

CELL = Path(__file__).parent / "cells" / "clamp-table.yaml"


@pytest.fixture(scope="module")
def found():
    return cellstress.search(CELL, "plan", budget=200, seed=0)


def test_plan_finds_a_clamping_hazard_the_transient_judgement_passes(found):
    assert found.found and found.episodes <= 200
    name, numbers = found.hazard.verdict
    assert name == "iso15066" and numbers["case"] == "clamping" and numbers["surface"] == "table"
    assert numbers["limit_N"] == 140.0 and numbers["region"] == "hands"
    assert numbers["force_N"] > 140.0 and numbers["gap_m"] <= 0.02
    assert "clamped against the table" in numbers["reason"]
    # the robot creeps (its own transient force cannot exceed a limit), so the worker's speed does not count,
    # and a clamping contact is not listed apart as creeping
    assert found.hazard.v_R < CREEP_SPEED and numbers["v_human"] == 0.0
    assert found.hazard.severity.creeping is False and found.hazard.severity.force_ratio > 1.0
    # the same contact judged as before issue 34 (a plain Contact: transient, the robot's speed alone) is safe
    sim = Simulator(CELL)
    trace = sim.run(list(found.hazard.actions))
    row = trace.rows[trace.unsafe_row]
    c = sim.contacts.contact(row, L.row_pose(trace.rows[trace.unsafe_row - 1]))
    plain = Contact(c.d_hr, c.v_r, c.robot_link, c.body_part, c.region, c.robot_point, c.human_point, c.normal,
                    c.v_rel, c.reflected_mass)
    old = Iso15066().judge(plain)
    assert old.case == "transient" and old.limit == 280.0 and old.force < 280.0 and not old.unsafe
    # and so is every contact of the episode before the unsafe one
    for i in np.flatnonzero(trace.rows[:-1, L.M_D] <= 0.0):
        assert not sim.verdict_at(trace, int(i)).unsafe


def test_the_search_result_is_the_same_bytes_every_time(found, tmp_path):
    again = cellstress.search(CELL, "plan", budget=200, seed=0)
    a, b = found.write(tmp_path / "a"), again.write(tmp_path / "b")
    assert Path(a).read_bytes() == Path(b).read_bytes()
    doc = json.loads(Path(a).read_text())
    assert doc["hazard"]["iso15066"]["case"] == "clamping"
    assert SearchResult.load(a).hazard.verdict[1]["case"] == "clamping"  # strict loading takes the new numbers
    # and a file written before them (no case, surface, gap, travel, worker speed) still loads
    for key in ("case", "v_human", "why_case", "surface", "gap_m", "travel_m"):
        del doc["hazard"]["iso15066"][key]
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "result.json").write_text(json.dumps(doc))
    assert SearchResult.load(tmp_path / "old").hazard.verdict[1]["force_N"] > 140.0


def test_replay_reproduces_the_clamping_hazard(found, tmp_path, capsys):
    path = found.write(tmp_path)
    assert main(["replay", str(path)]) == 0
    assert "REPRODUCED bit-exactly" in capsys.readouterr().out


def test_a_search_that_finds_nothing_names_the_case_of_its_strongest_contact():
    """What `search` prints when nothing is unsafe (report.scope.strongest_contact): force, limit, case, why."""
    sim = Simulator(CELL)
    for acts in np.random.default_rng(3).integers(0, sim.n_actions, (300, 8)).tolist():
        trace = sim.run(acts)
        if trace.unsafe or not np.any(trace.rows[:, L.M_D] <= 0.0):
            continue
        text = strongest_contact(sim, acts)
        assert re.match(r"\d+ N against a \d+ N limit \((quasi-static|transient), (hands|forearms); "
                        r"(clamped against the|free: the|no fixed surface)", text), text
        break
    else:
        pytest.fail("no safe episode with a contact in 300")


def test_the_fixed_twin_keeps_a_hand_gap_and_is_searched_clean():
    """clamp-table-ok: the same cell with the pick raised so that the gripper stays 100 mm over the table (ISO
    13854's gap for a hand). Hands still touch the creeping robot, but none is clamped and none is unsafe."""
    twin = Path(__file__).parent / "cells" / "clamp-table-ok.yaml"
    assert not cellstress.search(twin, "plan", budget=200, seed=0).found
    sim = Simulator(twin)
    acts = np.random.default_rng(0).integers(0, sim.n_actions, (300, 8))
    batch = sim.run_batch(acts)
    touched = np.flatnonzero(batch.min_d <= 0.0)
    assert len(touched) >= 20 and not batch.unsafe.any()
    for e in touched[:20]:
        trace = sim.run(acts[e].tolist())
        for i in np.flatnonzero(trace.rows[:, L.M_D] <= 0.0):
            assert sim.verdict_at(trace, int(i)).case == "transient"
