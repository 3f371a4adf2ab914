"""analysis.remedies: every flawed built-in cell tried yields a candidate whose cell passes ``check`` (the check
alone here, the re-test is tests/analysis/test_fix.py's), derived from its rows and never from its name; and
the moves follow the geometry the way the fixed twins do."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cellstress.analysis.fix import _moves, checked, footprint, hull_area
from cellstress.analysis.remedies import (
    MARGIN,
    cell_document,
    device_move,
    moved,
    panel_move,
    setting_remedies,
)
from cellstress.cell.load import builtin_file, load_cell, parse_cell

# flawed cell -> the kind of remedy that makes its check pass (a move, or the setting its failing row names)
FLAWED = {"s1-scanner-width": "move-device", "mat-short": "move-device", "long-gripper": "move-cell",
          "palletizing": "move-cell", "warning-field-short": "move-device", "door-unlocked": "guard-locking",
          "restart-auto": "manual-restart", "muting-long": "muting-end", "two-robots": "wire",
          "ssm-latency": "ssm-times", "reach-over": "move-cell"}


def _remedies(name, tmp_path, kinds=("settings", "move-device", "move-cell")):
    cell = load_cell(name)
    base, static = checked(cell)
    out = list(setting_remedies(cell, static)) if "settings" in kinds else []
    for whole in (False, True):
        if ("move-cell" if whole else "move-device") in kinds:
            moves = _moves(cell, static, whole, tmp_path / "scratch.yaml")
            if moves:
                out.append(moved(cell, moves, whole))
    return base, out


def _check(remedy, tmp_path):
    path = tmp_path / "candidate.yaml"
    path.write_text(remedy.text)
    return checked(parse_cell(remedy.text, str(path), tmp_path))[0]


@pytest.mark.parametrize(("name", "kind"), sorted(FLAWED.items()))
def test_a_flawed_cell_gets_a_candidate_that_passes_check(name, kind, tmp_path):
    base, remedies = _remedies(name, tmp_path, (kind if kind.startswith("move") else "settings",))
    assert base.failing
    passing = [r.kind for r in remedies if not _check(r, tmp_path).failing]
    assert kind in passing, (name, [(r.kind, r.change) for r in remedies])


def test_the_mat_moves_by_its_shortfall_plus_the_margin(tmp_path):
    """mat-short's row: 1.189 m where 1.600 m are needed; its front edge (y = 2.3) moves to y = 2.3 + 0.411 +
    0.05 rounded up to the cm = 2.77 (mat-ok moves it to 3.2); the start point (y = 2.45, beyond the edge)
    moves with it, the walls (ending at 3.2) stay."""
    cell = load_cell("mat-short")
    _, static = checked(cell)
    (row,) = [d for d in static.devices if d.device == "front-mat"]
    m = device_move(row)
    assert m.normal == (0.0, 1.0) and m.delta == pytest.approx(0.47)
    assert m.delta >= row.required - row.actual + MARGIN - 1e-9
    doc = parse_cell(moved(cell, (m,), False).text, "x.yaml", tmp_path).spec
    before = cell.spec
    mat = next(d for d in doc.devices if d.name == "front-mat")
    assert max(p[1] for p in mat.polygon) == pytest.approx(2.77)
    assert doc.human.start.xy[1] == pytest.approx(before.human.start.xy[1] + 0.47)
    assert doc.fences == before.fences


def test_moving_with_the_cell_stretches_the_walls_as_the_twin_does(tmp_path):
    """long-gripper-ok moved the field's front edge and the walls that end there by 0.6 m; the cell-wide move
    does the same with the shortfall's 0.40 m: every fence point at y = 3.2 moves, none other."""
    cell = load_cell("long-gripper")
    _, static = checked(cell)
    (m,) = [device_move(d) for d in static.devices if not d.ok]
    new = parse_cell(moved(cell, (m,), True).text, "x.yaml", tmp_path).spec
    for a, b in zip(cell.spec.fences, new.fences, strict=True):
        for p, q in zip(a.points, b.points, strict=True):
            assert q[1] == pytest.approx(p[1] + (0.4 if p[1] >= 3.2 - 1e-9 else 0.0))
    assert new.floor.ymax == pytest.approx(cell.spec.floor.ymax + 0.4)


def test_a_fence_panel_moves_as_reach_over_ok_moved_it(tmp_path):
    """reach-over: the 1.4 m front panel 0.44 m from the swept zone, Table 2 asks 1.1 m; reach-over-ok moved it
    0.7 m to the front (y = 2.25) with the side walls. The panel move: towards the worker (+y), c - distance +
    0.05 m rounded up to the cm, the side walls' ends with it."""
    cell = load_cell("reach-over")
    _, static = checked(cell)
    (pr,) = static.approach.reach_over_fails
    m = panel_move(pr)
    assert m.normal == (0.0, 1.0)
    assert m.delta == pytest.approx(math.ceil((pr.reach.required - pr.reach.behind + MARGIN) * 100) / 100)
    assert 0.6 < m.delta < 0.8
    new = parse_cell(moved(cell, (m,), False).text, "x.yaml", tmp_path).spec
    assert new.fences[0].points == ((-1.5, 1.55 + m.delta), (1.5, 1.55 + m.delta))
    assert new.fences[1].points[0] == (-1.5, 1.55 + m.delta) and new.fences[1].points[1] == (-1.5, -1.6)


def test_a_safe_cell_gets_no_candidate(tmp_path):
    base, remedies = _remedies("baseline", tmp_path)
    assert not base.failing and remedies == []


def test_file_paths_are_made_absolute():
    """long-gripper reads boxarm.urdf next to it: a changed copy written elsewhere reads the same file."""
    import os

    doc = cell_document(load_cell("long-gripper"))
    assert os.path.isabs(doc["robot"]["urdf"]) and doc["robot"]["urdf"].endswith("boxarm.urdf")


def test_hull_area_against_shapes():
    """The footprint's hull against areas computed by hand: a 3 x 4 rectangle with inner points, a triangle."""
    assert hull_area([(0, 0), (3, 0), (3, 4), (0, 4), (1, 1), (2, 3), (3, 2)]) == pytest.approx(12.0)
    assert hull_area([(0, 0), (2, 0), (0, 2)]) == pytest.approx(2.0)
    assert hull_area([(0, 0), (1, 1), (2, 2)]) == pytest.approx(0.0)
    # the baseline: fences from x -1.5..1.5, y -1.6..3.2 (and the bay), so at least 3 x 4.8
    assert footprint(load_cell("baseline")) >= 3.0 * 4.8 - 1e-9


def test_a_monitor_set_for_a_slower_robot_is_set_to_the_real_top_speed(tmp_path):
    """ssm-ok's monitor configured for 0.8 m/s while the robot reaches 1.12 m/s on its path: the setting
    candidate configures it with the real top speed (cm/s up), and its speed row passes."""
    text = Path(builtin_file("ssm-ok")).read_text()
    assert text.count("    max_speed: 1.2 ") == 1
    path = tmp_path / "slow-monitor.yaml"
    path.write_text(text.replace("    max_speed: 1.2 ", "    max_speed: 0.8 "))
    cell = parse_cell(path.read_text(), str(path), tmp_path)
    base, static = checked(cell)
    assert "ssm-speed" in base.failing
    (r,) = [r for r in setting_remedies(cell, static) if r.kind == "ssm-speed"]
    (sp,) = static.speeds
    assert f"max_speed: {math.ceil(sp.real * 100.0 - 1e-9) / 100.0}" in r.text
    assert "ssm-speed" not in _check(r, tmp_path).failing
