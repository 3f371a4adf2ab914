"""Getting round a device in the static check (ISO 13855:2010): reaching over a light curtain (C_RO, Table 1),
crawling under or stepping over it, a scanner's mounting height against its resolution, a mat's depth. Each rule
at its boundary, the expected numbers worked out here from the standard's formulas (docs/cells.md, "Ways in")."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from pydantic import ValidationError

from cellstress.analysis import espe_rules as E
from cellstress.analysis import iso13855 as iso
from cellstress.analysis import reach_over as R
from cellstress.cell.load import builtin_text, load_cell
from cellstress.core import iso13855 as I
from cellstress.devices.laser_scanner import LaserScanner
from cellstress.devices.light_curtain import LightCurtain
from cellstress.devices.safety_mat import SafetyMat


def _balls(*xyzr) -> R.HazardVolume:
    a = np.asarray(xyzr, dtype=float).reshape(-1, 4)
    return R.HazardVolume(a[:, :3].copy(), a[:, 3].copy(), np.zeros(len(a)), np.zeros(len(a), dtype=np.int64),
                          ("part",))


def _curtain(top: float = 1.0, bottom: float = 0.2) -> LightCurtain:
    return LightCurtain(type="light-curtain", name="c", start=(-1.0, 0.0), end=(1.0, 0.0), top=top, bottom=bottom)


# ---- Table 1 --------------------------------------------------------------------------------------------------
def test_table_1_never_grows_with_the_upper_edge():
    # why reading the lower column between two is the greater safety
    for a in I.C_RO_A_MM:
        row = I.C_RO_ROWS[a]
        assert all(x >= y for x, y in zip(row, row[1:], strict=False)), a


@pytest.mark.parametrize("a, b, c", [
    (1300.0, 1000.0, 1200.0),  # rows 1200 (1200) and 1400 (1200), column 1000
    (1100.0, 1000.0, 1200.0),  # rows 1000 (1150) and 1200 (1200): the larger
    (1500.0, 1800.0, 450.0),  # rows 1400 (0) and 1600 (450) at b = 1800
    (1500.0, 1700.0, 650.0),  # b = 1700 reads column 1600: rows 1400 (650), 1600 (650)
    (1400.0, 1800.0, 0.0),  # on a row: that row
    (2650.0, 900.0, 0.0),  # above the top row: out of reach
    (-100.0, 900.0, 750.0),  # below the floor: the lowest band, rows 0 (0) and 200 (750)
])
def test_c_ro_lookup(a, b, c):
    assert I.c_ro(a, b) == c


def test_no_column_below_900():
    assert math.isinf(I.c_ro(1000.0, 899.0)) and I.c_ro_column(899.0) is None


# ---- reaching over a curtain -----------------------------------------------------------------------------------
@pytest.mark.parametrize("y, ok", [(1.525, True), (1.515, False)])
def test_reach_over_at_its_boundary(y, ok):
    # hazard at 1.3 m, curtain top 1.0 m: C_RO = 1200 mm (rows 1200 and 1400 of column 1000); T = 0.2 s:
    # S_RO = 1600 * 0.2 + 1200 = 1520 mm. A ball of radius 1 mm at y: its near side is y - 0.001 from the line.
    r = E.curtain_reach_over(_curtain(1.0), _balls((0.0, y, 1.3, 0.001)), 0.2, 1.17)
    assert r.c_ro == 1200.0 and r.required == pytest.approx(1.52)
    assert r.behind == pytest.approx(y - 0.001)
    assert r.ok is ok
    assert E.failure_name(r) == ([] if ok else ["c-reach-over"])
    assert ("FAIL" in r.line()) is not ok and "1600*0.20 + 1200 = 1520 mm" in r.line()


def test_reach_over_takes_the_band_with_the_least_margin():
    # T = 0.25 s, K T = 400 mm, top 1.0 m. A low part at 0.5 m (rows 400 (700) and 600 (950) -> 950 mm):
    # S_RO = 1350 mm, 1299 mm away: margin -51 mm. A high part at 2.45 m (rows 2400 (550), 2500 (400) -> 550 mm):
    # S_RO = 950 mm, 949 mm away: margin -1 mm. The low one decides.
    vol = _balls((0.0, 1.30, 0.5, 0.001), (0.0, 0.95, 2.45, 0.001))
    r = E.curtain_reach_over(_curtain(1.0), vol, 0.25, 1.25)
    assert r.band == (0.4, 0.6) and r.c_ro == 950.0
    assert r.required == pytest.approx(1.35) and r.behind == pytest.approx(1.299)
    far = E.curtain_reach_over(_curtain(1.0), _balls((0.0, 2.0, 0.5, 0.001), (0.0, 0.95, 2.45, 0.001)), 0.25, 1.25)
    assert far.band == (2.4, 2.5) and far.c_ro == 550.0 and not far.ok  # now the high one: 949 < 950 mm


def test_a_low_top_is_no_curtain_to_reach_over():
    r = E.curtain_reach_over(_curtain(0.85), _balls((0.0, 5.0, 1.0, 0.01)), 0.2, 1.17)
    assert not r.ok and math.isinf(r.c_ro) and "no distance is enough" in r.line()


def _variant(tmp_path, name, edit) -> iso.StaticCheck:
    data = yaml.safe_load(builtin_text("baseline"))
    data["name"] = name
    edit(data)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return iso.check_cell(load_cell(str(path)))


def _bay(data) -> dict:
    return next(d for d in data["devices"] if d["type"] == "light-curtain")


def test_issue_34_baseline_with_a_1_m_curtain_fails(tmp_path):
    # T = 0.05 + 0.15 s; the zone reaches from 1.0 m up near the curtain: C_RO = 1200 mm at b = 1000 mm,
    # S_RO = 320 + 1200 = 1520 mm against the 1.367 m the curtain keeps (its S_RT is 1170 mm)
    low = _variant(tmp_path, "low-curtain", lambda d: _bay(d).update(top=1.0))
    r = next(a for a in low.access if isinstance(a, E.CurtainReachOver))
    assert r.required == pytest.approx(1.52) and r.behind < 1.52 and not r.ok
    assert "bay-curtain-reach-over" in low.failures()
    base = iso.check_cell(load_cell("baseline"))
    assert base.failures() == []
    b = next(a for a in base.access if isinstance(a, E.CurtainReachOver))
    assert b.ok and b.required <= b.through  # at 1.8 m, reaching over asks less than reaching through


# ---- crawling under, stepping over -------------------------------------------------------------------------
@pytest.mark.parametrize("bottom, top, names", [
    (0.30, 0.90, []),  # ISO 13855 6.2: lowest beam <= 300 mm, highest >= 900 mm
    (0.31, 0.90, ["c-crawl-under"]),
    (0.30, 0.89, ["c-step-over"]),
])
def test_beam_heights(bottom, top, names):
    b = E.device_rules(_Spec(_curtain(top, bottom)))[0]
    assert E.failure_name(b) == names
    assert ("cannot crawl" in b.line()) is bool(names)


@pytest.mark.parametrize("height, d, names", [
    (0.30, 70.0, []),  # 15 (70 - 50) = 300 mm
    (0.29, 70.0, ["s-mounting"]),
    (0.00, 50.0, []),  # d <= 50 mm: any height from the floor
    (0.30, 71.0, ["s-mounting"]),  # 15 * 21 = 315 mm
    (0.31, 50.0, ["s-crawl-under"]),  # above 300 mm: crawling under
])
def test_scanner_mounting(height, d, names):
    s = LaserScanner(type="laser-scanner", name="s", polygon=[(0, 0), (1, 0), (1, 1)], height=height,
                     resolution_mm=d)
    m = E.device_rules(_Spec(s))[0]
    assert m.min_height_mm == pytest.approx(max(0.0, 15.0 * (d - 50.0)))
    assert m.c_mm == pytest.approx(max(850.0, 1200.0 - 0.4 * height * 1000.0))
    assert E.failure_name(m) == names


def test_scanner_resolution_is_validated():
    for bad in (float("nan"), float("inf"), -1.0, 0.0, 1e6):
        with pytest.raises(ValidationError, match="resolution_mm"):
            LaserScanner(type="laser-scanner", name="s", polygon=[(0, 0), (1, 0), (1, 1)], resolution_mm=bad)
    assert LaserScanner(type="laser-scanner", name="s", polygon=[(0, 0), (1, 0), (1, 1)]).resolution_mm == 70.0


# ---- mats -------------------------------------------------------------------------------------------------------
class _Floor:
    xmin, xmax, ymin, ymax = -10.0, 10.0, -10.0, 10.0


class _Spec:
    """As much of a cell as ``device_rules`` reads: devices, no fences, no obstacles, a large floor."""

    def __init__(self, *devices, fences=(), model="paper"):
        self.devices, self.fences, self.floor = devices, fences, _Floor()
        self.human = type("_Human", (), {"model": model})()

    def solid_obstacles(self):
        return ()


@pytest.mark.parametrize("depth, ok", [(0.75, True), (0.74, False)])
def test_mat_depth(depth, ok):
    mat = SafetyMat(type="safety-mat", name="m", polygon=[(0, 0), (2, 0), (2, depth), (0, depth)])
    m = E.device_rules(_Spec(mat))[0]
    assert m.depth == pytest.approx(depth) and m.ok is ok
    assert E.failure_name(m) == ([] if ok else ["m-depth"])


def test_a_mat_against_a_wall_cannot_be_stepped_across():
    class Fence:
        points, bottom = ((-1.0, 0.5), (3.0, 0.5)), 0.0

    mat = SafetyMat(type="safety-mat", name="m", polygon=[(0, 0), (2, 0), (2, 0.5), (0, 0.5)])
    m = E.device_rules(_Spec(mat, fences=(Fence,)))[0]
    # from the open short sides across is 2 m; from the long open side the crossing ends at the fence
    assert m.depth == pytest.approx(2.0) and m.ok


def test_the_crawl_under_note_names_only_what_the_simulated_worker_cannot_do():
    """A curtain whose lowest beam is above 300 mm FAILs for every worker; the paper's worker cannot crawl under it
    (the row says a search will not find that way), the articulated one can (no note: it lies 0.30 m high)."""
    paper = E.device_rules(_Spec(_curtain(1.8, 0.4)))[0]
    crawler = E.device_rules(_Spec(_curtain(1.8, 0.4), model="articulated"))[0]
    assert not paper.ok and not crawler.ok
    assert E.CANNOT_CRAWL in paper.line() and "search" not in crawler.line()
    stepping = E.device_rules(_Spec(_curtain(0.8, 0.2), model="articulated"))[0]
    assert E.CANNOT_STEP in stepping.line()
