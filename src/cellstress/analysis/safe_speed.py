"""The maximum safe speed per move (``cellstress fix --criterion iso15066``): for each move of each robot's
program, the largest speed scale at which the search finds no contact over the body region's ISO/TS 15066 limit.

Two steps, the search (``plan``, ``--until budget --distinct``, the given budget and seed) the judge of every
try: a speed scale is safe when the search finds no hazard under the cell's criterion on the cell with those
scales. First the **program's** largest scale ``s*``, every move of every robot at the same scale; then, **per
move**, the largest scale of that move with every other move at ``s*``. Each is a scan of ``GRID`` (1/8 .. 1)
from the bottom up that stops at the first unsafe try: the search's verdict is not monotone in speed (on
``s1-scanner-width`` under iso15066 with ``plan``, budget 20: safe at 1.0, unsafe at 0.5, 0.25 and 0.125, the
faster robot gone before the worker arrives), so a scale is reported safe only with every slower one tried
safe too (0 when even 1/8 is not). A move's number holds with
the others at ``s*`` (a contact anywhere in the cycle counts against the try: the search does not say which
move it happened in). The program with every move at the lesser of its own scale and its safe one is then a
candidate like any other (``analysis.fix``: re-checked, re-tested as a whole), with the cycle time it costs.
A search that finds nothing is no proof, and the numbers are only as good as the budget: the table says so.
Every try keeps the worker's arrival at the same point of each robot's path (``map_phase``): with the phase
fixed in seconds a faster program put the robot elsewhere at arrival, and ``s1-scanner-width`` read safe at
scale 1.0 under iso15066 while unsafe at its own 0.5.
(A first version measured each move with the others crawling at 0.01: with the worker's arrival fixed in
seconds, the crawling moves pushed the measured move out of every episode and every move read as safe.)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cellstress.analysis.program_check import check_programs
from cellstress.analysis.remedies import Remedy, parse_candidate, program_moves, with_scales
from cellstress.cell.load import Cell
from cellstress.core.errors import CellstressError
from cellstress.searchers import search
from cellstress.sim.build import build_layout
from cellstress.sim.simulator import Simulator

GRID = tuple(i / 8 for i in range(1, 9))  # the speed scales tried, slowest first
SEARCHER = "plan"


@dataclass(frozen=True)
class MoveSpeed:
    robot: int  # index in the cell's robots
    move: int  # move i goes from waypoint i to the next (the last back to the first)
    original: float  # its speed scale in the cell
    safe: float  # the largest scale found safe with the other moves at the program's (0: not even 1/8)


Timing = tuple[tuple[tuple[float, float], ...], float]  # per robot: each move's (start, duration), the cycle [s]


def timings(cell: Cell) -> tuple[Timing, ...]:
    """Every robot's moves (path time each begins, its duration) and cycle, from the program check."""
    return tuple((tuple((m.start, m.duration) for m in p.moves), p.cycle)
                 for p in check_programs(build_layout(cell)))


def map_phase(phase: float, old: Timing, new: Timing) -> float:
    """The time in ``new``'s cycle at which the robot is where it is at ``phase`` in ``old``'s: within a move the
    same fraction of it (a minimum-jerk move's pose is a function of that fraction alone), within a dwell the same
    time before the next move (dwells do not change with speed)."""
    (moves, cycle), (moves2, cycle2) = old, new
    p = phase % cycle if cycle > 0 else 0.0
    for (s, d), (s2, d2) in zip(moves, moves2, strict=True):
        if p < s:
            return max(0.0, s2 - (s - p))
        if p <= s + d:
            return s2 + ((p - s) / d * d2 if d > 0 else 0.0)
    return max(0.0, cycle2 - (cycle - p))


def _scaled_cell(cell: Cell, scales: dict[tuple[int, int], float], words: str, scratch: Path) -> Remedy:
    """The cell at ``scales`` with each robot's phase mapped to the same point of its path, so that the worker
    arrives where the robot is in the cell as given (with the phase fixed in seconds, a faster or slower
    program would put the robot elsewhere at arrival, and speed would change what the search meets)."""
    first = with_scales(cell, scales, words)
    c = parse_candidate(cell, first.text, scratch)
    old, new = timings(cell), timings(c)
    phases = {k: map_phase(float(r.task.phase), old[k], new[k]) for k, r in enumerate(cell.spec.robots)
              if k < len(old) and not r.task.trajectory_csv}
    return with_scales(cell, scales, words, phases)


def _safe(cell: Cell, scales: dict[tuple[int, int], float], budget: int, seed: int, scratch: Path) -> bool:
    try:
        remedy = _scaled_cell(cell, scales, "", scratch)
        c = parse_candidate(cell, remedy.text, scratch)
    except CellstressError:  # e.g. a joint over its velocity limit at this scale
        return False
    return not search(Simulator(c), SEARCHER, budget, seed, until="budget", distinct=True).distinct


def _largest(ok, lo: float) -> float:
    """The largest grid scale above ``lo`` up to which every grid scale passes ``ok``, tried from the bottom up
    (``lo`` when the first fails): the search's verdict need not be monotone in speed (a faster program may pass
    the worker by before it arrives), so a scale counts as safe only with every slower one tried safe too."""
    best = lo
    for x in GRID:
        if x <= lo + 1e-12:
            continue
        if not ok(x):
            return best
        best = x
    return best


def move_speeds(cell: Cell, budget: int, seed: int, scratch: Path) -> tuple[MoveSpeed, ...]:
    """Every move's largest safe speed scale (module docstring)."""
    moves = program_moves(cell)
    if not moves:
        return ()
    keys = [(r, m) for r, m, _ in moves]
    program = _largest(lambda x: _safe(cell, dict.fromkeys(keys, x), budget, seed, scratch), 0.0)
    out = []
    others = dict.fromkeys(keys, program)
    for robot, move, original in moves:
        if program <= 0:
            out.append(MoveSpeed(robot, move, original, 0.0))
            continue
        safe = _largest(lambda x, k=(robot, move): _safe(cell, {**others, k: x}, budget, seed, scratch), program)
        out.append(MoveSpeed(robot, move, original, safe))
    if scratch.exists():
        scratch.unlink()
    return tuple(out)


def per_move_remedy(cell: Cell, speeds: tuple[MoveSpeed, ...], scratch: Path) -> Remedy | None:
    """Every move at the lesser of its own scale and its safe one (None when no move needs slowing, or when a
    move is unsafe at every scale tried)."""
    if not speeds or any(s.safe <= 0 for s in speeds) or all(s.safe >= s.original for s in speeds):
        return None
    scales = {(s.robot, s.move): min(s.original, s.safe) for s in speeds}
    words = "per-move speed scales " + ", ".join(f"robot {s.robot + 1} move {s.move + 1}: {s.original:g} -> "
                                                 f"{scales[(s.robot, s.move)]:.4g}" for s in speeds)
    try:
        return _scaled_cell(cell, scales, words + " (the phase mapped to the same point of the path)", scratch)
    except CellstressError:
        return with_scales(cell, scales, words)
