"""analysis.safe_speed: the per-move speed program and its bisection's judge; and the moves of a program."""

from __future__ import annotations

import pytest

from cellstress.analysis.remedies import program_moves, with_scales
from cellstress.analysis.safe_speed import MoveSpeed, move_speeds, per_move_remedy
from cellstress.cell.load import load_cell, parse_cell, with_criterion


def test_program_moves_and_per_move_scales():
    cell = with_criterion(load_cell("baseline"), "iso15066")
    assert program_moves(cell) == ((0, 0, 0.5), (0, 1, 0.5))
    spec = parse_cell(with_scales(cell, {(0, 1): 0.25}, "").text, "x.yaml", None).spec
    assert spec.robots[0].task.speed_scales == (0.5, 0.25)
    assert spec.criterion.type == "iso15066"  # the proposal file carries the criterion it was judged by


def test_the_per_move_program_slows_only_the_moves_that_need_it(tmp_path):
    cell = load_cell("baseline")
    scratch = tmp_path / "s.yaml"
    assert per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.75)), scratch) is None
    assert per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.0)), scratch) is None
    r = per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.3125)), scratch)
    spec = parse_cell(r.text, "x.yaml", None).spec
    assert spec.robots[0].task.speed_scales == (0.5, 0.3125)
    # the baseline arrives at 1.4 s, in its first move (0.2 s dwell, then move 1): that move is not slowed, so
    # the robot is at the same point of its path at the same time
    assert spec.robots[0].task.phase == pytest.approx(cell.spec.robots[0].task.phase)


def test_map_phase_keeps_the_point_of_the_path():
    """Moves (start, duration) [(0.2, 2.0), (2.4, 2.0)], cycle 4.4 s, made twice as slow: [(0.2, 4.0), (4.4,
    4.0)], cycle 8.4 s. Half-way through move 1 (1.2 s) -> half-way through the slower one (2.2 s); in the
    dwell before move 2 (2.3 s, 0.1 s before it) -> 0.1 s before the slower move 2 (4.3 s); the first dwell
    stays; a phase past the cycle wraps."""
    from cellstress.analysis.safe_speed import map_phase

    old = (((0.2, 2.0), (2.4, 2.0)), 4.4)
    new = (((0.2, 4.0), (4.4, 4.0)), 8.4)
    assert map_phase(1.2, old, new) == pytest.approx(2.2)
    assert map_phase(2.3, old, new) == pytest.approx(4.3)
    assert map_phase(0.1, old, new) == pytest.approx(0.1)
    assert map_phase(3.4, old, new) == pytest.approx(6.4)
    assert map_phase(4.4 + 1.2, old, new) == pytest.approx(2.2)


def test_a_trajectory_file_has_no_speed_to_scale():
    assert program_moves(load_cell("palletizing")) == ()


def test_the_safe_baseline_is_safe_at_full_scale_on_every_move(tmp_path):
    """The baseline's scanner stops the robot before any contact: every scale of the program's scan (1/8 .. 1,
    eight searches of 10 episodes) finds nothing, so each move is at 1.0 with no search of its own."""
    cell = with_criterion(load_cell("baseline"), "iso15066")
    speeds = move_speeds(cell, 10, 0, tmp_path / "scratch.yaml")
    assert [(s.move, s.safe) for s in speeds] == [(0, 1.0), (1, 1.0)]
    assert not (tmp_path / "scratch.yaml").exists()


@pytest.mark.parametrize("scale", [0.5, 1.0])
def test_the_judge_finds_s1s_hazard_at_speed(scale, tmp_path):
    """The judge is not blind: on s1-scanner-width (the field too short) the search finds the hazard with both
    moves at 0.5 and at 1.0 (contact-while-moving, budget 20)."""
    from cellstress.analysis.safe_speed import _safe

    cell = load_cell("s1-scanner-width")
    assert not _safe(cell, {(0, 0): scale, (0, 1): scale}, 20, 0, tmp_path / "s.yaml")


def test_the_scan_stops_at_the_first_unsafe_scale():
    """A judge that is not monotone (unsafe at 3/8 only): the scan reports 2/8, never the 1.0 above the gap."""
    from cellstress.analysis.safe_speed import _largest

    tried = []

    def ok(x):
        tried.append(x)
        return x != 3 / 8

    assert _largest(ok, 0.0) == 2 / 8 and tried == [1 / 8, 2 / 8, 3 / 8]
    assert _largest(lambda x: True, 0.5) == 1.0
    assert _largest(lambda x: False, 0.5) == 0.5
