"""The built-in long-gripper cells (issue 28): an arm drawn in URDF primitives carries a 0.5 m box gripper out
over the front of the U, where the scanner field laid out for the baseline's robot is too short; its twin has
the field and walls 0.6 m further out (docs/cells.md)."""

from __future__ import annotations

import pytest
import yaml

from cellstress.analysis.iso13855 import check_cell
from cellstress.cell.load import builtin_text, load_cell
from cellstress.sim.build import build_layout
from cellstress.sim.simulator import Simulator

WITNESS = "turn-right-45+upright,walk+upright,walk+bend-forward,walk+bend-forward"  # verify --horizon 4: class 1


def test_the_robot_is_primitives_only_and_fully_enclosed() -> None:
    from cellstress.analysis.robot_audit import audit_robot
    from cellstress.robot.geometry import robot_geometry

    layout = build_layout(load_cell("long-gripper"))
    geometry = robot_geometry(layout.robot.urdf)
    kinds = {s.kind for g in geometry.links for s in g.shapes}
    assert kinds == {"box", "cylinder"}
    assert [c.name for c in layout.capsules][-1] == "gripper" and len(layout.capsules) == 8
    assert audit_robot(geometry, layout.capsules).worst == 0.0


def test_the_twins_differ_only_in_the_front_edge() -> None:
    a, b = (yaml.safe_load(builtin_text(n)) for n in ("long-gripper", "long-gripper-ok"))
    assert b["devices"][0]["polygon"][:2] == [[-1.5, 3.8], [1.5, 3.8]] and b["floor"]["ymax"] == 4.8
    assert b["human"]["start"]["xy"][1] - 3.8 == pytest.approx(a["human"]["start"]["xy"][1] - 3.2)
    for doc in (a, b):
        for key in ("name", "description", "fences", "human", "floor"):
            doc.pop(key)
        doc["devices"][0].pop("polygon")
    assert a == b


def test_static_check_fails_by_the_gripper_and_passes_in_the_twin() -> None:
    flawed, fixed = (load_cell(n) for n in ("long-gripper", "long-gripper-ok"))
    a, b = check_cell(flawed, build_layout(flawed)), check_cell(fixed, build_layout(fixed))
    assert not a.ok and list(a.failures()) == ["front-scanner"] and b.ok
    text = "\n".join(a.lines())
    assert "1.539 m >= 1.880 m? FAIL" in text and "gripper at" in text
    assert "2.139 m >= 1.880 m? ok" in "\n".join(b.lines())


def test_the_gripper_is_what_the_worker_meets() -> None:
    trace = Simulator("long-gripper").run(WITNESS.split(","))
    assert trace.unsafe
    rec = trace.record(trace.unsafe_row)
    assert rec.robot_link == "gripper" and rec.v_R > 0.05
    twin = Simulator("long-gripper-ok").run(WITNESS.split(","))
    assert not twin.unsafe


def test_plan_finds_the_flaw_and_verify_proves_the_twin(tmp_path, capsys) -> None:
    from cellstress.cli import main

    assert main(["search", "long-gripper", "--searcher", "plan", "--budget", "200", "--seed", "0", "--out",
                 str(tmp_path / "s"), "--no-report"]) == 0
    out = capsys.readouterr().out
    assert "FOUND at episode" in out
    assert main(["verify", "long-gripper-ok", "--phases", "cell", "--horizon", "6", "--out",
                 str(tmp_path / "v")]) == 0
    assert "PROVED-SAFE" in capsys.readouterr().out
