"""The maximum safe speed per move (``cellstress fix --criterion iso15066``): for each move of each robot's
program, the largest speed scale at which the search finds no contact over the body region's ISO/TS 15066 limit.

Two steps, the search (``plan``, ``--until budget --distinct``, the given budget and seed) the judge of every
try: a speed scale is safe when the search finds no hazard under the cell's criterion on the cell with those
scales. First the **program's** largest scale ``s*``, every move of every robot at the same scale (1.0 tried
first, then a bisection of ``STEPS`` steps on (0, 1)); then, **per move**, the largest scale of that move with
every other move at ``s*`` (1.0 tried first, then a bisection between ``s*`` and 1). A move's number holds with
the others at ``s*`` (a contact anywhere in the cycle counts against the try: the search does not say which
move it happened in). The program with every move at the lesser of its own scale and its safe one is then a
candidate like any other (``analysis.fix``: re-checked, re-tested as a whole), with the cycle time it costs.
A search that finds nothing is no proof, and the numbers are only as good as the budget: the table says so.
(A first version measured each move with the others crawling at 0.01: with the worker's arrival fixed in
seconds, the crawling moves pushed the measured move out of every episode and every move read as safe.)
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

STEPS = 6  # bisection steps of the program's scale (to 1/64); a move's own take 4 (1/16 of what is left)
SEARCHER = "plan"


@dataclass(frozen=True)
class MoveSpeed:
    robot: int  # index in the cell's robots
    move: int  # move i goes from waypoint i to the next (the last back to the first)
    original: float  # its speed scale in the cell
    safe: float  # the largest scale found safe with the other moves at the program's (0: none, even at 1/64)


def _safe(cell: Cell, scales: dict[tuple[int, int], float], budget: int, seed: int, scratch: Path) -> bool:
    remedy = with_scales(cell, scales, "")
    atomic_write_text(scratch, remedy.text)
    try:
        c = parse_cell(remedy.text, str(scratch), scratch.resolve().parent)
    except CellstressError:  # e.g. a joint over its velocity limit at this scale
        return False
    return not search(Simulator(c), SEARCHER, budget, seed, until="budget", distinct=True).distinct


def _largest(ok, lo: float, steps: int) -> float:
    """The largest x in (lo, 1] with ok(x), 1.0 tried first then bisection (``lo`` when none is found)."""
    if ok(1.0):
        return 1.0
    hi = 1.0
    for _ in range(steps):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def move_speeds(cell: Cell, budget: int, seed: int, scratch: Path) -> tuple[MoveSpeed, ...]:
    """Every move's largest safe speed scale (module docstring)."""
    moves = program_moves(cell)
    if not moves:
        return ()
    keys = [(r, m) for r, m, _ in moves]
    program = _largest(lambda x: _safe(cell, dict.fromkeys(keys, x), budget, seed, scratch), 0.0, STEPS)
    out = []
    others = dict.fromkeys(keys, program)
    for robot, move, original in moves:
        if program <= 0:
            out.append(MoveSpeed(robot, move, original, 0.0))
            continue
        safe = _largest(lambda x, k=(robot, move): _safe(cell, {**others, k: x}, budget, seed, scratch), program,
                        STEPS - 2)
        out.append(MoveSpeed(robot, move, original, safe))
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
