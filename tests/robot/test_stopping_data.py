"""How a robot stops (robot.stopping, robot.stopping_file): the braking profile read from a maker's distance and
time, the conservative lookup of published points, the data file's checks, and category 0's grown capsules
against an independent forward kinematics (pinocchio)."""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.capsules import fitted_capsules
from cellstress.robot.model import load_pinocchio, load_robot, resolve_urdf
from cellstress.robot.stopping import (
    FASTER,
    MATCHED,
    SLOWER,
    StoppingDataError,
    hold_radii,
    joint_stops,
    peak_joint_speeds,
    profile,
)
from cellstress.robot.stopping_file import StoppingFileError, read_stopping_file
from cellstress.robot.trajectory import build_trajectory

HEADER = "joint,category,speed_pct,payload_kg,extension_pct,distance,unit,time_s\n"


@pytest.fixture(scope="module")
def ur5():
    return load_robot(resolve_urdf("ur5", None))


def travelled(delay: float, braking: float, v: float) -> float:
    """Distance of the model: full speed for ``delay``, then a linear ramp to 0 over ``braking`` (integrated
    numerically, independently of the closed form)."""
    t = np.linspace(0.0, delay + braking, 200_001)
    speed = np.where(t < delay, v, v * np.clip(1.0 - (t - delay) / max(braking, 1e-300), 0.0, 1.0))
    return float(np.trapezoid(speed, t))


@pytest.mark.parametrize("ratio", [0.05, 0.3, 0.49, 0.5, 0.6, 0.75, 0.9, 1.0, 1.2, 2.0])
def test_profile_matches_the_data_or_errs_on_the_safe_side(ratio):
    v, T = 2.0, 0.4
    S = ratio * v * T
    p = profile(S, T, v)
    dist, time = travelled(p.delay, p.braking, v), p.delay + p.braking
    assert dist >= S - 1e-6 and time >= T - 1e-12  # never less far, never sooner than published
    if 0.5 <= ratio <= 1.0:
        assert p.reading == MATCHED
        assert dist == pytest.approx(S, abs=1e-6) and time == pytest.approx(T, abs=1e-12)
    elif ratio < 0.5:
        assert p.reading == FASTER and (p.delay, p.braking) == (0.0, T)
    else:
        assert p.reading == SLOWER and dist == pytest.approx(S, abs=1e-6) and time > T


def test_profile_is_continuous_at_both_ends_of_the_matched_range():
    v, T = 1.5, 0.3
    for r in (0.5, 1.0):
        lo, hi = profile(r * v * T * (1 - 1e-9), T, v), profile(r * v * T * (1 + 1e-9), T, v)
        assert abs(lo.delay - hi.delay) < 1e-6 and abs(lo.braking - hi.braking) < 1e-6


def write(tmp_path, body: str, name: str = "stop.csv"):
    p = tmp_path / name
    p.write_text(body)
    return p


def grid_file(tmp_path, joint: str = "shoulder_pan_joint", category: int = 1, scale: float = 1.0, monotone=True):
    """A full 3x3x3 grid of published points whose distance and time grow with speed, payload and extension."""
    rows = ["# made-up numbers, for the test", HEADER.strip()]
    for sp, pl, ex in itertools.product((33, 66, 100), (1.65, 3.3, 5.0), (33, 66, 100)):
        d = scale * (0.05 + 0.3 * sp / 100 + 0.02 * pl + 0.05 * ex / 100)
        if not monotone and (sp, pl, ex) == (33, 1.65, 33):
            d = 5.0  # a lower point with a larger distance than the points above it
        t = 0.1 + 0.3 * sp / 100 + 0.01 * pl
        rows.append(f"{joint},{category},{sp},{pl},{ex},{d:.6f},rad,{t:.6f}")
    return write(tmp_path, "\n".join(rows) + "\n")


def test_the_file_reads_in_si_units(tmp_path):
    p = write(tmp_path, "# a comment\n" + HEADER + "shoulder_pan_joint,0,100,5,100,17.8,deg,0.244\n"
              "elbow_joint,1,33,0,33,0.22,rad,0.164\n")
    a, b = read_stopping_file(p)
    assert a.distance == pytest.approx(np.deg2rad(17.8)) and a.time == 0.244 and a.category == 0 and a.row == 3
    assert b.point == (33.0, 0.0, 33.0) and b.angular
    ms = write(tmp_path, HEADER.replace("time_s", "time_ms") + "shoulder_pan_joint,1,100,5,100,0.3,rad,244\n",
               "ms.csv")
    assert read_stopping_file(ms)[0].time == pytest.approx(0.244)


@pytest.mark.parametrize("body, where, words", [
    ("", "", "has no header"),
    ("joint,category,speed\n", "row 1", "the header must be"),
    (HEADER + "j,3,100,5,100,0.3,rad,0.2\n", "row 2, column 2 (category)", "not a stop category"),
    (HEADER + "j,1,0,5,100,0.3,rad,0.2\n", "row 2, column 3 (speed_pct)", "out of range"),
    (HEADER + "j,1,100,5,100,0.3,furlong,0.2\n", "row 2, column 7 (unit)", "is not a unit"),
    (HEADER + "j,1,100,5,100,nan,rad,0.2\n", "row 2, column 6 (distance)", "out of range"),
    (HEADER + "j,1,100,5,100,0.3,rad,0\n", "row 2, column 8 (time_s)", "out of range"),
    (HEADER + "j,1,100,5,100,0.3,rad\n", "row 2", "has 7 values"),
    (HEADER + "j,1,100,5,100,0.3,rad,0.2\nj,1,100,5,100,0.4,rad,0.3\n", "row 3", "repeats row 2"),
    (HEADER, "", "no data rows"),
])
def test_a_bad_file_is_one_error_naming_row_and_column(tmp_path, body, where, words):
    with pytest.raises(StoppingFileError) as exc:
        read_stopping_file(write(tmp_path, body))
    assert exc.value.where == where and words in exc.value.problem
    assert "\n" not in str(exc.value) and "furlong" not in str(exc.value)  # one line, never the file's text


def test_a_file_too_large_or_not_text_is_refused_before_parsing(tmp_path):
    for end in ("\n", "\r", "\r\n"):  # rows are counted whatever ends them
        big = write(tmp_path, (HEADER + "j,1,100,5,100,0.3,rad,0.2\n" * 10_001).replace("\n", end))
        with pytest.raises(StoppingFileError, match="more than 10,000 rows"):
            read_stopping_file(big)
    ok = write(tmp_path, (HEADER + "j,1,100,5,100,0.3,rad,0.2\n").replace("\n", "\r"))
    assert read_stopping_file(ok)[0].time == 0.2
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(StoppingFileError, match="not UTF-8"):
        read_stopping_file(tmp_path / "bin.csv")
    with pytest.raises(StoppingFileError, match="no such file"):
        read_stopping_file(tmp_path / "missing.csv")


def test_lookup_takes_the_next_published_point_at_or_above_the_programs(tmp_path, ur5):
    rows = read_stopping_file(grid_file(tmp_path))
    vmax = float(ur5.velocity_limits[0])
    rng = np.random.default_rng(28)
    for _ in range(50):
        peaks = np.zeros(ur5.n_joints)
        peaks[0] = rng.uniform(0.0, 1.0) * vmax
        payload, ext = float(rng.uniform(0.0, 5.0)), float(rng.uniform(1.0, 100.0))
        (j,) = joint_stops(rows, 1, ur5, peaks, payload, ext)
        pct = 100 * peaks[0] / vmax
        assert j.point == (min(x for x in (33, 66, 100) if x >= pct - 1e-9),
                           min(x for x in (1.65, 3.3, 5.0) if x >= payload), min(x for x in (33, 66, 100) if x >= ext))
        # never below the published data: every published point at or below the program's is covered
        below = [r for r in rows if r.speed_pct <= j.point[0] and r.payload_kg <= j.point[1]
                 and r.extension_pct <= j.point[2]]
        assert j.distance >= max(r.distance for r in below) and j.time >= max(r.time for r in below)
        assert j.speed == pytest.approx(j.point[0] / 100 * vmax)


def test_lookup_covers_data_that_are_not_monotone(tmp_path, ur5):
    rows = read_stopping_file(grid_file(tmp_path, monotone=False))
    peaks = np.zeros(ur5.n_joints)
    peaks[0] = 0.9 * ur5.velocity_limits[0]
    (j,) = joint_stops(rows, 1, ur5, peaks, 5.0, 100.0)
    assert j.point == (100.0, 5.0, 100.0) and j.distance == 5.0  # the lower point's larger distance


@pytest.mark.parametrize("mutate, where, words", [
    (dict(peak=1.01), "joint shoulder_pan_joint", "data are never extrapolated"),
    (dict(payload=6.0), "joint shoulder_pan_joint", "payload is 6 kg"),
    (dict(category=0), "", "no rows for stop category 0"),
])
def test_lookup_outside_the_data_is_an_error(tmp_path, ur5, mutate, where, words):
    rows = read_stopping_file(grid_file(tmp_path))
    peaks = np.zeros(ur5.n_joints)
    peaks[0] = mutate.get("peak", 0.5) * ur5.velocity_limits[0]
    with pytest.raises(StoppingDataError) as exc:
        joint_stops(rows, mutate.get("category", 1), ur5, peaks, mutate.get("payload", 1.0), 50.0)
    assert exc.value.where == where and words in exc.value.problem


def test_lookup_checks_joint_names_units_and_a_missing_corner(tmp_path, ur5):
    peaks = np.zeros(ur5.n_joints)
    bad = read_stopping_file(write(tmp_path, HEADER + "wrist_9,1,100,5,100,0.3,rad,0.2\n"))
    with pytest.raises(StoppingDataError, match="is not a joint of the robot") as exc:
        joint_stops(bad, 1, ur5, peaks, 1.0, 100.0)
    assert "wrist_9" not in str(exc.value)  # the file's text is never quoted
    metres = read_stopping_file(write(tmp_path, HEADER + "elbow_joint,1,100,5,100,0.3,m,0.2\n"))
    with pytest.raises(StoppingDataError, match="is revolute: its distance is in deg or rad"):
        joint_stops(metres, 1, ur5, peaks, 1.0, 100.0)
    holes = read_stopping_file(write(tmp_path, HEADER + "elbow_joint,1,100,5,33,0.3,rad,0.2\n"
                                     "elbow_joint,1,33,1,100,0.3,rad,0.2\n"))
    with pytest.raises(StoppingDataError, match="no published point at speed 33 %, payload 5 kg, extension 100 %"):
        joint_stops(holes, 1, ur5, peaks, 2.0, 100.0)


def test_category_2_falls_back_on_category_1_rows(tmp_path, ur5):
    rows = read_stopping_file(grid_file(tmp_path))
    peaks = np.zeros(ur5.n_joints)
    assert joint_stops(rows, 2, ur5, peaks, 1.0, 50.0) == joint_stops(rows, 1, ur5, peaks, 1.0, 50.0)


def test_peak_joint_speeds_is_the_minimum_jerk_peak():
    w = np.array([[0.0, 0.0], [1.0, -0.5]])
    traj = build_trajectory(w, np.array([0.2, 0.2]), np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    # 1 rad at half of 2 rad/s, minimum jerk: the move takes 1.875 s and peaks at exactly the scaled limit
    np.testing.assert_allclose(peak_joint_speeds(traj), [1.0, 0.5])


def test_grown_capsules_hold_every_pose_within_the_joints_travel(ur5):
    """Pinocchio poses the arm at q0 and at random q with |q - q0| <= travel joint by joint; every point of every
    capsule axis at q lies within the growth of the same point at q0."""
    caps = fitted_capsules(ur5)
    cap_joint = np.array([c.joint for c in caps])
    a, b = np.array([c.p0 for c in caps]), np.array([c.p1 for c in caps])
    model = load_pinocchio(ur5.urdf)
    data = model.createData()
    rng = np.random.default_rng(7)
    lo, hi = ur5.sampling_range()

    def axis_points(q):
        pin.forwardKinematics(model, data, ur5.pinocchio_q(q))
        out = []
        for c, j in enumerate(cap_joint):
            m = data.oMi[int(j) + 1]
            for f in np.linspace(0.0, 1.0, 9):
                out.append(m.act((1 - f) * a[c] + f * b[c]))
        return np.array(out).reshape(len(caps), 9, 3)

    worst = 0.0
    for _ in range(40):
        travel = rng.uniform(0.0, 0.6, ur5.n_joints)
        grow = hold_radii(ur5, cap_joint, a, b, travel)
        q0 = rng.uniform(lo, hi)
        p0 = axis_points(q0)
        for _ in range(10):
            q = q0 + rng.uniform(-1.0, 1.0, ur5.n_joints) * travel
            moved = np.linalg.norm(axis_points(q) - p0, axis=2).max(axis=1)
            assert np.all(moved <= grow + 1e-9)
            worst = max(worst, float((moved / np.maximum(grow, 1e-12)).max()))
    assert worst > 0.3  # the bound is not vacuous: some poses use a good part of it


def test_the_docs_example_reads_as_documented(tmp_path, ur5):
    """docs/robot.md's stopping block and data file: valid, and the UR5's category 0 rows (its manual's) stop
    faster than a linear ramp from the signal, as the page says."""
    import re
    from pathlib import Path

    import yaml

    from cellstress.cell.stopping import StoppingSpec

    text = (Path(__file__).resolve().parents[2] / "docs" / "robot.md").read_text(encoding="utf-8")
    section = text[text.index("## Stopping"):]
    block = yaml.safe_load(re.search(r"```yaml\n(.*?)```", section, re.S)[1])
    spec = StoppingSpec.model_validate(block["robot"]["stopping"], strict=True)
    assert spec.category == 1 and spec.data == "ur5-stopping.csv"
    rows = read_stopping_file(write(tmp_path, re.search(r"```csv\n(.*?)```", section, re.S)[1]))
    for r in rows:
        if r.category == 0:
            v = float(ur5.velocity_limits[ur5.joint_names.index(r.joint)])
            assert 0.40 <= r.distance / v / r.time <= 0.43
            assert profile(r.distance, r.time, v).reading == FASTER
