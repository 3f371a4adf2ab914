"""The built-in machine-tending-delay pair (issue 28): the UR5 of machine-tending stops as its maker's data say,
behind a safety PLC that adds 0.1 s; the flawed cell's curtain was laid out for the paper's 0.15 s stop, the twin
has it where machine-tending does (docs/cells.md)."""

from __future__ import annotations

import pytest
import yaml

from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.cell.load import builtin_text, load_cell, parse_cell
from cellstress.sim.build import build_layout
from cellstress.sim.simulator import Simulator

FLAWED, TWIN = "machine-tending-delay", "machine-tending-delay-ok"
# verify's worst class in the flawed cell (docs/cells.md): the upper arm, moving at 0.3 m/s, touches a hand
WITNESS = "walk+upright,walk+upright,turn-left-45+upright,walk+bend-forward-right,walk+bend-forward-right"


def paper_stop() -> Simulator:
    """The flawed cell's layout with the paper's stop (0.15 s, no delay): what its curtain was laid out for."""
    doc = yaml.safe_load(builtin_text(FLAWED))
    doc["robot"].pop("stopping")
    doc["robot"]["stopping_time"] = 0.15
    return Simulator(parse_cell(yaml.safe_dump(doc), "paper-stop.yaml", None))


def test_the_twins_differ_only_in_the_opening() -> None:
    a, b = (yaml.safe_load(builtin_text(n)) for n in (FLAWED, TWIN))
    assert a["devices"][0]["start"] == [1.6, -0.7] and b["devices"][0]["start"] == [2.0, -0.7]
    machine = yaml.safe_load(builtin_text("machine-tending"))
    assert b["fences"] == machine["fences"] and b["devices"] == machine["devices"]
    assert b["robot"]["task"]["poses"] == machine["robot"]["task"]["poses"]  # programmed by the same tool poses
    for doc in (a, b):
        for key in ("name", "description", "fences", "floor", "devices"):
            doc.pop(key)
        doc["human"].pop("start")
    assert a == b


def test_the_stop_read_from_the_data_and_the_plc() -> None:
    stop = build_layout(load_cell(FLAWED)).robots[0].stop
    assert stop.category == 1 and stop.controller_delay == 0.1 and stop.data == "ur5-stopping.csv"
    # every joint at the 33 % point (the program runs at 0.3 of the limits), 1.65 kg, 100 %: the file's 60 ms
    # reaction, then the shoulder's 0.106 s ramp
    assert all(j.point == (33.0, 1.65, 100.0) for j in stop.joints)
    assert stop.delay == pytest.approx(0.16, abs=1e-3) and stop.braking == pytest.approx(0.1055, abs=1e-3)


def test_static_check_fails_for_the_real_stop_only() -> None:
    flawed, fixed = (load_cell(n) for n in (FLAWED, TWIN))
    a, b = check_cell(flawed, build_layout(flawed)), check_cell(fixed, build_layout(fixed))
    assert list(a.failures()) == ["front-curtain"] and b.ok
    assert "1.326 m >= 1.355 m? FAIL" in "\n".join(a.lines())
    assert "1.726 m >= 1.355 m? ok" in "\n".join(b.lines())
    paper = paper_stop()
    assert check_cell(paper.cell, paper.layout).ok  # laid out for 0.15 s: S = 1.17 m
    for cell in (flawed, fixed):  # both pass their robot program check (issue 28, Deliver 2)
        assert all(p.ok for p in check_programs(build_layout(cell)))


def test_the_delay_turns_the_layout_unsafe() -> None:
    trace = Simulator(FLAWED).run(WITNESS.split(","))
    assert trace.unsafe
    rec = trace.record(trace.unsafe_row)
    assert rec.robot_link == "upper_arm_link" and rec.v_R > 0.2
    assert not paper_stop().run(WITNESS.split(",")).unsafe  # the same worker, the paper's stop
    assert not Simulator(TWIN).run(WITNESS.split(",")).unsafe


def test_plan_finds_the_flaw_and_verify_proves_the_twin(tmp_path, capsys) -> None:
    from cellstress.cli import main

    main(["search", FLAWED, "--searcher", "plan", "--budget", "200", "--seed", "0", "--out", str(tmp_path / "s"),
          "--no-report"])
    assert "FOUND at episode 5 of 200" in capsys.readouterr().out
    assert main(["verify", TWIN, "--phases", "cell", "--horizon", "5", "--out", str(tmp_path / "v")]) == 0
    assert "PROVED-SAFE" in capsys.readouterr().out
