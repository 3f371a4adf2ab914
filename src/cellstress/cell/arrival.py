"""When the worker arrives in the robot's cycle (``human.arrival``): a word or a window of the cycle."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Discriminator, Field, Tag, model_validator

from cellstress.core.fields import Record

MAX_CYCLE = 600.0  # s, the robot's longest cycle (the static check samples it every 10 ms)

class ArrivalWindow(Record):
    """A window of the robot's cycle in which the worker may arrive."""

    start: Annotated[float, Field(ge=0.0, le=MAX_CYCLE, allow_inf_nan=False)]
    """Earliest arrival: the robot's time in its cycle [s]."""
    end: Annotated[float, Field(ge=0.0, le=MAX_CYCLE, allow_inf_nan=False)]
    """Latest arrival [s], at least ``start``; past the cycle's end it wraps around to its beginning."""

    @model_validator(mode="after")
    def _ordered(self) -> ArrivalWindow:
        if self.end < self.start:
            raise ValueError(f"end ({self.end}) must not be before start ({self.start})")
        return self


def _arrival_kind(v: object) -> str:
    return "arrival-word" if isinstance(v, str) else "arrival-window"


# "cycle", "fixed" or a window; the discriminator keeps pydantic from reporting both union branches.
ArrivalField = Annotated[
    Annotated[Literal["cycle", "fixed"], Tag("arrival-word")] | Annotated[ArrivalWindow, Tag("arrival-window")],
    Discriminator(_arrival_kind),
]
