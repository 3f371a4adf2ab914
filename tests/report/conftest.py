"""Session fixtures for the report tests: one search result (with its report) per situation, made once.

The hazards come from a real search or from the witness sequences documented in docs/cells.md, never from
hard-coded coordinates: the cells may be recalibrated, the relations checked here must still hold.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def witnesses() -> dict[str, list[str]]:
    """cell -> actions, from the witness table of docs/cells.md."""
    text = (ROOT / "docs" / "cells.md").read_text(encoding="utf-8")
    section = text.split("## Witness sequences", 1)[1]
    rows = re.findall(r"^\| (s\d-[a-z0-9-]+) \| ([a-z0-9+\-, ]+) \|", section, flags=re.M)
    return {cell: [a.strip() for a in actions.split(",")] for cell, actions in rows}


@pytest.fixture(scope="session")
def s3_report(tmp_path_factory):
    """`cellstress search s3-fence-gap` (the README's main job) with its report, run in-process."""
    from cellstress.cli import main

    out = tmp_path_factory.mktemp("s3")
    assert main(["search", "s3-fence-gap", "--searcher", "mcts", "--budget", "200", "--seed", "0",
                 "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def s3_sim():
    from cellstress.sim.simulator import Simulator

    return Simulator("s3-fence-gap")


@pytest.fixture(scope="session")
def s3_witness_view(s3_sim):
    from cellstress.report.episode import replay

    return replay(s3_sim, witnesses()["s3-fence-gap"], episode=1)


@pytest.fixture(scope="session")
def s1_witness_view():
    from cellstress.report.episode import replay
    from cellstress.sim.simulator import Simulator

    return replay(Simulator("s1-scanner-width"), witnesses()["s1-scanner-width"], episode=1)


@pytest.fixture(scope="session")
def safe_report(tmp_path_factory, baseline_sim):
    """A search of the baseline that finds nothing: the report shows the riskiest episode."""
    import cellstress
    from cellstress.report import write_report

    out = tmp_path_factory.mktemp("baseline")
    result = cellstress.search(baseline_sim, searcher="random", budget=20, seed=0)
    assert not result.found
    result.write(out)
    write_report(out / "result.json", sim=baseline_sim)
    return out
