"""The robot's three program forms (joint waypoints with per-move speed and dwell, tool poses, a joint
trajectory file): the kernel's trajectory against robot.trajectory.evaluate, the timing each form promises,
and the limits each is checked against."""

from __future__ import annotations

import copy
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import yaml

from cellstress.cell.load import load_cell
from cellstress.core.errors import CellError
from cellstress.robot.trajectory import MIN_SEGMENT_TIME, evaluate
from cellstress.sim import kernels as K
from cellstress.sim.build import build_layout

UR10_VMAX = np.array([2.16, 2.16, 3.15, 3.2, 3.2, 3.2])  # rad/s, the URDF's (rounded)


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def write_cell(tmp_path: Path, baseline: dict, task: dict, name: str = "cell.yaml", **robot) -> Path:
    cell = copy.deepcopy(baseline)
    cell["robot"]["task"] = task
    cell["robot"].update(robot)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(cell, sort_keys=False), encoding="utf-8")
    return path


def kernel_matches_reference(layout, taus) -> None:
    P, traj = layout.params, layout.trajectory
    nj = P.placements.shape[0]
    q, qd = np.zeros(nj), np.zeros(nj)
    for tau in taus:
        K.joint_trajectory(P, tau, 0.7, q, qd)
        q_ref, qd_ref = evaluate(traj, tau)
        np.testing.assert_allclose(q, q_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(qd, 0.7 * qd_ref, rtol=0, atol=1e-9)


# ---- joint waypoints: a speed and a dwell per move ---------------------------------------------------------
def test_speed_scales_and_dwells_per_move(tmp_path, baseline):
    wps = [[124.8, -44.8, 78.4, -123.6, -90.0, 0.0], [37.1, -44.8, 78.4, -123.6, -90.0, 0.0],
           [80.0, -60.0, 90.0, -120.0, -90.0, 0.0]]
    task = {"waypoints_deg": wps, "speed_scales": [0.5, 0.2, 1.0], "dwells": [0.0, 0.5, 1.0]}
    layout = build_layout(load_cell(write_cell(tmp_path, baseline, task)))
    traj = layout.trajectory
    vmax = layout.robot.velocity_limits
    w = np.deg2rad(wps)
    for i, scale in enumerate((0.5, 0.2, 1.0)):
        dq = np.abs(w[(i + 1) % 3] - w[i])
        assert traj.move_times[i] == pytest.approx(max(MIN_SEGMENT_TIME, np.max(1.875 * dq / (scale * vmax))))
    np.testing.assert_array_equal(traj.dwells, [0.0, 0.5, 1.0])
    assert traj.cycle == pytest.approx(traj.move_times.sum() + 1.5)
    rng = np.random.default_rng(1)
    kernel_matches_reference(layout, np.concatenate([rng.uniform(-traj.cycle, 2 * traj.cycle, 500),
                                                     traj.starts, traj.starts + traj.dwells]))


def test_one_speed_scale_equals_the_same_value_per_move(tmp_path, baseline):
    """The old single speed_scale and a list of equal values give the same trajectory, to the bit."""
    wps = baseline["robot"]["task"]["waypoints_deg"]
    a = build_layout(load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps, "speed_scale": 0.4}, "a.yaml")))
    b = build_layout(load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps, "speed_scales": [0.4, 0.4]},
                                          "b.yaml")))
    np.testing.assert_array_equal(a.params.pre_v, b.params.pre_v)
    np.testing.assert_array_equal(a.params.pre_ra, b.params.pre_ra)


# ---- tool poses ----------------------------------------------------------------------------------------------
def test_poses_reproduce_the_baseline_waypoints(tmp_path, baseline):
    """The baseline's waypoints were made by IK (tool0 0.15 m above each leg, tool down, any turn about the
    tool axis): asking for those positions, tool down, gives the baseline's arm configuration (the first five
    joints; the last one sets the turn about the tool axis, which the baseline left free)."""
    poses = [{"xyz": [-0.72, 0.75, 1.0], "rpy_deg": [180.0, 0.0, 0.0]},
             {"xyz": [0.72, 0.75, 1.0], "rpy_deg": [180.0, 0.0, 0.0]}]
    seed = baseline["robot"]["task"]["waypoints_deg"][0]
    task = {"poses": poses, "tool_frame": "tool0", "ik_seed_deg": seed}
    layout = build_layout(load_cell(write_cell(tmp_path, baseline, task)))
    got = np.rad2deg(layout.trajectory.waypoints)
    np.testing.assert_allclose(got[:, :5], np.asarray(baseline["robot"]["task"]["waypoints_deg"])[:, :5], atol=0.1)


def test_unreachable_pose_names_the_waypoint(tmp_path, baseline):
    poses = [{"xyz": [-0.72, 0.75, 1.0], "rpy_deg": [180.0, 0.0, 0.0]},
             {"xyz": [3.0, 0.0, 1.0], "rpy_deg": [180.0, 0.0, 0.0]}]
    path = write_cell(tmp_path, baseline, {"poses": poses, "tool_frame": "tool0"})
    with pytest.raises(CellError) as err:
        load_cell(path)
    assert err.value.field == "robot.task.poses[1]"
    assert "cannot be reached" in err.value.problem and "mm" in err.value.problem


def test_unknown_tool_frame(tmp_path, baseline):
    poses = [{"xyz": [-0.72, 0.75, 1.0], "rpy_deg": [180.0, 0.0, 0.0]}] * 2
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"poses": poses, "tool_frame": "hand"}))
    assert err.value.field == "robot.task.tool_frame" and "tool0" in err.value.problem


# ---- a joint-trajectory file -----------------------------------------------------------------------------
def csv_rows(n: int, period: float = 8.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed, smooth joint path sampled at n rows over one period (rad)."""
    t = np.linspace(0.0, period, n)
    phase = 2 * np.pi * t / period
    q = np.stack([1.4 + 0.6 * np.sin(phase), -0.8 + 0.2 * np.sin(2 * phase), 1.3 + 0.0 * t,
                  -2.1 + 0.3 * np.cos(phase) - 0.3, -1.57 + 0 * t, 0.2 * np.sin(phase)], axis=1)
    q[-1] = q[0]  # sin(2 pi) is not exactly 0
    return t, q


def write_csv(path: Path, t, q, header: str = "time,q1,q2,q3,q4,q5,q6") -> None:
    lines = [header] + [",".join(repr(float(x)) for x in (ti, *qi)) for ti, qi in zip(t, q, strict=True)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def test_trajectory_file_is_played_linearly_and_cycled(tmp_path, baseline):
    t, q = csv_rows(4001)
    write_csv(tmp_path / "path.csv", t, q)
    layout = build_layout(load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "path.csv"})))
    traj, P = layout.trajectory, layout.params
    assert traj.linear and traj.cycle == pytest.approx(8.0) and traj.n_segments == 4000
    rng = np.random.default_rng(3)
    kernel_matches_reference(layout, np.concatenate([rng.uniform(-8.0, 24.0, 2000), t, t + 1e-9, t - 1e-9]))
    nj = 6
    qk, qdk = np.zeros(nj), np.zeros(nj)
    for i in (0, 17, 2000, 3999):  # every row is visited, moving at its segment's speed from its first instant
        K.joint_trajectory(P, t[i] + 8.0, 1.0, qk, qdk)
        np.testing.assert_allclose(qk, q[i], atol=1e-12)
        np.testing.assert_allclose(qdk, (q[i + 1] - q[i]) / (t[i + 1] - t[i]), rtol=1e-9, atol=1e-9)
    assert P.pre_v.max() > 0.1


def test_trajectory_file_by_joint_names_in_degrees(tmp_path, baseline):
    t, q = csv_rows(50)
    names = "shoulder_pan_joint,shoulder_lift_joint,elbow_joint,wrist_1_joint,wrist_2_joint,wrist_3_joint"
    write_csv(tmp_path / "deg.csv", t, np.rad2deg(q), header="time," + names)
    write_csv(tmp_path / "rad.csv", t, q)
    a = build_layout(load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "deg.csv", "csv_degrees": True},
                                          "a.yaml")))
    b = build_layout(load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "rad.csv"}, "b.yaml")))
    np.testing.assert_allclose(a.trajectory.waypoints, b.trajectory.waypoints, atol=1e-12)


def _csv_error(tmp_path, baseline, text: str, **task) -> CellError:
    (tmp_path / "bad.csv").write_text(text, encoding="utf-8")
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "bad.csv", **task}))
    assert err.value.field == "robot.task.trajectory_csv"
    assert "bad.csv" in err.value.problem
    return err.value


HEAD = "time,q1,q2,q3,q4,q5,q6\n"
ROW0 = "0,1.4,-0.8,1.3,-2.1,-1.57,0\n"


@pytest.mark.parametrize("text, words", [
    ("", ("empty",)),
    ("time,a,b\n" + ROW0, ("header must be", "q1", "shoulder_pan_joint")),
    (HEAD + ROW0 + "1,1.4,-0.8,x,-2.1,-1.57,0\n", ("row 3, column 4 (q3)", "is not a number")),
    (HEAD + ROW0 + "1,1.4,-0.8,nan,-2.1,-1.57,0\n", ("row 3, column 4 (q3)", "not a finite")),
    (HEAD + ROW0 + "1,1.4,-0.8\n", ("row 3", "has 3 values; expected 7")),
    (HEAD + ROW0 + "0,1.4,-0.8,1.3,-2.1,-1.57,0\n", ("row 3, column 1 (time)", "not after")),
    (HEAD + ROW0, ("at least 2 rows",)),
    (HEAD + ROW0 + "1,1.4,-0.8,7.0,-2.1,-1.57,0\n" + ROW0.replace("0,", "2,", 1),
     ("row 3, column 4 (elbow_joint)", "outside joint 'elbow_joint'", "deg")),
    (HEAD + ROW0 + "0.1,2.4,-0.8,1.3,-2.1,-1.57,0\n" + ROW0.replace("0,", "2,", 1),
     ("rows 2 to 3, column 2 (shoulder_pan_joint)", "over its limit")),
    (HEAD + ROW0 + "1,1.5,-0.8,1.3,-2.1,-1.57,0\n", ("last row must repeat the first",)),
    ("\xff\xfe", ()),
])
def test_bad_trajectory_file(tmp_path, baseline, text, words):
    err = _csv_error(tmp_path, baseline, text)
    for w in words:
        assert w in err.problem, err.problem


def test_trajectory_file_too_many_rows(tmp_path, baseline):
    err = _csv_error(tmp_path, baseline, HEAD + ROW0 * 200_002)
    assert "more than 200,000 rows" in err.problem


@pytest.mark.parametrize("text", [
    HEAD + ROW0 * 200_000 + ROW0.rstrip("\n"),  # 200,001 rows, no final newline (issue 29)
    (HEAD + ROW0 * 200_001).replace("\n", "\r"),  # old Mac line ends: no newline at all
])
def test_trajectory_file_rows_are_counted_whatever_ends_them(tmp_path, baseline, text):
    err = _csv_error(tmp_path, baseline, text)
    assert "more than 200,000 rows" in err.problem


@pytest.mark.parametrize("text", [
    "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n",
    "time,q1,q2,q3,q4,q5,SECRET-TOKEN\n" + ROW0 * 3,
    HEAD + ROW0 + "1,1.4,-0.8,SECRET-TOKEN,-2.1,-1.57,0\n",
    HEAD + ROW0 + "1,1.4,-0.8,1e999,-2.1,-1.57,0\n",
])
def test_an_error_never_quotes_the_file(tmp_path, baseline, text):
    """A cell may name any file as its trajectory (/etc/passwd, ~/secret.csv): the error names the row and the
    column, never the file's words (issue 29)."""
    err = _csv_error(tmp_path, baseline, text)
    assert "row" in err.problem or "column" in err.problem
    for secret in ("root:x", "daemon", "SECRET", "1e999"):
        assert secret not in str(err), str(err)


def test_trajectory_file_missing(tmp_path, baseline):
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "none.csv"}))
    assert "no such file" in err.value.problem


def test_trajectory_file_takes_no_speed_scales(tmp_path, baseline):
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"trajectory_csv": "x.csv", "speed_scales": [0.5]}))
    assert err.value.field == "robot.task" and "own timing" in err.value.problem


# ---- limits and joint counts -------------------------------------------------------------------------------
def test_waypoint_outside_joint_limits(tmp_path, baseline):
    wps = copy.deepcopy(baseline["robot"]["task"]["waypoints_deg"])
    wps[1][2] = 900.0
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps}))
    assert err.value.field == "robot.task.waypoints_deg[1][2]"
    assert err.value.problem == "900 deg is outside joint 'elbow_joint''s limits -180.0..180.0 deg"


def test_program_drives_the_joints_neither_held_nor_mimic(tmp_path, baseline):
    wps = copy.deepcopy(baseline["robot"]["task"]["waypoints_deg"])
    hold = [{"joint": "wrist_3_joint", "value": 10.0}]
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps}, hold=hold))
    assert err.value.field == "robot.task.waypoints_deg[0]"
    assert "has 6 joint values but the robot has 5 joints the program drives" in err.value.problem
    assert "wrist_2_joint [deg]" in err.value.problem and "wrist_3_joint" not in err.value.problem
    layout = build_layout(load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": [w[:5] for w in wps]},
                                               hold=hold)))
    np.testing.assert_array_equal(layout.trajectory.waypoints[:, 5], np.deg2rad(10.0))


@pytest.mark.parametrize("hold, field, words", [
    ([{"joint": "gripper", "value": 0.0}], "robot.hold[0].joint", ("no joint 'gripper'", "wrist_3_joint")),
    ([{"joint": "wrist_3_joint", "value": 400.0}], "robot.hold[0].value", ("400 deg is outside",)),
])
def test_bad_held_joint(tmp_path, baseline, hold, field, words):
    wps = [w[:5] for w in baseline["robot"]["task"]["waypoints_deg"]]
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps}, hold=hold))
    assert err.value.field == field
    for w in words:
        assert w in err.value.problem


def test_exactly_one_program(tmp_path, baseline):
    wps = baseline["robot"]["task"]["waypoints_deg"]
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"waypoints_deg": wps, "trajectory_csv": "a.csv"}))
    assert err.value.field == "robot.task" and "exactly one program" in err.value.problem
    with pytest.raises(CellError) as err:
        load_cell(write_cell(tmp_path, baseline, {"dwell": 0.1}))
    assert "got none" in err.value.problem
