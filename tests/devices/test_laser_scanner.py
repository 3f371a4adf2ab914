"""The laser scanner device kind: its ISO 13855 distance by hand, its primitive, its record's checks."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from cellstress.core.records import ScanPlane
from cellstress.devices.laser_scanner import LaserScanner

FIELD = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def scanner(**kw) -> LaserScanner:
    return LaserScanner.model_validate({"type": "laser-scanner", "name": "s", "polygon": FIELD, **kw})


def test_scanner_distance_by_hand():
    # T = 0.35 s scanner + 0.15 s stopping; H = 300 mm: 1600 * 0.5 + (1200 - 0.4 * 300) = 800 + 1080
    d = scanner(height=0.3, response_time=0.35).required_distance(0.15)
    assert (d.K, d.C) == (1600.0, 1080.0)
    assert d.S == pytest.approx(1880.0) and d.T == pytest.approx(0.5)


def test_scanner_intrusion_allowance_is_at_least_850():
    # H = 1000 mm: 1200 - 400 = 800 < 850, so C = 850
    d = scanner(height=1.0, response_time=0.35).required_distance(0.15)
    assert d.C == 850.0 and d.S == pytest.approx(800.0 + 850.0)
    assert "below 850" in d.formula


def test_primitive_and_description():
    s = scanner(height=0.25)
    assert s.primitives() == (ScanPlane(FIELD, 0.25),)
    assert s.describe() == "4-point field at 0.25 m"


def test_field_must_be_a_simple_polygon():
    with pytest.raises(ValidationError, match="intersects itself"):
        scanner(polygon=((0, 0), (1, 1), (1, 0), (0, 1)))
    with pytest.raises(ValidationError, match="greater than or equal to 0"):
        scanner(height=-0.1)
