"""What every criterion record has: the tolerances that say when a contact is one and when the robot moves."""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field

from cellstress.core.fields import Record


class CriterionRecord(Record):
    """The fields every criterion shares. A criterion kind is a subclass with a ``type: Literal[...]`` tag (its
    name in cell files and in the ``cellstress.criteria`` registry) and the ``core.protocols.Criterion`` methods.

    ``distance_tolerance`` [m]: a contact is d_HR at or below it (default 0: touching or overlapping);
    ``speed_tolerance`` [m/s]: the robot moves when v_R is above it (default 1 mm/s, so that the float residue of
    a completed stop is a standstill)."""

    distance_tolerance: Annotated[float, Field(ge=0.0, le=0.1)] = 0.0
    """A contact is d_HR at or below this [m]."""
    speed_tolerance: Annotated[float, Field(ge=0.0, le=0.1)] = 0.001
    """The robot moves when v_R is above this [m/s] (the float residue of a completed stop is a standstill)."""

    def describe(self) -> str:
        """What this criterion calls unsafe, in one sentence; a criterion kind says it better by overriding."""
        return (f"unsafe as the {getattr(self, 'type', type(self).__name__)} criterion judges a contact (contact: "
                f"d_HR at most {self.distance_tolerance:g} m; the robot moves: v_R above {self.speed_tolerance:g} m/s)")


def safety_index(d_hr: float, v_r: float) -> float:
    """The paper's safety index c_S = (d_HR^2 + 1) exp(-v_R): large when safe."""
    return (d_hr * d_hr + 1.0) * math.exp(-v_r)
