"""Can the simulated worker reach over a fence panel that ISO 13857 Table 2 fails? The answer ``check`` gives
beside such a row, so that a search that finds nothing there is explained (issue 34: check and search agree).

Table 2 speaks of any person. The simulated worker is one body with its own joints and limits, and a panel can
be too low for the standard and still too high for it. For every row band of Table 2 the zone's nearest part
lies ``behind`` the panel (``reach_over.band_rows``); the worker gets ``c`` beyond a top of that height at the
band's heights, from one of two sources:

- **search**: the articulated worker of a surveyed body size with the default trunk flexions: the deepest reach
  that ``benchmarks/iso13857.py``'s beam search finds over 8 actions (stored in ``reach_over_sim.json`` by
  ``scripts/build_reach_over_table.py``), the larger of the band's two rows, at the table's column at or below
  the panel's top (a lower top is reached over at least as far);
- **bound**: any other worker: ``human.reach_bound``'s reduced body with the worker's own trunk, arm, stances and
  flexions (a jointless arm bent over the edge: more than the worker can do), at ``BOUND_HEIGHTS`` heights of
  the band, plus ``BOUND_SLACK``.

The worker is said not to reach over the panel when in every band the zone lies further behind than ``c``; the
row's ``limit`` then says so, with the numbers and their source. Elsewhere the worker may get there, and a search
is expected to find it (``benchmarks/reach_over_grid.py`` measures whether it does). The check's verdict does not
change either way: the row fails for any person.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from cellstress.analysis.reach_over import HazardVolume, band_rows
from cellstress.human.reach_bound import Body2D, c_bound, worker_body
from cellstress.sim import layout as L

BOUND_HEIGHTS = 5  # heights per band at which the bound is evaluated (its ends included, every 50 mm or less)
BOUND_SLACK = 0.02  # m added to the bound for the heights between them
TABLE = "reach_over_sim.json"


@dataclass(frozen=True)
class SearchTable:
    """The stored c_sim [m] of one body: rows a, columns b [mm]."""

    a_mm: tuple[float, ...]
    b_mm: tuple[float, ...]
    c: np.ndarray

    def reach(self, lo: float, hi: float, top: float) -> float:
        col = int(np.searchsorted(self.b_mm, top * 1000.0 + 1e-6)) - 1
        if col < 0:
            return math.inf  # below the table's lowest top: nothing stored (no barrier below 1 m anyway)
        rows = [i for i, a in enumerate(self.a_mm) if max(lo, 0.0) * 1000.0 - 1e-6 <= a <= hi * 1000.0 + 1e-6]
        return float(self.c[rows, col].max()) if rows else math.inf


@lru_cache(maxsize=1)
def _stored() -> dict:
    return json.loads(resources.files("cellstress.analysis").joinpath(TABLE).read_text())


def search_table(body: str | None, forward_deg: float, lateral_deg: float) -> SearchTable | None:
    """The stored table for the articulated worker of body size ``body`` at these flexions, if there is one."""
    data = _stored()
    if body not in data["bodies"] or (forward_deg, lateral_deg) != (data["flexion_deg"], data["lateral_deg"]):
        return None
    return SearchTable(tuple(data["a_mm"]), tuple(data["b_mm"]), np.asarray(data["bodies"][body]) / 1000.0)


@lru_cache(maxsize=512)
def _bounded(body: Body2D, lo: float, hi: float, top: float) -> float:
    return max(c_bound(body, float(a), top)[0] for a in np.linspace(max(lo, 0.0), hi, BOUND_HEIGHTS)) + BOUND_SLACK


def worker_limit(spec_human, params, p0, p1, top: float, vol: HazardVolume, side: int) -> str:
    """'' when the simulated worker may reach the zone over the panel p0-p1 (top ``top``) in some band; else what
    it cannot do, with the numbers (see the module)."""
    articulated = params.body[L.B_MODEL] != 0.0
    table = search_table(spec_human.body, spec_human.max_forward_flexion_deg, spec_human.max_lateral_flexion_deg) \
        if articulated else None
    slack = float(params.body[L.B_R_HAND]) if articulated else 2.0 * float(params.scal[L.C_REACH_H])
    body = worker_body(params.body, params.act, slack)
    tightest = None
    for row in band_rows(p0, p1, top, vol, side):
        if not math.isfinite(row.behind):
            continue
        lo, hi = row.band
        if table is not None:
            c = table.reach(lo, hi, top)
        elif row.behind > body.trunk * math.sin(body.max_flexion) + body.arm + BOUND_SLACK:
            c = body.trunk * math.sin(body.max_flexion) + body.arm  # the hip at the face, trunk and arm level
        else:
            c = _bounded(body, lo, hi, top)
        if row.behind <= c:
            return ""
        if tightest is None or row.behind - c < tightest[0] - tightest[1]:
            tightest = (row.behind, c, lo, hi)
    if tightest is None:
        return ""
    behind, c, lo, hi = tightest
    who = (f"the articulated worker ({spec_human.body}) gets at most {c:.2f} m beyond a {top:.2f} m top at "
           f"{lo:.1f}-{hi:.1f} m (the deepest its beam search over 8 actions finds: {TABLE})" if table is not None
           else f"it gets at most {c:.2f} m beyond a {top:.2f} m top at {lo:.1f}-{hi:.1f} m "
           f"(a bound on its body: jointless arm, trunk tilted {math.degrees(body.max_flexion):.0f} deg)")
    return (f"the simulated worker cannot reach over the panel: {who}, where the zone lies {behind:.2f} m behind; "
            "at the other heights the zone lies further beyond its reach")
