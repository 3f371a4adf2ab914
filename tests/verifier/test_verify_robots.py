"""verify on a cell of two robots: no pruning bound (they assume one robot: docs/verify.md), and the tree's
count of hazardous sequences equals brute force, on either robot's side of the table."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import yaml

from cellstress.cell.load import builtin_text, parse_cell
from cellstress.sim.simulator import Simulator
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.tree import decide


@pytest.mark.parametrize(("xy", "heading"), [((1.6, 0.9), -110.0), ((-1.5, 0.7), -60.0)], ids=["near-b", "near-a"])
def test_two_robot_toy_cell_against_brute_force(xy, heading) -> None:
    data = yaml.safe_load(builtin_text("two-robots"))
    data["human"]["start"] = {"xy": list(xy), "heading_deg": heading}
    sim = Simulator(parse_cell(yaml.safe_dump(data), "two-robots-toy", None))
    assert sim.layout.stops_latch  # (the curtain restarts manually)
    bounds = Bounds(sim, horizon=2)
    assert bounds.at_rest and bounds.swept is not None  # (every robot's stop; each robot's field and path time)
    out = decide(sim, 2, bounds)
    brute = sim.run_batch(np.array(list(itertools.product(range(30), repeat=2))))
    assert out.decided and out.hazardous == int(brute.unsafe.sum())
    assert 0 < out.hazardous < 900
