"""Body sizes from the 5th percentile woman to the 95th percentile man, postures and gait speeds, with sources.

Body sizes (``BODY_SIZES``). One survey: British adults aged 19 to 65, 5th, 50th and 95th percentiles of men
and women, as printed on the dimension pages of City University of Hong Kong's "Online Anthropometry"
(Chapter 2, dimension N on page Ch2-N). It is the British adult population of Pheasant and Haslegrave's
*Bodyspace*; the book itself is not in our reference library, only these pages.

- ``stature``: dimension 1, stature (floor to vertex): women 1505 / 1610 / 1710 mm, men 1625 / 1740 / 1855 mm.
- ``upper_arm``: dimension 22, shoulder-elbow length (acromion to the underside of the elbow, sitting):
  women 300 / 330 / 360 mm, men 330 / 365 / 395 mm. It ends below the elbow, so it is a few centimetres longer
  than the joint-centre length (Drillis & Contini's 0.186 H gives 324 mm for the median man): an arm that
  reaches a little further, the safe side for a reach search.
- ``shoulder_breadth``: dimension 18, biacromial breadth: women 325 / 355 / 380 mm, men 365 / 400 / 430 mm.
- ``forearm``, ``hand``, ``hip_height``: not taken from the survey. Its hand length page (dimension 28) is not in
  the reference library, and the stored copies of dimension 23 (elbow-fingertip length) lack the women's 95th
  percentile and of dimension 5 (hip height) the women's columns. So these three come from the survey's stature
  with Drillis & Contini's proportions (Winter, *Biomechanics and Motor Control of Human Movement*, Fig. 4.1;
  the ones human/body.py uses): forearm 0.146 H, hand 0.108 H, hip (greater trochanter) 0.530 H. Check against
  the survey where it has a column: the men's hip heights 840 / 920 / 1000 mm against 0.530 H = 861 / 922 / 983.

Postures (``POSTURES``) put the hip (greater trochanter) at a fraction of stature, from Drillis & Contini's
segment lengths (foot height 0.039 H, shank 0.246 H, thigh 0.245 H; they add up to the standing hip, 0.530 H)
and normal joint ranges: see each posture's ``derivation``. Gait (``GAITS``): walking backwards and sideways as
fractions of forward walking; assumptions, as written there.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

# Drillis & Contini (1966) segment lengths as fractions of stature H, after Winter, Fig. 4.1
UPPER_ARM_FRACTION = 0.186
FOREARM_FRACTION = 0.146
HAND_FRACTION = 0.108
THIGH_FRACTION = 0.245  # hip (greater trochanter) to knee
SHANK_FRACTION = 0.246  # knee to ankle
FOOT_HEIGHT_FRACTION = 0.039  # ankle above the floor
HIP_FRACTION = FOOT_HEIGHT_FRACTION + SHANK_FRACTION + THIGH_FRACTION  # 0.530, as human/body.py
# Normal joint ranges [deg]: knee flexion 0-135 (the AAOS normative range) and ankle dorsiflexion 0-20 (World J
# Orthop 2017, 8(1):21-29, Table 5, which gives plantar flexion 0-50)
KNEE_FLEXION_DEG = 135.0
ANKLE_DORSIFLEXION_DEG = 20.0

SURVEY = ("British adults aged 19-65 (the population of Pheasant & Haslegrave, Bodyspace) as printed by City "
          "University of Hong Kong, Online Anthropometry, Chapter 2: dimensions 1 (stature), 18 (biacromial "
          "breadth), 22 (shoulder-elbow length)")


@dataclass(frozen=True)
class BodySize:
    """A worker's body dimensions [m]."""

    stature: float
    """Standing height, floor to the top of the head [m]."""
    upper_arm: float
    """Upper arm: shoulder (acromion) to elbow [m]."""
    forearm: float
    """Forearm: elbow to wrist [m]."""
    hand: float
    """Hand: wrist crease to the tip of the middle finger [m]."""
    shoulder_breadth: float | None = None
    """Distance between the two acromia (biacromial breadth) [m]; None where no source gives it."""
    hip_height: float | None = None
    """Height of the hip (greater trochanter) above the floor, standing [m]; None where no source gives it."""

    def __post_init__(self) -> None:
        for name in ("stature", "upper_arm", "forearm", "hand", "shoulder_breadth", "hip_height"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"BodySize.{name} must be a finite length > 0 m, got {v!r}")

    @property
    def arm_length(self) -> float:
        """Upper arm + forearm + hand [m]."""
        return self.upper_arm + self.forearm + self.hand


def from_stature(stature: float, upper_arm: float | None = None, shoulder_breadth: float | None = None) -> BodySize:
    """A body of the given stature [m]: forearm, hand and hip height by Drillis & Contini's proportions; the
    upper arm too unless a measured one is given."""
    h = float(stature)
    if not (math.isfinite(h) and h > 0.0):
        raise ValueError(f"stature must be a finite length > 0 m, got {stature!r}")
    return BodySize(stature=h, upper_arm=UPPER_ARM_FRACTION * h if upper_arm is None else upper_arm,
                    forearm=FOREARM_FRACTION * h, hand=HAND_FRACTION * h, shoulder_breadth=shoulder_breadth,
                    hip_height=HIP_FRACTION * h)


# percentile -> (stature, shoulder-elbow length, biacromial breadth) [mm], SURVEY
_SURVEY_MM: dict[str, tuple[int, int, int]] = {
    "p5-female": (1505, 300, 325),
    "p50-female": (1610, 330, 355),
    "p95-female": (1710, 360, 380),
    "p5-male": (1625, 330, 365),
    "p50-male": (1740, 365, 400),
    "p95-male": (1855, 395, 430),
}
BODY_SIZES: Mapping[str, BodySize] = MappingProxyType({
    key: from_stature(h / 1000, upper_arm=ua / 1000, shoulder_breadth=sb / 1000)
    for key, (h, ua, sb) in _SURVEY_MM.items()})


@dataclass(frozen=True)
class Posture:
    """A whole-body posture: where it puts the hip, and how far it lifts the body."""

    name: str
    """The posture's name: stand, crouch, kneel or tiptoe."""
    hip_fraction: float
    """Height of the hip (greater trochanter) above the floor as a fraction of stature, on flat feet."""
    rise: float
    """Lift of the whole body above its flat-footed pose [m] (tiptoe's heel lift); 0 for the others."""
    derivation: str
    """How the numbers follow from their sources, or that they are an assumption."""

    def hip_height(self, stature: float) -> float:
        """The hip's height above the floor [m] for a body of this stature [m]."""
        return self.hip_fraction * stature + self.rise


def _crouch_hip_fraction() -> float:
    # heels down, the shank leans forward by the full ankle dorsiflexion; the thigh turns back from the shank's
    # line by the full knee flexion, so it points 115 deg from vertical, down and back
    shank = math.radians(ANKLE_DORSIFLEXION_DEG)
    thigh = shank - math.radians(KNEE_FLEXION_DEG)
    return FOOT_HEIGHT_FRACTION + SHANK_FRACTION * math.cos(shank) + THIGH_FRACTION * math.cos(thigh)


TIPTOE_RISE = 0.08  # m, an assumption: see POSTURES["tiptoe"]
POSTURES: Mapping[str, Posture] = MappingProxyType({
    "stand": Posture("stand", HIP_FRACTION, 0.0,
                     "Drillis & Contini: foot height 0.039 H + shank 0.246 H + thigh 0.245 H = 0.530 H."),
    "crouch": Posture("crouch", _crouch_hip_fraction(), 0.0,
                      "Deep squat, heels down: the shank leans forward by the full ankle dorsiflexion (20 deg) and "
                      "the knee is flexed fully (135 deg), so the thigh points down and back, 115 deg from "
                      "vertical: 0.039 H + 0.246 H cos 20 deg + 0.245 H cos 115 deg = 0.167 H."),
    "kneel": Posture("kneel", THIGH_FRACTION, 0.0,
                     "Upright on both knees, thighs vertical: the hip is a thigh (0.245 H) above the knee joint, "
                     "whose centre is taken at the floor. Drillis & Contini give no knee depth, so the knee's "
                     "height above the floor (a few centimetres) is left out: a lower bound."),
    "tiptoe": Posture("tiptoe", HIP_FRACTION, TIPTOE_RISE,
                      "The standing hip (0.530 H) lifted by the heel lift. The reference library has no measured "
                      "heel-lift height and Drillis & Contini give no ankle-to-ball-of-foot length, so the lift "
                      "of 0.08 m is an assumption. For scale: an ankle-to-ball lever of 0.18 m (0.7 of the "
                      "median man's foot length, 0.152 H) turned by 25 deg (half the 50 deg plantar flexion "
                      "range) lifts the ankle 0.08 m."),
})


@dataclass(frozen=True)
class Gait:
    """A walking direction other than forward, as a fraction of the forward walking speed."""

    name: str
    """``step-back`` (walking backwards) or ``side-step`` (walking sideways)."""
    speed_fraction: float
    """Speed as a fraction of the worker's forward walking speed."""
    derivation: str
    """Where the fraction comes from, or that it is an assumption."""


GAITS: Mapping[str, Gait] = MappingProxyType({
    "step-back": Gait("step-back", 0.7,
                      "Assumption. Laufer (2005, J Gerontol A 60(5):627) found backward walking slower than forward "
                      "walking in young and old adults (shorter strides at an unchanged cadence); the library "
                      "holds no ratio we could read, so we take 0.7 of the forward speed."),
    "side-step": Gait("side-step", 0.7,
                      "Assumption: no study of sideways walking speed in the library; taken equal to step-back. "
                      "ISO 13855's approach speed (1.6 m/s) applies in every direction, so a cell that wants the "
                      "standard's worst case sets the worker's speed, not this fraction."),
})
