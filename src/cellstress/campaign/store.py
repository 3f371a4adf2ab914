"""``DIR/runs.jsonl``: one line per finished run, appended, flushed and fsynced when the run ends.

Only the main process writes, one whole line at a time (``core.journal``), so a crash can leave at most a
truncated last line; reading drops it (the file is rewritten without it) and its run is done again. Lines are
JSON with sorted keys and no wall-clock field, so sorting the lines of two campaigns' files gives byte-identical
text whatever the order in which runs finished.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, ValidationError, model_validator

from cellstress.campaign.plan import MANIFEST, CampaignError, CampaignPlan, Manifest, RunKey, manifest_difference
from cellstress.core.fields import Name, Record
from cellstress.core.io import (
    InputFileError,
    atomic_write_text,
    canonical_json,
    duplicate_json_key,
    json_line,
    json_ready,
    read_input_bytes,
)
from cellstress.core.journal import JournalWriter, read_journal
from cellstress.searchers.common import MAX_BUDGET
from cellstress.searchers.result import MAX_ACTIONS, Option, validation_problem

RUNS = "runs.jsonl"
LOCK = ".campaign.lock"
MAX_RUNS_BYTES = 2**30  # a run's line is about 500 bytes: two million runs (read whole, so memory is bounded)


class RunHazard(Record):
    episode: Annotated[int, Field(ge=1, le=MAX_BUDGET)]
    actions: Annotated[tuple[Name, ...], Field(max_length=MAX_ACTIONS)]
    step: Annotated[int, Field(ge=0, le=10**6)]
    time_s: float
    robot_link: Name | None
    body_part: Name | None


class RunRecord(Record):
    """A line of ``runs.jsonl`` as read back (``worker.execute`` writes it): strict types, bounded sizes, and
    the episode counts within the budget, so a forged line cannot reach the table as something else."""

    format: Annotated[int, Field(ge=0, le=10**6)]
    cell: Name
    cell_sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]
    searcher: Name
    params: Annotated[dict[Name, Option], Field(max_length=1000)]
    seed: Annotated[int, Field(ge=0)]
    budget: Annotated[int, Field(ge=1, le=MAX_BUDGET)]
    until: Name
    found: bool
    episodes: Annotated[int, Field(ge=0, le=MAX_BUDGET)]
    hazard: RunHazard | None
    version: Name

    @model_validator(mode="after")
    def _consistent(self) -> RunRecord:
        if self.episodes > self.budget:
            raise ValueError(f"episodes: {self.episodes:,} played, more than the budget of {self.budget:,}")
        if self.found != (self.hazard is not None):
            raise ValueError(f"found: {str(self.found).lower()}, but the line has "
                             f"{'a' if self.hazard is not None else 'no'} hazard")
        if self.hazard is not None and self.hazard.episode > self.episodes:
            raise ValueError(f"hazard.episode: episode {self.hazard.episode:,} of {self.episodes:,}")
        return self


def record_key(rec: dict[str, Any]) -> RunKey:
    return RunKey(str(rec["cell"]), str(rec["searcher"]), int(rec["seed"]))


@dataclass(frozen=True)
class Loaded:
    """What ``read_runs`` found: the records by run, and whether a truncated last line was dropped."""

    records: dict[RunKey, dict[str, Any]]
    dropped_partial: bool


def read_runs(path: Path, plan: CampaignPlan) -> Loaded:
    """Read ``runs.jsonl``; repair a truncated last line; check every line belongs to ``plan``."""
    try:
        lines, dropped = read_journal(path, MAX_RUNS_BYTES)
    except InputFileError as exc:
        raise CampaignError(f"{path}: {exc.problem}") from None
    expected = {s.key: s for s in plan.runs()}
    records: dict[RunKey, dict[str, Any]] = {}
    for n, line in enumerate(lines, start=1):
        try:
            RunRecord.model_validate_json(line, strict=True)
        except ValidationError as exc:
            raise CampaignError(f"{path}: line {n} is not a run record ({validation_problem(exc)}); the file is "
                                f"damaged (move it away to start over)") from None
        dup = duplicate_json_key(line)
        if dup is not None:
            raise CampaignError(f"{path}: line {n} is not a run record (the key {dup[:60]!r} appears twice); the "
                                f"file is damaged (move it away to start over)")
        rec = json.loads(line)
        key = record_key(rec)
        spec = expected.get(key)
        if spec is None or rec.get("budget") != spec.budget or rec.get("cell_sha256") != spec.cell.sha256 \
                or rec.get("params") != json_ready(spec.searcher.params_dict):
            raise CampaignError(f"{path}: line {n} ({key.cell}, {key.searcher}, seed {key.seed}) is not a run "
                                f"of the campaign in {MANIFEST}")
        old = records.get(key)
        if old is not None and json_line(old) != json_line(rec):
            raise CampaignError(f"{path}: line {n} repeats run ({key.cell}, {key.searcher}, seed {key.seed}) "
                                f"with a different outcome")
        records[key] = rec
    return Loaded(records, dropped)


RunWriter = JournalWriter  # appends the records to runs.jsonl (core.journal)


class FolderLock:
    """An exclusive lock on the --out folder, so two campaigns cannot append to the same runs.jsonl."""

    def __init__(self, out: Path):
        self.path = out / LOCK
        self._f = None

    def __enter__(self) -> FolderLock:
        try:
            import fcntl
        except ImportError:  # not on POSIX: no lock, as before
            return self
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
        self._f = os.fdopen(fd, "a")  # held open for the lock's lifetime
        try:
            fcntl.flock(self._f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self._f.close()
            self._f = None
            raise CampaignError(f"--out {self.path.parent}: another campaign is running there") from None
        return self

    def __exit__(self, *exc: object) -> None:
        if self._f is not None:
            self._f.close()  # closing releases the lock
            self._f = None


def open_manifest(out: Path, plan: CampaignPlan) -> bool:
    """Write ``out/campaign.json``, or check that the one there matches ``plan``. True if it existed."""
    path = out / MANIFEST
    new = plan.manifest()
    if not os.path.lexists(path):
        if os.path.lexists(out / RUNS):
            raise CampaignError(f"--out {out}: has a {RUNS} but no {MANIFEST}; use an empty folder")
        atomic_write_text(path, canonical_json(new))
        return False
    try:
        raw = read_input_bytes(path, follow=False)
    except InputFileError as exc:
        raise CampaignError(f"{path}: {exc.problem}") from None
    try:
        old = Manifest.model_validate_json(raw, strict=True)
    except ValidationError as exc:
        raise CampaignError(f"{path}: not a campaign manifest: {validation_problem(exc)}") from None
    key = duplicate_json_key(raw)
    if key is not None:
        raise CampaignError(f"{path}: not a campaign manifest: the key {key[:60]!r} appears twice in one object")
    diff = manifest_difference(old.model_dump(mode="json"), new)
    if diff is not None:
        raise CampaignError(f"--out {out} holds a campaign with other options: {diff} "
                            f"(resume with the same options, or use another --out)")
    return True
