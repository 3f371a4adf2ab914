"""The paper's criterion: no contact unless the robot stands still, U = {s : v_R > 0, d_HR = 0}.

The simulator evaluates it in its compiled loop (``kernel_test``: d_HR <= distance tolerance and v_R above the
speed tolerance); ``judge`` is the same predicate on a ``Contact``, the readable reference.

Reward (paper, sec. IV): the safety index c_S = (d_HR^2 + 1) exp(-v_R) is large when safe. After each action
k < n the search receives 1 / c_S; an episode that ends at k = n without reaching U receives -c_S instead.
Reaching U ends the episode and is rewarded like any other step (1/c_S = e^{v_R}, since d_HR = 0): the paper
gives no bonus, and neither do we.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

from cellstress.core.records import Contact, KernelTest, Measures
from cellstress.criteria.base import CriterionRecord, safety_index


@dataclass(frozen=True)
class MovingContact:
    """The verdict of ``contact-while-moving`` on one contact."""

    touching: bool
    moving: bool
    v_r: float

    @property
    def unsafe(self) -> bool:
        return self.touching and self.moving

    @property
    def reason(self) -> str | None:
        return f"contact while the robot moves at {self.v_r:.3f} m/s" if self.unsafe else None

    def summary(self) -> str:
        return self.reason or ("contact with the robot at a standstill" if self.touching else "no contact")

    def as_dict(self) -> dict[str, Any]:
        return {"unsafe": self.unsafe, "reason": self.reason, "v_R": self.v_r}


class ContactWhileMoving(CriterionRecord):
    type: Literal["contact-while-moving"] = "contact-while-moving"
    """No contact unless the robot stands still (the paper's unsafe set)."""

    def describe(self) -> str:
        return (f"unsafe when the worker touches the robot (d_HR at most {self.distance_tolerance:g} m) while it "
                f"moves (v_R above {self.speed_tolerance:g} m/s), whatever the force (the paper's criterion)")

    def is_unsafe(self, d_hr: float, v_r: float) -> bool:
        return d_hr <= self.distance_tolerance and v_r > self.speed_tolerance

    def kernel_test(self) -> KernelTest:
        return KernelTest(self.distance_tolerance, self.speed_tolerance)

    def judge(self, contact: Contact) -> MovingContact:
        return MovingContact(contact.d_hr <= self.distance_tolerance, contact.v_r > self.speed_tolerance,
                             contact.v_r)

    def severity(self, contact: Contact) -> None:
        return None

    @staticmethod
    def safety_index(d_hr: float, v_r: float) -> float:
        return safety_index(d_hr, v_r)

    def reward(self, horizon: int) -> SafetyIndexReward:
        return SafetyIndexReward(self)


class SafetyIndexReward:
    """The paper's reward and risk (1/c_S) for one action end, from a criterion's ``safety_index``."""

    def __init__(self, criterion):
        self.criterion = criterion
        self.safety_index = criterion.safety_index

    def __call__(self, measures: Measures, last_action: bool, unsafe: bool) -> tuple[float, float]:
        """(reward, risk) after one action; risk = 1/c_S."""
        c = self.safety_index(measures[0], measures[1])
        return (-c if last_action and not unsafe else 1.0 / c), 1.0 / c
