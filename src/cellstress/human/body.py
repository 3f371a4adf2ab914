"""The worker's body: capsules for legs, trunk, head and hanging arms, placed from the body height.

Segment proportions are fractions of body height H from Drillis & Contini (1966) as tabulated in Winter,
*Biomechanics and Motor Control of Human Movement* (4th ed., Fig. 4.1): hip (greater trochanter) 0.530 H,
shoulder 0.818 H, chin 0.870 H, shoulder width 0.259 H, hip width 0.191 H. Radii are round numbers for an
adult man in work clothes (see docs/cells.md). The trunk pivots at the hip: forward flexion about the body's
left axis, lateral flexion about its forward axis. Legs stay vertical; arms at rest hang straight down.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.core.vector_spec import VectorSpec

BODY_PARTS: tuple[str, ...] = (
    "left-leg",
    "right-leg",
    "trunk",
    "head",
    "left-arm",
    "right-arm",
    "left-reach",
    "right-reach",
)
N_CAPSULES = 6  # the first six parts are capsules; the last two are the reach volumes
BODY_RADIUS = 0.20  # m, the footprint that keeps the body centre from fences and table edges
WALK_BLOCK_HEIGHT = 0.5  # m: a fence panel whose bottom is above this does not stop walking (the worker ducks)

# The body parameter vector the compiled simulator poses the worker from (``BodyDimensions.params``).
BODY_PARAMS = VectorSpec("body parameters", (
    ("HIP_Z", "hip height above the floor [m]: the legs' top and the trunk's pivot"),
    ("SHOULDER_RISE", "shoulder joints above the hip, along the trunk [m]"),
    ("SHOULDER_HALF", "shoulder joint to the trunk's axis, sideways [m]"),
    ("LEG_HALF", "leg axis to the body's centre line, sideways [m]"),
    ("HEAD_RISE", "head centre above the hip, along the trunk [m]"),
    ("TRUNK_TOP", "top of the trunk capsule's axis above the hip [m]"),
    ("R_LEG", "leg capsule radius [m]"),
    ("R_TRUNK", "trunk capsule radius [m]"),
    ("R_HEAD", "head sphere radius [m]"),
    ("R_ARM", "hanging-arm capsule radius [m]"),
    ("ARM_LEN", "upper arm + forearm + hand [m]: the reach volumes lie within it of the shoulder"),
    ("BODY_RADIUS", "footprint radius kept clear of fences and table edges [m]"),
    ("WALK_SPEED", "walking speed [m/s]"),
))
(B_HIP_Z, B_SHOULDER_RISE, B_SHOULDER_HALF, B_LEG_HALF, B_HEAD_RISE, B_TRUNK_TOP, B_R_LEG, B_R_TRUNK, B_R_HEAD,
 B_R_ARM, B_ARM_LEN, B_BODY_RADIUS, B_WALK_SPEED) = BODY_PARAMS.indices(
    "HIP_Z", "SHOULDER_RISE", "SHOULDER_HALF", "LEG_HALF", "HEAD_RISE", "TRUNK_TOP", "R_LEG", "R_TRUNK", "R_HEAD",
    "R_ARM", "ARM_LEN", "BODY_RADIUS", "WALK_SPEED")
N_BODY_PARAMS = BODY_PARAMS.size


@dataclass(frozen=True)
class BodyDimensions:
    height: float
    upper_arm: float
    forearm: float
    hand: float
    walking_speed: float
    body_radius: float = BODY_RADIUS

    @property
    def arm_length(self) -> float:
        return self.upper_arm + self.forearm + self.hand

    @property
    def hip_height(self) -> float:
        return 0.530 * self.height

    @property
    def shoulder_rise(self) -> float:
        return (0.818 - 0.530) * self.height

    def params(self) -> np.ndarray:
        h = self.height
        p = np.zeros(N_BODY_PARAMS)
        p[B_HIP_Z] = self.hip_height
        p[B_SHOULDER_RISE] = self.shoulder_rise
        p[B_SHOULDER_HALF] = 0.259 * h / 2 - 0.05  # shoulder joint centre, inside the deltoid
        p[B_LEG_HALF] = 0.191 * h / 4  # each leg axis halfway between hip centre and hip side
        p[B_HEAD_RISE] = (0.935 - 0.530) * h  # head centre between chin (0.870 H) and vertex (1.0 H)
        p[B_TRUNK_TOP] = (0.818 - 0.530) * h - 0.03
        p[B_R_LEG] = 0.07
        p[B_R_TRUNK] = 0.15
        p[B_R_HEAD] = 0.10
        p[B_R_ARM] = 0.05
        p[B_ARM_LEN] = self.arm_length
        p[B_BODY_RADIUS] = self.body_radius
        p[B_WALK_SPEED] = self.walking_speed
        return p


@dataclass(frozen=True, eq=False)
class BodyPose:
    """The worker's capsules (``a``-``b`` axis, radius ``r``; order ``BODY_PARTS[:6]``: a[2] is the hip, a[3] the
    head centre), shoulders (left, right) and trunk frame (columns: forward, left, up) for one pose."""

    a: np.ndarray  # (6, 3)
    b: np.ndarray  # (6, 3)
    r: np.ndarray  # (6,)
    shoulders: np.ndarray  # (2, 3)
    trunk: np.ndarray  # (3, 3)

    @property
    def names(self) -> tuple[str, ...]:
        return BODY_PARTS[:N_CAPSULES]
