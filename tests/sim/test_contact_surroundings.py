"""sim.clamping: the worker's contact-point speed, the robot's time scaling and its travel until standstill,
each against an independent computation (issue 34, Deliver 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cellstress.cell.load import load_cell, with_criterion
from cellstress.human.body import B_LEG_HALF
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.clamping import body_point_velocity, remaining_path_time, travel
from cellstress.sim.contacts import at_contact, step_end_pose
from cellstress.sim.scene import time_scaling
from cellstress.sim.simulator import Simulator

DT = 0.05


@pytest.fixture(scope="module")
def s1():
    return Simulator("s1-scanner-width")


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_walking_moves_every_body_point_at_the_walking_speed(s1):
    lay = s1.layout
    before = scene.body_pose(lay, L.pose_vector(1.0, 2.0, 0.3))
    step = 1.6 * DT * np.array([math.cos(0.3), math.sin(0.3)])  # 1.6 m/s along the heading for one step
    now = scene.body_pose(lay, L.pose_vector(1.0 + step[0], 2.0 + step[1], 0.3))
    want = np.array([1.6 * math.cos(0.3), 1.6 * math.sin(0.3), 0.0])
    for part in (0, 2, 3, 5):  # a leg, the trunk, the head, an arm: capsules
        c = (0, 1, 2, 3, 4, 5).index(part)
        point = (now.a[c] + now.b[c]) / 2.0 + np.array([0.0, 0.0, now.r[c]])
        np.testing.assert_allclose(body_point_velocity(part, point, now, before, DT), want, atol=1e-9)
    point = now.shoulders[1] + np.array([0.4, -0.1, -0.2])  # a point in the right reach volume
    np.testing.assert_allclose(body_point_velocity(L.PART_RIGHT_REACH, point, now, before, DT), want, atol=1e-9)


def test_turning_moves_points_on_circles_about_the_body_axis(s1):
    """An upright worker turning by 0.2 rad in a step: every point turns about the vertical through (x, y)."""
    lay = s1.layout
    x, y, th = 0.5, -0.5, 0.2
    before = scene.body_pose(lay, L.pose_vector(x, y, 1.0))
    now = scene.body_pose(lay, L.pose_vector(x, y, 1.0 + th))
    centre = np.array([x, y, 0.0])
    # the reach volume is carried rigidly: the point was at Rz(-th) (p - c) + c one step earlier
    p = now.shoulders[0] + np.array([0.3, 0.2, 0.1])
    then = _rz(-th) @ (p - centre) + centre
    np.testing.assert_allclose(body_point_velocity(L.PART_LEFT_REACH, p, now, before, DT), (p - then) / DT,
                               atol=1e-9)
    # a leg's axis stands LEG_HALF beside the body axis: its points move along a chord 2 LEG_HALF sin(th / 2)
    leg_half = float(lay.params.body[B_LEG_HALF])
    v = body_point_velocity(0, now.a[0] + np.array([0.0, 0.0, 0.3]), now, before, DT)
    assert float(np.linalg.norm(v)) == pytest.approx(2.0 * leg_half * math.sin(th / 2.0) / DT, rel=1e-9)
    assert abs(v[2]) < 1e-12
    # the trunk's axis is the body axis: it does not move
    assert float(np.linalg.norm(body_point_velocity(2, now.a[2], now, before, DT))) < 1e-9


def test_time_scaling_is_the_one_joint_state_uses_and_travel_matches_the_braking_ramp(s1):
    """In S1 the worker trips the scanner and the robot brakes (stopping time 0.15 s, category 1: along its path).
    ``time_scaling`` gives joint_state's velocities, and the robot point's travel until standstill is its speed
    times the remaining braking time over 2 (linear deceleration), to the path's curvature."""
    lay, P = s1.layout, s1.params
    trace = s1.run(["walk+upright"] * 8)
    phases = trace.rows[:, L.M_PHASE].astype(int)
    braking = np.flatnonzero(phases == L.PHASE_BRAKING)
    assert len(braking) >= 2 and np.any(phases == L.PHASE_STOPPED)
    T = float(P.scal[L.C_STOP_TIME])
    nj = P.placements.shape[0]
    tau_stop = float(trace.rows[np.flatnonzero(phases == L.PHASE_STOPPED)[0], L.M_TAU])
    checked = 0
    for i in braking:
        row = trace.rows[i]
        sigma = time_scaling(lay, row)
        assert 0.0 < sigma <= 1.0
        q, qd = np.zeros(nj), np.zeros(nj)
        K.joint_trajectory(P, float(row[L.M_TAU]), sigma, q, qd)
        q2, qd2 = scene.joint_state(lay, row)
        np.testing.assert_array_equal(qd, qd2)
        assert remaining_path_time(lay, row) == pytest.approx(sigma * sigma * T / 2.0)
        # the wrist's end: its velocity by finite differences of the kernel's own kinematics along the path
        j = nj - 1
        rot, pos = np.zeros((nj, 3, 3)), np.zeros((nj, 3))
        K.joint_trajectory(P, float(row[L.M_TAU]), 1.0, q, qd)
        K.forward_kinematics(P, q, rot, pos)
        point = pos[j] + rot[j] @ np.array([0.0, 0.0, 0.1])
        local = rot[j].T @ (point - pos[j])
        h = 1e-6
        K.joint_trajectory(P, float(row[L.M_TAU]) + h, 1.0, q, qd)
        K.forward_kinematics(P, q, rot, pos)
        v_path = (pos[j] + rot[j] @ local - point) / h  # per unit path time; the point's speed is sigma times it
        speed = sigma * float(np.linalg.norm(v_path))
        if speed < 1e-3:
            continue
        d = v_path / np.linalg.norm(v_path)
        s = travel(lay, row, j, point, d, speed)
        # where the kernel's own braking left the robot: the path time of the first standstill row
        K.joint_trajectory(P, tau_stop, 1.0, q, qd)
        K.forward_kinematics(P, q, rot, pos)
        assert s == pytest.approx(float(d @ (pos[j] + rot[j] @ local - point)), rel=1e-6)
        # and, to the path's curvature and its speed changing along it, the linear ramp's speed x time / 2
        assert s == pytest.approx(speed * sigma * T / 2.0, rel=0.15)
        checked += 1
    assert checked >= 2
    stopped = trace.rows[np.flatnonzero(phases == L.PHASE_STOPPED)[0]]
    assert time_scaling(lay, stopped) == 0.0 and travel(lay, stopped, nj - 1, (0, 0, 1), (1, 0, 0), 0.0) == 0.0


def test_contacts_carry_the_worker_speed_and_the_verdict_is_the_judged_one():
    """The S3 witness under iso15066: the contact's worker speed is the body point's motion over the step before
    (checked against the two poses directly), and every entry point (run, verdict_at, run_batch) agrees."""
    sim = Simulator(with_criterion(load_cell("s3-fence-gap"), "iso15066"))
    acts = ["walk+bend-right", "turn-left-45+bend-forward-left", "walk+bend-forward", "walk+bend-forward-left"]
    trace = sim.run(acts)
    i = trace.unsafe_row
    assert i is not None
    row, prev = trace.rows[i], trace.rows[i - 1]
    c = sim.contacts.contact(row, L.row_pose(prev))
    n = np.asarray(c.normal)
    now, before = scene.body_pose(sim.layout, L.row_pose(row)), scene.body_pose(sim.layout, L.row_pose(prev))
    part = int(row[L.M_PART])
    assert part == L.PART_LEFT_REACH
    local = now.trunk.T @ (np.asarray(c.human_point) - now.shoulders[0])
    moved = np.asarray(c.human_point) - (before.shoulders[0] + before.trunk @ local)
    elapsed = at_contact(row, sim.dt)[1]  # a whole step, or the part of it before a contact found within it
    assert c.v_human == pytest.approx(max(0.0, -float(n @ moved)) / elapsed, rel=1e-9) and c.v_human > 0.0
    v = sim.verdict_at(trace, i)
    assert v.unsafe and v.v_human == pytest.approx(min(2.0, c.v_human))
    assert v.force == pytest.approx((c.v_rel + v.v_human) * math.sqrt(
        1.0 / (1.0 / 0.6 + 1.0 / (c.reflected_mass + 2.0)) * 75_000.0))
    batch = sim.run_batch(np.asarray([[sim.action_index(a) for a in acts]]))
    assert int(batch.unsafe_step[0]) == int(row[L.M_STEP])
    assert sim.run(acts).rows.tobytes() == trace.rows.tobytes()  # the same inputs, the same bytes


def test_a_contact_between_the_steps_is_judged_at_its_own_moment():
    """A contact the swept test found within a step (M_SWEPT 1) holds the poses of its own moment M_TC: the worker,
    moving at a constant velocity within the step, covered the pose change in M_TC minus the step before's time,
    so the same pose change half a step after the step before is twice the speed; and the robot's time scaling is
    read at M_TC (at_contact), not at the step's time."""
    sim = Simulator(with_criterion(load_cell("s3-fence-gap"), "iso15066"))
    acts = ["walk+bend-right", "turn-left-45+bend-forward-left", "walk+bend-forward", "walk+bend-forward-left"]
    trace = sim.run(acts)
    i = trace.unsafe_row
    row, prev = np.array(trace.rows[i]), L.row_pose(trace.rows[i - 1])
    row[L.M_SWEPT], row[L.M_TC] = 0.0, row[L.M_T]  # (the same poses, as a contact at the step's own sample)
    whole = sim.contacts.contact(row, prev)
    assert whole.v_human > 0.0
    half = np.array(row)
    half[L.M_SWEPT], half[L.M_TC] = 1.0, row[L.M_T] - sim.dt / 2.0
    at, elapsed = at_contact(half, sim.dt)
    assert at[L.M_T] == half[L.M_TC] and elapsed == pytest.approx(sim.dt / 2.0, rel=1e-12)
    assert at_contact(row, sim.dt)[0] is row and at_contact(row, sim.dt)[1] == sim.dt
    # the pose at the step's end: the line from the step's start through the contact's pose, continued
    end = step_end_pose(half, prev, sim.dt)
    assert end == pytest.approx(prev + 2.0 * (L.row_pose(half) - prev), abs=1e-12)
    assert step_end_pose(row, prev, sim.dt) is not None and np.array_equal(step_end_pose(row, prev, sim.dt),
                                                                              L.row_pose(row))
    assert sim.contacts.contact(half, prev).v_human == pytest.approx(2.0 * whole.v_human, rel=1e-9)
    # a step braking: the time scaling at the contact's own moment, not at the step's
    braking = np.array(row)
    braking[L.M_PHASE] = L.PHASE_BRAKING
    braking[L.M_SWEPT], braking[L.M_TC] = 1.0, row[L.M_T] - sim.dt / 2.0
    shifted = np.array(braking)
    shifted[L.M_T] = braking[L.M_TC]
    assert scene.time_scaling(sim.layout, at_contact(braking, sim.dt)[0]) == scene.time_scaling(sim.layout, shifted)


def test_a_trunk_pushed_against_a_fence_panel_is_backed_by_it():
    """The body-capsule branch of ContactModel: the push direction is the contact normal, the thickness the
    capsule's diameter (the trunk's), the surface the kernel's fence row straight behind the trunk."""
    sim = Simulator(with_criterion(load_cell("baseline"), "iso15066"))
    model, lay = sim.contacts, sim.layout
    row = sim.initial_metrics()
    fence = lay.params.fences[0]
    a, b = fence[0:2], fence[2:4]
    along = (b - a) / np.linalg.norm(b - a)
    n = np.array([-along[1], along[0], 0.0])  # horizontal, across the panel
    pose = scene.body_pose(lay, L.pose_vector(0.0, 0.0, 0.0))
    thick = 2.0 * float(pose.r[2])
    mid = np.array([*(a + b) / 2.0, 1.2])
    for extra, clamped in ((0.01, True), (0.1, False)):
        hp = mid - (thick + extra) * n  # the trunk's robot side, its far side `extra` from the panel
        backing = model._backing(row, 2, hp - 0.01 * n, hp, n, pose, -1, np.zeros(3), None)
        assert backing.surface == "fence panel 1" and backing.distance == pytest.approx(thick + extra)
        assert backing.thickness == pytest.approx(thick) and backing.travel == 0.0 and backing.v_push == 0.0
        assert (backing.gap <= 0.02) == clamped


def test_the_reported_verdict_is_the_one_the_simulator_judged():
    """For every episode, the verdicts `verdict_at` reports (search results, replay, verify's witnesses, the
    report) agree with where the simulator ended the episode: every earlier contact safe, the last one unsafe."""
    sim = Simulator(with_criterion(load_cell("s3-fence-gap"), "iso15066"))
    unsafe = 0
    for acts in np.random.default_rng(1).integers(0, sim.n_actions, (200, 8)).tolist():
        trace = sim.run(acts)
        touching = np.flatnonzero(trace.rows[:, L.M_D] <= 0.0)
        verdicts = [sim.verdict_at(trace, int(i)).unsafe for i in touching if i > 0]
        if trace.unsafe:
            unsafe += 1
            assert verdicts and verdicts[-1] and not any(verdicts[:-1])
            assert touching[-1] == trace.unsafe_row == len(trace.rows) - 1
        else:
            assert not any(verdicts)
    assert unsafe >= 1
