"""ISO/TS 15066 power and force limiting: a collision force estimate per body region, and its limits.

A contact (d_HR <= distance tolerance) is **unsafe** when

* the robot moves (v_R > speed tolerance) and the contact is on the skull/forehead or the face, or
* the predicted peak transient force F exceeds the region's transient limit, 2x its quasi-static limit.

F = v_rel * sqrt(mu * k) (ISO/TS 15066 Annex A, eq. A.6 rearranged for F), with the reduced mass
mu = (1/m_H + 1/m_R)^-1, the region's effective mass m_H and spring constant k (Table A.3), the robot's
effective mass m_R at the contact point along the contact normal n (the reflected mass (n J M^-1 J^T n)^-1 from
pinocchio's joint-space inertia M and point Jacobian J, plus the payload), and v_rel the speed of the robot's
contact point towards the human along n, v_rel = max(0, n . J q_dot). The worker's own motion is not included:
see docs/criteria.md for why. Every number and its source: docs/criteria.md.

Body regions: ``body_region`` maps a contact on the worker model (part and point) to an ISO/TS 15066 region.
Reward (``IsoReward``): risk grows with the ratio of the predicted force to the transient limit, and is guarded
against reward hacking (see its docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# ---- ISO/TS 15066:2016 Annex A ------------------------------------------------------------------------------
# region: (quasi-static force limit [N] (Table A.2), effective spring constant [N/mm], effective mass [kg]
# (Table A.3)). Transient limits are 2x the quasi-static ones (Table A.2's transient multiplier).
REGIONS: dict[str, tuple[float, float, float]] = {
    "skull-forehead": (130.0, 150.0, 4.4),
    "face": (65.0, 75.0, 4.4),
    "neck": (150.0, 50.0, 1.2),
    "back-shoulders": (210.0, 35.0, 40.0),
    "chest": (140.0, 25.0, 40.0),
    "abdomen": (110.0, 10.0, 40.0),
    "pelvis": (180.0, 25.0, 40.0),
    "upper-arms": (150.0, 30.0, 3.0),
    "forearms": (160.0, 40.0, 2.0),
    "hands": (140.0, 75.0, 0.6),
    "thighs": (220.0, 50.0, 75.0),
    "lower-legs": (130.0, 60.0, 75.0),
}
TRANSIENT_FACTOR = 2.0
HEAD_REGIONS = ("skull-forehead", "face")  # no contact while the robot moves

# Body landmarks as fractions of body height (Winter, Fig. 4.1, after Drillis & Contini): knee 0.285 H,
# chest (nipple) 0.720 H; the iliac crest (top of the pelvis) is taken at 0.600 H (our round number).
KNEE = 0.285
PELVIS_TOP = 0.600
CHEST_BOTTOM = 0.720
NECK_HALF_WIDTH = 0.07  # m: the trunk capsule's top within this of the mid-plane is the neck


def transient_limit(region: str) -> float:
    return TRANSIENT_FACTOR * REGIONS[region][0]


def peak_force(v_rel: float, m_robot: float, m_human: float, k_n_per_m: float) -> float:
    """Peak transient force F = v sqrt(mu k) of a fully inelastic contact (ISO/TS 15066 A.3)."""
    if v_rel <= 0.0:
        return 0.0
    mu = 1.0 / (1.0 / m_human + (0.0 if math.isinf(m_robot) else 1.0 / m_robot))
    return v_rel * math.sqrt(mu * k_n_per_m)


def region_force(region: str, v_rel: float, m_robot: float) -> float:
    _, k, m_h = REGIONS[region]
    return peak_force(v_rel, m_robot, m_h, k * 1000.0)


def reflected_mass(J_point: np.ndarray, M: np.ndarray, n: np.ndarray) -> float:
    """(n . J M^-1 J^T n)^-1: the robot's inertia felt at a point along the unit direction n (inf if the joints
    cannot move the point along n)."""
    u = J_point.T @ n
    w = float(u @ np.linalg.solve(M, u))
    return math.inf if w <= 1e-12 else 1.0 / w


def point_dynamics(model, data, q, joint_id: int, point) -> tuple[np.ndarray, np.ndarray]:
    """(3 x nv linear Jacobian of a point fixed to pinocchio joint ``joint_id``, given in the model's world frame;
    nv x nv joint-space inertia matrix M(q)) from pinocchio."""
    import pinocchio as pin

    pin.computeJointJacobians(model, data, q)
    Jj = np.asarray(pin.getJointJacobian(model, data, joint_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
    Jj = Jj.reshape(6, model.nv)  # (eigenpy hands a 6 x 1 matrix back as a vector)
    r = np.asarray(point, dtype=float) - data.oMi[joint_id].translation
    skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    M = np.asarray(pin.crba(model, data, q)).reshape(model.nv, model.nv)  # upper triangle filled
    return Jj[:3] - skew @ Jj[3:], np.triu(M) + np.triu(M, 1).T


def body_region(part: int, point, pose, height: float, upper_arm: float, forearm: float) -> str:
    """The ISO/TS 15066 region of a contact on body part ``part`` (index into BODY_PARTS) at ``point``.

    ``pose`` is ``sim.scene.BodyPose`` of the worker at that step. Legs: lower legs below the knee, thighs
    above. Trunk: pelvis below the iliac crest; above it the back half is back/shoulders, the front half the
    abdomen up to the chest line and the chest above; the top cap within 7 cm of the mid-plane is the neck.
    Head: the face is the front lower part (the outward direction within 73 degrees of forward and less than
    17 degrees above the head centre), the rest skull/forehead, the underside the neck. Hanging arms: upper arm,
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
    side = (part - 4) % 2
    dist = float(np.linalg.norm(p - pose.shoulders[side]))
    if part in (4, 5):
        if dist < upper_arm:
            return "upper-arms"
        return "forearms" if dist < upper_arm + forearm else "hands"
    return "hands" if dist >= upper_arm + forearm else "forearms"


@dataclass(frozen=True)
class Contact:
    """The force estimate of one step (at the closest points, whether touching or not)."""

    region: str
    normal: tuple[float, float, float]  # unit, from the robot towards the human
    v_rel: float  # m/s, the robot point's speed towards the human along the normal
    m_robot: float  # kg, reflected mass + payload
    m_human: float
    k: float  # N/m
    force: float  # N
    limit: float  # N, transient limit
    touching: bool
    moving: bool
    unsafe: bool
    reason: str | None

    @property
    def ratio(self) -> float:
        return self.force / self.limit

    def as_dict(self) -> dict:
        return {"region": self.region, "normal": list(self.normal), "v_rel": self.v_rel,
                "m_robot": self.m_robot, "m_human": self.m_human, "k_N_per_m": self.k, "force_N": self.force,
                "limit_N": self.limit, "ratio": self.ratio, "unsafe": self.unsafe, "reason": self.reason}


@dataclass(frozen=True)
class Iso15066:
    """The ``iso15066`` criterion's numbers (the physics is in ``ForceModel``)."""

    distance_tolerance: float = 0.0
    speed_tolerance: float = 0.001
    payload: float = 2.0

    name = "iso15066"

    def judge(self, region: str, force: float, moving: bool) -> tuple[bool, str | None]:
        """(unsafe, reason) of a contact on ``region`` with the predicted force [N]."""
        if moving and region in HEAD_REGIONS:
            return True, f"{region} contact while the robot moves"
        if force > transient_limit(region):
            return True, f"{force:.0f} N > {transient_limit(region):.0f} N transient limit ({region})"
        return False, None

    @staticmethod
    def safety_index(d_hr: float, v_r: float) -> float:
        """The paper's c_S (reported alongside; the search uses ``IsoReward``)."""
        return (d_hr * d_hr + 1.0) * math.exp(-v_r)


class ForceModel:
    """Contact force estimates for a simulator layout: pinocchio dynamics at the robot's joint state of a step."""

    def __init__(self, layout, criterion: Iso15066):
        from cellstress.robot.model import load_pinocchio

        self.layout = layout
        self.crit = criterion
        self.model = load_pinocchio(layout.robot.urdf)
        self.data = self.model.createData()
        P = layout.params
        self.P = P
        self.R_base = np.asarray(P.base[:3, :3])
        self.t_base = np.asarray(P.base[:3, 3])
        b = layout.body
        self.height, self.upper_arm, self.forearm = b.height, b.upper_arm, b.forearm

    def joint_state(self, row) -> tuple[np.ndarray, np.ndarray]:
        from cellstress.sim import scene

        return scene.joint_state(self.layout, row)

    def assess(self, row) -> Contact:
        """The force estimate at a metric row (closest robot point, body part, normal from the geometry)."""
        from cellstress.sim import kernels as K
        from cellstress.sim import scene

        P = self.P
        link, part = int(row[K.M_LINK]), int(row[K.M_PART])
        rp = np.array(row[K.M_RX:K.M_RZ + 1], dtype=float)
        hp = np.array(row[K.M_HX:K.M_HZ + 1], dtype=float)
        pose = scene.body_pose(self.layout, row[K.M_X], row[K.M_Y], row[K.M_HEADING], row[K.M_FWD], row[K.M_LAT])
        q, qd = self.joint_state(row)
        n = scene.contact_normal(self.layout, row, pose)
        region = body_region(part, hp, pose, self.height, self.upper_arm, self.forearm)
        j = int(P.cap_joint[link])
        touching = bool(row[K.M_D] <= self.crit.distance_tolerance)
        moving = bool(row[K.M_V] > self.crit.speed_tolerance)
        if j < 0:  # a capsule on the fixed base
            v_rel, m_r = 0.0, math.inf
        else:
            pb = self.R_base.T @ (rp - self.t_base)  # pinocchio works in the robot base frame
            nb = self.R_base.T @ n
            Jp, M = point_dynamics(self.model, self.data, q, j + 1, pb)
            m_r = reflected_mass(Jp, M, nb) + self.crit.payload
            v_rel = max(0.0, float(nb @ (Jp @ qd)))
        _, k, m_h = REGIONS[region]
        force = peak_force(v_rel, m_r, m_h, k * 1000.0)
        unsafe, reason = self.crit.judge(region, force, moving) if touching else (False, None)
        return Contact(region, (float(n[0]), float(n[1]), float(n[2])), v_rel, m_r, m_h, k * 1000.0, force,
                       transient_limit(region), touching, moving, unsafe, reason)

    def first_unsafe(self, rows) -> int | None:
        """Index of the first row that is unsafe under the criterion (contacts only: they are rare)."""
        from cellstress.sim import kernels as K

        tol = self.crit.distance_tolerance
        for i in np.flatnonzero(rows[:, K.M_D] <= tol):
            if self.assess(rows[i]).unsafe:
                return int(i)
        return None


class IsoReward:
    """Reward and risk of the ``iso15066`` criterion for one action end, from (d_HR, v_R, rho).

    rho is the predicted force ratio F / F_transient at the action's last step (at the closest points, as if
    they touched now; capped at 1 while safe), g = v_R / (v_R + 0.1 m/s) is 0 when the robot stands still.

    * risk = g (1 + min(rho, 1)) / (1 + d_HR^2) while safe (0..2); an unsafe end has risk 1 + max(rho, 1) (>= 2).
    * after an action k < n: reward = risk; after the last action without an unsafe state: risk - 2 (<= 0,
      like the paper's -c_S: a penalty that is smaller the closer and faster the episode ended).
    * reaching an unsafe state: reward = 2 n (a bonus).

    Guards against reward hacking: (1) risk is 0 with the robot at a standstill, so a worker who trips a device
    and then hugs the stopped robot earns nothing (under the paper's 1/c_S such a contact earns 1 per action,
    more than approaching a moving robot from 1 m); (2) under this criterion safe contacts do not end the
    episode, so the unsafe bonus 2 n exceeds what any safe episode can collect (at most 2 (n - 1)), and staying
    in a safe contact to farm per-action rewards never beats a hazard.
    """

    V0 = 0.1

    def __init__(self, horizon: int):
        self.horizon = int(horizon)

    def risk(self, d_hr: float, v_r: float, rho: float, unsafe: bool) -> float:
        if unsafe:
            return 1.0 + max(rho, 1.0)
        g = v_r / (v_r + self.V0) if v_r > 0.0 else 0.0
        return g * (1.0 + min(rho, 1.0)) / (1.0 + d_hr * d_hr)

    def __call__(self, d_hr: float, v_r: float, rho: float, last_action: bool, unsafe: bool):
        risk = self.risk(d_hr, v_r, rho, unsafe)
        if unsafe:
            return 2.0 * self.horizon, risk
        return (risk - 2.0 if last_action else risk), risk
