"""ISO 13855:2010 constants shared by the device kinds (their minimum distances) and the static check.

S = K T + C: K the approach speed [mm/s], T the overall stopping time [s] (device response + robot stopping
time), C the intrusion allowance [mm]. The values and the sections they come from are in docs/cells.md.
"""

from __future__ import annotations

K_WALK = 1600.0  # mm/s, approach speed of the body (walking)
K_HAND = 2000.0  # mm/s, approach speed of hand and arm (vertical fields with d <= 40 mm, while S <= 500 mm)
MIN_C_BODY = 850.0  # mm, intrusion allowance for devices that do not detect a hand (reach of the arm)


def mm(x: float) -> str:
    """A distance in millimetres as the formulas print it: whole numbers without decimals."""
    return f"{x:.0f}" if abs(x - round(x)) < 1e-6 else f"{x:.1f}"

C_MAT = 1200.0  # mm, intrusion allowance for pressure-sensitive mats (ISO 13855:2010, pressure-sensitive mats)

# ---- getting round an electro-sensitive device (ISO 13855:2010; docs/cells.md, "Ways in") ------------------
CRAWL_UNDER_MAX_MM = 300.0  # lowest beam of a body-detecting curtain, a scan plane: higher lets a person crawl under
CRAWL_UNDER_CHILDREN_MM = 200.0  # the same where children may be present (not applied: cells are for adults)
STEP_OVER_MIN_MM = 900.0  # uppermost beam of a body-detecting curtain: lower lets a person step over it
SCAN_PLANE_MAX_MM = 1000.0  # highest scan plane of a horizontal field
NO_MIN_HEIGHT_UP_TO_D_MM = 50.0  # H >= 15 (d - 50): a resolution up to 50 mm may scan at the floor
MAT_MIN_DEPTH_MM = 750.0  # a pressure-sensitive mat this deep cannot be stepped across without actuating it
K_REACH_OVER = K_WALK  # mm/s in S_RO = K T + C_RO (as the curtain's through-distance with body sensing)


def horizontal_c_mm(height_mm: float) -> float:
    """ISO 13855:2010, detection zone parallel to the approach: C = 1200 - 0.4 H [mm], not below 850 mm."""
    return max(MIN_C_BODY, 1200.0 - 0.4 * height_mm)


def min_scan_height_mm(d_mm: float) -> float:
    """ISO 13855:2010, horizontal detection zone: the lowest scan plane for detection capability d, 15 (d - 50) mm,
    never below the floor."""
    return max(0.0, 15.0 * (d_mm - NO_MIN_HEIGHT_UP_TO_D_MM))


# ISO 13855:2010 Table 1: the additional distance C_RO [mm] for reaching over the vertical detection zone of an
# electro-sensitive device, by the height a of the hazard zone (rows) and the height b of the detection zone's
# upper edge (columns). Where the values come from, and how far they are confirmed: docs/cells.md.
C_RO_B_MM = (900.0, 1000.0, 1100.0, 1200.0, 1300.0, 1400.0, 1600.0, 1800.0, 2000.0, 2200.0, 2400.0, 2600.0)
C_RO_ROWS = {
    2600.0: (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    2500.0: (400, 400, 350, 300, 300, 300, 300, 300, 250, 150, 100, 0),
    2400.0: (550, 550, 550, 500, 450, 450, 400, 400, 300, 250, 100, 0),
    2200.0: (800, 750, 750, 700, 650, 650, 600, 550, 400, 250, 0, 0),
    2000.0: (950, 950, 850, 850, 800, 750, 700, 550, 400, 0, 0, 0),
    1800.0: (1100, 1100, 950, 950, 850, 800, 650, 550, 0, 0, 0, 0),
    1600.0: (1150, 1150, 1100, 1000, 900, 850, 650, 450, 0, 0, 0, 0),
    1400.0: (1200, 1200, 1100, 1000, 900, 850, 650, 0, 0, 0, 0, 0),
    1200.0: (1200, 1200, 1100, 1000, 850, 800, 0, 0, 0, 0, 0, 0),
    1000.0: (1200, 1150, 1050, 950, 750, 700, 0, 0, 0, 0, 0, 0),
    800.0: (1150, 1050, 950, 800, 500, 450, 0, 0, 0, 0, 0, 0),
    600.0: (1050, 950, 750, 550, 0, 0, 0, 0, 0, 0, 0, 0),
    400.0: (900, 700, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    200.0: (750, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    0.0: (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
}
C_RO_A_MM = tuple(sorted(C_RO_ROWS))


def c_ro_column(b_mm: float) -> tuple[float, ...] | None:
    """Table 1's column for an upper edge at b [mm], per row of ``C_RO_A_MM``: between columns the lower one (its
    distances are never smaller: the greater safety); None below the first column (900 mm: no value, and a
    body-detecting curtain that low can be stepped over)."""
    cols = [j for j, b in enumerate(C_RO_B_MM) if b <= b_mm + 1e-9]
    if not cols:
        return None
    return tuple(float(C_RO_ROWS[a][cols[-1]]) for a in C_RO_A_MM)


def c_ro(a_mm: float, b_mm: float) -> float:
    """C_RO [mm] for a hazard at height a and an upper edge at b: between rows the larger of the two neighbours
    (the greater safety), no distance at 2600 mm and above; inf for b below 900 mm (no value)."""
    col = c_ro_column(b_mm)
    if col is None:
        return float("inf")
    if a_mm >= C_RO_A_MM[-1]:
        return 0.0
    if a_mm in C_RO_A_MM:
        return col[C_RO_A_MM.index(a_mm)]
    i = max(sum(a <= a_mm for a in C_RO_A_MM) - 1, 0)  # the row below a (below the floor: the first band)
    return max(col[i], col[i + 1])
