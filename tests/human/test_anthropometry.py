"""Body sizes, postures and gaits: inside the cell schema's ranges, ordered as percentiles and sexes are, and
derived as their docstrings say."""

from __future__ import annotations

import math

import pytest

from cellstress.cell.schema import Anthropometry
from cellstress.human import anthropometry as anth
from cellstress.human.anthropometry import BODY_SIZES, GAITS, POSTURES, BodySize, from_stature

KEYS = ("p5-female", "p50-female", "p95-female", "p5-male", "p50-male", "p95-male")
# the cell schema's ranges (cell/schema.py Anthropometry) [m]
RANGES = {"stature": (1.4, 2.1), "upper_arm": (0.2, 0.45), "forearm": (0.18, 0.40), "hand": (0.12, 0.25)}


def test_the_six_sizes_are_there_and_read_only():
    assert tuple(BODY_SIZES) == KEYS
    with pytest.raises(TypeError):
        BODY_SIZES["p99-male"] = BODY_SIZES["p95-male"]  # type: ignore[index]
    with pytest.raises(AttributeError):
        BODY_SIZES["p50-male"].stature = 2.0  # type: ignore[misc]


@pytest.mark.parametrize("key", KEYS)
def test_every_size_lies_inside_the_schemas_ranges(key):
    b = BODY_SIZES[key]
    for field, (lo, hi) in RANGES.items():
        assert lo <= getattr(b, field) <= hi, (key, field)
    # and the schema itself accepts it as a cell's anthropometry
    Anthropometry(height=b.stature, upper_arm=b.upper_arm, forearm=b.forearm, hand=b.hand)


@pytest.mark.parametrize("sex", ["female", "male"])
@pytest.mark.parametrize("field", ["stature", "upper_arm", "forearm", "hand", "shoulder_breadth", "hip_height"])
def test_percentiles_grow_within_each_sex(sex, field):
    p5, p50, p95 = (getattr(BODY_SIZES[f"p{p}-{sex}"], field) for p in (5, 50, 95))
    assert p5 < p50 < p95


@pytest.mark.parametrize("p", [5, 50, 95])
def test_men_are_larger_than_women_at_the_same_percentile(p):
    f, m = BODY_SIZES[f"p{p}-female"], BODY_SIZES[f"p{p}-male"]
    assert m.stature > f.stature and m.upper_arm > f.upper_arm and m.shoulder_breadth > f.shoulder_breadth
    assert m.arm_length > f.arm_length


def test_survey_values_and_derived_segments():
    """The survey's numbers as printed (mm); forearm, hand and hip by Drillis & Contini of the survey stature."""
    mm = {k: (round(b.stature * 1000), round(b.upper_arm * 1000), round(b.shoulder_breadth * 1000))
          for k, b in BODY_SIZES.items()}
    assert mm == {"p5-female": (1505, 300, 325), "p50-female": (1610, 330, 355), "p95-female": (1710, 360, 380),
                  "p5-male": (1625, 330, 365), "p50-male": (1740, 365, 400), "p95-male": (1855, 395, 430)}
    for b in BODY_SIZES.values():
        assert b.forearm == pytest.approx(0.146 * b.stature)
        assert b.hand == pytest.approx(0.108 * b.stature)
        assert b.hip_height == pytest.approx(0.530 * b.stature)
        assert b.arm_length == pytest.approx(b.upper_arm + b.forearm + b.hand)
    # the survey's men's hip heights (840 / 920 / 1000 mm) lie within 25 mm of 0.530 H
    for key, hip in (("p5-male", 0.840), ("p50-male", 0.920), ("p95-male", 1.000)):
        assert abs(BODY_SIZES[key].hip_height - hip) < 0.025


def test_from_stature_uses_drillis_and_contini():
    b = from_stature(1.78)
    assert (b.upper_arm, b.forearm, b.hand, b.hip_height) == pytest.approx(
        (0.186 * 1.78, 0.146 * 1.78, 0.108 * 1.78, 0.530 * 1.78))
    assert b.shoulder_breadth is None
    assert from_stature(1.78, upper_arm=0.3).upper_arm == 0.3


@pytest.mark.parametrize("bad", [0.0, -1.7, math.nan, math.inf])
def test_bad_lengths_raise(bad):
    with pytest.raises(ValueError, match="finite"):
        from_stature(bad)
    with pytest.raises(ValueError, match="finite"):
        BodySize(stature=1.7, upper_arm=bad, forearm=0.25, hand=0.18)
    with pytest.raises(ValueError, match="finite"):
        BodySize(stature=1.7, upper_arm=0.3, forearm=0.25, hand=0.18, hip_height=bad)


def test_the_leg_segments_add_up_to_the_standing_hip():
    assert anth.FOOT_HEIGHT_FRACTION + anth.SHANK_FRACTION + anth.THIGH_FRACTION == pytest.approx(0.530)
    assert POSTURES["stand"].hip_fraction == pytest.approx(0.530)


def test_postures_order_the_hip():
    """Crouch < kneel < stand < tiptoe for the hip's height, at every body size."""
    for b in BODY_SIZES.values():
        h = {name: p.hip_height(b.stature) for name, p in POSTURES.items()}
        assert 0 < h["crouch"] < h["kneel"] < h["stand"] < h["tiptoe"]
        assert h["tiptoe"] - h["stand"] == pytest.approx(anth.TIPTOE_RISE)


def test_the_crouch_follows_from_the_joint_ranges():
    expected = 0.039 + 0.246 * math.cos(math.radians(20)) + 0.245 * math.cos(math.radians(20 - 135))
    assert POSTURES["crouch"].hip_fraction == pytest.approx(expected)
    assert POSTURES["crouch"].hip_fraction == pytest.approx(0.167, abs=5e-4)
    assert POSTURES["kneel"].hip_fraction == pytest.approx(0.245)
    assert all(p.rise == 0 for n, p in POSTURES.items() if n != "tiptoe")


def test_every_posture_and_gait_says_where_it_comes_from():
    for p in POSTURES.values():
        assert p.derivation and p.name in POSTURES
    for g in GAITS.values():
        assert 0 < g.speed_fraction <= 1 and "ssumption" in g.derivation
    assert set(GAITS) == {"step-back", "side-step"}
    assert "assumption" in POSTURES["tiptoe"].derivation


def test_docs_print_the_body_sizes():
    """docs/worker.md's body-size table is the module's, to the millimetre."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "worker.md").read_text(encoding="utf-8")
    rows = {ln.split("|")[1].strip(): [float(x) for x in ln.split("|")[2:-1]]
            for ln in text.splitlines() if ln.startswith("| p") and "male" in ln}
    assert set(rows) == set(KEYS)
    for key, b in BODY_SIZES.items():
        want = [b.stature, b.upper_arm, b.forearm, b.hand, b.arm_length, b.shoulder_breadth, b.hip_height]
        assert rows[key] == pytest.approx(want, abs=6e-4), key  # printed to the mm
