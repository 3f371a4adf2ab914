"""ISO 13857:2019 tables as data: their shape, the greater-safety reading between entries, the rules around the
tables and the opening lookups at every range edge."""

from __future__ import annotations

import math

import pytest

from cellstress.core import iso13857 as iso
from cellstress.core.iso13857 import (
    ARM,
    FINGER,
    FINGERTIP,
    HAND,
    TABLE_1,
    TABLE_2,
    opening_body_part,
    opening_distance,
    reach_over_distance,
    reach_over_steps,
    whole_body_access,
)

TABLES = (TABLE_2, TABLE_1)


@pytest.mark.parametrize("t", TABLES, ids=lambda t: t.risk)
def test_the_grids_are_rectangular_ascending_and_non_negative(t):
    assert list(t.a_mm) == sorted(set(t.a_mm)) and list(t.b_mm) == sorted(set(t.b_mm))
    assert len(t.c_mm) == len(t.a_mm) and all(len(row) == len(t.b_mm) for row in t.c_mm)
    assert all(c >= 0 for row in t.c_mm for c in row)
    assert t.checked and all(a in t.a_mm and b in t.b_mm for a, b in t.checked)


def test_table_2_spans_the_standards_grid():
    assert TABLE_2.a_mm[0] == 0 and TABLE_2.a_mm[-1] == 2700
    assert TABLE_2.b_mm == (1000, 1200, 1400, 1600, 1800, 2000, 2200, 2400, 2500, 2700)
    assert reach_over_steps() is TABLE_2 and reach_over_steps(high_risk=False) is TABLE_1


@pytest.mark.parametrize("t", TABLES, ids=lambda t: t.risk)
def test_c_never_grows_with_the_structures_height(t):
    """Every row is non-increasing along b (a higher structure never needs more distance). Along a the tables
    are not monotone: c peaks at middle hazard heights (Table 2, b = 1000: 1100 at a = 0, 1500 at 800-1800,
    900 at 2600), so no monotonicity in a is asserted."""
    for row in t.c_mm:
        assert all(x >= y for x, y in zip(row, row[1:], strict=False))
    col = [row[0] for row in TABLE_2.c_mm]
    assert max(col) > col[0] and max(col) > col[-2]


@pytest.mark.parametrize("t", TABLES, ids=lambda t: t.risk)
def test_the_top_row_is_out_of_reach(t):
    """4.2.1: at 2700 mm (high risk) or 2500 mm (low risk) a hazard cannot be reached upwards."""
    top = iso.REACH_UP_HIGH_RISK_MM if t.risk == "high" else iso.REACH_UP_LOW_RISK_MM
    assert t.a_mm[-1] == top and set(t.c_mm[-1]) == {0}
    for b in (1000, 1350, 2000, 3000):
        assert reach_over_distance(top, b, high_risk=t.risk == "high") == 0.0
        assert reach_over_distance(top + 500, b, high_risk=t.risk == "high") == 0.0


def test_cells_two_sources_agree_on():
    # Birn's b = 2000 column and b = 1800 cells; the JIS B 9718 exam table's a = 2700 row
    assert [TABLE_2.c(a, 2000) for a in (1400, 1600, 1800, 2000, 2200, 2400, 2600, 2700)] == [
        0, 500, 600, 600, 600, 600, 500, 0]
    assert TABLE_2.c(1400, 1800) == 800 and TABLE_2.c(1000, 1800) == 0
    # Table 1, rows the Austrian AAV table prints too
    assert [TABLE_1.c(2000, b) for b in (1000, 1200, 1400, 1600, 1800, 2000, 2200)] == [
        1100, 900, 700, 600, 500, 350, 0]
    assert [TABLE_1.c(a, 1000) for a in (800, 1000, 1200, 1400, 1600, 1800, 2000, 2200, 2400)] == [
        1300, 1400, 1400, 1300, 1300, 1100, 1100, 600, 100]
    with pytest.raises(ValueError, match="not a cell"):
        TABLE_2.c(1300, 2000)


@pytest.mark.parametrize("t", TABLES, ids=lambda t: t.risk)
def test_grid_points_give_the_tables_value(t):
    for i, a in enumerate(t.a_mm):
        for j, b in enumerate(t.b_mm):
            assert reach_over_distance(a, b, high_risk=t.risk == "high") == t.c_mm[i][j]


@pytest.mark.parametrize("t", TABLES, ids=lambda t: t.risk)
def test_between_grid_points_the_safer_value_is_read(t):
    """No interpolation: between entries the largest c of the neighbouring cells (the lower structure's column,
    and of the two rows the one needing more distance)."""
    high = t.risk == "high"
    for i in range(len(t.a_mm) - 1):
        for j in range(len(t.b_mm) - 1):
            a = (t.a_mm[i] + t.a_mm[i + 1]) / 2
            b = (t.b_mm[j] + t.b_mm[j + 1]) / 2
            c = reach_over_distance(a, b, high_risk=high)
            assert c == max(t.c_mm[i][j], t.c_mm[i + 1][j], t.c_mm[i][j + 1], t.c_mm[i + 1][j + 1])
            assert c == max(t.c_mm[i][j], t.c_mm[i + 1][j])  # the lower column decides (rows are monotone)
            assert c >= reach_over_distance(t.a_mm[i], t.b_mm[j + 1], high_risk=high)


def test_worked_examples():
    # a hazard at 2300 mm over a 1300 mm structure: rows 2200 / 2400, column 1200 -> 1200 mm
    assert reach_over_distance(2300, 1300) == 1200
    # just above a row the next row up can need more: a = 1450 over 2000 mm reads row 1600 (500), not 1400 (0)
    assert reach_over_distance(1400, 2000) == 0 and reach_over_distance(1450, 2000) == 500
    # a structure taller than the last column counts as the last column
    assert reach_over_distance(2600, 3000) == 0
    assert reach_over_distance(2000, 1500, high_risk=False) == 700


def test_a_structure_below_1000_mm_is_no_barrier():
    for b in (0, 500, 999.9):
        assert reach_over_distance(1200, b) == math.inf
        assert reach_over_distance(1200, b, high_risk=False) == math.inf
    assert math.isfinite(reach_over_distance(1200, 1000))
    assert iso.MIN_HIGH_RISK_STRUCTURE_MM == 1400


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf, -math.inf])
def test_bad_heights_raise(bad):
    with pytest.raises(ValueError, match="finite"):
        reach_over_distance(bad, 1400)
    with pytest.raises(ValueError, match="finite"):
        reach_over_distance(1400, bad)


# (e at the upper edge of a row, slot, square, round, body part for slot / square / round)
EDGES = [
    (4, 2, 2, 2, (FINGERTIP, FINGERTIP, FINGERTIP)),
    (6, 10, 5, 5, (FINGERTIP, FINGERTIP, FINGERTIP)),
    (8, 20, 15, 5, (FINGER, FINGER, FINGER)),
    (10, 80, 25, 20, (FINGER, FINGER, FINGER)),
    (12, 100, 80, 80, (HAND, HAND, HAND)),
    (20, 120, 120, 120, (HAND, HAND, HAND)),
    (30, 850, 120, 120, (ARM, HAND, HAND)),
    (40, 850, 200, 120, (ARM, HAND, HAND)),
    (120, 850, 850, 850, (ARM, ARM, ARM)),
]


@pytest.mark.parametrize(("e", "slot", "square", "round_", "parts"), EDGES)
def test_openings_at_the_range_edges(e, slot, square, round_, parts):
    """A row holds e up to and including its edge; just above the edge the next row applies."""
    assert [opening_distance(e, s) for s in iso.SHAPES] == [slot, square, round_]
    assert tuple(opening_body_part(e, s) for s in iso.SHAPES) == parts
    if e < 120:
        nxt = next(r for r in EDGES if r[0] > e)
        assert [opening_distance(e + 0.01, s) for s in iso.SHAPES] == list(nxt[1:4])


def test_distances_never_shrink_as_the_opening_widens():
    for s in iso.SHAPES:
        d = [opening_distance(e / 10, s) for e in range(1, 1201)]
        assert all(x <= y for x, y in zip(d, d[1:], strict=False))
        assert d[-1] == iso.ARM_REACH_MM


def test_above_120_mm_table_4_does_not_apply():
    """4.2.4.1: a larger opening is treated with the reach-over distances; the lookup says so."""
    for s in iso.SHAPES:
        with pytest.raises(ValueError, match="reach-over"):
            opening_distance(120.01, s)
        with pytest.raises(ValueError, match="reach-over"):
            opening_body_part(121, s)


def test_whole_body_access():
    assert not whole_body_access(180, "slot") and whole_body_access(180.5, "slot")
    for s in ("square", "round"):
        assert not whole_body_access(240, s) and whole_body_access(241, s)


def test_a_short_slot_stops_at_the_thumb():
    assert opening_distance(25, "slot") == 850
    assert opening_distance(25, "slot", slot_length_mm=65) == 200
    assert opening_distance(25, "slot", slot_length_mm=66) == 850
    assert opening_distance(35, "slot", slot_length_mm=60) == 850  # the footnote is on the 20-30 mm row only
    assert opening_distance(15, "slot", slot_length_mm=60) == 120


@pytest.mark.parametrize(("e", "shape", "kw"), [
    (0, "slot", {}), (-3, "round", {}), (math.nan, "square", {}), (math.inf, "slot", {}),
    (10, "hexagon", {}), (10, "Slot", {}), (25, "square", {"slot_length_mm": 60}),
    (25, "slot", {"slot_length_mm": 10}), (25, "slot", {"slot_length_mm": math.nan})])
def test_bad_opening_arguments_raise(e, shape, kw):
    with pytest.raises(ValueError):
        opening_distance(e, shape, **kw)


def test_bad_whole_body_arguments_raise():
    with pytest.raises(ValueError):
        whole_body_access(-1, "slot")
    with pytest.raises(ValueError):
        whole_body_access(200, "oval")


def _doc_tables() -> list[list[list[str]]]:
    """The markdown tables of docs/worker.md, each a list of rows of cell texts (header and rule dropped)."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "worker.md").read_text(encoding="utf-8")
    tables, cur = [], []
    for line in [*text.splitlines(), ""]:
        if line.startswith("|"):
            cur.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif cur:
            tables.append(cur[2:])
            cur = []
    return tables


def test_docs_print_the_modules_tables():
    """docs/worker.md shows Tables 2, 1 and 4 exactly as the module holds them, bold exactly on checked cells."""
    docs = {len(t[0]): t for t in _doc_tables() if t and t[0][0] in ("2700", "2500")}
    for t in (TABLE_2, TABLE_1):
        rows = docs[len(t.b_mm) + 1]
        assert [float(r[0]) for r in rows] == list(reversed(t.a_mm))
        for r in rows:
            a = float(r[0])
            assert [float(x.strip("*")) for x in r[1:]] == list(t.c_mm[t.a_mm.index(a)])
            assert [x.startswith("**") for x in r[1:]] == [(a, b) in t.checked for b in t.b_mm], (t.table, a)
    t4 = next(t for t in _doc_tables() if t and t[0][0].startswith("0 < e"))
    assert [(float(r[1]), float(r[2]), float(r[3]), r[4]) for r in t4] == [
        (row.slot_mm, row.square_mm, row.round_mm, row.body_part) for row in iso.TABLE_4]
