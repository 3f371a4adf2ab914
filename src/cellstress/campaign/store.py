"""``DIR/runs.jsonl``: one line per finished run, appended, flushed and fsynced when the run ends.

Only the main process writes, one whole line per ``os.write`` on an ``O_APPEND`` descriptor, so a crash can
leave at most a truncated last line. Reading tolerates exactly that: the partial line is dropped (the file is
rewritten without it, atomically) and its run is done again. Lines are JSON with sorted keys and no
wall-clock field, so sorting the lines of two campaigns' files gives byte-identical text whatever the order
in which runs finished.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cellstress.campaign.plan import MANIFEST, CampaignError, CampaignPlan, RunKey, manifest_difference
from cellstress.core.io import atomic_write, atomic_write_text, canonical_json, json_line, json_ready

RUNS = "runs.jsonl"
LOCK = ".campaign.lock"


def record_key(rec: dict[str, Any]) -> RunKey:
    return RunKey(str(rec["cell"]), str(rec["searcher"]), int(rec["seed"]))


@dataclass(frozen=True)
class Loaded:
    """What ``read_runs`` found: the records by run, and whether a truncated last line was dropped."""

    records: dict[RunKey, dict[str, Any]]
    dropped_partial: bool


def read_runs(path: Path, plan: CampaignPlan) -> Loaded:
    """Read ``runs.jsonl``; repair a truncated last line; check every line belongs to ``plan``."""
    if not path.exists():
        return Loaded({}, False)
    raw = path.read_bytes()
    lines = raw.split(b"\n")
    tail = lines.pop()  # b"" when the file ends with a newline, else a line cut short by a crash
    dropped = bool(tail)
    if dropped:
        atomic_write(path, raw[: len(raw) - len(tail)])
    expected = {s.key: s for s in plan.runs()}
    records: dict[RunKey, dict[str, Any]] = {}
    for n, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
            key = record_key(rec)
        except (UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError):
            raise CampaignError(f"{path}: line {n} is not a run record; the file is damaged (move it away to "
                                f"start over)") from None
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


class RunWriter:
    """Appends records to ``runs.jsonl``: one ``os.write`` of a whole line, then fsync."""

    def __init__(self, path: Path):
        self.path = path
        # O_NOFOLLOW: a symbolic link planted at runs.jsonl must not redirect the appends to its target
        self._fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)

    def append(self, record: dict[str, Any]) -> None:
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

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


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
    if not path.exists():
        if (out / RUNS).exists():
            raise CampaignError(f"--out {out}: has a {RUNS} but no {MANIFEST}; use an empty folder")
        atomic_write_text(path, canonical_json(new))
        return False
    try:
        old = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CampaignError(f"--out {out}: {MANIFEST} is not readable ({exc})") from None
    if not isinstance(old, dict):
        raise CampaignError(f"--out {out}: {MANIFEST} is not a campaign manifest")
    diff = manifest_difference(old, new)
    if diff is not None:
        raise CampaignError(f"--out {out} holds a campaign with other options: {diff} "
                            f"(resume with the same options, or use another --out)")
    return True
