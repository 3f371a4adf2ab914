"""The records of a verification: its options, one per decided (start point, arrival phase), one per hazard class
with its witness, and the whole (``verify.json``). Frozen and typed; the file holds no wall-clock field, so the
same inputs give the same bytes."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, model_validator

from cellstress.core.fields import Record
from cellstress.core.io import canonical_json, json_ready, write_in_folder
from cellstress.searchers.result import CellRef, HazardClass, Severity
from cellstress.sim.records import Name

FORMAT = 2  # 2: what the verdict covers (scope), arrival windows and their alarms; no merge tolerances
FILE_NAME = "verify.json"
PROVED_SAFE, UNSAFE, UNDECIDED = "PROVED-SAFE", "UNSAFE", "UNDECIDED"
VERDICTS = (PROVED_SAFE, UNSAFE, UNDECIDED)
EXIT_CODES = {PROVED_SAFE: 0, UNSAFE: 1, UNDECIDED: 3}  # 2 is a bad input, as for every command

Count = Annotated[int, Field(ge=0)]


class VerifyOptions(Record):
    """What to decide: episodes of ``horizon`` actions, at the arrival phases ``phases`` selects
    (``verifier.phases``: ``all``, ``cell``, or ``window``, the grid phases within ``window`` [s]), from the start
    points named in ``starts`` (none named: every one), with the pruning ``bounds`` named; ``time_limit`` [s]
    (None: none). ``moments``: ``all``, each grid phase stands for every arrival moment within half a time step of
    it where the cell allows the argument (``verifier.arrival``); ``grid``, the grid moments alone."""

    horizon: Annotated[int, Field(ge=1, le=12)] = 8
    phases: Literal["all", "cell", "window"] = "all"
    moments: Literal["all", "grid"] = "all"
    bounds: tuple[Literal["at-rest", "distance"], ...] = ("at-rest", "distance")
    time_limit: Annotated[float, Field(gt=0.0)] | None = None
    window: tuple[Annotated[float, Field(ge=0.0, allow_inf_nan=False)],
                  Annotated[float, Field(ge=0.0, allow_inf_nan=False)]] | None = None
    starts: Annotated[tuple[Name, ...], Field(max_length=1000)] = ()

    @model_validator(mode="after")
    def _window_with_its_mode(self) -> VerifyOptions:
        if (self.phases == "window") != (self.window is not None):
            raise ValueError("phases: a window of phases (A:B) and only it gives the window's ends")
        if self.window is not None and self.window[0] > self.window[1]:
            raise ValueError(f"phases: the window {self.window[0]:g}:{self.window[1]:g} ends before it begins")
        return self

    @property
    def phases_text(self) -> str:
        """``all``, ``cell`` or the window ``A:B``, as the command line takes it."""
        return self.phases if self.window is None else f"{self.window[0]:g}:{self.window[1]:g}"


class Pruned(Record):
    """What one bound cut: living states proved safe, and the sequences through them."""

    bound: Name
    states: Count
    sequences: Count


class ClassCount(Record):
    """Hazardous sequences of one hazard class (an index into ``VerifyResult.classes``) in one sub-tree."""

    klass: Count
    sequences: Count


class Subtree(Record):
    """One start point at one arrival phase: its verdict and exact counts (``sequences`` = n^horizon, n the
    worker's actions per decision: 30 or 119) at that phase; ``window``: the arrival moments within this many
    seconds of it are covered too (0: the phase alone), by a model whose robot capsules were grown by up to
    ``margin`` m (``verifier.arrival``); ``confirmed``:
    sequences of that model hazardous at a moment of the window when replayed; ``alarms``: its other
    hazardous sequences, hazardous at none of the moments replayed (not a proof, not a hazard)."""

    start: Name
    phase: float
    window: Annotated[float, Field(ge=0.0)] = 0.0
    margin: Annotated[float, Field(ge=0.0)] = 0.0
    confirmed: Count = 0
    alarms: Count = 0
    verdict: Literal[VERDICTS]
    sequences: Count
    hazardous: Count
    undecided: Count
    probability: float  # hazardous / sequences: a uniformly random worker's chance of the hazard (exact ratio)
    states: tuple[Count, ...]  # distinct living states per layer (after 0, 1, ... actions)
    expanded: Count  # children made by the compiled expansion
    pruned: tuple[Pruned, ...]
    classes: tuple[ClassCount, ...]


class Approximation(Record):
    """One way the model the verdict is about differs from a continuous one, with its size."""

    name: Name
    size: float
    unit: Name
    what: Annotated[str, Field(max_length=400)]


class Scope(Record):
    """What a verdict covers (``verifier.scope``): the worker model and its actions, the horizon against the
    cell's own, the start points, the arrival moments, and each approximation with its size; ``statement``
    says it in one paragraph."""

    worker: Name
    actions: Count  # actions the worker chooses from at each decision
    horizon: Count
    cell_horizon: Count  # the cell's own simulation.actions_per_episode
    starts: tuple[Name, ...]
    arrival: Annotated[str, Field(max_length=400)]
    margin: Annotated[float, Field(ge=0.0)]  # m: the largest capsule growth covering moments between grid points
    approximations: tuple[Approximation, ...]
    statement: Annotated[str, Field(max_length=4000)]


class Witness(Record):
    """A hazard class and its witness: the first hazardous sequence of the class in the order of decision
    (start points, phases, then the shortest and lexicographically smallest), replayable from ``file``."""

    klass: HazardClass = Field(alias="class")
    root_cause: tuple[Name, Name]  # (safeguard that failed or none, body area): searchers.distinct.root_cause
    start: Name
    phase: float
    actions: tuple[Name, ...]
    step: Count
    time_s: float
    sequences: Count  # hazardous sequences of this class, over every sub-tree
    file: str  # the witness's result.json, relative to verify.json
    severity: Severity | None = None  # its contact's (searchers.severity): the classes are listed worst first


class StaticFailure(Record):
    """A row ``cellstress check`` fails, kept beside a verdict that did not turn it into a contact (a proof is about
    the simulated worker; the static check is about any person): ``limit`` names what the simulated worker cannot
    do there, '' where it could but no sequence of the verdict's scope did."""

    name: Name
    value: Annotated[str, Field(max_length=400)]
    limit: Annotated[str, Field(max_length=400)] = ""


class VerifyResult(Record):
    """What ``cellstress.verify`` returns and ``verify.json`` holds."""

    cell: CellRef
    options: VerifyOptions
    dt: float
    cycle: float
    scope: Scope
    verdict: Literal[VERDICTS]
    sequences: Count
    hazardous: Count
    undecided: Count
    alarms: Count  # sequences hazardous only in the arrival-window model, at no moment replayed
    states: Count  # distinct states visited over every sub-tree
    pruned: tuple[Pruned, ...]
    subtrees: tuple[Subtree, ...]
    classes: tuple[Witness, ...]
    version: Name
    static_failures: tuple[StaticFailure, ...] = ()  # the cell's failing check rows (cellstress.analysis.check_rows)
    format: Literal[2] = FORMAT

    @property
    def exit_code(self) -> int:
        return EXIT_CODES[self.verdict]

    def to_json(self) -> str:
        return canonical_json(json_ready(self.model_dump(by_alias=True)))

    def write(self, out_dir: str | Path) -> Path:
        """Write ``out_dir/verify.json`` atomically; returns its path."""
        return write_in_folder(out_dir, FILE_NAME, self.to_json())
