"""``cellstress show``: the static check's distances drawn as dimension lines, named start points labelled, and
action labels of the top view that never print over each other."""

from __future__ import annotations

import itertools

import pytest

from cellstress.analysis.iso13855 import check_cell
from cellstress.cell.load import load_cell
from cellstress.report.hazard import FAIL_COLOR, OK_COLOR, StillOptions, _free_spot, layout_figure
from cellstress.sim.build import build_layout


@pytest.mark.parametrize("name", ["baseline", "s1-scanner-width", "all-flaws", "door-unlocked", "door-locked",
                                  "muting-long"])
def test_dimension_lines_carry_the_check_numbers(name) -> None:
    layout = build_layout(load_cell(name))
    static = check_cell(layout.cell, layout)
    _, ax = layout_figure(layout, StillOptions().layout, static=static)
    texts = [t.get_text() for t in ax.texts]
    for d in static.devices:
        if d.where is None:
            continue
        label = f"{d.device}: S {d.required:.2f} m needed, {d.actual:.2f} m here"
        text = next(t for t in ax.texts if t.get_text() == label)
        assert text.get_color() == (OK_COLOR if d.ok else FAIL_COLOR)
    assert any(t.startswith("reach around: ") for t in texts) == (static.approach.where is not None)
    for start in layout.cell.spec.human.starts:
        assert start.name in texts


def test_action_labels_never_overlap() -> None:
    """Eight actions ending at one spot (a worker turning in place) get eight separate label boxes."""
    mark = 0.16
    placed: list[tuple[float, float]] = []
    for _ in range(8):
        _free_spot(1.0, 2.0, placed, mark)
    for (ax_, ay), (bx, by) in itertools.combinations(placed, 2):
        assert abs(ax_ - bx) >= 1.2 * mark or abs(ay - by) >= 0.85 * mark
