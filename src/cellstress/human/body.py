"""The worker's body: capsules for legs, trunk, head and hanging arms, placed from the body height.

Segment proportions are fractions of body height H from Drillis & Contini (1966) as tabulated in Winter,
*Biomechanics and Motor Control of Human Movement* (4th ed., Fig. 4.1): hip (greater trochanter) 0.530 H,
shoulder 0.818 H, chin 0.870 H, shoulder width 0.259 H, hip width 0.191 H. Radii are round numbers for an
adult man in work clothes (see docs/cells.md). The trunk pivots at the hip: forward flexion about the body's
left axis, lateral flexion about its forward axis. Legs stay vertical (but for the articulated worker lying prone:
kernels.body.pose_body); arms at rest hang straight down.
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
    "left-forearm",
    "right-forearm",
    "left-hand",
    "right-hand",
)
N_CAPSULES = 6  # the paper worker's capsules are the first six parts; the next two are its reach volumes
# The articulated worker (human.articulated) has ten capsules: the six above (its "arms" are the upper arms),
# then forearms and hands. Capsule c is body part CAPSULE_PART[c] (the reach volumes sit between).
MAX_CAPSULES = 10
CAPSULE_PART: tuple[int, ...] = (0, 1, 2, 3, 4, 5, 8, 9, 10, 11)
MODEL_PAPER, MODEL_ARTICULATED = 0.0, 1.0  # BODY_PARAMS' MODEL: how the kernels pose the arms
NO_WALK_BELOW = -0.15  # m: with the hip this far below standing (crouching, kneeling) the worker does not walk
BODY_RADIUS = 0.20  # m, the footprint that keeps the body centre from fences and table edges
WALK_BLOCK_HEIGHT = 0.5  # m: a fence panel whose bottom is above this does not stop walking (the worker ducks)
R_TRUNK = 0.15  # m, the trunk capsule's radius
# The crawling (prone) body of the articulated worker: lying on the floor, its trunk capsule's axis at R_TRUNK, so
# the body is 2 R_TRUNK = 0.30 m high: ISO 13855's 300 mm (core.iso13855.CRAWL_UNDER_MAX_MM), the plane height at
# which the standard counts on a crawling person being detected. PRONE_HEIGHT is THE rule for passing under a
# panel prone (kernels.sensing.panel_stops_body) and the height `check` names (analysis.openings); docs/worker.md.
PRONE_HIP_Z = R_TRUNK  # m: the hip (the trunk's pivot) when prone
PRONE_HEIGHT = 2.0 * R_TRUNK  # m: the prone body's top; it passes under a panel whose bottom is above this
PRONE_BEGIN_Z = 0.22  # m: from this hip height down the body tips forward to prone (below every crouch, 0.167 H)
PRONE_TOL = 1e-9  # m: a hip this close to PRONE_HIP_Z is prone (the stance's drop is computed in floating point)
# Crawling speed [m/s]: low crawling (body on the floor), 0.77 m/s, the mean of 24 young adults over up to 91 m
# (Cao, Davis, Gallagher, Schall, Sesek, Safety Science 104:1-9, 2018); never faster than the cell's walking speed.
CRAWL_SPEED = 0.77

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
    # the articulated worker (appended, so the slots above never move)
    ("MODEL", "0: the paper's worker (hanging arms, reach volumes); 1: articulated arms (human.articulated)"),
    ("N_CAPS", "body capsules the kernels pose, sense and measure: 6 (paper) or 10 (articulated)"),
    ("UPPER_ARM", "shoulder to elbow [m]"),
    ("FOREARM", "elbow to wrist [m]"),
    ("HAND", "wrist to fingertip [m]"),
    ("R_UPPER", "upper-arm capsule radius of the articulated worker [m]"),
    ("R_FORE", "forearm capsule radius [m]"),
    ("R_HAND", "hand capsule radius [m]"),
))
(B_HIP_Z, B_SHOULDER_RISE, B_SHOULDER_HALF, B_LEG_HALF, B_HEAD_RISE, B_TRUNK_TOP, B_R_LEG, B_R_TRUNK, B_R_HEAD,
 B_R_ARM, B_ARM_LEN, B_BODY_RADIUS, B_WALK_SPEED, B_MODEL, B_N_CAPS, B_UPPER_ARM, B_FOREARM, B_HAND, B_R_UPPER,
 B_R_FORE, B_R_HAND) = BODY_PARAMS.indices(
    "HIP_Z", "SHOULDER_RISE", "SHOULDER_HALF", "LEG_HALF", "HEAD_RISE", "TRUNK_TOP", "R_LEG", "R_TRUNK", "R_HEAD",
    "R_ARM", "ARM_LEN", "BODY_RADIUS", "WALK_SPEED", "MODEL", "N_CAPS", "UPPER_ARM", "FOREARM", "HAND", "R_UPPER",
    "R_FORE", "R_HAND")
N_BODY_PARAMS = BODY_PARAMS.size


@dataclass(frozen=True)
class BodyDimensions:
    height: float
    upper_arm: float
    forearm: float
    hand: float
    walking_speed: float
    body_radius: float = BODY_RADIUS
    articulated: bool = False

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
        p[B_R_TRUNK] = R_TRUNK
        p[B_R_HEAD] = 0.10
        p[B_R_ARM] = 0.05
        p[B_ARM_LEN] = self.arm_length
        p[B_BODY_RADIUS] = self.body_radius
        p[B_WALK_SPEED] = self.walking_speed
        p[B_MODEL] = MODEL_ARTICULATED if self.articulated else MODEL_PAPER
        p[B_N_CAPS] = MAX_CAPSULES if self.articulated else N_CAPSULES
        p[B_UPPER_ARM], p[B_FOREARM], p[B_HAND] = self.upper_arm, self.forearm, self.hand
        # Round numbers for an adult's limbs in work clothes (as the radii above): the upper arm as the hanging
        # arm, the forearm between its mid-length and the wrist, the hand about its thickness (docs/worker.md).
        p[B_R_UPPER], p[B_R_FORE], p[B_R_HAND] = 0.05, 0.04, 0.025
        return p


@dataclass(frozen=True, eq=False)
class BodyPose:
    """The worker's capsules (``a``-``b`` axis, radius ``r``; capsule c is body part ``CAPSULE_PART[c]``: a[2] is
    the hip, a[3] the head centre), shoulders (left, right) and trunk frame (columns: forward, left, up) for one
    pose: six capsules for the paper's worker, ten for the articulated one."""

    a: np.ndarray  # (n, 3)
    b: np.ndarray  # (n, 3)
    r: np.ndarray  # (n,)
    shoulders: np.ndarray  # (2, 3)
    trunk: np.ndarray  # (3, 3)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(BODY_PARTS[CAPSULE_PART[c]] for c in range(self.r.shape[0]))
