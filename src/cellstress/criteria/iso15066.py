"""ISO/TS 15066 power and force limiting: a collision force estimate per body region, and its limits.

A contact (d_HR <= distance tolerance) is **quasi-static** (clamping) when a fixed surface of the cell lies behind
the body region, along the direction the robot pushes it, within the region's thickness + ``CLAMP_TOLERANCE``;
**transient** otherwise. It is **unsafe** when

* the robot moves (v_R > speed tolerance) and the contact is on the skull/forehead or the face, or
* the predicted peak force F exceeds the region's limit: its quasi-static limit (Table A.2) when clamped, the
  transient limit (2x) otherwise.

Transient: F = v_rel * sqrt(mu * k) (ISO/TS 15066 Annex A, eq. A.6 rearranged for F), with the reduced mass
mu = (1/m_H + 1/m_R)^-1, the region's effective mass m_H and spring constant k (Table A.3), the robot's
effective mass m_R at the contact point along the contact normal n (the reflected mass the simulator computes
with pinocchio, ``robot.dynamics``, plus the payload), and v_rel the speed of the robot's contact point towards
the human along n plus, while the robot moves faster than ``CREEP_SPEED``, the worker's own speed towards the robot
along n (capped at ``HUMAN_SPEED_CAP``). Clamping: the body region cannot recoil, so the robot's whole effective
mass is felt, and the robot keeps pushing until it stands: F = max(transient F, v_push sqrt(m_R k), k * travel).
Derivations and every number's source: docs/criteria.md.

The simulator has no fast path for this criterion: it hands every contact to ``judge`` (``core.records.Contact``:
body region, normal, v_rel and reflected mass at the closest points), and the force ratio at every action end to
the reward (``severity``). Reward (``IsoReward``): risk grows with the ratio of the predicted force to the
transient limit, and is guarded against reward hacking (see its docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Annotated, Any, Literal

from pydantic import Field

from cellstress.core.records import Contact, Measures
from cellstress.core.surroundings import Backing
from cellstress.criteria.base import CriterionRecord, safety_index

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
# A fixed surface at most this far beyond the body region's far side (its capsule's thickness behind the contact
# point) makes the contact clamping: the body's envelope is approximate, and a centimetre or two of compliant
# tissue, clothing or glove closes such a gap (our choice, docs/criteria.md).
CLAMP_TOLERANCE = 0.02  # m
# The worker's own speed towards the robot counts up to this: ISO 13855's approach speed of a hand or arm,
# K = 2000 mm/s (ISO 13855:2010, 6.2.3). The kinematic worker's posture changes move a body point faster than a
# person can (up to 0.68 m in a 50 ms step for the articulated hand), which would make the model, not the robot,
# the hazard.
HUMAN_SPEED_CAP = 2.0  # m/s

def transient_limit(region: str) -> float:
    return TRANSIENT_FACTOR * REGIONS[region][0]


def creep_speed() -> float:
    """The robot speed [m/s] below which no transient contact exceeds its ISO/TS 15066 limit on any body region
    but the head, however heavy the robot: F = v sqrt(mu k) <= v sqrt(m_H k) (mu < m_H), so the least of
    2 F_qs / sqrt(m_H k) over those regions (Tables A.2 and A.3; the lower legs' 0.123 m/s). Results list contacts
    slower than this apart, after the others (docs/criteria.md)."""
    return min(transient_limit(r) / math.sqrt(m * k * 1000.0) for r, (_, k, m) in REGIONS.items()
               if r not in HEAD_REGIONS)


CREEP_SPEED = creep_speed()


def peak_force(v_rel: float, m_robot: float, m_human: float, k_n_per_m: float) -> float:
    """Peak transient force F = v sqrt(mu k) of a fully inelastic contact (ISO/TS 15066 A.3)."""
    if v_rel <= 0.0:
        return 0.0
    mu = 1.0 / (1.0 / m_human + (0.0 if math.isinf(m_robot) else 1.0 / m_robot))
    return v_rel * math.sqrt(mu * k_n_per_m)


def region_force(region: str, v_rel: float, m_robot: float) -> float:
    _, k, m_h = REGIONS[region]
    return peak_force(v_rel, m_robot, m_h, k * 1000.0)


def quasi_static_limit(region: str) -> float:
    return REGIONS[region][0]


def clamping_force(v_push: float, m_push: float, k_n_per_m: float, travel: float) -> float:
    """The force [N] on a body region clamped against a fixed surface, from the robot alone: the larger of the
    robot's kinetic energy along the push compressed into the region (1/2 m_R v^2 = F^2 / (2 k): the region cannot
    recoil, so the reduced mass is the robot's own) and the region compressed by the robot's further travel
    until it stands (F = k * travel). docs/criteria.md derives both. An infinite reflected mass (the joints cannot
    move the point along the push, to numerical precision) has no kinetic energy along it to speak of: the travel
    term alone, the robot driving the point along its path, gives the force (and keeps it finite)."""
    if v_push <= 0.0 or math.isinf(m_push):
        energy = 0.0
    else:
        energy = v_push * math.sqrt(m_push * k_n_per_m)
    return max(energy, k_n_per_m * max(0.0, travel))


@dataclass(frozen=True)
class ForceVerdict:
    """The force estimate of one contact (at the closest points, whether touching or not) and its judgement."""

    region: str
    normal: tuple[float, float, float]  # unit, from the robot towards the human
    v_rel: float  # m/s, the relative speed along the normal: the robot point's, plus the worker's counted
    m_robot: float  # kg, reflected mass + payload
    m_human: float
    k: float  # N/m
    force: float  # N
    limit: float  # N: the quasi-static limit when clamped, else the transient limit
    touching: bool
    moving: bool
    unsafe: bool
    reason: str | None
    case: str = "transient"  # or "clamping"
    v_human: float = 0.0  # m/s, the worker's speed towards the robot counted in v_rel
    backing: Backing | None = None  # the fixed surface found behind the body region (within the search range)

    @property
    def ratio(self) -> float:
        return self.force / self.limit

    def why_case(self) -> str:
        """Why the contact is clamping or transient, in words: the surface found and the gap."""
        b = self.backing
        if b is None:
            return "no fixed surface behind the body region"
        where = (f"{b.surface} {b.distance * 1000:.0f} mm behind the contact, the body region "
                 f"{b.thickness * 1000:.0f} mm thick")
        if self.case == "clamping":
            return f"clamped against the {where}"
        return f"free: the {where} (gap {b.gap * 1000:.0f} mm > {CLAMP_TOLERANCE * 1000:.0f} mm)"

    def summary(self) -> str:
        if self.reason:
            return self.reason
        kind = "quasi-static" if self.case == "clamping" else "transient"
        return f"{self.force:.0f} N against a {self.limit:.0f} N limit ({kind}, {self.region}; {self.why_case()})"

    def as_dict(self) -> dict[str, Any]:
        b = self.backing
        return {"region": self.region, "normal": list(self.normal), "v_rel": self.v_rel,
                "m_robot": self.m_robot, "m_human": self.m_human, "k_N_per_m": self.k, "force_N": self.force,
                "limit_N": self.limit, "ratio": self.ratio, "unsafe": self.unsafe, "reason": self.reason,
                "case": self.case, "v_human": self.v_human, "why_case": self.why_case(),
                "surface": None if b is None else b.surface, "gap_m": None if b is None else b.gap,
                "travel_m": b.travel if self.case == "clamping" else None}


class Iso15066(CriterionRecord):
    """``payload`` [kg] is added to the robot's reflected mass (see docs/criteria.md)."""

    type: Literal["iso15066"] = "iso15066"
    """A contact is unsafe when its estimated force exceeds the ISO/TS 15066 limit of its body region (quasi-static
    when the region is clamped against a fixed surface, transient otherwise)."""
    payload: Annotated[float, Field(ge=0.0, le=1000.0)] = 2.0
    """Mass [kg] added to the robot's reflected mass (tool and part)."""

    def describe(self) -> str:
        return ("unsafe when a contact's estimated peak force exceeds the ISO/TS 15066 limit of the body region "
                "touched (quasi-static when the region is clamped against a fixed surface within its thickness + "
                f"{CLAMP_TOLERANCE * 1000:.0f} mm, transient otherwise; the worker's own speed towards a robot faster "
                f"than {CREEP_SPEED:.3f} m/s counted, up to {HUMAN_SPEED_CAP:g} m/s), or the head is touched while "
                "the robot moves (robot payload "
                f"{self.payload:g} kg; docs/criteria.md)")

    def rule(self, region: str, force: float, moving: bool, clamped: bool = False) -> tuple[bool, str | None]:
        """(unsafe, reason) of a contact on ``region`` with the predicted force [N]; ``clamped``: judged against
        the quasi-static limit instead of the transient one."""
        if moving and region in HEAD_REGIONS:
            return True, f"{region} contact while the robot moves"
        limit = quasi_static_limit(region) if clamped else transient_limit(region)
        if force > limit:
            kind = "quasi-static" if clamped else "transient"
            return True, f"{force:.0f} N > {limit:.0f} N {kind} limit ({region})"
        return False, None

    @staticmethod
    def clamped(backing: Backing | None) -> bool:
        """A fixed surface within the body region's thickness + CLAMP_TOLERANCE behind the contact point."""
        return backing is not None and backing.gap <= CLAMP_TOLERANCE

    def kernel_test(self) -> None:
        return None

    def assess(self, contact: Contact) -> ForceVerdict:
        """The force estimate at ``contact`` and its verdict. A plain ``core.records.Contact`` (no surroundings)
        is judged transient, with the robot's speed alone; a ``core.surroundings.ContactInCell`` as the module
        docstring says."""
        m_r = contact.reflected_mass + self.payload
        _, k, m_h = REGIONS[contact.region]
        k = k * 1000.0
        moving = bool(contact.v_r > self.speed_tolerance)
        # the worker's speed towards the robot counts while the robot moves faster than it creeps: below
        # CREEP_SPEED the robot's own motion brings no region but the head over its limit, and the worker meets
        # a robot that practically stands, as they would a machine part (docs/criteria.md)
        v_human = min(HUMAN_SPEED_CAP, float(getattr(contact, "v_human", 0.0))) if contact.v_r > CREEP_SPEED else 0.0
        v_rel = contact.v_rel + v_human
        force = peak_force(v_rel, m_r, m_h, k)
        backing = getattr(contact, "backing", None)
        clamped = self.clamped(backing)
        if clamped:
            force = max(force, clamping_force(backing.v_push, backing.m_push + self.payload, k, backing.travel))
        touching = bool(contact.d_hr <= self.distance_tolerance)
        unsafe, reason = self.rule(contact.region, force, moving, clamped) if touching else (False, None)
        verdict = ForceVerdict(contact.region, contact.normal, v_rel, m_r, m_h, k, force,
                               quasi_static_limit(contact.region) if clamped else transient_limit(contact.region),
                               touching, moving, unsafe, reason, "clamping" if clamped else "transient", v_human,
                               backing)
        if reason is None:
            return verdict
        worker = f"; v_rel {v_rel:.2f} m/s with the worker's {v_human:.2f} m/s towards the robot" if v_human else ""
        return replace(verdict, reason=f"{reason}: {verdict.why_case()}{worker}")

    def judge(self, contact: Contact) -> ForceVerdict:
        return self.assess(contact)

    def severity(self, contact: Contact) -> float:
        """The predicted force over its limit (quasi-static when clamped, else transient) at the closest points,
        as if they touched now."""
        return float(self.assess(contact).ratio)

    @staticmethod
    def safety_index(d_hr: float, v_r: float) -> float:
        """The paper's c_S (reported alongside; the search uses ``IsoReward``)."""
        return safety_index(d_hr, v_r)

    def reward(self, horizon: int) -> IsoReward:
        return IsoReward(horizon)


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

    def __call__(self, measures: Measures, last_action: bool, unsafe: bool) -> tuple[float, float]:
        risk = self.risk(measures.d_hr, measures.v_r, measures.severity, unsafe)
        if unsafe:
            return 2.0 * self.horizon, risk
        return (risk - 2.0 if last_action else risk), risk
