"""A joint-trajectory file: CSV with a header ``time,q1,...,qn`` (or the joint names) and a row per sample.

The file is untrusted: its size and row count are bounded before anything is parsed, and every bad value is
one error naming its row (the header is row 1, so a row is its line) and its column. An error never quotes the
file's text: a cell may name any file (``/etc/passwd``), and its first line must not end up in a log.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.core.io import InputFileError, read_input_bytes

MAX_BYTES = 20 * 1024 * 1024
MAX_ROWS = 200_000


class JointFileError(CellstressError):
    """A problem with the file: ``where`` is '' or 'row R, column C (name)'."""

    def __init__(self, where: str, problem: str):
        self.where = where
        self.problem = problem
        super().__init__(f"{where}: {problem}" if where else problem)


@dataclass(frozen=True)
class JointFile:
    times: np.ndarray  # (n,) s, strictly increasing
    values: np.ndarray  # (n, nd) in the file's units


def read_joint_file(path: Path, joint_names: tuple[str, ...]) -> JointFile:
    """The file's times and values for the driven joints ``joint_names`` (columns q1..qn or those names)."""
    try:
        raw = read_input_bytes(path, MAX_BYTES)
    except InputFileError as exc:
        raise JointFileError("", exc.problem) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise JointFileError(f"row {line}", "is not UTF-8 text") from None
    text = text.replace("\r\n", "\n").replace("\r", "\n")  # a row ends at any of the three line ends
    # header + MAX_ROWS rows, the last one with or without its newline (the loop below counts them again)
    if text.count("\n") + (not text.endswith("\n")) > MAX_ROWS + 1:
        raise JointFileError("", f"has more than {MAX_ROWS:,} rows")
    rows = csv.reader(io.StringIO(text))
    try:
        header = [h.strip() for h in next(rows)]
    except StopIteration:
        raise JointFileError("row 1", "the file is empty; it needs a header 'time,q1,...'") from None
    except csv.Error as exc:
        raise JointFileError("row 1", f"not valid CSV ({exc})") from None
    n = len(joint_names)
    numbered = ["time", *(f"q{i + 1}" for i in range(n))]
    named = ["time", *joint_names]
    if header not in (numbered, named):
        raise JointFileError("row 1", f"the header must be {','.join(numbered)} or {','.join(named)} "
                                      f"(the program drives {n} joints); {_header_problem(header, numbered, named)}")
    times, values = [], []
    try:
        for r, row in enumerate(rows, start=2):
            if r - 1 > MAX_ROWS:
                raise JointFileError("", f"has more than {MAX_ROWS:,} rows")
            if not row or all(not c.strip() for c in row):
                continue
            if len(row) != n + 1:
                raise JointFileError(f"row {r}", f"has {len(row)} values; expected {n + 1} ({','.join(header)})")
            nums = [_number(c, r, k, header[k]) for k, c in enumerate(row)]
            if times and not nums[0] > times[-1]:
                raise JointFileError(f"row {r}, column 1 (time)",
                                     f"time {nums[0]:g} s is not after the previous row's {times[-1]:g} s")
            times.append(nums[0])
            values.append(nums[1:])
    except csv.Error as exc:
        raise JointFileError(f"row {rows.line_num}", f"not valid CSV ({exc})") from None
    if len(times) < 2:
        raise JointFileError("", f"needs at least 2 rows after the header, got {len(times)}")
    return JointFile(np.asarray(times), np.asarray(values, dtype=float).reshape(len(times), n))


def _header_problem(header: list[str], numbered: list[str], named: list[str]) -> str:
    """What is wrong with the header, by column number: never the file's own words."""
    if len(header) != len(numbered):
        return f"row 1 has {len(header)} columns, not {len(numbered)}"
    k = next(k for k, h in enumerate(header) if h not in (numbered[k], named[k]))
    return f"column {k + 1} should be {numbered[k]} or {named[k]}"


def _number(text: str, row: int, col: int, name: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise JointFileError(f"row {row}, column {col + 1} ({name})", "is not a number") from None
    if not math.isfinite(x) or abs(x) > 1e6:
        raise JointFileError(f"row {row}, column {col + 1} ({name})", "is not a finite number of sensible size "
                                                                       "(at most 1e6 in size)")
    return x
