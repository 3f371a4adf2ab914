"""The articulated worker in the simulator (issue 20): its arms' kinematics against human.reach's, arms held off
fences and the table, stances and gaits, devices that see the arms, d_HR to the arm capsules, and replay."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from cellstress.cell.load import parse_cell
from cellstress.core.errors import ActionError
from cellstress.human.anthropometry import GAITS, POSTURES
from cellstress.human.reach import arm_points
from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.kernels.body import arm_chain
from cellstress.sim.simulator import Simulator

PANEL_X = 0.6  # the panel's plane in the test cells; the worker starts at x = 0 facing +x

ROBOT = {  # far from the worker: only the worker matters in most tests here
    "urdf": "ur10", "base": {"xyz": [2.4, 2.4, 0.0], "yaw_deg": 0.0}, "capsules": "auto", "stopping_time": 0.15,
    "task": {"waypoints_deg": [[0, -90, 0, -90, 0, 0], [90, -90, 0, -90, 0, 0]], "dwell": 0.2,
             "speed_scale": 0.5, "phase": 0.0},
}


def _cell(*, model="articulated", panel_top=None, table=False, curtain_x=None, robot=None, body="p50-male"):
    doc = {
        "name": "articulated-test",
        "robot": robot or ROBOT,
        "floor": {"xmin": -3.0, "xmax": 3.0, "ymin": -3.0, "ymax": 3.0},
        "human": {"model": model, "start": {"xy": [0.0, 0.0], "heading_deg": 0.0}, "arrival": "fixed"},
        "criterion": {"type": "contact-while-moving", "distance_tolerance": 0.0, "speed_tolerance": 0.001},
    }
    if body is not None:
        doc["human"]["body"] = body
    if panel_top is not None:
        doc["fences"] = [{"points": [[PANEL_X, -2.0], [PANEL_X, 2.0]], "top": panel_top}]
    if table:
        doc["table"] = {"height": 0.85, "polygons": [[[0.5, -1.0], [1.5, -1.0], [1.5, 1.0], [0.5, 1.0]]]}
    if curtain_x is not None:
        doc["devices"] = [{"type": "light-curtain", "name": "curtain", "start": [curtain_x, -1.0],
                           "end": [curtain_x, 1.0], "bottom": 0.3, "top": 1.9, "response_time": 0.05,
                           "resolution_mm": 30}]
    return Simulator(parse_cell(yaml.safe_dump(doc), "articulated-test.yaml", None))


def _capsules(sim, actions):
    """Every pose of playing ``actions`` (worker only) and the capsules there."""
    poses = sim.worker_paths(np.array([[sim.action_index(a) for a in actions]]))[0]
    return poses, sim.worker_capsules(poses)


def test_the_arm_chain_is_human_reach_kinematics():
    rng = np.random.default_rng(7)
    lengths = np.array([0.33, 0.27, 0.19])
    for _ in range(200):
        q = rng.uniform(-math.pi, math.pi, 5)
        ref = arm_points(q, lengths)
        got = np.array(arm_chain(*q, *lengths)).reshape(3, 3)
        np.testing.assert_allclose(got, ref, atol=1e-12)


def test_the_paper_worker_stays_the_default():
    sim = Simulator("s3-fence-gap")
    assert sim.n_actions == 30 and not sim.layout.worker.articulated
    assert sim.worker_capsules(sim.worker_paths(np.zeros((1, 2), dtype=np.int64))[0])[2].shape[1] == 6


def test_actions_are_the_models_own():
    sim = _cell()
    assert sim.n_actions == 119 and sim.action_names[0] == "walk+upright"
    assert sim.action_index("stand+reach-over") == sim.action_names.index("stand+reach-over")
    with pytest.raises(ActionError, match="MOVE\\+CHANGE"):
        sim.action_index("turn-left-90+upright")  # a paper action


def test_stances_lower_and_raise_the_hip_and_a_crouched_worker_does_not_walk():
    sim = _cell()
    h = sim.layout.body.height
    poses, _ = _capsules(sim, ["stand+crouch", "walk+hang", "stand+stand-up", "stand+tiptoe"])
    spa = sim.steps_per_action
    crouch = POSTURES["crouch"].hip_height(h) - POSTURES["stand"].hip_height(h)
    assert poses[spa - 1, L.POSE_EXT] == pytest.approx(crouch, abs=1e-12)
    assert np.all(poses[spa:2 * spa, 0] == 0.0)  # walking while crouched: the feet stay
    assert poses[3 * spa - 1, L.POSE_EXT] == pytest.approx(0.0, abs=1e-12)
    assert poses[-1, L.POSE_EXT] == pytest.approx(POSTURES["tiptoe"].rise, abs=1e-12)
    a, b, _ = sim.worker_capsules(poses[[spa - 1]])
    assert a[0, 2, 2] == pytest.approx(POSTURES["crouch"].hip_height(h), abs=1e-9)  # the hip


def test_stepping_back_and_sideways_at_their_gaits():
    sim = _cell()
    stride = sim.cell.spec.human.walking_speed * sim.dt * sim.steps_per_action
    poses, _ = _capsules(sim, ["step-back+upright", "side-left+upright"])
    spa = sim.steps_per_action
    assert poses[spa - 1, 0] == pytest.approx(-GAITS["step-back"].speed_fraction * stride)
    assert poses[2 * spa - 1, 1] == pytest.approx(GAITS["side-step"].speed_fraction * stride)
    assert poses[-1, 2] == 0.0  # the heading holds


def test_arms_do_not_pass_through_the_table():
    """Bent over a table, the paper worker's hanging arm goes through its top (issue 20); the articulated
    worker's arms stop on it."""
    acts = ["walk+upright", "walk+upright", "stand+bend-forward", "stand+hang"]
    art = _cell(table=True)
    _, (a, b, r) = _capsules(art, acts)
    low = np.minimum(a[:, 4:, 2], b[:, 4:, 2]) - r[:, 4:]
    over_table = (np.maximum(a[:, 4:, 0], b[:, 4:, 0]) > 0.5 + 0.1)
    assert np.all(low[over_table] >= 0.85 - 1e-9)
    paper = _cell(model="paper", table=True)
    _, (pa, pb, pr) = _capsules(paper, ["walk+upright", "walk+upright", "walk+bend-forward"])
    assert np.min(np.minimum(pa[:, 4:6, 2], pb[:, 4:6, 2]) - pr[:, 4:6]) < 0.85 - 0.2


def test_arms_do_not_pass_through_a_fence_panel():
    sim = _cell(panel_top=2.0)
    _, (a, b, r) = _capsules(sim, ["walk+upright", "walk+reach-forward", "stand+reach-high", "stand+bend-forward",
                                   "stand+reach-low"])
    front = np.maximum(a[:, 2:, 0], b[:, 2:, 0]) + r[:, 2:]
    assert front.max() <= PANEL_X + 1e-9


def test_the_articulated_worker_reaches_over_a_low_panel():
    """A 1.3 m panel (ISO 13857: a structure above 1 m): the arms go over it, raised first (away from the panel:
    swung up in front of it, they would pass through it), then reaching over."""
    sim = _cell(panel_top=1.3, body="p95-male")
    acts = ["step-back+upright", "step-back+upright", "stand+reach-up", "walk+upright", "walk+upright",
            "walk+upright", "stand+tiptoe", "stand+reach-over", "stand+bend-forward"]
    _, (a, b, r) = _capsules(sim, acts)
    beyond = np.maximum(a[:, 8:, 0], b[:, 8:, 0]) + r[:, 8:] - PANEL_X  # the hands beyond the panel's plane
    assert beyond.max() > 0.3
    # right in front of the panel, an arm swung forward or up from hanging would sweep through it below its top
    # edge (the motion is checked between time steps, not only where it ends): it is held
    for arm in ("reach-low", "reach-forward", "reach-up"):
        _, (a, b, r) = _capsules(sim, ["walk+upright", "walk+upright", f"stand+{arm}"])
        assert (np.maximum(a[:, 4:, 0], b[:, 4:, 0]) + r[:, 4:]).max() <= PANEL_X + 1e-9, arm


def test_a_light_curtain_sees_the_reaching_arm_not_the_hanging_one():
    sim = _cell(curtain_x=0.55)
    reach = sim.run(["stand+reach-forward"]).rows
    hang = sim.run(["stand+hang", "stand+upright"]).rows
    assert int(reach[-1, L.M_SEEN]) == 1
    assert not hang[:, L.M_SEEN].any()


def test_contact_is_measured_to_the_arm_capsules():
    robot = dict(ROBOT, base={"xyz": [1.3, 0.0, 0.0], "yaw_deg": 0.0})
    sim = _cell(robot=robot)
    rows = sim.run(["walk+reach-forward", "stand+reach-high", "stand+reach-up", "stand+reach-side"]).rows
    parts = {int(p) for p in rows[:, L.M_PART]}
    assert parts <= {0, 1, 2, 3, 4, 5, 8, 9, 10, 11}  # capsules only: no reach volume (6, 7)
    assert parts & {8, 9, 10, 11}  # the forearms or hands are nearest somewhere
    rec = sim.run(["walk+reach-forward"]).records()[-1]
    assert rec.limbs is not None and rec.limbs[1] == pytest.approx(90.0) and rec.limbs[6] == pytest.approx(90.0)


def test_the_articulated_worker_is_deterministic_and_replays():
    robot = dict(ROBOT, base={"xyz": [1.3, 0.0, 0.0], "yaw_deg": 0.0})
    sim = _cell(robot=robot)
    rng = np.random.default_rng(3)
    seqs = rng.integers(0, sim.n_actions, size=(12, 8)).tolist()
    assert check_determinism(sim, seqs) == 12
    batch = sim.run_batch(np.asarray(seqs))
    for e, seq in enumerate(seqs):
        trace = sim.run(seq)
        assert trace.unsafe == (batch.unsafe_step[e] >= 0)


def test_records_of_the_paper_worker_have_no_limbs():
    rec = Simulator("s3-fence-gap").run(["walk+upright"]).records()[-1]
    assert rec.limbs is None and "limbs" not in rec.model_dump()


def test_the_worker_page_example_is_a_valid_worker():
    """docs/worker.md's cell fragment, played in a cell."""
    from pathlib import Path

    text = (Path(__file__).parents[2] / "docs" / "worker.md").read_text(encoding="utf-8")
    block = text.split("```yaml\n", 1)[1].split("```", 1)[0]
    human = yaml.safe_load(block)["human"]
    doc = {"name": "doc-example", "robot": ROBOT, "floor": {"xmin": -3.0, "xmax": 3.0, "ymin": -3.0, "ymax": 3.0},
           "human": human}
    sim = Simulator(parse_cell(yaml.safe_dump(doc), "doc-example.yaml", None))
    assert sim.layout.worker.articulated and sim.layout.body.height == 1.855
    assert len(sim.run(["walk+reach-up"]).rows) == 1 + sim.steps_per_action
