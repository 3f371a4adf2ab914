"""The ISO 13855 / ISO 13857 static check: the arithmetic by hand, the geometry on toy cases, and the verdict
on the four built-in cells (baseline passes; each flaw fails its own check). Numbers: docs/cells.md."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
import yaml

from cellstress.analysis import iso13855 as iso
from cellstress.analysis import plane
from cellstress.cell.load import builtin_text, load_cell

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap", "s2-deceptive")


# ---- body numbers used by the check -----------------------------------------------------------------------
@pytest.fixture(scope="module")
def results():
    from cellstress.sim.simulator import Simulator

    out = {}
    for name in CELLS:
        sim = Simulator(name)
        out[name] = (sim, iso.check_cell(sim.cell, sim.layout))
    return out


def test_reach_over_a_2m_fence_is_impossible(results):
    r = results["baseline"][1]
    assert r.shoulder_height == pytest.approx(0.818 * 1.78)  # 1.456 m, Winter's shoulder height
    assert r.arm_length == pytest.approx(0.30 + 0.31 + 0.18)  # 0.79 m
    # straight up the fingertip gets 2.246 m high, only 0.246 m over the 2.0 m top
    assert r.shoulder_height + r.arm_length - 2.0 == pytest.approx(0.24604, abs=1e-5)
    # ISO 13857 Table 2 behind a 2.0 m top: nothing up to a = 1.4 m, 0.5 m from 1.4 m up (the zone's top reaches
    # into that band); the zone is at least 0.7 m behind every panel
    for p in r.fences:
        assert p.closed and p.reach_over.ok and p.to_hazard >= 0.7
        assert p.reach_over.required in (0.5, 0.0) and p.reach_over.behind >= 0.7
    assert {(p.panel.fence, p.panel.panel) for p in r.approach.panels_at} == {(1, 1), (1, 2), (2, 1), (2, 2)}


def _lean_by_hand(height=1.78, fwd_deg=55.0, lat_deg=35.0):
    """Horizontal hip-to-shoulder distance of the outer shoulder at full forward and lateral flexion."""
    rise = (0.818 - 0.530) * height
    half = 0.259 * height / 2 - 0.05
    f, lt = math.radians(fwd_deg), math.radians(lat_deg)
    xb = np.array([math.cos(f), 0.0, -math.sin(f)])
    zb = np.array([math.sin(f) * math.cos(lt), math.sin(lt), math.cos(f) * math.cos(lt)])
    yb = np.cross(zb, xb)
    return max(float(np.hypot(*(rise * zb + s * half * yb)[:2])) for s in (1.0, -1.0))


def test_lean_by_hand(results):
    # forward 55 deg alone: the shoulders move 0.288 * 1.78 * sin 55 = 0.420 m forward
    assert (0.818 - 0.530) * 1.78 * math.sin(math.radians(55)) == pytest.approx(0.41993, abs=1e-5)
    # the largest reach of the trunk is at full forward and lateral flexion: 0.512 m
    assert _lean_by_hand() == pytest.approx(0.5123, abs=1e-4)
    assert results["baseline"][1].approach.lean == pytest.approx(_lean_by_hand(), abs=1e-9)


def test_detection_margins(results):
    a = results["baseline"][1].approach
    assert a.scanner_margin == pytest.approx(0.07)  # only the legs cross a 0.3 m scan plane
    assert a.curtain_margin == pytest.approx(0.15)  # the trunk is the widest capsule in 0.2..1.8 m


# ---- the four cells ---------------------------------------------------------------------------------------
def test_baseline_passes(results):
    r = results["baseline"][1]
    assert r.ok and r.failures() == []
    scanner, curtain = r.devices
    assert scanner.required == pytest.approx(1.88)
    assert curtain.required == pytest.approx(1.17)
    assert scanner.actual == pytest.approx(3.2 - 1.111, abs=0.002)  # front edge 3.2, zone's front 1.111
    assert curtain.actual == pytest.approx(1.6 - 0.233, abs=0.002)  # curtain -1.6, zone's rear -0.233
    assert len(scanner.entries) == 1  # only the front edge can be stepped across
    assert r.approach.ok and r.approach.distance > 1.5


def test_s1_fails_only_the_scanner(results):
    r = results["s1-scanner-width"][1]
    assert r.failures() == ["front-scanner"]
    base = results["baseline"][1].devices[0].actual
    # the same zone, the field's front edge 0.7 m closer: 2.089 - 0.7 = 1.389 m < 1.88 m
    assert r.devices[0].actual == pytest.approx(base - 0.7, abs=1e-9)
    assert r.devices[0].actual < 1.88


@pytest.mark.parametrize("cell", ["s2-elbow-intrusion", "s2-deceptive"])  # same robot and path, other phases
def test_s2_fails_only_the_curtain(results, cell):
    r = results[cell][1]
    assert r.failures() == ["bay-curtain"]
    curtain = r.devices[1]
    assert curtain.actual == pytest.approx(0.985, abs=0.005) and curtain.actual < 1.17
    assert curtain.where.robot_part == "upper_arm_link"
    # the folded elbow is the closest point, and an episode meets it (docs/cells.md, S2)
    assert curtain.where.hazard_point[1] == pytest.approx(-0.615, abs=0.005)
    assert curtain.episode_actual == pytest.approx(curtain.actual, abs=1e-3)


def test_s3_fails_undetected_reach_at_the_gap(results):
    r = results["s3-fence-gap"][1]
    assert r.failures() == ["front-scanner", "undetected-reach"]
    a = r.approach
    assert not a.ok and a.distance < 0.85
    assert 1.5 < a.stand[0] < 1.75 and -0.2 < a.stand[1] < 0.8  # standing in the gap, outside the field
    assert a.where.point[0] < 1.5  # leaning over the field's edge
    # the scanner fails only at the opened edge x = 1.5, y -0.2..0.8; the front edge is as in the baseline
    entries = {(p0, p1): d for p0, p1, d in r.devices[0].entries}
    assert set(entries) == {((-1.5, 3.2), (1.5, 3.2)), ((1.5, 0.8), (1.5, -0.2))}
    assert entries[((-1.5, 3.2), (1.5, 3.2))] >= 1.88
    assert entries[((1.5, 0.8), (1.5, -0.2))] == pytest.approx(1.5 - 0.792, abs=0.002)


def test_hazard_zone_covers_the_simulator_table(results):
    """Every robot capsule the simulator poses at its 50 ms steps lies inside the sampled zone's extent."""
    for sim, r in results.values():
        P = sim.params
        lo = np.minimum(P.pre_ra, P.pre_rb)[..., :2] - P.cap_r[None, :, None]
        hi = np.maximum(P.pre_ra, P.pre_rb)[..., :2] + P.cap_r[None, :, None]
        x0, x1, y0, y1 = r.zone.extent()
        # hazard_zone drops poses equal to another within 1e-6 m (its repeat key), so the extent may differ by
        # that much: S2 visits its fold pose twice per cycle, arriving from pick and from place
        tol = 1e-6
        assert lo[..., 0].min() >= x0 - tol and hi[..., 0].max() <= x1 + tol
        assert lo[..., 1].min() >= y0 - tol and hi[..., 1].max() <= y1 + tol


def test_static_check_lines(results):
    sim, _ = results["baseline"]
    lines = iso.static_check(sim.cell, sim.layout)
    assert all(isinstance(s, str) for s in lines)
    assert lines[-1] == "result: pass"
    lines = iso.static_check("s2-elbow-intrusion")
    assert lines[-1] == "result: FAIL (bay-curtain)"
    assert any("1600*0.20 + 850 = 1170 mm" in s for s in lines)


def test_device_distances_records(results):
    sim, _ = results["s1-scanner-width"]
    recs = iso.device_distances(sim.cell, sim.layout)
    assert [(d.device, d.type, d.ok) for d in recs] == [("front-scanner", "laser-scanner", False),
                                                        ("bay-curtain", "light-curtain", True)]
    assert recs[0].T == pytest.approx(0.5) and recs[1].T == pytest.approx(0.2)
    with pytest.raises(AttributeError):
        recs[0].ok = True  # frozen


def test_deterministic_and_fast(results):
    sim, r = results["s2-elbow-intrusion"]  # the longest cycle
    t0 = time.perf_counter()
    again = iso.check_cell(sim.cell, sim.layout)
    assert time.perf_counter() - t0 < 5.0  # about 1 s; generous for loaded CI machines
    assert again.lines() == r.lines()


def test_low_fence_counts_as_open(tmp_path):
    """ISO 13857: a fence lower than 1 m is no barrier; lowering the right wall to 0.9 m lets a worker outside
    it reach the robot undetected (it still blocks walking)."""
    data = yaml.safe_load(builtin_text("baseline"))
    data["fences"][1]["top"] = 0.9
    path = tmp_path / "low.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    r = iso.check_cell(load_cell(str(path)))
    assert "undetected-reach" in r.failures()
    assert any(not p.closed and "ISO 13857" in p.reason for p in r.fences)


def test_the_reach_line_names_only_the_devices_the_cell_has(tmp_path):
    """A cell with only a curtain is not told to keep away from scanner fields (and one with none from either)."""
    data = yaml.safe_load(builtin_text("baseline"))
    data["devices"] = [d for d in data["devices"] if d["type"] == "light-curtain"]
    path = tmp_path / "curtain-only.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    line = next(ln for ln in iso.check_cell(load_cell(str(path))).lines() if ln.startswith("undetected reach"))
    assert "from curtains" in line and "scanner" not in line
    data["devices"] = []
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    line = next(ln for ln in iso.check_cell(load_cell(str(path))).lines() if ln.startswith("undetected reach"))
    assert "no detection zone to keep away from" in line and "scanner" not in line and "curtain" not in line


# ---- geometry on toy cases --------------------------------------------------------------------------------
def test_open_intervals():
    covers = [((0.0, 0.0), (1.0, 0.0)), ((2.0, 0.0), (5.0, 0.0)), ((1.5, 0.1), (1.8, 0.1))]
    assert plane.open_intervals((0.0, 0.0), (3.0, 0.0), covers) == [((1.0, 0.0), (2.0, 0.0))]
    # a collinear cover lying wholly beyond the edge's end covers nothing
    assert plane.open_intervals((0.0, 0.0), (1.0, 0.0), [((2.0, 0.0), (3.0, 0.0))]) == [((0.0, 0.0), (1.0, 0.0))]


def _zone_point(x, y, r):
    a = np.array([[x, y]], dtype=float)
    return a, a.copy(), np.array([r])


def test_arm_path_around_a_wall_end():
    segs = [((0.0, -1.0), (0.0, 1.0))]
    walls = plane.extended_walls(segs)
    nodes = plane.detour_nodes(segs)
    assert len(nodes) == 2  # one beyond each free end
    za, zb, zr = _zone_point(1.0, 0.0, 0.1)
    g, gi = plane.node_values(nodes, za, zb, zr, walls)
    d, _ = plane.arm_path(-1.0, 0.0, za, zb, zr, walls, nodes, g, gi, math.inf)
    assert d == pytest.approx(2 * math.sqrt(2) - 0.1, abs=2e-3)  # around an end: sqrt 2 + sqrt 2 - r
    d, _ = plane.arm_path(1.0, 2.0, za, zb, zr, walls, nodes, g, gi, math.inf)
    assert d == pytest.approx(1.9)  # in plain view: straight


def test_no_leak_through_a_joined_corner():
    # an L: the straight line from inside through the corner point must not count as clear
    segs = [((0.0, 0.0), (2.0, 0.0)), ((0.0, 0.0), (0.0, 2.0))]
    walls = plane.extended_walls(segs)
    assert plane.blocked(1.0, 1.0, -1.0, -1.0, walls)
    assert not plane.blocked(1.0, 1.0, 1.5, 0.5, walls)
    nodes = plane.detour_nodes(segs)
    assert len(nodes) == 3  # beyond both free ends and outside the corner (its 270 deg side)
    za, zb, zr = _zone_point(-1.0, -1.0, 0.0)
    g, gi = plane.node_values(nodes, za, zb, zr, walls)
    d, _ = plane.arm_path(1.0, 1.0, za, zb, zr, walls, nodes, g, gi, math.inf)
    # out around the end (2, 0): sqrt 2 + |(2, 0) - (-1, -1)| = 1.414 + 3.162
    assert d == pytest.approx(math.sqrt(2) + math.sqrt(10), abs=2e-3)


def test_t_junction_is_closed():
    # a wall along x = 0 and a short wall ending on it: a line sliding along x = 0 past the junction is blocked
    segs = [((0.0, -2.0), (0.0, 2.0)), ((-1.0, 0.0), (0.0, 0.0))]
    walls = plane.extended_walls(segs)
    assert plane.blocked(0.0, 1.0, 0.0, -1.0, walls)
    assert plane.blocked(-0.5, 0.5, -0.5, -0.5, walls)
    assert not plane.blocked(0.5, 0.5, 0.5, -0.5, walls)
    # no detour node at the junction: only beyond the three free ends
    assert len(plane.detour_nodes(segs)) == 3


def test_docs_calibration_example_runs(capsys):
    """The calibration script in docs/cells.md runs (with 2,000 instead of 200,000 episodes)."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "cells.md").read_text(encoding="utf-8")
    code = text.split("```python\n", 1)[1].split("```", 1)[0]
    assert "200_000" in code
    exec(compile(code.replace("200_000", "2_000"), "docs/cells.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out] == ["s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap",
                                                 "baseline"]
    assert float(out[-1].split()[1]) == 0.0  # the baseline is safe


@pytest.mark.parametrize("cell, device, required, actual, ok", [
    ("warning-field-short", "front-scanner", 1.700, 1.389, False),
    ("warning-field-short", "front-scanner:warning", 2.440, 2.489, True),
    ("warning-field-ok", "front-scanner", 1.700, 1.789, True),
    ("mat-short", "front-mat", 1.600, 1.189, False),
    ("mat-ok", "front-mat", 1.600, 2.089, True),
    ("door-unlocked", "bay-door", 1.570, 1.367, False),
    ("door-locked", "bay-door", 0.0, 1.367, True),
])
def test_safeguard_distances(cell, device, required, actual, ok):
    """Required against actual for the new device kinds (docs/cells.md gives the arithmetic)."""
    d = next(c for c in iso.check_cell(cell).devices if c.device == device)
    assert d.required == pytest.approx(required, abs=5e-4)
    assert d.actual == pytest.approx(actual, abs=5e-3)
    assert d.ok is ok


def test_guard_door_check_rows():
    bad = iso.check_cell("door-unlocked")
    assert bad.failures() == ["bay-door"]
    lines = bad.lines()
    assert any("1600*(0.05 + 1 - 0.6 opening) + 850 = 1570 mm" in ln for ln in lines)
    assert any("access time 0.6 + max(1.367 - 0.850, 0)/1.6 = 0.92 s" in ln and "guard locking required" in ln
               for ln in lines)
    good = iso.check_cell("door-locked")
    assert good.ok
    assert any("guard locking holds the door" in ln for ln in good.lines())


def test_muting_check():
    bad = iso.check_cell("muting-long")
    assert bad.failures() == ["bay-curtain-muting"]
    assert any("muted 1.50 s after the pallet cleared" in ln for ln in bad.lines())
    good = iso.check_cell("muting-ok")
    assert good.ok and len(good.mutings) == 1


def test_automatic_restart_check():
    bad = iso.check_cell("restart-auto")
    assert bad.failures() == ["bay-curtain-restart"]
    (rc,) = bad.restarts
    assert rc.clear_time == 0.5 and rc.behind.distance < 0.85
    assert any("restarts while the worker stands unseen" in ln for ln in bad.lines())
    good = iso.check_cell("restart-manual")
    assert good.ok and good.restarts == ()
