"""The robot program check (issue 28): per move the largest joint travel, the tool's top speed and the cycle; a
FAIL for a joint turned the long way round and for a link whose capsule axis passes through a solid. Every
built-in cell passes; a UR10 whose shoulder turns 382 deg fails both ways, and each claim is checked against an
independent computation (pinocchio's kinematics, finite differences, a box's depth by hand)."""

from __future__ import annotations

import copy

import numpy as np
import pinocchio as pin
import pytest
import yaml

from cellstress.analysis.program_check import check_program, check_programs
from cellstress.analysis.program_sweep import DEPTH, capsule_axes
from cellstress.cell.load import BUILTIN_CELLS, builtin_text, load_cell, parse_cell
from cellstress.cli import main
from cellstress.robot.trajectory import evaluate
from cellstress.sim import kernels as K
from cellstress.sim import scene
from cellstress.sim.build import build_layout


def _layout(data: dict, name: str):
    return build_layout(parse_cell(yaml.safe_dump(data), name, None))


def baseline_with(waypoints_deg) -> dict:
    data = yaml.safe_load(builtin_text("baseline"))
    data["robot"]["task"]["waypoints_deg"] = waypoints_deg
    return data


SWING = [[124.8, -44.8, 78.4, -123.6, -90.0, 0.0], [124.8, 337.2, 78.4, -123.6, -90.0, 0.0]]  # +382 deg


@pytest.fixture(scope="module")
def swing():
    """The baseline's UR10 with its shoulder turned 382 deg (where 22 deg back reaches the same angle): the arm
    swings down through the table it stands on, its pedestal and the floor."""
    layout = _layout(baseline_with(SWING), "swing")
    return layout, check_program(layout, 0)


@pytest.mark.parametrize("name", BUILTIN_CELLS)
def test_every_built_in_cell_passes_its_program_check(name):
    for p in check_programs(build_layout(load_cell(name))):
        assert p.ok, "\n".join(p.lines())
        assert p.lines()[-1].endswith("no link passes through a solid")


def test_a_needless_turn_fails_with_the_link_and_what_it_passes_through(swing):
    layout, p = swing
    assert not p.ok and p.failures() == ["program"]
    move = p.moves[0]
    assert move.joint == "shoulder_lift_joint" and move.turn_deg == pytest.approx(382.0)
    assert move.long_way == (("shoulder_lift_joint", pytest.approx(382.0), pytest.approx(22.0)),)
    solids = {(x.link, x.solid) for x in p.passes}
    assert ("forearm_link", "table") in solids and ("forearm_link", "robot-pedestal") in solids
    assert any(x.solid == "the floor" for x in p.passes)
    text = "\n".join(p.lines())
    assert "FAIL move 1 (waypoint 1 -> 2): shoulder_lift_joint turns 382.0 deg the long way round" in text
    assert "FAIL move 1 (waypoint 1 -> 2): link forearm_link passes" in text and "into table at " in text
    # what it reports holds: at the reported time the forearm's axis is that deep in the table (the U's base is
    # a box x -1..1, y -0.4..0.3, 0..0.85 m), by pinocchio's kinematics
    x = next(x for x in p.passes if (x.link, x.solid) == ("forearm_link", "table"))
    a, b = _axis_by_pinocchio(layout, "forearm_link", x.t)
    u = np.linspace(0.0, 1.0, 2001)[:, None]
    pts = a + u * (b - a)
    depth = np.minimum.reduce([pts[:, 0] + 1.0, 1.0 - pts[:, 0], pts[:, 1] + 0.4, 0.3 - pts[:, 1], pts[:, 2],
                               0.85 - pts[:, 2]])
    assert x.depth - 1e-6 <= depth.max() <= x.depth + DEPTH / 2 + 1e-6


def _axis_by_pinocchio(layout, capsule: str, tau: float):
    """A capsule's axis ends in the cell at path time tau: the trajectory's joint values, pinocchio's joint
    placements, the base."""
    part = layout.robots[0]
    cap = next(c for c in part.capsules if c.name == capsule)
    model = pin.buildModelFromUrdf(str(part.model.urdf))
    data = model.createData()
    q, _ = evaluate(part.trajectory, tau)
    pin.forwardKinematics(model, data, part.model.pinocchio_q(q))
    m = data.oMi[cap.joint + 1].homogeneous
    base = layout.params.base
    return [(base @ m @ np.append(p, 1.0))[:3] for p in (cap.p0, cap.p1)]


def test_three_stations_around_the_base_turn_back_once_and_pass():
    """67, 180, 293 deg of the UR10's base: the cycle must turn back 226 deg once, whatever the values; the
    same stations with the third at -67 deg turn 247 deg where 226 would do, and fail."""
    needed = _layout(baseline_with([[a, -90, 90, -90, -90, 0] for a in (67, 180, 293)]), "around")
    p = check_program(needed, 0)
    assert max(m.turn_deg for m in p.moves) == pytest.approx(226.0)
    assert not any(m.long_way for m in p.moves)
    needless = check_program(_layout(baseline_with([[a, -90, 90, -90, -90, 0] for a in (67, 180, -67)]), "x"), 0)
    assert [m.long_way for m in needless.moves if m.long_way] == [
        (("shoulder_pan_joint", pytest.approx(247.0), pytest.approx(226.0)),)]


def test_a_fence_in_the_way_is_named():
    data = baseline_with([[124.8, -44.8, 78.4, -123.6, -90.0, 0.0], [37.1, -44.8, 78.4, -123.6, -90.0, 0.0]])
    data["fences"].append({"points": [[0.0, 0.4], [0.0, 2.0]], "top": 2.0})  # across the arm's swing
    p = check_program(_layout(data, "fenced"), 0)
    fences = {x.solid for x in p.passes if x.solid.startswith("fence ")}
    assert fences == {f"fence {len(data['fences'])} panel 1"}
    assert f"link forearm_link passes through fence {len(data['fences'])} panel 1 at " in "\n".join(p.lines())


def test_tool_top_speed_matches_finite_differences():
    """The tool's top speed (pinocchio's frame velocity) against finite differences of tool0's position posed
    by the kernel's own kinematics."""
    layout = build_layout(load_cell("baseline"))
    p = check_program(layout, 0)
    part, P = layout.robots[0], layout.params
    joint, placement = part.model.link_frame("tool0")
    W = K.make_work(P)
    traj = part.trajectory
    for m in p.moves:
        taus = m.start + np.arange(0.0, m.duration, 1e-3)
        pos = []
        for tau in taus:
            K.joint_trajectory(P, float(tau), 1.0, W.q, W.qd)
            K.forward_kinematics(P, W.q, W.rot, W.pos)
            pos.append(W.pos[joint] + W.rot[joint] @ placement[:3, 3])
        fd = np.linalg.norm(np.diff(np.asarray(pos), axis=0), axis=1).max() / 1e-3
        assert m.tool_speed == pytest.approx(fd, rel=5e-3)
    assert p.tool == "tool0" and p.cycle == pytest.approx(traj.cycle)


def test_check_prints_the_program_and_fails_on_it(tmp_path, capsys):
    path = tmp_path / "swing.yaml"
    path.write_text(yaml.safe_dump(baseline_with(SWING)), encoding="utf-8")
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert "robot program check:\n  2 moves, cycle " in out
    assert "    move 1 (waypoint 1 -> 2): " in out and "largest joint travel shoulder_lift_joint 382.0 deg" in out
    assert out.strip().splitlines()[-1].startswith("FAIL: the cell file is valid, the static check fails (program")
    assert main(["check", "baseline"]) == 0
    out = capsys.readouterr().out
    assert "  ok: no move turns a joint the long way round, no link passes through a solid\n" in out


def test_a_cell_of_two_robots_names_each():
    layout = build_layout(load_cell("two-robots"))
    checks = check_programs(layout)
    assert [p.robot for p in checks] == ["a", "b"]
    assert checks[1].lines()[0].startswith("robot b: 2 moves, cycle ")
    # robot b's capsules posed for the check are the ones the simulator poses for it
    part = layout.robots[1]
    a, _ = capsule_axes(layout, 1, np.array([0.5]))
    ra, _ = scene.robot_capsules(layout, [0.0, 0.5])
    np.testing.assert_allclose(a[0], ra[part.first_capsule:part.first_capsule + len(part.capsules)], atol=1e-12)


def test_same_output_twice():
    layout = build_layout(load_cell("two-robots"))
    assert [p.lines() for p in check_programs(layout)] == [p.lines() for p in check_programs(layout)]
    assert copy.deepcopy(check_programs(layout)) == check_programs(layout)
