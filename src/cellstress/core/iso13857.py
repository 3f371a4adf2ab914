"""ISO 13857:2019 safety distances as data: reaching over a protective structure (Table 2, high risk; Table 1,
low risk) and reaching through regular openings (Table 4, persons of 14 years and older), with the rules the
standard states around its tables.

Units are millimetres, as in the standard. Where each number was found, and which numbers two sources agree on,
is written in docs/worker.md ("Body sizes, postures and the standard's tables"); ``ReachOverTable.checked``
lists the cells of a reach-over table that two independent sources confirm.

Rules encoded here (clause numbers of ISO 13857:2019):

- 4.2.1, reaching upwards: a hazard at least 2700 mm above the reference plane (high risk; 2500 mm at low risk)
  cannot be reached; the top row of each reach-over table is zero.
- 4.2.2, reaching over: a structure lower than 1000 mm does not restrict the body enough to count as one
  (``reach_over_distance`` returns infinity: no horizontal distance is given); at high risk a structure lower
  than 1400 mm needs additional protective measures (4.4 and the note to Table 2).
- Between table entries the standard does not interpolate: the value that gives the greater safety is used.
  Reach-over distances never grow with the structure's height b, so this is the lower column, and of the two
  neighbouring rows the one with the larger distance.
- 4.2.4.1, regular openings: e is the narrow width of a slot, the side of a square, the diameter of a round
  hole. Table 4 ends at 120 mm; a larger opening is treated with the reach-over distances. A slot not longer
  than 65 mm stops at the thumb, which lowers the distance to 200 mm (the table's footnote on the 20 < e <= 30
  slot). Slots wider than 180 mm and square or round openings wider than 240 mm let the whole body through (4.4).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

REACH_UP_HIGH_RISK_MM = 2700.0  # 4.2.1: at or above this a hazard is out of reach (high risk)
REACH_UP_LOW_RISK_MM = 2500.0  # 4.2.1: the same at low risk
NO_BARRIER_BELOW_MM = 1000.0  # 4.2.2: lower structures are no barrier to reaching over
MIN_HIGH_RISK_STRUCTURE_MM = 1400.0  # 4.4 / Table 2 note: lower only with additional protective measures
MAX_REGULAR_OPENING_MM = 120.0  # Table 4's last row; larger openings: reach-over distances (4.2.4.1)
THUMB_STOP_SLOT_LENGTH_MM = 65.0  # Table 4 footnote: a slot this short stops at the thumb ...
THUMB_STOP_DISTANCE_MM = 200.0  # ... and then needs only this distance
WHOLE_BODY_SLOT_MM = 180.0  # 4.4: a wider slot admits the whole body
WHOLE_BODY_SQUARE_ROUND_MM = 240.0  # 4.4: a wider square or round opening admits the whole body
SHAPES: tuple[str, ...] = ("slot", "square", "round")


@dataclass(frozen=True)
class ReachOverTable:
    """One reach-over table of ISO 13857:2019 (4.2.2): the horizontal distance c a hazard zone at height a must
    keep from a protective structure of height b."""

    table: str
    """Which table of the standard, e.g. ``"ISO 13857:2019, Table 2"``."""
    risk: str
    """``"high"`` or ``"low"``: the risk the table is for (chosen by a risk assessment, ISO 12100)."""
    a_mm: tuple[float, ...]
    """Rows: heights of the hazard zone above the reference plane [mm], ascending."""
    b_mm: tuple[float, ...]
    """Columns: heights of the protective structure [mm], ascending."""
    c_mm: tuple[tuple[float, ...], ...]
    """``c_mm[i][j]``: the horizontal distance [mm] for ``a_mm[i]`` and ``b_mm[j]``."""
    checked: frozenset[tuple[float, float]]
    """Cells ``(a, b)`` that two independent sources give alike (docs/worker.md); the others rest on one."""

    def c(self, a_mm: float, b_mm: float) -> float:
        """The table's own entry at a row and a column (ValueError if either is not one of the table's)."""
        if a_mm not in self.a_mm or b_mm not in self.b_mm:
            raise ValueError(f"({a_mm:g}, {b_mm:g}) mm is not a cell of {self.table}")
        return self.c_mm[self.a_mm.index(a_mm)][self.b_mm.index(b_mm)]


def _table(table: str, risk: str, b: tuple[float, ...], rows: dict[float, tuple[float, ...]],
           checked: set[tuple[float, float]]) -> ReachOverTable:
    a = tuple(sorted(rows))
    return ReachOverTable(table, risk, a, b, tuple(rows[x] for x in a), frozenset(checked))


# Table 2, high risk. Rows as the standard prints them, from the top (a = 2700) down.
_T2_B = (1000.0, 1200.0, 1400.0, 1600.0, 1800.0, 2000.0, 2200.0, 2400.0, 2500.0, 2700.0)
_T2 = {
    2700.0: (0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    2600.0: (900, 800, 700, 600, 600, 500, 400, 300, 100, 0),
    2400.0: (1100, 1000, 900, 800, 700, 600, 400, 300, 100, 0),
    2200.0: (1300, 1200, 1000, 900, 800, 600, 400, 300, 0, 0),
    2000.0: (1400, 1300, 1100, 900, 800, 600, 400, 0, 0, 0),
    1800.0: (1500, 1400, 1100, 900, 800, 600, 0, 0, 0, 0),
    1600.0: (1500, 1400, 1100, 900, 800, 500, 0, 0, 0, 0),
    1400.0: (1500, 1400, 1100, 900, 800, 0, 0, 0, 0, 0),
    1200.0: (1500, 1400, 1100, 900, 700, 0, 0, 0, 0, 0),
    1000.0: (1500, 1400, 1000, 800, 0, 0, 0, 0, 0, 0),
    800.0: (1500, 1300, 900, 600, 0, 0, 0, 0, 0, 0),
    600.0: (1400, 1300, 800, 0, 0, 0, 0, 0, 0, 0),
    400.0: (1400, 1200, 400, 0, 0, 0, 0, 0, 0, 0),
    200.0: (1200, 900, 0, 0, 0, 0, 0, 0, 0, 0),
    0.0: (1100, 500, 0, 0, 0, 0, 0, 0, 0, 0),
}
# Cells a second source gives alike, seen independently of this grid: the whole b = 2000 column and two
# b = 1800 cells (Birn), the a = 2700 row (the JIS B 9718 exam table). docs/worker.md has the rest.
_T2_CHECKED = ({(a, 2000.0) for a in _T2} | {(1400.0, 1800.0), (1000.0, 1800.0)} | {(2700.0, b) for b in _T2_B})

# Table 1, low risk.
_T1_B = (1000.0, 1200.0, 1400.0, 1600.0, 1800.0, 2000.0, 2200.0, 2400.0, 2500.0)
_T1 = {
    2500.0: (0, 0, 0, 0, 0, 0, 0, 0, 0),
    2400.0: (100, 100, 100, 100, 100, 100, 100, 100, 0),
    2200.0: (600, 600, 500, 500, 400, 350, 250, 0, 0),
    2000.0: (1100, 900, 700, 600, 500, 350, 0, 0, 0),
    1800.0: (1100, 1000, 900, 900, 600, 0, 0, 0, 0),
    1600.0: (1300, 1000, 900, 900, 500, 0, 0, 0, 0),
    1400.0: (1300, 1000, 900, 800, 100, 0, 0, 0, 0),
    1200.0: (1400, 1000, 900, 500, 0, 0, 0, 0, 0),
    1000.0: (1400, 1000, 900, 300, 0, 0, 0, 0, 0),
    800.0: (1300, 900, 600, 0, 0, 0, 0, 0, 0),
    600.0: (1200, 500, 0, 0, 0, 0, 0, 0, 0),
    400.0: (1200, 300, 0, 0, 0, 0, 0, 0, 0),
    200.0: (1100, 200, 0, 0, 0, 0, 0, 0, 0),
    0.0: (1100, 500, 0, 0, 0, 0, 0, 0, 0),
}
# Rows 800..2400 at b = 1000..2400: the reach-over table of Austria's AAV (Anhang 1) prints the same values.
_T1_CHECKED = {(a, b) for a in (800.0, 1000.0, 1200.0, 1400.0, 1600.0, 1800.0, 2000.0, 2200.0, 2400.0)
               for b in _T1_B[:-1]}

TABLE_2 = _table("ISO 13857:2019, Table 2", "high", _T2_B, _T2, _T2_CHECKED)
TABLE_1 = _table("ISO 13857:2019, Table 1", "low", _T1_B, _T1, _T1_CHECKED)


def _finite(name: str, x: float) -> float:
    x = float(x)
    if not math.isfinite(x) or x < 0.0:
        raise ValueError(f"{name} must be a finite height or width >= 0 mm, got {x!r}")
    return x


def _bracket(grid: tuple[float, ...], x: float) -> tuple[int, int]:
    """Indices of the grid values just below and just above x (the same index on a grid value; the last one
    above the grid)."""
    i = bisect.bisect_left(grid, x)
    if i == len(grid):
        return i - 1, i - 1
    if grid[i] == x or i == 0:
        return i, i
    return i - 1, i


def reach_over_steps(high_risk: bool = True) -> ReachOverTable:
    """The reach-over table (its a and b grids and c values), for benchmarks that build a cell per entry."""
    return TABLE_2 if high_risk else TABLE_1


def reach_over_distance(a_mm: float, b_mm: float, high_risk: bool = True) -> float:
    """The horizontal distance c [mm] ISO 13857 requires between a protective structure of height ``b_mm`` and a
    hazard zone at height ``a_mm`` (Table 2, or Table 1 with ``high_risk=False``).

    Between table entries the value giving the greater safety is used (the largest c of the neighbouring cells).
    A structure lower than 1000 mm is no barrier: infinity (no distance suffices). Above the tables' top row
    (2700 mm high risk, 2500 mm low risk) the hazard is out of reach: 0. ValueError for a negative or non-finite
    height.
    """
    a, b = _finite("a (hazard height)", a_mm), _finite("b (structure height)", b_mm)
    if b < NO_BARRIER_BELOW_MM:
        return math.inf
    t = reach_over_steps(high_risk)
    rows, cols = _bracket(t.a_mm, a), _bracket(t.b_mm, b)
    return float(max(t.c_mm[i][j] for i in set(rows) for j in set(cols)))


@dataclass(frozen=True)
class OpeningRow:
    """One row of ISO 13857:2019 Table 4 (reaching through regular openings, persons of 14 years and older)."""

    e_above_mm: float
    """The row holds openings wider than this [mm] ..."""
    e_max_mm: float
    """... up to and including this [mm]."""
    slot_mm: float
    """Safety distance sr [mm] behind a slot of this width."""
    square_mm: float
    """Safety distance sr [mm] behind a square opening of this side."""
    round_mm: float
    """Safety distance sr [mm] behind a round opening of this diameter."""
    body_part: str
    """The part of the body the row names (fingertip, finger up to the knuckle, hand up to the wrist, arm up to
    the armpit)."""

    def distance(self, shape: str) -> float:
        """The row's safety distance for one opening shape."""
        return {"slot": self.slot_mm, "square": self.square_mm, "round": self.round_mm}[_shape(shape)]


FINGERTIP, FINGER, HAND, ARM = ("fingertip", "finger up to the knuckle", "hand up to the wrist",
                                "arm up to the armpit")
TABLE_4: tuple[OpeningRow, ...] = (
    OpeningRow(0.0, 4.0, 2.0, 2.0, 2.0, FINGERTIP),
    OpeningRow(4.0, 6.0, 10.0, 5.0, 5.0, FINGERTIP),
    OpeningRow(6.0, 8.0, 20.0, 15.0, 5.0, FINGER),
    OpeningRow(8.0, 10.0, 80.0, 25.0, 20.0, FINGER),
    OpeningRow(10.0, 12.0, 100.0, 80.0, 80.0, HAND),
    OpeningRow(12.0, 20.0, 120.0, 120.0, 120.0, HAND),
    OpeningRow(20.0, 30.0, 850.0, 120.0, 120.0, HAND),
    OpeningRow(30.0, 40.0, 850.0, 200.0, 120.0, HAND),
    OpeningRow(40.0, 120.0, 850.0, 850.0, 850.0, ARM),
)
ARM_REACH_MM = 850.0  # Table 4: the reach of the arm up to the armpit through an opening it fits


def _shape(shape: str) -> str:
    if shape not in SHAPES:
        raise ValueError(f"opening shape must be one of {', '.join(SHAPES)}, got {shape!r}")
    return shape


def opening_row(e_mm: float) -> OpeningRow:
    """The Table 4 row of an opening of width e [mm] (0 < e <= 120). ValueError outside: e <= 0 is no opening;
    above 120 mm Table 4 does not apply and the reach-over distances do (4.2.4.1)."""
    e = float(e_mm)
    if not math.isfinite(e) or e <= 0.0:
        raise ValueError(f"an opening's width e must be a finite number > 0 mm, got {e_mm!r}")
    if e > MAX_REGULAR_OPENING_MM:
        raise ValueError(f"ISO 13857 Table 4 ends at e = {MAX_REGULAR_OPENING_MM:g} mm (got {e:g} mm): a larger "
                         "opening is treated with the reach-over distances (4.2.4.1), see reach_over_distance")
    return TABLE_4[bisect.bisect_left([r.e_max_mm for r in TABLE_4], e)]


def opening_distance(e_mm: float, shape: str, slot_length_mm: float | None = None) -> float:
    """The safety distance sr [mm] behind a regular opening (Table 4): ``shape`` is slot, square or round, e its
    narrow width, side or diameter. A slot no longer than 65 mm (``slot_length_mm``) stops at the thumb, so a
    slot of 20 < e <= 30 mm needs 200 mm instead of 850 mm. ValueError as ``opening_row``, for an unknown shape
    and for a slot length that is not a positive number."""
    row = opening_row(e_mm)
    sr = row.distance(shape)
    if slot_length_mm is not None:
        length = float(slot_length_mm)
        if shape != "slot" or not math.isfinite(length) or length < float(e_mm):
            raise ValueError(f"slot_length_mm applies to slots and must be at least the width, got {slot_length_mm!r}")
        if length <= THUMB_STOP_SLOT_LENGTH_MM and row.e_above_mm == 20.0:
            sr = THUMB_STOP_DISTANCE_MM
    return sr


def opening_body_part(e_mm: float, shape: str) -> str:
    """The part of the body that reaches through the opening. It is the row's part, except where the distance
    for this shape is the arm's reach (850 mm): a 20-40 mm slot lets the arm through up to the armpit."""
    row = opening_row(e_mm)
    return ARM if row.distance(shape) >= ARM_REACH_MM else row.body_part


def whole_body_access(e_mm: float, shape: str) -> bool:
    """True when the opening lets the whole body through (4.4): a slot wider than 180 mm, a square or round
    opening wider than 240 mm."""
    e = _finite("e (opening width)", e_mm)
    return e > (WHOLE_BODY_SLOT_MM if _shape(shape) == "slot" else WHOLE_BODY_SQUARE_ROUND_MM)
