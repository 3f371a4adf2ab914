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
