"""The safety mat device kind: its ISO 13855 distance by hand, its primitive at the feet, its record's checks."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from cellstress.core.records import ScanPlane
from cellstress.devices.safety_mat import SENSING_HEIGHT, SafetyMat

AREA = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def mat(**kw) -> SafetyMat:
    return SafetyMat.model_validate({"type": "safety-mat", "name": "m", "polygon": AREA, **kw})


def test_mat_distance_by_hand():
    # ISO 13855, pressure-sensitive mats: S = 1600 T + 1200, T = 0.1 + 0.15 s: 400 + 1200
    d = mat().required_distance(0.15)
    assert (d.K, d.C) == (1600.0, 1200.0)
    assert d.T == pytest.approx(0.25) and d.S == pytest.approx(1600.0)
    assert "1200" in d.formula


def test_mat_primitive_is_a_plane_at_the_feet():
    assert mat().primitives() == (ScanPlane(AREA, SENSING_HEIGHT),)
    assert SENSING_HEIGHT < 0.07  # below the top of the leg capsule's foot end (radius 0.07 m from the floor)
    assert mat(restart={"automatic": 1.0}).channels()[0].clear_time == 1.0


def test_mat_record_checks():
    with pytest.raises(ValidationError, match="at least 3 points"):
        mat(polygon=((0, 0), (1, 1)))
    with pytest.raises(ValidationError, match="extra"):
        mat(height=0.3)
