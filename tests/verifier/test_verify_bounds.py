"""What the pruning bounds rest on, checked over many random steps (docs/verify.md gives the arguments): the
worker within its radius of the hip pivot, the pivot moving at most a stride a step, the robot's capsule axes
no faster than the speed bound, the distance bound never above a d_HR the simulator measures later, and a robot
at rest never moving again."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cellstress.cell.load import builtin_text, parse_cell
from cellstress.sim import layout as L
from cellstress.sim.scene import robot_capsules
from cellstress.sim.simulator import Simulator
from cellstress.verifier.bounds import AT_REST, Bounds
from cellstress.verifier.reach import SweptField, field_height, robot_point_speed, worker_radius, worker_stride

FEATURES = Path(__file__).parent / "cells"
# the paper's cells, a prismatic joint (linear-axis), a guard door and a muted curtain (the bounds' cells: every
# stop latches)
CELLS = ["baseline", "s1-scanner-width", "s3-fence-gap", str(FEATURES / "linear-axis.yaml"),
         str(FEATURES / "door-near.yaml"), str(FEATURES / "muting-near.yaml")]


@pytest.mark.parametrize("cell", CELLS)
def test_worker_within_its_radius_and_a_stride(cell) -> None:
    sim = Simulator(cell)
    P = sim.params
    rng = np.random.default_rng(1)
    paths = sim.worker_paths(rng.integers(0, 30, size=(200, 8))).reshape(-1, L.N_POSE)
    stride = P.body[L.B_WALK_SPEED] * sim.dt
    steps = np.hypot(*np.diff(paths.reshape(200, -1, L.N_POSE)[:, :, :2], axis=1).transpose(2, 0, 1))
    assert steps.max() <= stride * (1 + 1e-12)
    radius = worker_radius(P)
    assert field_height(P) == P.body[L.B_HIP_Z] and radius == P.scal[L.C_RHO]  # the paper's worker: no stance
    poses = paths[rng.choice(len(paths), 400, replace=False)]
    hip = np.column_stack([poses[:, :2], np.full(len(poses), P.body[L.B_HIP_Z])])
    points = hip[:, None, :] + rng.uniform(-2.5, 2.5, size=(len(poses), 64, 3))
    d = sim.worker_distances(poses, points)
    assert np.all(d >= np.linalg.norm(points - hip[:, None, :], axis=2) - radius)


# the articulated worker (119 actions: it crouches, kneels, lies prone and crawls, rises on tiptoe, reaches)
ARTICULATED_CELLS = ["reach-over", "crawl-under", str(FEATURES / "reach-near.yaml")]


@pytest.mark.parametrize("cell", ARTICULATED_CELLS)
def test_articulated_worker_within_its_radius_and_a_stride(cell) -> None:
    sim = Simulator(cell)
    P = sim.params
    rng = np.random.default_rng(4)
    crawl = [i for i, name in enumerate(sim.action_names) if name.endswith("+crawl")]
    acts = rng.integers(0, sim.n_actions, size=(300, 10))
    acts[::3, :3] = rng.choice(crawl, size=(100, 3))  # a third lie down and crawl first
    paths = sim.worker_paths(acts)
    steps = np.hypot(*np.diff(paths[:, :, :2], axis=1).transpose(2, 0, 1))
    assert steps.max() <= worker_stride(P) * (1 + 1e-12)
    poses = paths.reshape(-1, L.N_POSE)
    drops = poses[:, L.POSE_EXT]
    assert drops.min() < -0.8 and drops.max() > 0.05  # prone and on tiptoe were among them
    a, b, r = sim.worker_capsules(poses)
    pivot = np.column_stack([poses[:, :2], np.full(len(poses), field_height(P))])[:, None, :]
    reach = np.maximum(np.linalg.norm(a - pivot, axis=2), np.linalg.norm(b - pivot, axis=2)) + r
    assert reach.max() <= worker_radius(P)
    assert reach.max() > 0.8 * worker_radius(P)  # and not a uselessly loose radius


@pytest.mark.parametrize("cell", CELLS)
def test_robot_no_faster_than_its_speed_bound(cell) -> None:
    sim = Simulator(cell)
    speed = robot_point_speed(sim.layout)
    h = 1e-3
    taus = np.arange(0.0, sim.layout.trajectory.cycle, h)
    poses = [robot_capsules(sim.layout, t) for t in taus]
    a = np.stack([p[0] for p in poses])
    b = np.stack([p[1] for p in poses])
    moved = np.maximum(np.linalg.norm(np.diff(a, axis=0), axis=2), np.linalg.norm(np.diff(b, axis=0), axis=2))
    assert moved.max() <= speed * h
    assert moved.max() > 0.2 * speed * h  # and not a uselessly loose bound


# and the cells whose devices restart or slow the robot (the distance bound follows their path time)
SPEED_CELLS = ["restart-auto", "warning-field-short", "ssm-latency", str(FEATURES / "restart-fast.yaml"),
               str(FEATURES / "warning-trunk.yaml"), str(FEATURES / "warning-hold.yaml")]
# and cells of several robots (each robot its own field and path time; the curtain stops one of them)
ROBOTS_CELLS = ["two-robots", str(FEATURES / "two-near.yaml")]


@pytest.mark.parametrize("cell", CELLS + SPEED_CELLS + ROBOTS_CELLS + ARTICULATED_CELLS)
def test_distance_bound_never_above_a_later_d_hr(cell) -> None:
    base = Simulator(cell)
    walking = np.array([i for i, name in enumerate(base.action_names) if name.startswith("walk+")])
    rng = np.random.default_rng(2)
    phases = rng.choice(np.arange(0.0, base.layout.trajectory.cycle, 0.05), 4, replace=False)
    braking = live = 0
    for phase in phases:
        sim = base.with_start(base.start, float(phase))
        field = SweptField(sim, 8)
        spa = sim.steps_per_action
        # walking (any posture) at the robot half the time, so that devices stop, slow and restart it
        for n, acts in enumerate(rng.integers(0, sim.n_actions, size=(60, 8))):
            if n % 2:
                acts = walking[acts % len(walking)]
            rows = sim.run(acts).rows
            state = sim.reset()
            for layer in range(1, 8):
                state, _ = sim.step(state, int(acts[layer - 1]))
                k = layer * spa
                if sim.is_unsafe(state) or k >= len(rows) - 1:
                    break
                braking += rows[k, L.M_PHASE] != L.PHASE_RUNNING
                live += state[L.S_LIVE] != 0.0
                later = rows[k + 1:]
                # the bound over the next j steps, from the state's own path time, holds at the j-th
                for j in sorted({1, min(spa, len(later)), len(later) // 2, len(later)} - {0}):
                    lb = field.lower_bound(state[None, :], j)[0]
                    assert later[j - 1, L.M_D] >= lb - field.radius
    if cell in SPEED_CELLS:  # states whose robot was slowed or restarted (``live_path_time``) were bounded too
        assert braking > 0 and live > 0


# (cell, actions drawn from 0..n-1: walking with any posture into the cell, or anything from inside it)
AT_REST_CELLS = [("baseline", 6), (str(FEATURES / "linear-axis.yaml"), 6), ("door-unlocked", 6),
                 (str(FEATURES / "two-stop.yaml"), 30), (str(FEATURES / "warning-hold.yaml"), 30),
                 ("warning-field-short", 6)]


@pytest.mark.parametrize(("cell", "n_actions"), AT_REST_CELLS)
def test_a_robot_at_rest_stays_at_rest(cell, n_actions) -> None:
    sim = Simulator(cell)  # its devices stop the robot(s) when the worker walks in (or pushes the door)
    n = max(8, sim.actions_per_episode)
    bounds = Bounds(sim, horizon=n)
    assert bounds.at_rest
    x_phases = [L.M_XPHASE + r for r in range(sim.params.x_scal.shape[0])]
    rng = np.random.default_rng(3)
    rested = 0
    for acts in rng.integers(0, n_actions, size=(400, n)):
        rows = sim.run(acts).rows
        state = sim.reset()
        for i, a in enumerate(acts):
            state, _ = sim.step(state, int(a))
            if sim.is_unsafe(state):
                break
            cut = dict(bounds.prune(state[None, :], rows[-1:], np.ones(1, dtype=bool), n - 1 - i))[AT_REST]
            if cut[0]:  # every robot stands (robot 0's speed 0, the others stopped), and nothing is unsafe
                later = rows[int(state[L.S_K]) + 1:]
                assert np.all(later[:, L.M_V] == 0.0) and not later[:, L.M_UNSAFE].any()
                assert np.all(later[:, x_phases] == L.PHASE_STOPPED)
                rested += 1
                break
    assert rested >= 5  # (most walks in linear-axis end at the arm first)


def test_an_automatic_restart_keeps_the_distance_bound_only():
    # an automatic restart breaks "at rest for good"; the path time still advances no faster than the clock
    for cell in ("restart-auto", str(FEATURES / "restart-fast.yaml"), str(FEATURES / "warning-trunk.yaml")):
        sim = Simulator(cell)
        assert not sim.layout.stops_hold
        b = Bounds(sim)
        assert not b.at_rest and b.swept is not None
    # a warning field or a separation monitor slows the robot but does not release a stop
    for cell in ("restart-manual", "warning-field-short", "ssm-latency"):
        assert Simulator(cell).layout.stops_hold and Bounds(Simulator(cell)).at_rest


def test_at_rest_behind_a_warning_field_needs_a_speed_tolerance():
    # the ramp to standstill re-anchored after the stop may end a rounding error late (Bounds)
    data = yaml.safe_load(builtin_text("warning-field-short"))
    data["criterion"]["speed_tolerance"] = 0.0
    sim = Simulator(parse_cell(yaml.safe_dump(data), "warning-exact", None))
    assert not Bounds(sim).at_rest and Bounds(Simulator("restart-manual")).at_rest
