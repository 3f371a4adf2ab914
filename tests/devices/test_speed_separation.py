"""The speed-separation device kind: its ISO/TS 15066 protective separation by hand, the fraction its controller
commands, its kernel channel, its record's checks and its row of the static check."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from cellstress.analysis.iso13855 import check_cell
from cellstress.core.records import ScanPlane
from cellstress.devices.speed_separation import SpeedSeparation, intrusion_for_height

AREA = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def ssm(**kw) -> SpeedSeparation:
    return SpeedSeparation.model_validate({"type": "speed-separation", "name": "s", "polygon": AREA,
                                           "reaction_time": 0.05, "stopping_time": 0.15, "max_speed": 1.2, **kw})


def test_protective_separation_by_hand():
    # ISO/TS 15066 5.5.4 with the real times T_r = 0.3 s, T_s = 0.15 s, v_h 1.6 m/s, v_max 1.2 m/s, C at 0.3 m
    # (ISO 13855: 1200 - 0.4*300 = 1080 mm), Z_d = 0.1, Z_r = 0.05:
    # 1.6*0.45 + 1.2*0.3 + 1.2*0.15/2 + 1.08 + 0.1 + 0.05 = 0.72 + 0.36 + 0.09 + 1.23 = 2.40 m
    d = ssm(response_time=0.3, z_d=0.1, z_r=0.05).required_distance(0.15)
    assert d.S == pytest.approx(2400.0)
    assert (d.K, d.T) == (1600.0, pytest.approx(0.45))
    assert d.C == pytest.approx(2400.0 - 720.0)
    assert "= 2400 mm" in d.formula
    assert intrusion_for_height(0.3) == pytest.approx(1.08) and intrusion_for_height(1.0) == pytest.approx(0.85)


def test_commanded_fraction_follows_the_formula():
    s = ssm(reaction_time=0.3, intrusion=1.0)
    # full speed down to S_p(v_max) = 1.6*0.45 + 1.2*(0.3 + 0.075) + 1.0 = 2.17 m; stop at or below 1.72 m
    assert s.configured_separation() == pytest.approx(2.17)
    assert s.fraction(3.0) == 1.0 and s.fraction(2.17) == pytest.approx(1.0)
    assert s.fraction(1.72) == pytest.approx(0.0) and s.fraction(0.5) == 0.0
    assert s.fraction(1.945) == pytest.approx(0.5)  # halfway: 0.225 m of the 0.45 m that full speed adds


def test_channel_carries_the_configured_rule():
    s = ssm(response_time=0.3, z_d=0.1)
    (c,) = s.channels()
    assert c.primitive == ScanPlane(AREA, 0.3)
    assert c.response_time == 0.3  # the real response: when a command takes effect
    r = c.separation
    assert (r.human_speed, r.max_speed, r.reaction_time, r.stopping_time) == (1.6, 1.2, 0.05, 0.15)
    assert r.allowance == pytest.approx(1.08 + 0.1)


def test_configured_note_names_the_shorter_time():
    note = ssm(response_time=0.3).configured_note(0.15)
    assert "T_r 0.05 s < real 0.3 s" in note and "T_s" not in note.split("underestimated")[1]
    assert "underestimated" not in ssm(response_time=0.05).configured_note(0.15)
    assert "T_s 0.15 s < real 0.5 s" in ssm(response_time=0.05).configured_note(0.5)


def test_record_checks():
    with pytest.raises(ValidationError, match="at least 3 points"):
        ssm(polygon=((0, 0), (1, 1)))
    with pytest.raises(ValidationError, match="greater than 0"):
        ssm(max_speed=0.0)
    with pytest.raises(ValidationError, match="reaction_time"):
        SpeedSeparation.model_validate({"type": "speed-separation", "name": "s", "polygon": AREA,
                                        "stopping_time": 0.15, "max_speed": 1.2})
    with pytest.raises(ValidationError, match="no restart"):
        ssm(restart={"automatic": 1.0})


@pytest.mark.parametrize(("cell", "ok", "actual"), [("ssm-latency", False, 1.55), ("ssm-ok", True, 2.25)])
def test_static_check_of_the_built_in_pair(cell, ok, actual):
    # required 1.6*0.45 + 1.2*(0.3 + 0.075) + 1.08 = 2.25 m with the real 0.3 s; the area allows 2.489 m; the
    # flawed controller (T_r 0.05 s) runs at full speed down to 1.6*0.2 + 1.2*0.125 + 1.08 = 1.55 m
    r = check_cell(cell)
    (row,) = [d for d in r.devices if d.device == "ssm"]
    assert row.required == pytest.approx(2.25)
    assert row.actual == pytest.approx(actual, abs=5e-3)
    assert row.ok is ok and r.ok is ok
    assert ("underestimated" in row.note) is not ok
