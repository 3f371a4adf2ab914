"""The Python API: plain functions with real signatures, for notebooks and scripts.

    import cellstress
    cell = cellstress.load_cell("s3-fence-gap")
    verdict = cellstress.check(cell)                  # the static ISO 13855 / 13857 check
    result = cellstress.search(cell, searcher="plan", budget=200, seed=0)
    trace = cellstress.simulate(cell, ["walk+bend-right", "walk+bend-forward"])
    proof = cellstress.verify("baseline", phases="cell")  # every action sequence decided exactly
    cellstress.write_report(result, "out/s3")

Each accepts what the command line accepts (a built-in cell name or a cell file's path, or a ``Cell``), raises
``cellstress.core.errors.CellstressError`` for a user's mistake, and returns a typed record.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from cellstress.analysis.check_rows import static_failures
from cellstress.analysis.iso13855 import StaticCheck, check_cell
from cellstress.cell import load
from cellstress.cell.load import Cell
from cellstress.core import registry
from cellstress.report.make import ReportFiles
from cellstress.report.make import write_report as _write_report
from cellstress.searchers import DEFAULT_BUDGET, DEFAULT_TOP_K
from cellstress.searchers import search as _search
from cellstress.searchers.result import SearchResult
from cellstress.sim.simulator import Simulator, Trace
from cellstress.verifier.records import VerifyResult
from cellstress.verifier.run import verify_cell

CellLike = Cell | str | Path


def make_simulator(name: str = "cell", **options) -> Simulator:
    """A registered simulator (``cellstress.simulators`` entry points: ``cell``, the cell simulator, takes a cell;
    ``gym`` any deterministic Gymnasium env, ``cellstress.envs.GymSimulator``), made with ``options``."""
    return registry.load("simulators", name)(**options)


def load_cell(path_or_name: str | Path) -> Cell:
    """A built-in cell by name (``cellstress.BUILTIN_CELLS``) or a cell file by path, validated."""
    return load.load_cell(path_or_name)


def parse_cell(text: str, source: str = "<text>", directory: str | Path | None = None) -> Cell:
    """A cell from the text of a cell file (YAML); ``source`` names it in error messages and ``directory`` is
    where its relative paths (a URDF) are looked up."""
    return load.parse_cell(text, source, None if directory is None else Path(directory))


def _cell(cell: CellLike, criterion: str | None = None) -> Cell:
    c = cell if isinstance(cell, Cell) else load.load_cell(cell)
    return load.with_criterion(c, criterion)


def check(cell: CellLike) -> StaticCheck:
    """The static check of a cell: ISO 13855 distance of every device, the undetected reach around the fences.
    ``.ok`` is the verdict, ``.failures()`` names what failed, ``.lines()`` is what ``cellstress check`` prints."""
    return check_cell(_cell(cell))


def search(cell: CellLike | Simulator, searcher: str = "mcts", budget: int = DEFAULT_BUDGET, seed: int = 0, *,
           until: str = "first", top_k: int = DEFAULT_TOP_K, distinct: bool = False, criterion: str | None = None,
           progress: Callable[[int, float], None] | None = None, **options) -> SearchResult:
    """Search a cell for a sequence of worker actions that ends in an unsafe state.

    ``searcher``: a registered searcher (``random``, ``mcts``, ``mcts-commit``, ``evolve``, ``plan``, or a
    plug-in's); ``options`` are its options (e.g. ``ec=0.5`` for ``mcts``). ``until="first"`` stops at the first
    hazard, ``"budget"`` plays the whole budget; ``distinct=True`` (with ``until="budget"``) lists one hazard per
    class. ``criterion`` overrides the cell's. The same arguments always give the same result."""
    sim = cell if isinstance(cell, Simulator) and criterion is None else Simulator(_cell(
        cell.cell if isinstance(cell, Simulator) else cell, criterion))
    return _search(sim, searcher, budget, seed, until=until, top_k=top_k, progress=progress, distinct=distinct,
                   **options)


def simulate(cell: CellLike, actions: Sequence[int | str], criterion: str | None = None) -> Trace:
    """Play ``actions`` (names such as ``"walk+bend-left"`` or indices 0..29) from the cell's start; the trace
    has one row per 50 ms step, ``.unsafe`` and ``.records()``."""
    return Simulator(_cell(cell, criterion)).run(list(actions))


def write_report(result: SearchResult | str | Path, out: str | Path | None = None) -> ReportFiles:
    """Write the report of a search result (pictures, animation, report.html) into ``out`` (default: the
    result file's folder)."""
    return _write_report(result, out)


def verify(cell: CellLike, *, horizon: int | None = None, phases: str = "all", moments: str = "all",
           time_limit: float | None = None, workers: int | None = 1, out: str | Path | None = None,
           criterion: str | None = None, progress: Callable[[int, int], None] | None = None,
           starts: Sequence[str] | None = None, backend: str = "processes", address: str | None = None) -> VerifyResult:
    """Decide exactly whether any sequence of ``horizon`` worker actions (default: the cell's
    ``actions_per_episode``) reaches the unsafe set, from every start point (or those named in ``starts``), at every
    arrival phase of the robot's cycle on the time-step grid (``phases="all"``), at the cell's own phases
    (``"cell"``) or at the grid phases of a window (``"A:B"``, seconds of the cycle); with
    ``moments="all"`` each grid phase also stands for the arrival moments within half a step of it where the cell
    allows it (``"grid"``: the grid alone). ``.scope`` says exactly what the verdict covers.

    ``.verdict`` is ``PROVED-SAFE``, ``UNSAFE`` or ``UNDECIDED`` (``time_limit`` [s] ran out; never a proof);
    ``.hazardous`` the exact number of hazardous sequences, per sub-tree in ``.subtrees``; ``.classes`` one witness
    per hazard class; ``.static_failures`` the rows ``check`` fails, which a proof of the simulated worker does not
    clear (each says what that worker cannot do there, if anything). ``workers`` processes decide sub-trees in
    parallel (``backend="ray"``: Ray tasks, on the cluster at ``address`` or a local one; the same result);
    ``out``: a folder for verify.json, the witnesses' replayable result files and the checkpoint a stopped run
    resumes from. docs/verify.md says what a proof means."""
    sim = Simulator(_cell(cell, criterion))
    return verify_cell(sim, horizon=horizon, phases=phases, moments=moments, time_limit=time_limit, workers=workers,
                       out=out, progress=progress, static_failures=static_failures(check_cell(sim.cell)),
                       starts=None if starts is None else tuple(starts), backend=backend, address=address)
