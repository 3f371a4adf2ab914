"""analysis.way_remedies: the candidates that close a way in, derived from check's openings and device rules,
each the least change of its kind that passes ``check`` (the re-test is ``fix``'s, tests/cli/test_fix_cli.py)."""

from __future__ import annotations

import math
from pathlib import Path

import yaml

from cellstress.analysis.espe_rules import CurtainReachOver
from cellstress.analysis.fix import _device_moves, checked
from cellstress.analysis.remedies import MARGIN, moved
from cellstress.analysis.way_remedies import (
    closed_gaps,
    device_heights,
    lowered_panels,
    raised_fences,
    raised_tops,
)
from cellstress.cell.load import builtin_file, load_cell, parse_cell
from cellstress.core.iso13857 import TABLE_2


def _cell_of(text, tmp_path, name="candidate.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return parse_cell(text, str(path), tmp_path)


def _failing(text, tmp_path):
    return checked(_cell_of(text, tmp_path))[0].failing


def test_a_raised_panel_is_lowered_to_the_slot_limit_first(tmp_path):
    """crawl-under's front wall 0.35 m off the floor: lowered to 180 mm (ISO 13857's whole-body slot), then to the
    floor; the first already passes check (its twin chose 150 mm)."""
    cell = load_cell("crawl-under")
    base, static = checked(cell)
    assert base.failing == ("whole-body-opening",)
    (tries,) = lowered_panels(cell, static)
    bottoms = [yaml.safe_load(r.text)["fences"][0]["bottom"] for r in tries]
    assert bottoms == [0.18, 0.0] and all(r.kind == "lower-panel" and r.parts_added == 0 for r in tries)
    assert _failing(tries[0].text, tmp_path) == ()
    assert [f["points"] for f in yaml.safe_load(tries[0].text)["fences"]] == \
        [[list(p) for p in f.points] for f in cell.spec.fences]  # only the bottom changed


def test_a_curtain_reached_over_gets_the_lowest_top_that_passes(tmp_path):
    """curtain-reach-over's front curtain tops out at 0.9 m: raised to the lowest column of ISO 13855 Table 1 at
    which its reach-over row passes; the column below it still fails."""
    cell = load_cell("curtain-reach-over")
    base, static = checked(cell)
    assert base.failing == ("front-curtain-reach-over",)
    seen = []

    def static_of(text):
        seen.append(text)
        return checked(_cell_of(text, tmp_path))[1]

    (r,) = raised_tops(cell, static, static_of)
    assert r.kind == "raise-top" and r.rows == ("front-curtain-reach-over",) and 0 < len(seen) <= 4  # bisected
    top = next(d for d in yaml.safe_load(r.text)["devices"] if d["name"] == "front-curtain")["top"]
    assert _failing(r.text, tmp_path) == ()
    columns = [b / 1000 for b in (900, 1000, 1100, 1200, 1300, 1400, 1600, 1800, 2000, 2200, 2400, 2600)]
    below = columns[columns.index(top) - 1]
    assert below > 0.9  # (the curtain's own column fails: that is the row)
    text = r.text.replace(f"top: {top}", f"top: {below}")
    assert "front-curtain-reach-over" in _failing(text, tmp_path)


def test_a_curtain_reached_over_is_moved_back_to_s_ro(tmp_path):
    """The same curtain moved straight back instead: by S_RO minus its distance plus the margin, with the cell
    beyond its line; the move passes check."""
    cell = load_cell("curtain-reach-over")
    _, static = checked(cell)
    (m,) = _device_moves(static)
    (row,) = [r for r in static.access if isinstance(r, CurtainReachOver) and not r.ok]
    assert m.device == row.device == "front-curtain"
    assert m.delta == math.ceil((row.required - row.behind + MARGIN) * 100 - 1e-9) / 100
    assert _failing(moved(cell, (m,), True).text, tmp_path) == ()


def test_a_gap_the_scanner_sees_too_late_is_closed_the_way_in_is_not(tmp_path):
    """s3-fence-gap: the missing metre of its right wall is the scanner's entry closest to the robot, too close
    for ISO 13855: one panel across it (a part added) passes check. Its front opening (3 m, the way in, far
    enough) is never closed."""
    cell = load_cell("s3-fence-gap")
    _, static = checked(cell)
    (r,) = closed_gaps(cell, static)
    assert r.kind == "close-gap" and r.parts_added == 1 and r.rows == ("front-scanner",)
    fences = yaml.safe_load(r.text)["fences"]
    # the right wall drawn as one run again, as the baseline draws it: fence 2 continued, fence 3 joined to it
    assert len(fences) == len(cell.spec.fences) - 1
    assert fences[1]["points"] == [[1.5, 3.2], [1.5, -1.6], [0.6, -1.6]] and fences[1]["top"] == 2.0
    assert _failing(r.text, tmp_path) == ()


def test_a_cell_whose_openings_pass_gets_no_gap_closed():
    cell = load_cell("baseline")
    _, static = checked(cell)
    assert closed_gaps(cell, static) == [] and lowered_panels(cell, static) == []


def test_a_scanner_too_low_for_its_resolution_is_raised(tmp_path):
    """The baseline's scanner at 0.1 m with 70 mm resolution: ISO 13855 6.3 wants 15 (70 - 50) = 300 mm; the
    candidate puts the plane there and passes check."""
    text = Path(builtin_file("baseline")).read_text()
    assert text.count("    height: 0.3\n") == 1
    cell = _cell_of(text.replace("    height: 0.3\n", "    height: 0.1\n"), tmp_path, "low.yaml")
    base, static = checked(cell)
    assert base.failing == ("front-scanner-mounting",)
    (r,) = device_heights(cell, static)
    assert r.kind == "device-height" and "from 100 to 300 mm" in r.change
    assert _failing(r.text, tmp_path) == ()


def test_a_fence_reached_over_is_raised_to_the_lowest_column_that_holds(tmp_path):
    """reach-over: the hazard zone is too close behind the front panel for ISO 13857 Table 2 at its height; the
    fence is raised to the lowest column of the table at which none of its panels fails, and the cell then
    passes check (its twin moved the panel back 0.70 m instead, 2.10 m^2 of floor)."""
    cell = load_cell("reach-over")
    base, static = checked(cell)
    assert "reach-over" in base.failing
    (r,) = raised_fences(cell, static, lambda text: checked(_cell_of(text, tmp_path))[1])
    assert r.kind == "raise-fence" and r.rows == ("reach-over",) and r.parts_added == 0
    before = [f.top for f in cell.spec.fences]
    after = [f["top"] for f in yaml.safe_load(r.text)["fences"]]
    raised = [i for i, (a, b) in enumerate(zip(before, after, strict=True)) if a != b]
    assert raised and all(after[i] * 1000 in TABLE_2.b_mm for i in raised)
    assert _failing(r.text, tmp_path) == ()
    for i in raised:  # one column lower fails again (unless the fence's own height is that column)
        lower = [b / 1000 for b in TABLE_2.b_mm if before[i] < b / 1000 < after[i]]
        if lower:
            doc = yaml.safe_load(r.text)
            doc["fences"][i]["top"] = lower[-1]
            assert "reach-over" in _failing(yaml.safe_dump(doc), tmp_path)


def test_a_gap_to_a_fence_of_another_height_is_closed_by_continuing_the_run_alone(tmp_path):
    """s3-fence-gap with the fence the gap ends at made 2.2 m high: one run cannot have two heights, so fence 2
    is continued to it and fence 3 stays a run of its own."""
    text = Path(builtin_file("s3-fence-gap")).read_text()
    old = "[[1.5, -0.2], [1.5, -1.6], [0.6, -1.6]], top: 2.0}"
    assert text.count(old) == 1
    cell = _cell_of(text.replace(old, old.replace("top: 2.0", "top: 2.2")), tmp_path, "taller.yaml")
    _, static = checked(cell)
    (r,) = closed_gaps(cell, static)
    fences = yaml.safe_load(r.text)["fences"]
    assert len(fences) == len(cell.spec.fences) and "joined" not in r.change
    assert fences[1]["points"] == [[1.5, 3.2], [1.5, -0.2]] and fences[2]["top"] == 2.2
