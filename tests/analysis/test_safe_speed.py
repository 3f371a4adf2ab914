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


def test_the_per_move_program_slows_only_the_moves_that_need_it():
    cell = load_cell("baseline")
    assert per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.75))) is None
    assert per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.0))) is None  # none safe
    r = per_move_remedy(cell, (MoveSpeed(0, 0, 0.5, 1.0), MoveSpeed(0, 1, 0.5, 0.3125)))
    spec = parse_cell(r.text, "x.yaml", None).spec
    assert spec.robots[0].task.speed_scales == (0.5, 0.3125)


def test_a_trajectory_file_has_no_speed_to_scale():
    assert program_moves(load_cell("palletizing")) == ()


def test_the_safe_baseline_is_safe_at_full_scale_on_every_move(tmp_path):
    """The baseline's scanner stops the robot before any contact: the program's first try (every move at scale
    1.0) and each move's find nothing, so no bisection is needed (three searches of 10 episodes)."""
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
