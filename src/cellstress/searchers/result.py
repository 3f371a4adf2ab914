"""The result record of a search and its JSON file (``result.json``).

Typed, frozen records: the same types are made by a search (without validation: the values are ours) and
checked when a result file is read (``SearchResult.load``): result files come from other people, so a file is
parsed with strict types (no ``true`` for a number, no text for a number), bounded sizes and nesting, and any
problem is one ``SearchError`` naming the file, the field and the problem.

``result.json`` holds no wall-clock fields: the same inputs give a byte-identical file (keys sorted, floats
written with Python's shortest round-trip repr, non-finite floats as null, written atomically through a
temporary file and ``os.replace``). Timing goes to the console only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, TypeAdapter, ValidationError, model_serializer, model_validator

from cellstress.core import registry
from cellstress.core.fields import Record
from cellstress.core.io import (
    InputFileError,
    canonical_json,
    duplicate_json_key,
    json_ready,
    read_input_bytes,
    write_in_folder,
)
from cellstress.core.provenance import InputFiles
from cellstress.searchers.common import UNTIL, SearchError
from cellstress.sim.records import Name, StepRecord

FORMAT = 1
FILE_NAME = "result.json"
MAX_EPISODES = 10_000_000  # the budget a result may claim (the command line allows no more)
MAX_ACTIONS = 101  # a start point and up to 100 actions (SimulationSpec.actions_per_episode <= 100)
MAX_ROWS = 1 + 100 * 100  # the rows of one episode: 100 actions of up to 100 steps
MAX_LISTED = 100_000  # hazards, classes and kept episodes listed in one file

Episode = Annotated[int, Field(ge=1, le=MAX_EPISODES)]
Actions = Annotated[tuple[Name, ...], Field(max_length=MAX_ACTIONS)]
Trace = Annotated[tuple[StepRecord, ...], Field(max_length=MAX_ROWS)]
Option = bool | int | float | Annotated[str, Field(max_length=1000)] | None
VERDICT = TypeAdapter(dict[Name, bool | int | float | Annotated[str, Field(max_length=1000)] | None
                           | Annotated[list[float], Field(max_length=16)]])


class CellRef(Record):
    """The cell searched: its name, the sha256 of its file's text, where it came from (a built-in name or an
    absolute path), the criterion it was judged by (absent from early files: the default,
    contact-while-moving) and every file it read, with size and sha256 (``cell.files``; absent from files
    written before issue 29)."""

    name: Name
    sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]
    source: Annotated[str, Field(max_length=4096)]
    criterion: Name | None = None
    files: InputFiles | None = None

    @model_serializer(mode="wrap")
    def _drop_absent(self, handler):
        out = handler(self)
        if out.get("files") is None:
            out.pop("files", None)
        return out


class HazardClass(Record):
    """A distinct-mode class (``searchers.distinct``): the device that stopped the robot too late (or ``none``),
    the robot link, the ISO/TS 15066 body region, the 0.5 m floor cell (x0, y0, x1, y1) of the approach."""

    device: Name
    robot_link: Name
    body_region: Name
    approach_cell: tuple[float, float, float, float]
    # a cell whose arrival phase is searched (absent otherwise): the move of the robot's program at the contact,
    # 1-based (move i runs from waypoint i to the next, its dwell at waypoint i included)
    robot_move: Annotated[int, Field(ge=1, le=100_000)] | None = None


class EpisodeRef(Record):
    episode: Episode
    actions: Actions


class TopEpisode(Record):
    episode: Episode
    actions: Actions
    ret: float | None = Field(alias="return")
    risk: float | None
    unsafe: bool


class DeviceTiming(Record):
    """One safety device in a hazardous episode: when it first saw the worker, and when its stop took effect."""

    device: Name
    saw_at_s: float | None
    """First time the device saw the worker [s]; None: never, up to the contact."""
    stop_at_s: float | None
    """When the stop it asked for took effect (saw_at_s plus its response time): its signal reached the robot [s].
    The robot begins to brake after its controller's delay (``Why.braking_from_s``)."""


class Why(Record):
    """Why a hazardous episode was not prevented, from its timeline (``searchers.why``)."""

    detected: bool
    """Did any device see the worker before the contact?"""
    devices: Annotated[tuple[DeviceTiming, ...], Field(max_length=1000)]
    """Every device of the cell, in the cell's order."""
    stopped_by: Name | None
    """The device whose stop took effect first; None: undetected."""
    braking_from_s: float | None
    """When the robot began to brake [s]."""
    standstill_at_s: float | None
    """When the robot stood (or would have stood) still [s]."""
    contact_at_s: float
    """The unsafe contact [s]."""
    late_by_s: float | None
    """How much earlier the robot needed to stand still: standstill_at_s - contact_at_s [s]."""
    safeguards: Annotated[str, Field(max_length=2000)] | None = None
    """What a warning field's speed reduction or an automatic restart did before the contact, in words; None
    (and absent from the file) when neither happened."""

    @model_serializer(mode="wrap")
    def _drop_absent(self, handler):
        # absent rather than null, so that result files of cells without these safeguards keep their bytes
        out = handler(self)
        if out.get("safeguards") is None:
            out.pop("safeguards", None)
        return out


class Severity(Record):
    """How bad a hazard's contact is (``searchers.severity``): the robot's speed there and, under a criterion that
    judges forces (iso15066), the predicted force over its limit; ``creeping``: the robot slower than
    ``criteria.iso15066.CREEP_SPEED`` (no transient contact can exceed a limit but the head's) and the contact not
    clamping. Findings are listed worst first, creeping ones after the others."""

    v_R: Annotated[float, Field(ge=0.0, le=1000.0)]
    """The robot's speed at the contact [m/s] (the simulator's v_R: its fastest joint)."""
    force_ratio: Annotated[float, Field(ge=0.0, le=1e9)] | None = None
    """The predicted peak force over the body region's limit (iso15066: quasi-static when clamped, else transient;
    a head contact while the robot moves counts at least 1); absent for other criteria."""
    creeping: bool
    """v_R below the creep speed (a transient contact): shown apart, after the others."""

    @model_serializer(mode="wrap")
    def _drop_absent(self, handler):
        out = handler(self)
        if out.get("force_ratio") is None:
            out.pop("force_ratio", None)
        return out


class Hazard(Record):
    """The first hazardous episode: its actions, the unsafe step and its trace. A criterion that judges contacts
    adds its verdict under the criterion's name (e.g. ``iso15066``): the one field not declared here."""

    model_config = ConfigDict(extra="allow")

    episode: Episode
    actions: Actions
    step: Annotated[int, Field(ge=0, le=MAX_ROWS)]
    time_s: float
    robot_link: Name | None
    body_part: Name | None
    point: tuple[float, float, float]
    human_point: tuple[float, float, float]
    v_R: float | None
    d_HR: float | None
    trace: Trace
    why: Why | None = None  # absent from files written before it was recorded
    severity: Severity | None = None  # absent from files written before it was recorded

    @model_validator(mode="after")
    def _one_verdict(self) -> Hazard:
        extra = self.model_extra or {}
        for key, value in extra.items():
            if key not in registry.names("criteria"):
                raise ValueError(f"unknown field {key!r}")
            VERDICT.validate_python(value, strict=True)
        if len(extra) > 1:
            raise ValueError(f"more than one criterion's verdict ({', '.join(sorted(extra))})")
        return self

    @property
    def verdict(self) -> tuple[str, dict[str, Any]] | None:
        """(criterion, its verdict's numbers) for a criterion that judges contacts, else None."""
        extra = self.model_extra or {}
        return next(iter(extra.items()), None)


class DistinctHazard(Record):
    """The first hazard of one class (distinct mode)."""

    klass: HazardClass = Field(alias="class")
    episode: Episode
    actions: Actions
    step: Annotated[int, Field(ge=0, le=MAX_ROWS)]
    time_s: float
    robot_link: Name | None
    body_part: Name | None
    v_R: float | None
    trace: Trace
    why: Why | None = None  # absent from files written before it was recorded
    severity: Severity | None = None  # absent from files written before it was recorded


class SearchResult(Record):
    """What ``cellstress.search`` returns and ``result.json`` holds."""

    cell: CellRef
    searcher: Name
    params: dict[Name, Option]  # the searcher's options (defaults filled in)
    seed: Annotated[int, Field(ge=0)]
    budget: Episode
    until: Literal[UNTIL]
    found: bool
    episodes: Annotated[int, Field(ge=0, le=MAX_EPISODES)]  # used: up to the first hazard, or the whole budget
    hazard: Hazard | None  # the first hazardous episode, with its trace
    hazards: Annotated[tuple[EpisodeRef, ...], Field(max_length=MAX_LISTED)]  # every hazardous episode
    top: Annotated[tuple[TopEpisode, ...], Field(max_length=MAX_LISTED)]  # the top-k episodes by return
    risk_per_episode: Annotated[tuple[float | None, ...], Field(max_length=MAX_EPISODES)]  # max 1/c_S each
    # how many different action sequences the episodes played (counted up to searchers.common.MAX_TRACKED;
    # absent from files written before it was recorded)
    distinct_sequences: Annotated[int, Field(ge=0, le=MAX_EPISODES)] | None = None
    version: Name
    format: Literal[1] = FORMAT
    # distinct mode only (absent from the file otherwise): the first hazard of each class, worst first (creeping
    # contacts last; ties in the order found: searchers.severity)
    distinct: Annotated[tuple[DistinctHazard, ...], Field(max_length=MAX_LISTED)] | None = None

    @model_validator(mode="after")
    def _agrees_with_its_budget(self) -> SearchResult:
        # a file from elsewhere: every list is one entry per episode played, or a few of those episodes, so a
        # file claiming 40 episodes cannot carry 600,000 risks (issue 29); each message names its field. Claims
        # that are merely false (which episode found the hazard, whether one was found) are replay's to refute.
        n = self.episodes
        if n > self.budget:
            raise ValueError(f"episodes: {n:,} played, more than the budget of {self.budget:,}")
        if len(self.risk_per_episode) != n:
            raise ValueError(f"risk_per_episode: lists {len(self.risk_per_episode):,} values for {n:,} episodes "
                             "(one per episode played)")
        if self.distinct_sequences is not None and self.distinct_sequences > n:
            raise ValueError(f"distinct_sequences: {self.distinct_sequences:,}, more than the {n:,} episodes")
        for field, items in (("hazards", self.hazards), ("top", self.top), ("distinct", self.distinct or ())):
            if len(items) > n:
                raise ValueError(f"{field}: lists {len(items):,} episodes of {n:,}")
            for i, e in enumerate(items):
                if e.episode > n:
                    raise ValueError(f"{field}[{i}].episode: episode {e.episode:,} of {n:,}")
        return self

    def to_dict(self) -> dict[str, Any]:
        doc = self.model_dump(by_alias=True)
        for key in ("distinct", "distinct_sequences"):
            if doc[key] is None:
                del doc[key]
        for d in doc.get("distinct") or ():
            if d["class"]["robot_move"] is None:
                del d["class"]["robot_move"]
        for h in (doc["hazard"], *(doc.get("distinct") or ())):
            for key in ("why", "severity"):
                if h is not None and h.get(key, 0) is None:
                    del h[key]
        if doc["cell"]["criterion"] is None:
            del doc["cell"]["criterion"]
        return json_ready(doc)

    def to_json(self) -> str:
        return canonical_json(self.to_dict())

    def write(self, out_dir: str | Path, *, inside: str | Path | None = None) -> Path:
        """Write ``out_dir/result.json`` atomically; returns its path. ``inside``: the output folder the user
        chose, when ``out_dir`` is a folder of ours within it (``core.io.write_in_folder``)."""
        return write_in_folder(out_dir, FILE_NAME, self.to_json(), inside=inside)

    @classmethod
    def load(cls, path: str | Path) -> SearchResult:
        """Read and check a result file (or the ``result.json`` in a folder); SearchError with one line naming
        the file, the field and the problem for anything that is not a result file of ours."""
        p = Path(path)
        if p.is_dir():
            p = p / FILE_NAME
        try:
            raw = read_input_bytes(p)
        except InputFileError as exc:
            problem = "no such result file" if exc.problem == "no such file" else exc.problem
            raise SearchError(f"{p}: {problem}") from None
        try:
            res = cls.model_validate_json(raw, strict=True)
        except ValidationError as exc:
            raise SearchError(f"{p}: not a cellstress result file: {validation_problem(exc)}") from None
        key = duplicate_json_key(raw)
        if key is not None:
            raise SearchError(f"{p}: not a cellstress result file: the key {key[:60]!r} appears twice in one object")
        return res


def validation_problem(exc: ValidationError) -> str:
    """The first problem of a validation error in one line: the field's path and what is wrong (the value is
    never echoed whole: it may be huge or hostile). A check of the whole record names its field itself."""
    errors = exc.errors(include_input=False, include_url=False)
    e = errors[0]
    where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in e["loc"]).lstrip(".") or "(top level)"
    msg = e["msg"]
    if e["type"] == "json_invalid":
        msg = f"invalid JSON ({e.get('ctx', {}).get('error', 'malformed')})"
        where = "(file)"
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    if e["type"] == "value_error" and not e["loc"]:
        return f"{msg.removeprefix('Value error, ')[:300]}{more}"
    return f"{where}: {msg[:200]}{more}"
