"""``cellstress fix``: candidate changes (``analysis.remedies``), each re-checked and re-tested, with its cost.

A candidate is **kept** when the changed cell passes ``check`` (every row) and its re-test finds nothing:

* ``verify`` at the cell's horizon, ``--phases cell --moments grid`` (the cell's own arrival moments, grid
  moments only), one worker process, within ``time_limit`` seconds: PROVED-SAFE keeps it, UNSAFE drops it;
* where verify cannot decide (UNDECIDED at the time limit, a horizon over verify's 12):
  the search ``plan`` over ``budget`` episodes, ``--until budget --distinct`` with ``seed``: no hazard keeps it
  (a search is not a proof, and the row says "search").

Cost, the ranking (cheapest first, docs/fix.md): cycle time added [s], then floor area added [m^2] (the cell's
footprint: the convex hull of its fences and devices), then parts added, then the order the candidates were
tried in (settings named by rows; ``analysis.way_remedies``' device heights, ``analysis.device_remedies``'
scanner resolutions, closed gaps and gaps covered by a curtain, raised curtain tops and fences, enlarged warning
fields, reduced speeds, deeper mats, lowered panels; the device moved alone; the device moved with the cell;
the program slowed per move: ``analysis.safe_speed``, also where check passes and the re-test finds a hazard).
A move that passes check while its re-test still finds a hazard is tried again ``EXTRA`` metres further. Wall-clock
time is kept out of every file: the same inputs give the same bytes, unless a verify ends within a hair of
the time limit on one run and not on another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from cellstress.analysis.check_rows import CheckRow, check_rows
from cellstress.analysis.device_remedies import (
    covered_gaps,
    deeper_mats,
    enlarged_warnings,
    finer_resolutions,
    reduced_speeds,
)
from cellstress.analysis.espe_rules import CurtainReachOver
from cellstress.analysis.iso13855 import StaticCheck, check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.analysis.remedies import (
    ROUNDS,
    Move,
    Remedy,
    cell_document,
    device_entry,
    device_move,
    moved,
    panel_move,
    parse_candidate,
    reach_over_move,
    setting_remedies,
)
from cellstress.analysis.safe_speed import MoveSpeed, move_speeds, per_move_remedy
from cellstress.analysis.way_remedies import (
    closed_gaps,
    device_heights,
    lowered_panels,
    raised_fences,
    raised_tops,
)
from cellstress.cell.load import Cell
from cellstress.core.errors import CellstressError
from cellstress.robot.capsules import convex_hull_2d
from cellstress.searchers import search
from cellstress.sim.build import build_layout
from cellstress.sim.simulator import Simulator
from cellstress.verifier.run import VerifyError, verify_cell

MAX_VERIFY_HORIZON = 12  # verify's own limit
SEARCHER = "plan"
EXTRA = (0.1, 0.2, 0.4)  # m beyond ISO 13855 tried in turn where a move passes check and the re-test finds a hazard
SECOND_STEPS = 3  # first changes a second one is tried on, where no single change works


@dataclass(frozen=True)
class Retest:
    """How a cell was re-tested and what that found."""

    method: str  # 'verify' or 'search'
    hazards: int  # hazard classes found (verify: its classes; search: distinct classes)
    proved: bool  # verify PROVED-SAFE
    words: str  # e.g. 'verify horizon 8, cell phases, grid moments: PROVED-SAFE'


@dataclass(frozen=True)
class Checked:
    rows: tuple[CheckRow, ...]
    cycle: float  # s, the longest robot cycle
    footprint: float  # m^2, the cell's footprint (``footprint``)

    @property
    def failing(self) -> tuple[str, ...]:
        return tuple(r.name for r in self.rows if not r.ok)


@dataclass(frozen=True)
class Proposal:
    """One candidate, its cost and its verdict after."""

    number: int  # the candidate's file number (candidate-N.yaml)
    kind: str
    change: str
    answers: tuple[str, ...]
    cycle_added: float  # s
    floor_added: float  # m^2
    parts_added: int
    failing_after: tuple[str, ...]  # check rows still failing
    retest: Retest | None  # None when check failed (no re-test run)
    kept: bool
    text: str  # the changed cell file

    @property
    def cost(self) -> tuple[float, float, int, int]:
        return (round(self.cycle_added, 6), round(self.floor_added, 6), self.parts_added, self.number)


@dataclass(frozen=True)
class FixResult:
    cell: str
    failing_before: tuple[str, ...]
    retest_before: Retest | None  # None when check failed (the original is not re-tested)
    budget: int
    seed: int
    time_limit: float
    candidates: tuple[Proposal, ...]  # in the order tried
    criterion: str = ""  # the criterion every re-test judged by
    speeds: tuple[MoveSpeed, ...] = ()  # --criterion iso15066: each move's largest safe speed scale

    @property
    def needs_nothing(self) -> bool:
        return not self.failing_before and self.retest_before is not None and self.retest_before.hazards == 0

    @property
    def kept(self) -> tuple[Proposal, ...]:
        """The proposals that work, cheapest first."""
        return tuple(sorted((p for p in self.candidates if p.kept), key=lambda p: p.cost))

    @property
    def exit_code(self) -> int:
        return 0 if self.needs_nothing or self.kept else 1


# ---- check and re-test -------------------------------------------------------------------------------------
def checked(cell: Cell) -> tuple[Checked, StaticCheck]:
    layout = build_layout(cell)
    static, programs = check_cell(cell, layout), check_programs(layout)
    cycle = max((p.cycle for p in programs), default=0.0)
    return Checked(check_rows(static, programs), cycle, footprint(cell)), static


def footprint(cell: Cell) -> float:
    """The floor area the cell takes [m^2]: the convex hull of its fences' points and its devices' outlines
    (fields, curtain and door lines, warning fields), what a layout change moves; the floor rectangle of the
    file is only the simulated area and is not counted."""
    pts: list[tuple[float, float]] = []
    for f in cell.spec.fences:
        pts += [tuple(p) for p in f.points]
    for d in cell.spec.devices:
        for key in ("start", "end"):
            if getattr(d, key, None) is not None:
                pts.append(tuple(getattr(d, key)))
        pts += [tuple(p) for p in getattr(d, "polygon", None) or ()]
        warning = getattr(d, "warning", None)
        pts += [tuple(p) for p in getattr(warning, "polygon", None) or ()]
    return hull_area(pts)


def hull_area(points: list[tuple[float, float]]) -> float:
    """Area of the convex hull (``robot.capsules.convex_hull_2d``, then the shoelace formula); 0 for fewer than
    3 distinct points."""
    try:
        hull = convex_hull_2d(np.asarray(points, dtype=float).reshape(-1, 2))
    except ValueError:
        return 0.0
    x, y = hull[:, 0], hull[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) / 2)


def retest(cell: Cell, budget: int, seed: int, time_limit: float) -> Retest:
    """verify where it decides within ``time_limit``, else the search (module docstring)."""
    sim = Simulator(cell)
    horizon = sim.actions_per_episode
    why = ""
    if horizon > MAX_VERIFY_HORIZON:
        why = f"horizon {horizon} > verify's {MAX_VERIFY_HORIZON}"
    else:
        try:
            res = verify_cell(sim, phases="cell", moments="grid", time_limit=time_limit, workers=1)
        except VerifyError as exc:
            why = str(exc)
        else:
            if res.verdict != "UNDECIDED":
                proved = res.verdict == "PROVED-SAFE"
                return Retest("verify", len(res.classes), proved,
                              f"verify horizon {horizon}, cell phases, grid moments: {res.verdict}"
                              + ("" if proved else f" ({len(res.classes)} hazard classes)"))
            why = f"verify undecided within {time_limit:g} s"
    res = search(sim, SEARCHER, budget, seed, until="budget", distinct=True)
    n = len(res.distinct or ())
    return Retest("search", n, False, f"search {SEARCHER}, {budget} episodes, seed {seed} ({why}): "
                  + (f"{n} hazard classes" if n else "no hazard found (not a proof)"))


# ---- the candidates ----------------------------------------------------------------------------------------


def _moves(cell: Cell, static: StaticCheck, whole: bool, scratch: Path) -> tuple[Move, ...]:
    """Move every short device, re-measure, repeat (ROUNDS at most): the moves that make every ISO 13855
    device row pass, or the last tried."""
    moves: list[Move] = []
    current = static
    doc = cell_document(cell)
    for _ in range(ROUNDS):
        new = _device_moves(current)
        if not whole:  # a row that names no device of the file (a warning field's) cannot move alone
            new = [m for m in new if device_entry(doc, m.device) is not None]
        if whole:  # a fence panel too close for ISO 13857 Table 2 moves with the walls that meet it
            panels = [pr for a in (current.approach, *current.robot_approaches) for pr in a.reach_over_fails]
            new += list({m.line: m for pr in panels if (m := panel_move(pr)) is not None}.values())
        if not new:
            break
        moves += new
        try:
            c = parse_candidate(cell, moved(cell, tuple(moves), whole).text, scratch)
        except CellstressError:
            break  # the candidate's own evaluation reports it
        current = checked(c)[1]
    return tuple(moves)


def _device_moves(static: StaticCheck) -> list[Move]:
    """Each short device's move (ISO 13855 S, and for a curtain reached over its top S_RO): one per device, the
    larger where both rows fail, so one edge is not moved twice."""
    rows = {d.device: d for d in static.devices}
    found = [m for d in static.devices if (m := device_move(d)) is not None]
    found += [m for r in static.access if isinstance(r, CurtainReachOver) and r.device in rows
              and (m := reach_over_move(r, rows[r.device])) is not None]
    best: dict[str, Move] = {}
    for m in found:
        if m.device not in best or m.delta > best[m.device].delta:
            best[m.device] = m
    return list(best.values())


def fix_cell(cell: Cell, out: Path, budget: int = 100, seed: int = 0, time_limit: float = 30.0,
             safe_speeds: bool = False) -> FixResult:
    """Every candidate for ``cell``, each written to ``out``/candidate-N.yaml, checked and re-tested;
    ``safe_speeds``: also each move's largest safe speed (``analysis.safe_speed``) and, where a move must slow
    down, the program at those speeds as a candidate."""
    base, static = checked(cell)
    before = None if base.failing else retest(cell, budget, seed, time_limit)
    scratch = out / ".fix-scratch.yaml"  # each try written and read back as a cell file; removed at the end
    speeds = move_speeds(cell, budget, seed, scratch) if safe_speeds else ()
    result = FixResult(cell.spec.name, base.failing, before, budget, seed, time_limit, (),
                       cell.spec.criterion.type, speeds)
    if result.needs_nothing:
        return result
    proposals: list[Proposal] = []

    def evaluate(r: Remedy) -> Proposal:
        proposals.append(_evaluate(cell, len(proposals) + 1, r, base, out, budget, seed, time_limit))
        return proposals[-1]

    if base.failing:
        _try_every_kind(cell, static, evaluate, scratch)
        _second_steps(cell, base, proposals, evaluate, out, scratch)
    elif not speeds:  # check passes and the re-test found a hazard: slowing is the remedy left
        speeds = move_speeds(cell, budget, seed, scratch)
        result = replace(result, speeds=speeds)
    per_move = per_move_remedy(cell, speeds, scratch)
    if per_move is not None:
        evaluate(per_move)
    if scratch.exists():
        scratch.unlink()
    return replace(result, candidates=tuple(proposals))


def _try_every_kind(cell: Cell, static: StaticCheck, evaluate, scratch: Path) -> None:
    """Every candidate kind for ``cell``'s failing rows, in the order tried (module docstring), each handed to
    ``evaluate`` (which checks, re-tests and records it, and returns its ``Proposal``)."""

    def static_of(text: str) -> StaticCheck | None:
        return _static_of(cell, text, scratch)

    for r in (setting_remedies(cell, static) + device_heights(cell, static) + finer_resolutions(cell, static)
              + closed_gaps(cell, static) + covered_gaps(cell, static)):
        evaluate(r)
    for r in (raised_tops(cell, static, static_of) + raised_fences(cell, static, static_of)
              + enlarged_warnings(cell, static, static_of) + reduced_speeds(cell, static, static_of)
              + deeper_mats(cell, static)):
        evaluate(r)
    for tries in lowered_panels(cell, static):  # the least lowering first; a lower one only where it fails
        for r in tries:
            if evaluate(r).kept:
                break
    for whole in (False, True):
        moves = _moves(cell, static, whole, scratch)
        for extra in (0.0, *EXTRA):
            if not moves:
                break
            p = evaluate(moved(cell, moves, whole, extra))
            if p.failing_after or p.kept:  # more room helps only where check passes and a hazard remains
                break


def _second_steps(cell: Cell, base: Checked, proposals: list[Proposal], evaluate, out: Path, scratch: Path) -> None:
    """Where no candidate works, a candidate that leaves fewer failing rows (and no new one) is taken as the
    cell and every kind is tried on it again, the two changes as one candidate (its cost against the cell as
    given): one row answered by each, as a closed gap and a moved scanner. At most ``SECOND_STEPS`` first
    changes, fewest rows left first; it stops at the first that gives a working pair."""
    if any(p.kept for p in proposals):
        return
    before = set(base.failing)
    firsts = sorted((p for p in proposals if p.retest is None and p.failing_after
                     and set(p.failing_after) < before), key=lambda p: (len(p.failing_after), p.number))
    for first in firsts[:SECOND_STEPS]:
        try:  # read from its own file: every generator reads the cell's file again, and the scratch one changes
            c = parse_candidate(cell, first.text, out / f"candidate-{first.number}.yaml")
        except CellstressError:
            continue
        _, static = checked(c)

        def then(r: Remedy, first: Proposal = first) -> Proposal:
            return evaluate(Remedy(f"{first.kind}+{r.kind}", f"{first.change}; then {r.change}",
                                   tuple(dict.fromkeys(first.answers + r.rows)), first.parts_added + r.parts_added,
                                   r.text))

        _try_every_kind(c, static, then, scratch)
        if any(p.kept for p in proposals):
            return


def _static_of(cell: Cell, text: str, scratch: Path) -> StaticCheck | None:
    """The static check of the changed copy ``text`` of ``cell`` (``parse_candidate``), None if invalid."""
    try:
        c = parse_candidate(cell, text, scratch)
    except CellstressError:
        return None
    return checked(c)[1]


def _evaluate(cell: Cell, number: int, r: Remedy, base: Checked, out: Path, budget: int, seed: int,
              time_limit: float) -> Proposal:
    path = out / f"candidate-{number}.yaml"
    try:
        c = parse_candidate(cell, r.text, path)
    except CellstressError as exc:
        return Proposal(number, r.kind, r.change, r.rows, 0.0, 0.0, r.parts_added, (f"invalid: {exc}",), None,
                        False, r.text)
    after, _ = checked(c)
    test = None if after.failing else retest(c, budget, seed, time_limit)
    kept = not after.failing and test is not None and test.hazards == 0
    return Proposal(number, r.kind, r.change, r.rows, _tidy(after.cycle - base.cycle),
                    _tidy(after.footprint - base.footprint), r.parts_added, after.failing, test, kept, r.text)


def _tidy(x: float) -> float:
    x = round(x, 6)
    return 0.0 if math.isclose(x, 0.0, abs_tol=1e-9) else x
