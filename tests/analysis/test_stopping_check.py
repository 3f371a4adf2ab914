"""``check`` and how the robot stops (issue 28): the ISO 13855 rows take the simulator's own delay and braking, a
speed and separation monitor gets the delay in its T_r, configured speeds are compared with the robot's real top
speed (cross-checked with pinocchio), and ``cellstress new`` writes a stopping block."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pinocchio as pin
import pytest
import yaml

from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.stopping import top_speed
from cellstress.cell.load import parse_cell
from cellstress.robot.model import load_pinocchio
from cellstress.robot.trajectory import evaluate
from cellstress.sim import layout as L
from cellstress.sim.build import build_layout


def builtin(name: str) -> dict:
    return yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", f"{name}.yaml").read_text())


def layout_of(data: dict, tmp_path):
    return build_layout(parse_cell(yaml.safe_dump(data), str(tmp_path / "cell.yaml"), tmp_path))


def with_stop(name: str, **block) -> dict:
    data = builtin(name)
    data["robot"].pop("stopping_time", None)
    data["robot"]["stopping"] = block
    return data


def test_iso_rows_take_the_delay_and_the_braking_the_simulator_uses(tmp_path):
    lay = layout_of(with_stop("baseline", controller_delay=0.1, time=0.15), tmp_path)
    rows = check_cell(lay.cell, lay).devices
    total = float(lay.params.scal[L.C_STOP_DELAY] + lay.params.scal[L.C_STOP_TIME])
    assert total == pytest.approx(0.25)
    for d in rows:
        assert d.stopping_time == pytest.approx(total) and d.T == pytest.approx(d.response_time + total)
    scanner = next(d for d in rows if d.type == "laser-scanner")
    assert scanner.required == pytest.approx((1600 * (0.35 + 0.25) + 1200 - 0.4 * 300) / 1000)  # ISO 13855, by hand
    # the same as a robot that simply needs 0.25 s: ISO 13855 counts time only
    same = builtin("baseline")
    same["robot"]["stopping_time"] = 0.25
    plain = layout_of(same, tmp_path)
    assert [d.required for d in rows] == [d.required for d in check_cell(plain.cell, plain).devices]


def test_a_warning_field_and_a_separation_monitor_split_the_delay_from_the_braking(tmp_path):
    lay = layout_of(with_stop("warning-field-ok", controller_delay=0.1, time=0.15), tmp_path)
    rows = {d.type: d for d in check_cell(lay.cell, lay).devices}
    r = 0.25  # the warning field's reduced speed in warning-field-ok
    prot = rows["laser-scanner"]
    assert prot.T == pytest.approx(0.35 + 0.1 + r * 0.15)  # the delay at the reduced speed, braking from it
    warn = rows["laser-scanner warning field"]
    assert warn.T == pytest.approx(prot.T + 0.35 + 0.1 + (1 - r) * 0.15)
    lay = layout_of(with_stop("ssm-ok", controller_delay=0.05, time=0.15), tmp_path)
    ssm = next(d for d in check_cell(lay.cell, lay).devices if d.type == "speed-separation")
    dev = next(d for d in lay.cell.spec.devices if d.type == "speed-separation")
    t_r, t_s, v, v_h = dev.response_time + 0.05, 0.15, dev.max_speed, dev.human_speed
    s_p = v_h * (t_r + t_s) + v * t_r + v * t_s / 2 + dev.allowance  # ISO/TS 15066 5.5.4, by hand
    assert ssm.required == pytest.approx(s_p) and "T_r 0.3 s" in ssm.note


def test_maker_data_give_the_check_and_the_simulator_the_same_times(tmp_path):
    (tmp_path / "stop.csv").write_text(
        "# made-up, for the test\njoint,category,speed_pct,payload_kg,extension_pct,distance,unit,time_s\n"
        "shoulder_pan_joint,1,100,10,100,0.45,rad,0.25\nshoulder_lift_joint,1,100,10,100,0.2,rad,0.2\n")
    lay = layout_of(with_stop("baseline", category=1, controller_delay=0.02, data="stop.csv", payload_kg=5.0), tmp_path)
    stop = lay.robots[0].stop
    vmax = float(lay.robot.velocity_limits[0])
    # shoulder_pan: S / v = 0.45 / vmax in [T/2, T]: delay 2 S / v - T, braking 2 (T - S / v)
    assert 0.125 <= 0.45 / vmax <= 0.25
    assert stop.delay == pytest.approx(0.02 + 2 * 0.45 / vmax - 0.25)
    assert stop.braking == pytest.approx(max(2 * (0.25 - 0.45 / vmax), 0.2))
    assert lay.params.scal[L.C_STOP_DELAY] == stop.delay and lay.params.scal[L.C_STOP_TIME] == stop.braking
    assert all(d.stopping_time == pytest.approx(stop.to_standstill) for d in check_cell(lay.cell, lay).devices)


def test_top_speed_against_pinocchio(tmp_path):
    """Robot 0's top speed: the largest speed of a capsule axis end, from pinocchio's kinematics and the Python
    trajectory reference (independent of the kernel's forward kinematics)."""
    lay = layout_of(builtin("ssm-ok"), tmp_path)
    top = top_speed(lay)
    model = load_pinocchio(lay.robot.urdf)
    data = model.createData()
    base = lay.params.base
    caps = lay.capsules
    h = 1e-4

    def ends(tau):
        q, _ = evaluate(lay.trajectory, tau)
        pin.forwardKinematics(model, data, lay.robot.pinocchio_q(q))
        out = []
        for c in caps:
            m = data.oMi[c.joint + 1] if c.joint >= 0 else pin.SE3.Identity()
            out += [base[:3, :3] @ m.act(np.asarray(p)) + base[:3, 3] for p in (c.p0, c.p1)]
        return np.array(out)

    best = 0.0
    for tau in np.arange(0.0, lay.trajectory.cycle, 0.005):
        best = max(best, float(np.linalg.norm(ends(tau + h) - ends(tau - h), axis=1).max() / (2 * h)))
    assert top.speed == pytest.approx(best, rel=1e-6)
    assert top.speed > 1.0


def test_a_configured_speed_below_the_real_one_fails(tmp_path):
    data = builtin("ssm-ok")
    ssm = next(d for d in data["devices"] if d["type"] == "speed-separation")
    ssm["max_speed"] = 0.4
    lay = layout_of(data, tmp_path)
    res = check_cell(lay.cell, lay)
    assert f"{ssm['name']}-speed" in res.failures()
    line = next(ln for ln in res.lines() if "max_speed" in ln)
    assert "0.4 m/s" in line and "FAIL" in line
    ok = layout_of(builtin("ssm-ok"), tmp_path)
    assert not any(f.endswith("-speed") for f in check_cell(ok.cell, ok).failures())
    # a warning field laid out for a speed its reduced speed exceeds
    data = builtin("warning-field-ok")
    scanner = next(d for d in data["devices"] if d.get("warning"))
    scanner["warning"]["speed_limit"] = 0.1
    lay = layout_of(data, tmp_path)
    res = check_cell(lay.cell, lay)
    assert f"{scanner['name']}:warning-speed" in res.failures()
    scanner["warning"]["speed_limit"] = 1.0
    lay = layout_of(data, tmp_path)
    assert not any(f.endswith("-speed") for f in check_cell(lay.cell, lay).failures())


def test_new_writes_a_stopping_block_to_fill_in(tmp_path):
    from cellstress.cli import main

    for robot in (None, "panda"):
        out = tmp_path / f"n-{robot}.yaml"
        assert main(["new", "n", "--out", str(out), *(["--robot", robot] if robot else [])]) == 0
        text = out.read_text()
        assert "stopping_time" not in text and "FILL IN" in text and "ISO 10218-1" in text
        doc = yaml.safe_load(text)
        assert doc["robot"]["stopping"] == {"category": 1, "controller_delay": 0.0, "time": 0.15}
