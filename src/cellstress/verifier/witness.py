"""Witnesses as result files that ``cellstress replay`` and ``cellstress report`` read.

A witness is a hazardous action sequence from one start point at one arrival phase. Neither is something a
result file can say of the cell itself (its actions start at ``human.start`` at ``robot.task.phase``), so a
witness comes with its own cell file, ``cell.yaml``: the verified cell with that start as its only start point
and that phase as the robot task's. Its result file names that cell (absolute path and sha256) and records the
sequence as the hazard of a one-episode "search" by ``verify``: every claim of the file follows from the
sequence alone, so ``replay`` re-checks it by playing the sequence again (``witness_result``), bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from cellstress.cell.load import Cell, builtin_text, load_cell, safe_load_yaml, with_criterion
from cellstress.core.io import atomic_write_text, read_input_bytes
from cellstress.core.version import __version__
from cellstress.human.actions import ACTION_NAMES
from cellstress.robot.model import BUILTIN_URDFS
from cellstress.searchers import hazard_record
from cellstress.searchers.result import FORMAT, CellRef, EpisodeRef, SearchResult, TopEpisode
from cellstress.verifier.phases import StartPoint

SEARCHER = "verify"  # the ``searcher`` of a witness's result file
CELL_FILE = "cell.yaml"


def cell_text(cell: Cell) -> str:
    """The text of the cell's file (a built-in's from the installation)."""
    if cell.directory is None:
        return builtin_text(cell.source)
    return read_input_bytes(Path(cell.source).expanduser()).decode("utf-8")


def witness_cell_text(cell: Cell, start: StartPoint, phase: float) -> str:
    """``cell``'s file with ``start`` as its only start point and the robot's task at ``phase``."""
    data = safe_load_yaml(cell_text(cell))
    data["robot"]["task"]["phase"] = float(phase)
    urdf = data["robot"].get("urdf", "ur10")
    if urdf not in BUILTIN_URDFS and cell.directory is not None and not Path(urdf).expanduser().is_absolute():
        data["robot"]["urdf"] = str((cell.directory / urdf).resolve())  # the witness lives in another folder
    data["human"]["start"] = {"xy": [start.x, start.y], "heading_deg": start.heading_deg}
    data["human"].pop("starts", None)
    head = (f"# A verify witness's cell: {cell.name} from start point {start.name!r} with the robot's cycle at "
            f"{phase:g} s when the worker arrives.\n")
    return head + yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=120)


def witness_result(sim, actions: list[str], params: dict, source: str) -> SearchResult:
    """The result file of a witness: ``actions`` played in ``sim`` (the witness's cell) as episode 1 of 1."""
    c = sim.cell
    reward = sim.criterion.reward(sim.actions_per_episode)
    state, ret, risk = sim.reset(), 0.0, 0.0
    for k, a in enumerate(actions):
        state, rows = sim.step(state, a)
        unsafe = sim.is_unsafe(state)
        r, rk = reward(sim.measures(rows), k == sim.actions_per_episode - 1, unsafe)
        ret, risk = ret + r, max(risk, rk)
        if unsafe:
            break
    acts = tuple(actions)
    return SearchResult.model_construct(
        cell=CellRef.model_construct(name=c.name, sha256=c.sha256, source=source, criterion=c.spec.criterion.type),
        searcher=SEARCHER, params=dict(params), seed=0, budget=1, until="first", found=True, episodes=1,
        hazard=hazard_record(sim, 1, list(acts)),
        hazards=(EpisodeRef.model_construct(episode=1, actions=acts),),
        top=(TopEpisode.model_construct(episode=1, actions=acts, ret=ret, risk=risk, unsafe=True),),
        risk_per_episode=(risk,), distinct_sequences=1, version=__version__, format=FORMAT, distinct=None)


def write_witness(sim, cell: Cell, start: StartPoint, phase: float, actions: tuple[int, ...],
                  folder: Path) -> Path:
    """Write ``folder/cell.yaml`` and ``folder/result.json`` for a witness; returns the result file's path.
    ``sim``: the verified simulator (its criterion is the witness's)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = (folder / CELL_FILE).resolve()
    atomic_write_text(path, witness_cell_text(cell, start, phase))
    # the witness's simulator exactly as ``replay`` makes it from the file
    wsim = type(sim)(with_criterion(load_cell(path), sim.criterion.type))
    names = [ACTION_NAMES[a] for a in actions]
    res = witness_result(wsim, names, {"start": start.name, "phase": float(phase)}, str(path))
    return res.write(folder)
