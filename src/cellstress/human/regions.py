"""ISO/TS 15066 body regions of a point on the worker model (Table A.2's regions: skull and forehead, face,
neck, back and shoulders, chest, abdomen, pelvis, upper arms, forearms, hands, thighs, lower legs).

A contact's region decides its force limit (``criteria.iso15066``) and is part of a hazard's class
(``search.distinct``).
"""

from __future__ import annotations

import numpy as np

from cellstress.human.body import N_CAPSULES, BodyPose

# Body landmarks as fractions of body height (Winter, Fig. 4.1, after Drillis & Contini): knee 0.285 H,
# chest (nipple) 0.720 H; the iliac crest (top of the pelvis) is taken at 0.600 H (our round number).
KNEE = 0.285
PELVIS_TOP = 0.600
CHEST_BOTTOM = 0.720
NECK_HALF_WIDTH = 0.07  # m: the trunk capsule's top within this of the mid-plane is the neck


def body_region(part: int, point, pose: BodyPose, height: float, upper_arm: float, forearm: float) -> str:
    """The ISO/TS 15066 region of a contact on body part ``part`` (index into BODY_PARTS) at ``point``.

    ``pose`` is the worker's ``human.body.BodyPose`` at that step. Legs: lower legs below the knee, thighs
    above. Trunk: pelvis below the iliac crest; above it the back half is back/shoulders, the front half the
    abdomen up to the chest line and the chest above; the top cap within 7 cm of the mid-plane is the neck.
    Head: the face is the front lower part (the outward direction within 73 degrees of forward and less than
    17 degrees above the head centre), the rest skull/forehead, the underside the neck. The articulated worker's
    arms are their capsules: upper arm, forearm, hand. The paper worker's hanging arms: upper arm,
    forearm, hand by the distance from the shoulder. The reach volumes (where a hand *could* be) count as hand
    beyond upper arm + forearm from the shoulder and as forearm within it.
    """
    p = np.asarray(point, dtype=float)
    fwd, left, up = pose.trunk[:, 0], pose.trunk[:, 1], pose.trunk[:, 2]
    if part in (0, 1):
        return "lower-legs" if p[2] < KNEE * height else "thighs"
    if part == 2:
        hip = pose.a[2]
        s = float((p - hip) @ up)  # height along the trunk axis above the hip
        out = p - (hip + s * up)
        rise = 0.818 - 0.530
        if s < (PELVIS_TOP - 0.530) * height:
            return "pelvis"
        if s > rise * height and abs(float(out @ left)) < NECK_HALF_WIDTH:
            return "neck"
        if float(out @ fwd) < 0.0 or s > rise * height:
            return "back-shoulders"
        return "chest" if s >= (CHEST_BOTTOM - 0.530) * height else "abdomen"
    if part == 3:
        d = p - pose.a[3]
        r = float(np.linalg.norm(d))
        if r <= 1e-12:
            return "skull-forehead"
        d = d / r
        if float(d @ up) < -0.8:
            return "neck"
        if float(d @ fwd) > 0.3 and float(d @ up) < 0.3:
            return "face"
        return "skull-forehead"
    if part in (8, 9):  # the articulated worker's forearms and hands; its parts 4 and 5 are the upper arms
        return "forearms"
    if part in (4, 5) and pose.r.shape[0] > N_CAPSULES:
        return "upper-arms"
    if part in (10, 11):
        return "hands"
    side = (part - 4) % 2
    dist = float(np.linalg.norm(p - pose.shoulders[side]))
    if part in (4, 5):
        if dist < upper_arm:
            return "upper-arms"
        return "forearms" if dist < upper_arm + forearm else "hands"
    return "hands" if dist >= upper_arm + forearm else "forearms"


# ISO/TS 15066's regions gathered into the body areas a safety engineer groups findings by (its Table A.2 lists
# them under the same headings: head with face and neck; trunk; upper limbs; lower limbs)
REGION_GROUPS = {
    "skull-forehead": "head", "face": "head", "neck": "head",
    "back-shoulders": "trunk", "chest": "trunk", "abdomen": "trunk", "pelvis": "trunk",
    "upper-arms": "upper limbs", "forearms": "upper limbs", "hands": "upper limbs",
    "thighs": "lower limbs", "lower-legs": "lower limbs",
}


def region_group(region: str) -> str:
    """The body area (head, trunk, upper limbs, lower limbs) of an ISO/TS 15066 region."""
    return REGION_GROUPS.get(region, region)
