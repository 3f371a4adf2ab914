"""The records of a verification: its options, one per decided (start point, arrival phase), one per hazard class
with its witness, and the whole (``verify.json``). Frozen and typed; the file holds no wall-clock field, so the
same inputs give the same bytes."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from cellstress.core.fields import Record
from cellstress.core.io import canonical_json, json_ready, write_in_folder
from cellstress.searchers.result import CellRef, HazardClass, Severity
from cellstress.sim.records import Name

FORMAT = 1
FILE_NAME = "verify.json"
PROVED_SAFE, UNSAFE, UNDECIDED = "PROVED-SAFE", "UNSAFE", "UNDECIDED"
VERDICTS = (PROVED_SAFE, UNSAFE, UNDECIDED)
EXIT_CODES = {PROVED_SAFE: 0, UNSAFE: 1, UNDECIDED: 3}  # 2 is a bad input, as for every command

Count = Annotated[int, Field(ge=0)]


class VerifyOptions(Record):
    """What to decide: episodes of ``horizon`` actions, at the arrival phases ``phases`` selects
    (``verifier.phases``), with the pruning ``bounds`` named; ``time_limit`` [s] (None: none)."""

    horizon: Annotated[int, Field(ge=1, le=12)] = 8
    phases: Literal["all", "cell"] = "all"
    bounds: tuple[Literal["at-rest", "distance"], ...] = ("at-rest", "distance")
    time_limit: Annotated[float, Field(gt=0.0)] | None = None


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
    """One start point at one arrival phase: its verdict and exact counts (``sequences`` = 30^horizon)."""

    start: Name
    phase: float
    verdict: Literal[VERDICTS]
    sequences: Count
    hazardous: Count
    undecided: Count
    probability: float  # hazardous / sequences: a uniformly random worker's chance of the hazard (exact ratio)
    states: tuple[Count, ...]  # distinct living states per layer (after 0, 1, ... actions)
    expanded: Count  # children made by the compiled expansion
    pruned: tuple[Pruned, ...]
    classes: tuple[ClassCount, ...]


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


class VerifyResult(Record):
    """What ``cellstress.verify`` returns and ``verify.json`` holds."""

    cell: CellRef
    options: VerifyOptions
    dt: float
    cycle: float
    merge_xy: float  # m: positions closer than this were merged
    merge_angle: float  # rad: headings and flexions closer than this were merged
    verdict: Literal[VERDICTS]
    sequences: Count
    hazardous: Count
    undecided: Count
    states: Count  # distinct states visited over every sub-tree
    pruned: tuple[Pruned, ...]
    subtrees: tuple[Subtree, ...]
    classes: tuple[Witness, ...]
    version: Name
    format: Literal[1] = FORMAT

    @property
    def exit_code(self) -> int:
        return EXIT_CODES[self.verdict]

    def to_json(self) -> str:
        return canonical_json(json_ready(self.model_dump(by_alias=True)))

    def write(self, out_dir: str | Path) -> Path:
        """Write ``out_dir/verify.json`` atomically; returns its path."""
        return write_in_folder(out_dir, FILE_NAME, self.to_json())
