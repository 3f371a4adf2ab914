"""The light curtain device kind: ISO 13855 arithmetic by hand (nominal and body detection), its primitive."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from cellstress.core.records import VerticalField
from cellstress.devices.light_curtain import LightCurtain, nominal_distance


def curtain(**kw) -> LightCurtain:
    return LightCurtain.model_validate({"type": "light-curtain", "name": "c", "start": (-0.6, -1.6),
                                        "end": (0.6, -1.6), **kw})


def test_curtain_nominal_by_hand():
    # d = 30 mm, T = 0.05 + 0.15 s: 2000 * 0.2 + 8 * (30 - 14) = 400 + 128 = 528 > 500,
    # so 1600 * 0.2 + 128 = 448 mm, below the 500 mm minimum: 500 mm
    d = nominal_distance(0.05 + 0.15, 30.0)
    assert (d.K, d.C) == (1600.0, 128.0)
    assert d.S == pytest.approx(500.0)


def test_curtain_nominal_other_branches():
    assert nominal_distance(0.2, 14.0).S == pytest.approx(400.0)  # 2000 * 0.2 + 0 <= 500: K = 2000
    assert nominal_distance(0.2, 14.0).K == 2000.0
    assert nominal_distance(0.02, 14.0).S == pytest.approx(100.0)  # 40 mm < the 100 mm minimum
    assert nominal_distance(0.4, 30.0).S == pytest.approx(640.0 + 128.0)  # 1600 * 0.4 + 128 > 500
    assert nominal_distance(0.2, 50.0).S == pytest.approx(1170.0)  # d > 40 mm: 1600 T + 850


def test_curtain_body_detection_distance_by_hand():
    # our devices see only the body: ISO's body-detection allowance C = 850 mm, K = 1600 mm/s
    d = curtain(response_time=0.05, resolution_mm=30.0).required_distance(0.15)
    assert (d.K, d.C) == (1600.0, 850.0)
    assert d.S == pytest.approx(320.0 + 850.0)
    assert d.formula.startswith("ISO for d = S = 2000*0.20 + 8*(30 - 14)")


def test_primitive_and_checks():
    c = curtain(bottom=0.1, top=1.9)
    assert c.primitives() == (VerticalField((-0.6, -1.6), (0.6, -1.6), 0.1, 1.9),)
    with pytest.raises(ValidationError, match="same point"):
        curtain(end=(-0.6, -1.6))
    with pytest.raises(ValidationError, match="must be above bottom"):
        curtain(bottom=1.0, top=0.5)
