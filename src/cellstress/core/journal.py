"""Append-only journals of JSON lines: how a long job (a campaign's runs, a verification's sub-trees) keeps what
it has finished, so that a run killed at any moment resumes.

Only one process writes, one whole line per ``os.write`` on an ``O_APPEND`` descriptor, then fsync: a crash can
leave at most a truncated last line. Reading tolerates exactly that: the partial line is dropped (the file is
rewritten without it, atomically) and its work is done again.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from cellstress.core.io import atomic_write, json_line, read_input_bytes


class JournalWriter:
    """Appends records as JSON lines (``core.io.json_line``): one ``os.write`` of a whole line, then fsync."""

    def __init__(self, path: Path):
        self.path = path
        # O_NOFOLLOW: a symbolic link planted at the journal's name must not redirect the appends to its target
        self._fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)

    def append(self, record: Any) -> None:
        data = (json_line(record) + "\n").encode("utf-8")
        view = memoryview(data)
        while view:  # a regular file takes the whole line at once; loop only for safety
            n = os.write(self._fd, view)
            view = view[n:]
        os.fsync(self._fd)

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def __enter__(self) -> JournalWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_journal(path: Path, max_bytes: int) -> tuple[list[bytes], bool]:
    """The complete lines of a journal (none if it does not exist) and whether a truncated last line was dropped
    (and the file rewritten without it). InputFileError for a file that is not a regular file or is too large."""
    if not os.path.lexists(path):
        return [], False
    raw = read_input_bytes(path, max_bytes, follow=False)
    lines = raw.split(b"\n")
    tail = lines.pop()  # b"" when the file ends with a newline, else a line cut short by a crash
    if tail:
        atomic_write(path, raw[: len(raw) - len(tail)])
    return [ln for ln in lines if ln.strip()], bool(tail)
