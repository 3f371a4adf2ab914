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
    assert s.describe() == "4-point field at 0.25 m, 70 mm"


def test_field_must_be_a_simple_polygon():
    with pytest.raises(ValidationError, match="intersects itself"):
        scanner(polygon=((0, 0), (1, 1), (1, 0), (0, 1)))
    with pytest.raises(ValidationError, match="greater than or equal to 0"):
        scanner(height=-0.1)


WIDE = ((-1.0, -1.0), (2.0, -1.0), (2.0, 2.0), (-1.0, 2.0))


def test_warning_field_distances_by_hand():
    # behind a warning field at r = 0.25: T = 0.35 + 0.25 * 0.15 = 0.3875 s, S = 1600 T + 1080 = 620 + 1080
    s = scanner(response_time=0.35, warning={"polygon": WIDE, "reduced_speed": 0.25})
    d = s.required_distance(0.15)
    assert d.T == pytest.approx(0.3875) and d.S == pytest.approx(1700.0)
    # the warning field leads it by 1600 * (0.35 + 0.75 * 0.15) = 740 mm
    w = s.warning_distance(0.15)
    assert w.S == pytest.approx(2440.0)
    assert scanner().warning_distance(0.15) is None


@pytest.mark.parametrize("warning", [
    FIELD,  # the same field: contains it (a shared boundary is inside)
    ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 1.5), (0.0, 1.0)),  # sharing three edges
])
def test_a_warning_field_around_the_protective_field_is_accepted(warning):
    assert scanner(warning={"polygon": warning}).warning is not None


@pytest.mark.parametrize("warning", [
    ((0.2, 0.2), (0.8, 0.2), (0.8, 0.8), (0.2, 0.8)),  # inside the protective field (issue 29)
    ((2.0, 2.0), (3.0, 2.0), (3.0, 3.0)),  # apart
    ((-1.0, -1.0), (0.9, -1.0), (0.9, 2.0), (-1.0, 2.0)),  # a corner of the protective field pokes out
    # a U around it whose notch cuts into the protective field: every corner is inside, an edge is not
    ((-1.0, -1.0), (2.0, -1.0), (2.0, 2.0), (0.6, 2.0), (0.6, 0.5), (0.4, 0.5), (0.4, 2.0), (-1.0, 2.0)),
])
def test_a_warning_field_must_contain_the_protective_field(warning):
    with pytest.raises(ValidationError, match="warning.polygon must contain the protective field"):
        scanner(warning={"polygon": warning})


def test_warning_field_channels():
    s = scanner(response_time=0.35, warning={"polygon": WIDE, "reduced_speed": 0.4, "restart": {"automatic": 1.0}})
    stop, warn = s.channels()
    assert (stop.speed, stop.clear_time, stop.name) == (0.0, float("inf"), "s")
    assert (warn.speed, warn.clear_time, warn.name) == (0.4, 1.0, "s:warning")
    assert warn.primitive == ScanPlane(WIDE, 0.3) and s.primitives() == (ScanPlane(FIELD, 0.3),)
    assert "warning field" in s.describe()


def test_restart_field():
    assert scanner().clear_time == float("inf")
    assert scanner(restart={"automatic": 0.5}).clear_time == 0.5
    with pytest.raises(ValidationError, match="greater than 0"):
        scanner(restart={"automatic": 0.0})
    with pytest.raises(ValidationError, match="'manual'"):
        scanner(restart="automatic")
