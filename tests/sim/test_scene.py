"""sim.scene, the geometry behind the pictures, agrees with what the compiled kernels measure."""

from __future__ import annotations

import math

import numpy as np

from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.simulator import Simulator

S3 = "walk+bend-right,turn-left-45+bend-forward-left,walk+bend-forward,walk+bend-forward-left".split(",")


def test_robot_capsules_follow_the_path_time(baseline_sim):
    """Before a stop the pose is the kernel's pre-stop table; while braking and stopped it is the kernel's live
    pose for the stop the devices requested (the baseline's scanner stops the robot in this episode)."""
    P = baseline_sim.params
    trace = baseline_sim.run(["walk+upright"] * 3)
    recs = trace.records()
    taus = scene.path_times(trace.rows)
    det = next(i for i, r in enumerate(recs) if r.devices)
    t_stop = recs[det].t + float(P.dev_resp[0])
    assert recs[-1].stop_phase == "stopped"
    W = K.make_work(P)
    for k, r in enumerate(recs):
        a, b = scene.robot_capsules(baseline_sim.layout, taus[k])
        if r.stop_phase in ("running", "stop-pending"):
            want_a, want_b = P.pre_ra[k], P.pre_rb[k]
        else:
            K.robot_live(P, k * baseline_sim.dt, t_stop, W)
            want_a, want_b = W.ra, W.rb
        np.testing.assert_allclose(a, want_a, atol=1e-9)
        np.testing.assert_allclose(b, want_b, atol=1e-9)


def test_reach_points_are_inside_the_kernels_reach_volume():
    sim = Simulator("s3-fence-gap")
    trace = sim.run(S3)
    r = trace.record(trace.unsafe_row)
    args = (r.x, r.y, math.radians(r.heading_deg), math.radians(r.forward_flexion_deg),
            math.radians(r.lateral_flexion_deg))
    pose = scene.body_pose(sim.layout, L.pose_vector(*args))
    P = sim.params
    W = K.make_work(P)
    K.human_pose(P, L.pose_vector(*args), W)
    np.testing.assert_array_equal(pose.a, W.ha[:len(pose.a)])  # (the paper worker: its six capsules)
    np.testing.assert_array_equal(pose.shoulders, W.sh)
    n_near = K.near_fences(P, W, P.body[L.B_ARM_LEN] + 0.05)
    assert n_near > 0  # S3's contact is made around a fence end: the detour test is exercised
    side = 0 if r.body_part == "left-reach" else 1
    pts = scene.reach_points(sim.layout, pose, side)
    sample = pts[np.random.default_rng(0).integers(0, len(pts), 500)]
    assert max(K.reach_value(P, p.copy(), side, W, n_near) for p in sample) <= 1e-6
    # the contact point is on the volume: a node lies within one grid diagonal of it
    h = sim.layout.reach.spacing
    assert np.linalg.norm(pts - np.asarray(r.robot_point), axis=1).min() < h * math.sqrt(3)
    # the fences cut the volume: fewer nodes than the free field holds
    assert len(pts) < int((sim.layout.reach.values <= 0).sum())
