"""The maximum safe speed per move (``cellstress fix --criterion iso15066``): for each move of each robot's
program, the largest speed scale at which the search finds no contact over the body region's ISO/TS 15066 limit.

Each move is measured on its own: the move under test runs at the scale being tried and every other move of
every robot crawls at ``CRAWL`` (so a contact elsewhere in the cycle does not decide this move's number); a
bisection of ``STEPS`` steps on (0, 1] with the search (``plan``, ``--until budget --distinct``, the given
budget and seed) as the judge: a scale is safe when the search finds no hazard under the cell's criterion.
The program with every move at its safe scale is then a candidate like any other (``analysis.fix``: re-checked,
re-tested by verify or the search together), with the cycle time it costs. A search that finds nothing is no
proof, and a move's number is only as good as the search's budget: the table says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cellstress.analysis.remedies import Remedy, program_moves, with_scales
from cellstress.cell.load import Cell, parse_cell
from cellstress.core.errors import CellstressError
from cellstress.core.io import atomic_write_text
from cellstress.searchers import search
from cellstress.sim.simulator import Simulator

CRAWL = 0.01  # the other moves' speed scale while one is measured (the schema's smallest)
STEPS = 6  # bisection steps: the safe scale is found to 1/64
SEARCHER = "plan"


@dataclass(frozen=True)
class MoveSpeed:
    robot: int  # index in the cell's robots
    move: int  # move i goes from waypoint i to the next (the last back to the first)
    original: float  # its speed scale in the cell
    safe: float  # the largest scale found safe (0: none, a hazard even at 1/64)


def _safe(cell: Cell, scales: dict[tuple[int, int], float], budget: int, seed: int, scratch: Path) -> bool:
    remedy = with_scales(cell, scales, "")
    atomic_write_text(scratch, remedy.text)
    try:
        c = parse_cell(remedy.text, str(scratch), scratch.resolve().parent)
    except CellstressError:  # e.g. a joint over its velocity limit at this scale
        return False
    return not search(Simulator(c), SEARCHER, budget, seed, until="budget", distinct=True).distinct


def move_speeds(cell: Cell, budget: int, seed: int, scratch: Path) -> tuple[MoveSpeed, ...]:
    """Every move's largest safe speed scale (module docstring)."""
    moves = program_moves(cell)
    out = []
    for robot, move, original in moves:
        crawl = {(r, m): CRAWL for r, m, _ in moves if (r, m) != (robot, move)}
        lo, hi = 0.0, 1.0
        if _safe(cell, {**crawl, (robot, move): hi}, budget, seed, scratch):
            lo = hi
        else:
            for _ in range(STEPS):
                mid = (lo + hi) / 2
                lo, hi = (mid, hi) if _safe(cell, {**crawl, (robot, move): mid}, budget, seed, scratch) else (lo, mid)
        out.append(MoveSpeed(robot, move, original, lo))
    if scratch.exists():
        scratch.unlink()
    return tuple(out)


def per_move_remedy(cell: Cell, speeds: tuple[MoveSpeed, ...]) -> Remedy | None:
    """Every move at the lesser of its own scale and its safe one (None when no move needs slowing, or when a
    move is unsafe at every scale tried)."""
    if not speeds or any(s.safe <= 0 for s in speeds) or all(s.safe >= s.original for s in speeds):
        return None
    scales = {(s.robot, s.move): min(s.original, s.safe) for s in speeds}
    words = "per-move speed scales " + ", ".join(f"robot {s.robot + 1} move {s.move + 1}: {s.original:g} -> "
                                                 f"{scales[(s.robot, s.move)]:.4g}" for s in speeds)
    return with_scales(cell, scales, words)
