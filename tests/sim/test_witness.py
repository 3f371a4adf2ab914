"""Each flawed cell has a short action sequence that reaches U; the same sequence is SAFE in the baseline,
played from the same start point. The witnesses were found by random search (see docs/cells.md)."""

from __future__ import annotations

import pytest

from cellstress.sim.simulator import Simulator

WITNESSES = {
    # cell: (actions, unsafe time step, robot link, body part, devices that saw the worker at contact)
    "s1-scanner-width": ("walk+bend-left,walk+bend-left,walk+bend-forward,walk+bend-forward-right",
                         15, "wrist_2_link", "left-reach", ["front-scanner"]),
    "s2-elbow-intrusion": ("walk+upright,walk+bend-left,walk+bend-forward",
                           12, "upper_arm_link", "left-reach", ["bay-curtain"]),
    "s2-deceptive": ("walk+bend-right,walk+bend-left,turn-right-45+upright,walk+bend-forward-left",
                     14, "forearm_link", "left-reach", ["bay-curtain"]),
    "s3-fence-gap": ("walk+bend-right,turn-left-45+bend-forward-left,walk+bend-forward,walk+bend-forward-left",
                     15, "forearm_link", "left-reach", []),
}


@pytest.fixture(scope="module")
def baseline():
    return Simulator("baseline")


@pytest.mark.parametrize("cell", sorted(WITNESSES))
def test_witness_reaches_unsafe_state(cell):
    actions, step, link, part, devices = WITNESSES[cell]
    trace = Simulator(cell).run(actions.split(","))
    assert trace.unsafe
    hit = trace.record(trace.unsafe_row)
    assert hit.step == step
    assert hit.robot_link == link
    assert hit.body_part == part
    assert hit.d_HR == 0.0
    assert hit.v_R > 0.01  # ten times the standstill tolerance: moving, not a rounding artefact
    assert hit.stop_phase != "stopped"
    assert list(hit.devices) == devices
    # the contact points coincide at contact
    assert max(abs(a - b) for a, b in zip(hit.robot_point, hit.human_point, strict=True)) < 1e-9


@pytest.mark.parametrize("cell", sorted(WITNESSES))
def test_witness_is_safe_in_baseline(cell, baseline):
    actions = WITNESSES[cell][0].split(",")
    flawed = Simulator(cell)
    trace = baseline.with_start(flawed.start).run(actions)
    assert not trace.unsafe
    assert trace.unsafe_row is None
    assert len(trace.rows) == 1 + 4 * len(actions)
