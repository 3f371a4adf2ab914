"""Which files a cell read: each with its size and SHA-256 (``cell.files`` lists them, ``cellstress check`` prints
them, result files record them, ``replay`` compares them).

A path is shown where it can be the same on every machine: a file shipped with cellstress as
``cellstress:cell/builtin/NAME``, one of example-robot-data's robots as ``example-robot-data:robots/...``;
any other file by its absolute path with links resolved (the file actually read).
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from cellstress.core.fields import Name, Record

MAX_FILES = 10_000  # files one cell may pull in: a cell file, four robots' URDFs, their meshes, trajectories
MAX_PATH = 4096


class InputFile(Record):
    """One file a cell read: what for (``use``: ``cell``, ``robot.urdf``, ``robot.urdf mesh``,
    ``robots[1].task.trajectory_csv``), where, its size and its SHA-256."""

    use: Name
    path: Annotated[str, Field(min_length=1, max_length=MAX_PATH, pattern=r"^[^\x00-\x1f\x7f]+$")]
    bytes: Annotated[int, Field(ge=0, le=2**50)]
    sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]


InputFiles = Annotated[tuple[InputFile, ...], Field(max_length=MAX_FILES)]


def file_changes(recorded: tuple[InputFile, ...], now: tuple[InputFile, ...]) -> list[str]:
    """What differs between the files a result recorded and those the cell reads now, one phrase each: a file
    whose bytes changed, one no longer read, one read now that was not."""
    by_path = {f.path: f for f in now}
    out = []
    for f in recorded:
        g = by_path.pop(f.path, None)
        if g is None:
            out.append(f"{f.path} ({f.use}) is no longer read by the cell")
        elif g.sha256 != f.sha256:
            out.append(f"{f.path} ({f.use}) has changed (sha256 {f.sha256[:12]} recorded, {g.sha256[:12]} now; "
                       f"{f.bytes:,} bytes recorded, {g.bytes:,} now)")
    out += [f"{g.path} ({g.use}) is read by the cell now but was not recorded" for g in by_path.values()]
    return out
