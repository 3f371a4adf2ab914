"""``--out/verify-checkpoint.jsonl``: the sub-trees a verification has decided, one line each as it finishes, so
that a run stopped at any moment (Ctrl-C, SIGKILL, a time limit) resumes where it was and ends with the same
``verify.json`` bytes as a run never stopped.

The first line says which verification the file belongs to (the cell's sha256, its criterion, the options but
the time limit, the number of sub-trees, the version); a file of another verification is refused, not mixed in.
Only sub-trees decided whole are kept (one left partly undecided by a time limit is decided again). A line cut
short by a crash is dropped (``core.journal``). The file goes once every sub-tree is decided.

A checkpoint is read back as any other input file: strict JSON of these records, its size bounded, each line
matched to the sub-tree it claims to be (start point and arrival phase), never unpickled.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, ValidationError

from cellstress.core.errors import CellstressError
from cellstress.core.fields import Record
from cellstress.core.io import InputFileError, duplicate_json_key
from cellstress.core.journal import JournalWriter, read_journal
from cellstress.searchers.result import validation_problem
from cellstress.sim.records import Name
from cellstress.verifier.records import Count, Subtree, VerifyOptions
from cellstress.verifier.tree import MAX_ACTIONS

CHECKPOINT = "verify-checkpoint.jsonl"
MAX_CHECKPOINT_BYTES = 2**30  # a sub-tree's line is a few hundred bytes: millions of sub-trees
KIND = "cellstress verify checkpoint"
Action = Annotated[int, Field(ge=0, lt=MAX_ACTIONS)]  # the cell's own count: read_checkpoint


class CheckpointError(CellstressError):
    """A checkpoint that is not this verification's, or is damaged (a user error: exit code 2)."""


class CheckpointHead(Record):
    """Which verification the file belongs to."""

    kind: Literal[KIND]
    cell_sha256: Name
    criterion: Name
    options: VerifyOptions  # without the time limit, which changes what is decided, never how
    tasks: Count
    version: Name


class FoundLine(Record):
    """A hazard class as one sub-tree found it (``run.Found``)."""

    key: tuple[Name, Name, Name, int, int] | tuple[Name, Name, Name, int, int, int]
    actions: Annotated[tuple[Action, ...], Field(max_length=12)]
    step: Count
    time_s: float
    sequences: Count
    phase: float


class DecidedLine(Record):
    """One sub-tree decided whole: its index in the verification's order, its record and its hazard classes."""

    task: Count
    subtree: Subtree
    found: tuple[FoundLine, ...]


def head_of(cell_sha256: str, criterion: str, options: VerifyOptions, tasks: int, version: str) -> CheckpointHead:
    return CheckpointHead(kind=KIND, cell_sha256=cell_sha256, criterion=criterion,
                          options=options.model_copy(update={"time_limit": None}), tasks=tasks, version=version)


def _parse(model, line: bytes, path: Path, n: int):
    try:
        rec = model.model_validate_json(line, strict=True)
    except ValidationError as exc:
        raise CheckpointError(f"{path}: line {n} is not a checkpoint record ({validation_problem(exc)}); the file "
                              "is damaged (remove it to start over)") from None
    dup = duplicate_json_key(line)
    if dup is not None:
        raise CheckpointError(f"{path}: line {n}: the key {dup[:60]!r} appears twice; the file is damaged (remove "
                              "it to start over)")
    return rec


def read_checkpoint(path: Path, head: CheckpointHead, subtrees: list[tuple[str, float]], n_actions: int
                    ) -> dict[int, DecidedLine]:
    """The sub-trees a checkpoint holds, by index (``subtrees``: each task's start point and phase, in order;
    ``n_actions``: the cell's worker's actions per decision); an empty dict when there is none. CheckpointError
    for one of another verification or a damaged one."""
    try:
        lines, _ = read_journal(path, MAX_CHECKPOINT_BYTES)
    except InputFileError as exc:
        raise CheckpointError(f"{path}: {exc.problem}") from None
    if not lines:
        return {}
    if _parse(CheckpointHead, lines[0], path, 1) != head:
        raise CheckpointError(f"{path}: the checkpoint of another verification (another cell, criterion, option or "
                              "version): remove it, or give another --out")
    done: dict[int, DecidedLine] = {}
    for n, line in enumerate(lines[1:], start=2):
        rec = _parse(DecidedLine, line, path, n)
        if rec.task >= len(subtrees) or (rec.subtree.start, rec.subtree.phase) != subtrees[rec.task]:
            raise CheckpointError(f"{path}: line {n} is not a sub-tree of this verification; the file is damaged "
                                  "(remove it to start over)")
        if any(a >= n_actions for f in rec.found for a in f.actions):
            raise CheckpointError(f"{path}: line {n} holds an action this cell's worker does not have (it has "
                                  f"{n_actions}); the file is damaged (remove it to start over)")
        if rec.subtree.undecided:
            raise CheckpointError(f"{path}: line {n} holds a sub-tree not decided whole; the file is damaged "
                                  "(remove it to start over)")
        done[rec.task] = rec
    return done


class CheckpointWriter(JournalWriter):
    """Appends decided sub-trees; writes the head first into a new file."""

    def __init__(self, path: Path, head: CheckpointHead):
        new = not os.path.lexists(path) or os.path.getsize(path) == 0
        super().__init__(path)
        if new:
            self.append(head.model_dump(by_alias=True))

    def add(self, task: int, line: DecidedLine) -> None:
        if not line.subtree.undecided:
            self.append(line.model_copy(update={"task": task}).model_dump(by_alias=True))


def remove_checkpoint(path: Path) -> None:
    """The verification is complete: its checkpoint goes (a link planted there is removed, never followed)."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
