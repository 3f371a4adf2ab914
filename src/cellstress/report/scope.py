"""What a search judged and what it covered, in words, for every output that reports one (the command line,
report.html): the criterion that decided "unsafe", and, when nothing was found, what was tried. A search that
finds nothing has not shown that there is nothing to find, and the words say so."""

from __future__ import annotations

from cellstress.cell.schema import CellSpec
from cellstress.core.protocols import Criterion
from cellstress.searchers.common import MAX_TRACKED
from cellstress.searchers.result import SearchResult
from cellstress.sim.starts import phase_grid

NOT_A_PROOF = ("A search is not a proof: it played these sequences, not every sequence, so a hazard may remain "
               "(cellstress check gives the static ISO 13855 distances).")


def judged_by(criterion: Criterion) -> str:
    """``criterion NAME: what it calls unsafe``."""
    return f"{criterion.type}: {criterion.describe()}"


def search_scope(res: SearchResult, spec: CellSpec, cycle: float) -> str:
    """The episodes, different action sequences, start points and robot phases a search covered."""
    n = res.distinct_sequences
    if n is None:
        sequences = ""
    else:
        sequences = f" ({'at least ' if n >= MAX_TRACKED else ''}{n:,} different action sequences)"
    per = spec.simulation.actions_per_episode
    if spec.human.arrival != "fixed":
        return (f"{res.episodes:,} episodes of up to {per} actions{sequences}, {_where(spec, None)}, each arriving at "
                f"a moment of the robot's cycle the search chose: {_arrival_grid(spec, cycle)} (cycle {cycle:.2f} s)")
    return (f"{res.episodes:,} episodes of up to {per} actions{sequences}, {_where(spec, spec)} (cycle {cycle:.2f} s; "
            "other arrival moments were not searched)")


def _where(spec: CellSpec, with_phase: CellSpec | None) -> str:
    """The start points, each with its robot phase when ``with_phase`` (arrival fixed)."""
    human = spec.human

    def phase(p):
        return "" if with_phase is None else f" with the robot {_phase(p, spec)} s into its cycle"

    if human.starts:
        starts = ", ".join(f"{s.name} at ({s.xy[0]:g}, {s.xy[1]:g}){phase(s.phase)}" for s in human.starts)
        return f"from {len(human.starts)} start points: {starts}"
    x, y = human.start.xy
    return f"from the start point ({x:g}, {y:g}){phase(None)}"


def _arrival_grid(spec: CellSpec, cycle: float) -> str:
    dt = spec.simulation.dt
    arrival = spec.human.arrival
    if arrival == "cycle":
        grid = [p for p in phase_grid(dt, 0.0, cycle) if p < cycle]
    else:
        grid = list(phase_grid(dt, arrival.start, arrival.end))
    if not grid:
        return "none"
    return f"{len(grid):,} moments, every {dt:g} s from {grid[0]:g} to {grid[-1]:g} s"


def _phase(phase: float | None, spec: CellSpec) -> str:
    return f"{spec.robot.task.phase if phase is None else phase:g}"


def strongest_contact(sim, actions) -> str | None:
    """For a criterion that judges contacts (``iso15066``): its account of the strongest contact of an episode
    (region, estimated force, limit), or None when the criterion has a fast path or the episode touches nothing.
    A search that found no hazard shows it, so the reader sees how far below the limit the worst contact was."""
    if sim.contacts is None:
        return None
    trace = sim.run(list(actions))
    tol = sim.criterion.distance_tolerance
    verdicts = [sim.verdict_at(trace, i) for i, rec in enumerate(trace.records()) if rec.d_HR <= tol]
    if not verdicts:
        return None
    worst = max(verdicts, key=lambda v: getattr(v, "ratio", 0.0))
    return worst.summary()


def static_lines(failures, verdict: str) -> list[str]:
    """One ``static`` line per row ``cellstress check`` fails (``StaticFailure``s) beside a ``verdict`` ("this
    proof", "this search") that found no contact: the static verdict stands, and where the simulated worker cannot
    take that way in at all, the line says what it cannot do."""
    out = []
    for f in failures:
        head = f"static    check FAILs {f.name} ({f.value}): "
        if f.limit:
            out.append(head + f"{f.limit}; {verdict} does not cover that way in: the static verdict stands")
        else:
            out.append(head + f"{verdict} turned it into no contact within its scope; the static verdict stands")
    return out
