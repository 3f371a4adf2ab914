"""Every file a cell reads, with its size and SHA-256, and the rule for files outside the cell's folder.

A cell reads its own file, each robot's URDF, the collision meshes that URDF names, any trajectory file and any
stopping data file. A
robot from elsewhere is legitimate (a ROS package, example-robot-data), so by default a cell may read any file;
but none unseen: ``cellstress check`` lists them all (marking those outside the cell's folder) and result files
record them, so ``replay`` names the input that changed. ``CELLSTRESS_FILES=inside`` makes the rule strict: a
file outside the cell file's folder (after links are resolved) and outside the robots shipped with cellstress
and example-robot-data is then refused before it is read. docs/security.md gives the reasons.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from pydantic import ValidationError

from cellstress.cell.program import trajectory_path
from cellstress.cell.robot_stop import stopping_data_path
from cellstress.core.errors import CellError, CellstressError
from cellstress.core.io import InputFileError, file_digest
from cellstress.core.provenance import MAX_FILES, InputFile
from cellstress.robot.files import referenced_meshes
from cellstress.robot.model import example_robot_data_share, resolve_urdf

CONFINE_VAR = "CELLSTRESS_FILES"
ANYWHERE, INSIDE = "anywhere", "inside"


@dataclass(frozen=True)
class Read:
    """A file a cell reads: what for (``use``), the path it is read at, and whether that is outside the cell's
    folder and the robot packages cellstress trusts."""

    use: str
    path: Path
    outside: bool


def _roots() -> list[tuple[str, Path]]:
    """(name shown, folder) of the places cellstress ships files from: its built-in cells, example-robot-data."""
    roots = [("cellstress:cell/builtin/", Path(os.path.realpath(str(resources.files("cellstress.cell")
                                                                   .joinpath("builtin")))))]
    try:
        roots.append(("example-robot-data:", Path(os.path.realpath(example_robot_data_share()))))
    except CellstressError:
        pass
    return roots


def shown_path(path: Path) -> str:
    """``path`` as result files record it: the same on every machine for a shipped file, else absolute, links
    resolved."""
    real = Path(os.path.realpath(path))
    for name, root in _roots():
        if real.is_relative_to(root):
            return name + real.relative_to(root).as_posix()
    return str(real)


def _outside(cell, path: Path) -> bool:
    real = Path(os.path.realpath(path))
    if any(real.is_relative_to(root) for _, root in _roots()):
        return False
    return cell.directory is None or not real.is_relative_to(os.path.realpath(cell.directory))


def confined() -> bool:
    """Whether ``CELLSTRESS_FILES`` says a cell may read only files in its own folder (and shipped robots)."""
    value = os.environ.get(CONFINE_VAR, ANYWHERE).strip().lower() or ANYWHERE
    if value not in (ANYWHERE, INSIDE):
        raise CellstressError(f"{CONFINE_VAR}={value[:40]!r}: must be {ANYWHERE!r} (the default) or {INSIDE!r}")
    return value == INSIDE


def _refuse_outside(cell, read: Read) -> None:
    if read.outside and confined():
        where = "no folder (a built-in cell)" if cell.directory is None else f"the cell's folder {cell.directory}"
        field, what = (read.use[: -len(" mesh")], "names the mesh") if read.use.endswith(" mesh") else \
            (read.use, "is")
        raise CellError(cell.source, field, f"{what} {os.path.realpath(read.path)}, outside {where}; with "
                        f"{CONFINE_VAR}={INSIDE} a cell reads only files in its folder and the robots shipped with "
                        "cellstress and example-robot-data")


def _robots(cell) -> list[tuple[str, object]]:
    several = "robots" in cell.spec.model_fields_set
    return [(f"robots[{i}]" if several else "robot", rs) for i, rs in enumerate(cell.spec.robots)]


def robot_reads(cell) -> list[Read]:
    """The URDF, trajectory file and stopping data file of every robot, before any is read."""
    out = []
    for where, rs in _robots(cell):
        urdf = resolve_urdf(rs.urdf, cell.files_dir)
        out.append(Read(f"{where}.urdf", urdf, _outside(cell, urdf)))
        if rs.task.trajectory_csv:
            csv = trajectory_path(rs.task.trajectory_csv, cell.files_dir)
            out.append(Read(f"{where}.task.trajectory_csv", csv, _outside(cell, csv)))
        if rs.stopping is not None and rs.stopping.data is not None:
            data = stopping_data_path(rs.stopping.data, cell.files_dir)
            out.append(Read(f"{where}.stopping.data", data, _outside(cell, data)))
    return out


def refuse_files_outside(cell) -> None:
    """With ``CELLSTRESS_FILES=inside``: CellError for a robot's URDF or trajectory file outside the cell's folder,
    before anything reads it (a mesh is checked by ``cell_reads``, before the robot's meshes are loaded)."""
    if confined():
        for read in robot_reads(cell):
            _refuse_outside(cell, read)


def cell_reads(cell) -> list[Read]:
    """Every file the cell reads, each once (the first use named): its own file, then per robot the URDF, its
    collision meshes and its trajectory file. CellError for a mesh outside the folder when confined."""
    out: list[Read] = []
    if cell.directory is not None:
        out.append(Read("cell", Path(cell.source).expanduser(), False))
    for read in robot_reads(cell):
        out.append(read)
        if read.use.endswith(".urdf"):
            try:
                meshes = referenced_meshes(read.path)
            except CellstressError as exc:
                raise CellError(cell.source, read.use, str(exc)) from None
            out += [Read(f"{read.use} mesh", m, _outside(cell, m)) for m in meshes]
    seen, unique = set(), []
    for read in out:
        key = os.path.realpath(read.path)
        if key not in seen:
            seen.add(key)
            unique.append(read)
            _refuse_outside(cell, read)
    if len(unique) > MAX_FILES:
        raise CellError(cell.source, "", f"reads {len(unique):,} files; at most {MAX_FILES:,}")
    return unique


def cell_files(cell, text: str) -> tuple[InputFile, ...]:
    """``cell_reads`` with each file's size and SHA-256 (the cell's own file: of ``text``, the bytes parsed)."""
    out = []
    if cell.directory is None:
        from_text = text.encode("utf-8")
        out.append(("cell", f"cellstress:cell/builtin/{cell.source}.yaml", len(from_text), cell.sha256))
    for read in cell_reads(cell):
        if read.use == "cell":
            size, digest = len(text.encode("utf-8")), cell.sha256
        else:
            try:
                size, digest = file_digest(read.path)
            except InputFileError as exc:
                raise CellError(cell.source, read.use.removesuffix(" mesh"), f"{read.path}: {exc.problem}") from None
        out.append((read.use, shown_path(read.path), size, digest))
    try:
        return tuple(InputFile(use=u, path=p, bytes=n, sha256=h) for u, p, n, h in out)
    except ValidationError:
        raise CellError(cell.source, "", "reads a file whose path has control characters or is longer than "
                                         "4,096 characters") from None


def outside_paths(cell) -> set[str]:
    """The shown paths (``shown_path``) of the files the cell reads outside its folder and the shipped robots."""
    return {shown_path(r.path) for r in cell_reads(cell) if r.outside}
