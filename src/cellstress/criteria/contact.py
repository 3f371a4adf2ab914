"""The paper's criterion: no contact unless the robot stands still, U = {s : v_R > 0, d_HR = 0}.

Tolerances: contact means d_HR <= ``distance_tolerance`` (default 0: touching or overlapping); moving means
v_R > ``speed_tolerance`` (default 1 mm/s, so that the float residue of a completed stop is a standstill).
The simulator evaluates the predicate in its compiled loop with these two numbers; this object is the
readable reference and the reward.

Reward (paper, sec. IV): the safety index c_S = (d_HR^2 + 1) exp(-v_R) is large when safe. After each action
k < n the search receives 1 / c_S; an episode that ends at k = n without reaching U receives -c_S instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cellstress.cell.schema import CriterionSpec


@dataclass(frozen=True)
class ContactWhileMoving:
    distance_tolerance: float = 0.0
    speed_tolerance: float = 0.001

    name = "contact-while-moving"

    def is_unsafe(self, d_hr: float, v_r: float) -> bool:
        return d_hr <= self.distance_tolerance and v_r > self.speed_tolerance

    @staticmethod
    def safety_index(d_hr: float, v_r: float) -> float:
        return (d_hr * d_hr + 1.0) * math.exp(-v_r)

    def reward(self, d_hr: float, v_r: float, last_action: bool, unsafe: bool) -> float:
        """Reward after one action (the paper's eq. for R; an unsafe end is rewarded like any other step)."""
        c = self.safety_index(d_hr, v_r)
        if last_action and not unsafe:
            return -c
        return 1.0 / c


def criterion_for(spec: CriterionSpec):
    """The criterion object of a cell file's ``criterion`` record."""
    if spec.type == "iso15066":
        from cellstress.criteria.iso15066 import Iso15066

        return Iso15066(spec.distance_tolerance, spec.speed_tolerance, spec.payload)
    return ContactWhileMoving(spec.distance_tolerance, spec.speed_tolerance)


def with_criterion(cell, name: str | None):
    """``cell`` judged by the criterion ``name`` (its tolerances kept); the cell itself if ``name`` is None or
    already its criterion. CellstressError for an unknown name."""
    from dataclasses import replace

    from cellstress.cell.schema import CRITERIA
    from cellstress.errors import CellstressError

    if name is None or name == cell.spec.criterion.type:
        return cell
    if name not in CRITERIA:
        raise CellstressError(f"unknown criterion {name!r} (choose from {', '.join(CRITERIA)})")
    crit = cell.spec.criterion.model_copy(update={"type": name})
    return replace(cell, spec=cell.spec.model_copy(update={"criterion": crit}))
