"""ISO 13857 Table 2 in the static check: the row band arithmetic on hand-made hazard volumes, the panels a worker
stands at, and cells whose right wall is lowered, raised or moved back (docs/cells.md, reach over the fences)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from cellstress.analysis import iso13855 as iso
from cellstress.analysis import reach_over as R
from cellstress.cell.load import builtin_text, load_cell
from cellstress.core import iso13857 as T

PANEL = ((0.0, -1.0), (0.0, 1.0))  # along the y axis; +x is its right side (side -1), -x its left (side +1)


def _balls(*xzr) -> R.HazardVolume:
    """Balls at (x, 0, z) of radius r, one per triple."""
    a = np.asarray(xzr, dtype=float).reshape(-1, 3)
    c = np.stack([a[:, 0], np.zeros(len(a)), a[:, 1]], axis=1)
    return R.HazardVolume(c, a[:, 2].copy(), np.zeros(len(a)), np.zeros(len(a), dtype=np.int64), ("part",))


# ---- the table, band by band --------------------------------------------------------------------------------
def test_table_2_never_asks_less_than_table_1():
    assert R.TABLE_2_COVERS_TABLE_1  # why the check may take the high-risk table without a risk assessment


@pytest.mark.parametrize("z, top, need", [
    (1.5, 1.4, 1.1),  # between rows 1400 and 1600 at b = 1400: both 1100
    (1.5, 2.0, 0.5),  # rows 1400 (0) and 1600 (500) at b = 2000: the greater safety, 500
    (1.3, 2.0, 0.0),  # rows 1200 and 1400 at b = 2000: 0, a hazard right behind the top is out of reach
    (2.65, 1.0, 0.9),  # between 2600 (900) and 2700 (0): 900
    (0.7, 1.5, 0.9),  # b = 1500 reads the lower column, 1400: rows 600 (800) and 800 (900)
])
def test_required_distance_follows_the_lookup(z, top, need):
    assert T.reach_over_distance(z * 1000.0, top * 1000.0) / 1000.0 == pytest.approx(need)
    ro = R.reach_over(*PANEL, top, _balls((0.05, z, 0.001)))
    if need == 0.0:  # no band that asks a distance holds any of the zone
        assert ro.ok and math.isinf(ro.behind) and math.isnan(ro.hazard_height)
    else:
        assert ro.required == pytest.approx(need) and ro.hazard_height == pytest.approx(z)
        assert ro.behind == pytest.approx(0.049) and not ro.ok


def test_a_ball_counts_in_the_bands_it_reaches_into():
    # centre at 1.35 m, radius 0.1: its top 1.40..1.45 m lies in the 1400..1600 band, where b = 2000 asks 500 mm;
    # at the band's edge (5 cm above the centre) the ball's disc has radius sqrt(0.1^2 - 0.05^2)
    ro = R.reach_over(*PANEL, 2.0, _balls((0.3, 1.35, 0.1)))
    assert ro.required == pytest.approx(0.5) and ro.band == (1.4, 1.6)
    assert ro.behind == pytest.approx(0.3 - math.sqrt(0.1 ** 2 - 0.05 ** 2))
    assert ro.hazard_height == pytest.approx(1.4) and not ro.ok


def test_hostile_heights():
    """ISO 13857 4.2.1: at 2.7 m and above a hazard is out of reach; a structure of 2.7 m or more needs no
    distance at any height; below the floor the lowest row holds."""
    assert R.reach_over(*PANEL, 1.0, _balls((0.05, 2.8, 0.05))).ok  # 2.75..2.85 m: nothing within reach
    grazing = R.reach_over(*PANEL, 1.0, _balls((0.05, 2.72, 0.05)))  # dips to 2.67 m: row 2600, 900 mm
    assert grazing.required == pytest.approx(0.9) and not grazing.ok
    for top in (2.7, 2.8, 10.0):
        ro = R.reach_over(*PANEL, top, _balls((0.05, 1.5, 0.02), (0.01, 0.0, 0.01)))
        assert ro.ok and ro.required == 0.0
    under = R.reach_over(*PANEL, 1.0, _balls((0.5, -0.3, 0.05)))  # in a pit: the lowest band, rows 0 and 200
    assert under.required == pytest.approx(1.2) and under.hazard_height == 0.0 and not under.ok
    low = R.reach_over(*PANEL, 0.99, _balls((5.0, 1.0, 0.05)))  # no barrier: no distance is enough
    assert math.isinf(low.required) and not low.ok


def test_only_the_far_side_counts():
    vol = _balls((0.3, 1.0, 0.05), (-1.0, 1.0, 0.05))
    assert R.reach_over(*PANEL, 1.4, vol).behind == pytest.approx(0.25)  # both sides
    assert R.reach_over(*PANEL, 1.4, vol, side=+1).behind == pytest.approx(0.25)  # worker at -x: the ball at +x
    assert R.reach_over(*PANEL, 1.4, vol, side=-1).behind == pytest.approx(0.95)  # worker at +x: the one at -x


def test_panels_at_skips_joints():
    """At an L corner and a T-junction the worker stands at the panel that runs on, not the one that ends there;
    a free end counts."""
    panels = [((1.5, 3.0), (1.5, -1.6)), ((1.0, -0.4), (1.5, -0.4)), ((1.5, -1.6), (0.6, -1.6))]
    # outside the wall at the T (the wall only), at the corner (neither), below the back wall (its left side)
    xs, ys = np.array([1.7, 1.7, 1.3]), np.array([-0.4, -1.8, -1.8])
    assert R.panels_at(xs[:2], ys[:2], panels, 0.25) == [(0, 1)]
    assert R.panels_at(xs, ys, panels, 0.25) == [(0, 1), (2, 1)]
    assert R.panels_at(np.array([0.4]), np.array([-1.6]), panels, 0.25) == [(2, 0)]  # beyond the free end, in line


# ---- cells --------------------------------------------------------------------------------------------------
def _variant(tmp_path, name, edit) -> iso.StaticCheck:
    data = yaml.safe_load(builtin_text("baseline"))
    data["name"] = name
    edit(data)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return iso.check_cell(load_cell(str(path)))


def _right_wall(r: iso.StaticCheck) -> iso.PanelReach:
    return next(p for p in r.approach.panels_at if (p.panel.fence, p.panel.panel) == (2, 1))


def test_a_low_panel_close_to_the_robot_fails(tmp_path):
    """The baseline's right wall at 1.4 m: the wrist at the place point is 0.707 m behind it at 1.09 m, where
    Table 2 asks 1.1 m (rows 1000 and 1200 at b = 1400)."""
    r = _variant(tmp_path, "right-1400", lambda d: d["fences"][1].update(top=1.4))
    assert r.failures() == ["undetected-reach", "reach-over"]  # open, so the arm also reaches past it
    (bad,) = r.approach.reach_over_fails
    assert (bad.panel.fence, bad.panel.panel) == (2, 1) and not bad.panel.closed
    assert bad.reach.required == pytest.approx(1.1) and bad.reach.behind == pytest.approx(0.707, abs=1e-3)
    assert bad.reach.hazard_height == pytest.approx(1.09, abs=0.01) and bad.reach.band == (1.0, 1.2)
    row = next(ln for ln in r.lines() if ln.strip().startswith("fence 2 panel 1") and "c = " in ln)
    assert "top 1.40 m, hazard at 1.09 m, c = 0.707 m behind it; ISO 13857 Table 2 requires 1.100 m" in row
    assert "FAIL" in row and r.lines()[-1] == "result: FAIL (undetected-reach, reach-over)"
    assert not any("4.4 allows" in ln for ln in r.lines())  # 1.4 m is high enough for high risk (4.4)


@pytest.mark.parametrize("top, need, ok", [(1.6, 0.9, False), (1.8, 0.8, False), (2.0, 0.5, True)])
def test_raising_the_panel(tmp_path, top, need, ok):
    """Raised, the wall needs less: 0.9 m at 1.6 m, 0.8 m at 1.8 m (the forearm at 1.2 m is 0.760 m behind it),
    and at 2.0 m, the baseline's, 0.5 m from 1.4 m up: met. (The old rule, shoulder-to-top climb plus distance
    >= 0.85 m, passed the 1.8 m wall.)"""
    r = _variant(tmp_path, f"right-{top}", lambda d: d["fences"][1].update(top=top))
    right = _right_wall(r)
    assert right.reach.required == pytest.approx(need) and right.reach.ok is ok and right.panel.closed is ok
    assert ("reach-over" not in r.failures()) is ok and r.ok is ok


def test_moving_the_panel_back_meets_table_2(tmp_path):
    """The 1.4 m right wall 0.5 m farther out (the scanner field, the aisle closure and the back wall with it):
    1.207 m behind it is more than the 1.1 m Table 2 asks."""
    def edit(d):
        d["fences"][1].update(top=1.4)
        for pts in (d["fences"][1]["points"], d["fences"][3]["points"], d["devices"][0]["polygon"]):
            for p in pts:
                p[0] = 2.0 if p[0] == 1.5 else p[0]
        d["floor"]["xmax"] = 3.0

    r = _variant(tmp_path, "right-back", edit)
    assert r.ok, r.failures()
    right = _right_wall(r)
    assert right.reach.ok and right.reach.required == pytest.approx(1.1)
    assert right.reach.behind == pytest.approx(1.207, abs=1e-3)


def test_a_panel_under_one_metre_stays_no_barrier(tmp_path):
    r = _variant(tmp_path, "right-900", lambda d: d["fences"][1].update(top=0.9))
    assert r.failures() == ["undetected-reach"]  # no Table 2 row: the panel is no structure to reach over
    assert all(p.panel.fence != 2 for p in r.approach.panels_at)
    wall = next(p for p in r.fences if (p.fence, p.panel) == (2, 1))
    assert wall.reach_over is None and not wall.closed and "no barrier" in wall.reason


def test_a_hazard_above_2700_needs_no_distance(tmp_path):
    """The robot hung at 2.9 m (nothing of it below 2.8 m) behind 1.0 m walls: out of reach upwards (4.2.1), so
    the walls close the way; under the old rule (climb plus distance >= 0.85 m) they were open."""
    def edit(d):
        d["robot"]["base"]["xyz"] = [0.0, 0.0, 2.9]
        d["robot"]["pedestal"] = "none"
        for f in d["fences"]:
            f["top"] = 1.0

    r = _variant(tmp_path, "hung", edit)
    assert r.ok and all(p.closed for p in r.fences)
    assert all(math.isinf(p.reach.behind) for p in r.approach.panels_at)
    assert any("no part of the hazard zone lies within the table's distances" in ln for ln in r.lines())
    assert any("4 lower than 1.4 m, which 4.4 allows only with further protective measures" in ln
               for ln in r.lines())


def test_a_panel_above_2700_needs_no_distance(tmp_path):
    r = _variant(tmp_path, "right-2800", lambda d: d["fences"][1].update(top=2.8))
    right = _right_wall(r)
    assert right.reach.required == 0.0 and right.reach.ok and right.panel.closed and r.ok


def test_the_built_in_cells_keep_their_verdicts():
    """Every 2 m wall of the paper's cells meets Table 2: the zone reaches at most 1.75 m high (S2's fold) and lies
    at least 0.67 m behind the walls at 1.4 m and above, where a 2 m wall needs 0.5-0.6 m."""
    for name, fails in (("baseline", []), ("s1-scanner-width", ["front-scanner"]),
                        ("s2-elbow-intrusion", ["bay-curtain"]),
                        ("s3-fence-gap", ["front-scanner", "undetected-reach"])):
        r = iso.check_cell(name)
        assert r.failures() == fails
        assert all(p.closed for p in r.fences)
        assert r.approach.panels_at and not r.approach.reach_over_fails
