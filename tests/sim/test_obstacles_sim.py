"""Obstacles in the simulator: the worker cannot walk into one nor lean the trunk into it; the robot's pedestal is
one. Checked against the prism's geometry sampled densely."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from cellstress.cell.load import parse_cell
from cellstress.sim import layout as L
from cellstress.sim.build import PEDESTAL, build_layout
from cellstress.sim.geometry import capsule_touches_prism
from cellstress.sim.simulator import Simulator

SQUARE = np.asarray([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
L_SHAPE = np.asarray([(0.0, 0.0), (1.0, 0.0), (1.0, 0.4), (0.4, 0.4), (0.4, 1.0), (0.0, 1.0)])


def _distance_sampled(a, b, poly, h, n=400):
    """Distance from the segment ab to the prism (poly raised to h), by dense sampling of the segment."""
    from cellstress.core.plane import polygon_distance

    best = np.inf
    for t in np.linspace(0.0, 1.0, n):
        p = a + t * (b - a)
        plan = polygon_distance(float(p[0]), float(p[1]), [tuple(v) for v in poly])
        dz = max(0.0, p[2] - h)
        best = min(best, float(np.hypot(plan, dz)) if p[2] >= 0 else plan)
    return best


coord = st.floats(-0.8, 1.8, allow_nan=False)
height = st.floats(0.0, 2.2, allow_nan=False)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(ax=coord, ay=coord, az=height, bx=coord, by=coord, bz=height, r=st.floats(0.05, 0.3), poly=st.sampled_from(
    [SQUARE, L_SHAPE]), h=st.floats(0.2, 1.5))
def test_capsule_touches_prism_agrees_with_sampling(ax, ay, az, bx, by, bz, r, poly, h):
    a, b = np.asarray([ax, ay, az]), np.asarray([bx, by, bz])
    d = _distance_sampled(a, b, poly, h)
    got = capsule_touches_prism(ax, ay, az, bx, by, bz, r, poly, 0, len(poly), h)
    step = np.linalg.norm(b - a) / 399  # sampling resolution: decide only outside it
    if d < r - step:
        assert got
    elif d > r + step:
        assert not got


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def _sim(data: dict, tmp_path) -> Simulator:
    return Simulator(parse_cell(yaml.safe_dump(data), str(tmp_path / "cell.yaml"), tmp_path))


def test_the_worker_cannot_walk_into_an_obstacle(baseline, tmp_path):
    # the worker starts at (0.7, 3.35) facing -y; a crate 0.6 m ahead
    data = dict(baseline, obstacles=[{"name": "crate", "box": {"center": [0.7, 2.5], "size": [0.6, 0.2]},
                                      "height": 0.3}])
    free = Simulator("baseline").run(["walk+upright"] * 4)
    blocked = _sim(data, tmp_path).run(["walk+upright"] * 4)
    y_free, y_blocked = free.rows[-1, L.M_Y], blocked.rows[-1, L.M_Y]
    assert y_free < 2.3  # without the crate the worker walks on past it
    # with it, the body's 0.2 m footprint stays off the crate's near edge at y = 2.6
    assert y_blocked >= 2.6 + 0.2 - 1e-9
    assert y_blocked < 2.6 + 0.2 + 1.6 * 0.05 + 1e-9  # and got as close as one stride allows


def test_the_trunk_cannot_lean_into_a_tall_obstacle(baseline, tmp_path):
    # a 1.3 m machine right in front of the worker: bending forward over it would put the trunk inside
    x, y = baseline["human"]["start"]["xy"]
    data = dict(baseline, obstacles=[{"name": "machine", "box": {"center": [x, y - 0.45], "size": [0.8, 0.4]},
                                      "height": 1.3}])
    low = dict(baseline, obstacles=[{"name": "machine", "box": {"center": [x, y - 0.45], "size": [0.8, 0.4]},
                                     "height": 0.5}])
    tall = _sim(data, tmp_path).run(["walk+bend-forward"])
    short = _sim(low, tmp_path).run(["walk+bend-forward"])
    assert short.rows[-1, L.M_FWD] > np.deg2rad(50.0)  # over a low one the worker bends fully
    assert tall.rows[-1, L.M_FWD] < short.rows[-1, L.M_FWD]


def test_the_robot_base_is_an_obstacle(baseline, tmp_path):
    # the UR10 on the floor at (0.7, 1.9), right on the worker's way
    data = dict(baseline, robot=dict(baseline["robot"], base={"xyz": [0.7, 1.9, 0.0], "yaw_deg": 0.0}))
    sim = _sim(data, tmp_path)
    ped = [o for o in sim.layout.obstacles if o.name == PEDESTAL]
    assert len(ped) == 1 and 0.03 < ped[0].height < 0.1  # the UR10's base link is 38 mm high
    xs = [p[0] for p in ped[0].footprint()]
    assert min(xs) < 0.7 < max(xs)
    none = dict(data, robot=dict(data["robot"], pedestal="none"))
    assert PEDESTAL not in [o.name for o in build_layout(parse_cell(
        yaml.safe_dump(none), str(tmp_path / "c2.yaml"), tmp_path)).obstacles]
