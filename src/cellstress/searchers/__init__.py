"""Search for hazards: ``random``, ``mcts`` (the paper's MCTS1), ``mcts-commit`` (MCTS2), and ours: ``evolve``
and ``plan``; any other searcher registered in the ``cellstress.searchers`` entry-point group.

One module per searcher over shared machinery (``common``: budget, top-k, records, rollouts; ``tree``: the DPW
tree; ``result``: the result record); the distinct and multi-start modes apart (``distinct``, ``multistart``,
``slices``). ``search`` is the public entry point.
"""

from __future__ import annotations

from dataclasses import asdict, fields
from pathlib import Path

from cellstress.core import registry
from cellstress.core.errors import PluginError
from cellstress.core.io import duplicate_json_key
from cellstress.core.version import __version__
from cellstress.searchers.common import (
    UNTIL,
    Episode,
    Outcome,
    Recorder,
    SearchError,
    Stop,
    check_common,
)
from cellstress.searchers.distinct import DistinctRecorder, DistinctReward, distinct_problem, hazard_class_record
from cellstress.searchers.multistart import ArrivalProblem, PhaseProblem
from cellstress.searchers.result import (
    FORMAT,
    CellRef,
    DistinctHazard,
    EpisodeRef,
    Hazard,
    SearchResult,
    TopEpisode,
)
from cellstress.searchers.severity import severity, worst_first
from cellstress.searchers.slices import SLICE_LEN, ClassRecorder, cell_starts, run_slices
from cellstress.searchers.why import explain
from cellstress.sim.simulator import Simulator

DEFAULT_BUDGET = 200
DEFAULT_TOP_K = 10

__all__ = ["UNTIL", "Episode", "Outcome", "Recorder", "SearchError", "SearchResult", "distinct_record",
           "hazard_record", "make_searcher", "parse_options", "run_search", "search", "searcher_class",
           "searcher_names"]


def searcher_names() -> tuple[str, ...]:
    """The registered searchers (``cellstress.searchers`` entry points), cellstress's own first."""
    return registry.names("searchers")


def searcher_class(name: str):
    """The class registered as searcher ``name``; SearchError naming the choices for an unknown name."""
    try:
        return registry.load("searchers", name)
    except PluginError as exc:
        raise SearchError(str(exc)) from None


def parse_options(settings: list[str] | tuple[str, ...] | None, flag: str = "--set") -> dict:
    """``["pool=5", "score=risk"]`` -> ``{"pool": 5, "score": "risk"}``: each VALUE is read as JSON (numbers,
    true/false, null, quoted strings), else taken as plain text. SearchError for a malformed or repeated one."""
    import json

    out: dict = {}
    for item in settings or ():
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep or not name:
            raise SearchError(f"{flag} {item!r}: expected NAME=VALUE (e.g. {flag} pool=5)")
        if name in out:
            raise SearchError(f"{flag}: option {name!r} given twice")
        try:
            out[name] = json.loads(text)
        except (ValueError, RecursionError):
            out[name] = text.strip()
        dup = duplicate_json_key(text)
        if dup is not None:
            raise SearchError(f"{flag} {name}: the key {dup[:60]!r} appears twice in the value")
    return out


def make_searcher(name: str, **options):
    """The searcher ``name`` with ``options``; SearchError for an unknown name or option."""
    cls = searcher_class(name)
    known = {f.name for f in fields(cls)}
    bad = sorted(set(options) - known)
    if bad:
        raise SearchError(f"searcher {name!r} has no option {', '.join(bad)} (options: {', '.join(sorted(known))})")
    return cls(**options)


def run_search(problem, reward, searcher="mcts", budget=DEFAULT_BUDGET, seed=0, *, until="first",
               top_k=DEFAULT_TOP_K, progress=None, recorder=None, **options) -> Outcome:
    """Search any ``core.protocols.Simulator`` (e.g. a toy) with a reward ``reward(measures, last_action, unsafe)``
    -> (reward, risk).
    ``recorder``: a ``Recorder`` made by the caller (e.g. ``distinct.DistinctRecorder``)."""
    check_common(budget, seed, until, top_k)
    s = searcher if not isinstance(searcher, str) else make_searcher(searcher, **options)
    rec = recorder if recorder is not None else Recorder(int(budget), until, int(top_k), progress)
    try:
        s.run(problem, reward, rec, int(seed))
    except Stop:
        pass
    return Outcome(rec.episodes, tuple(rec.hazards), tuple(rec.top.best()), tuple(rec.risks),
                   rec.distinct_sequences)


def search(cell, searcher: str = "mcts", budget: int = DEFAULT_BUDGET, seed: int = 0, *, until: str = "first",
           top_k: int = DEFAULT_TOP_K, progress=None, distinct: bool = False, **options) -> SearchResult:
    """Search a cell (built-in name, path, ``Cell`` or ``Simulator``) for an unsafe action sequence.

    ``searcher`` is ``random``, ``mcts``, ``mcts-commit``, ``evolve`` or ``plan``; ``options`` are its parameters
    (see ``MCTS``, ``MCTSCommit``, ``RandomSearch``, ``Evolve``, ``Plan``). ``until="first"`` stops at the first hazard,
    ``until="budget"`` plays the whole budget. ``progress(episodes, best_risk)`` is called after each episode.
    ``distinct=True`` (with ``until="budget"``) clusters the hazards into classes and steers the search away
    from classes already found (``search.distinct``); the result lists each class's first hazard. A cell with
    several start points (``human.starts``) lets each episode's first decision pick one (``search.multistart``);
    with ``evolve`` and ``plan`` the distinct mode instead shares the budget between the start points in slices
    (``search.slices``), and ``plan``, which searches one start point's problem, always does so on such a cell.
    """
    check_common(budget, seed, until, top_k)
    s = make_searcher(searcher, **options)
    sim = cell if isinstance(cell, Simulator) else Simulator(cell)
    c = sim.cell
    if distinct and until != "budget":
        raise SearchError("distinct needs until='budget' (--until budget --distinct)")
    reward = sim.criterion.reward(sim.actions_per_episode)
    problem = sim
    names = None
    searched_phase = c.spec.human.arrival != "fixed"
    if c.spec.human.starts or searched_phase:
        problem = ArrivalProblem(sim) if c.spec.human.starts else PhaseProblem(sim)
        names = problem.names
    rec = None
    missing = [p.__name__ for p in getattr(type(s), "needs", ()) if not isinstance(problem, p)]
    if missing and not type(s).whole_episodes:
        raise SearchError(f"searcher {s.name!r} needs a problem with {', '.join(missing)}")
    if (distinct or missing) and type(s).whole_episodes:
        # the budget in slices shared by the starts: the distinct mode, and the way a searcher that needs one start
        # point's problem (plan) searches a cell with several (each slice searches one of them)
        starts = cell_starts(problem, reward)
        rec = ClassRecorder(int(budget), until, int(top_k), progress, n_starts=len(starts))
        # (the distinct mode's slices are measured; for the first hazard every start point gets its share early)
        slice_len = SLICE_LEN if distinct else min(SLICE_LEN, max(1, int(budget) // len(starts)))
        out = run_slices(s, starts, reward, rec, int(seed), slice_len)
    else:
        if distinct:
            problem = distinct_problem(problem, sim, reward)
            reward = DistinctReward(reward)
            rec = DistinctRecorder(int(budget), until, int(top_k), progress, problem=problem)
        out = run_search(problem, reward, s, budget, seed, until=until, top_k=top_k, progress=progress,
                         recorder=rec)

    if names is None:
        def names(actions):
            return [sim.action_names[a] for a in actions]

    first = out.first_hazard
    hazard = None if first is None else hazard_record(sim, first.index, names(first.actions))
    # a cell file by its absolute path, so that `cellstress replay` works from any folder
    source = c.source if c.directory is None else str(Path(c.source).expanduser().resolve())
    crit = c.spec.criterion.type
    return SearchResult.model_construct(
        cell=CellRef.model_construct(name=c.name, sha256=c.sha256, source=source, criterion=crit, files=c.files),
        searcher=s.name,
        params=asdict(s),
        seed=int(seed),
        budget=int(budget),
        until=until,
        found=out.found,
        episodes=out.episodes,
        hazard=hazard,
        hazards=tuple(EpisodeRef.model_construct(episode=h.index, actions=tuple(names(h.actions)))
                      for h in out.hazards),
        top=tuple(TopEpisode.model_construct(episode=e.index, actions=tuple(names(e.actions)), ret=e.ret,
                                             risk=e.risk, unsafe=e.unsafe) for e in out.top),
        risk_per_episode=tuple(out.risks),
        distinct_sequences=out.distinct_sequences,
        version=__version__,
        format=FORMAT,
        distinct=None if rec is None or not distinct else tuple(worst_first([
            distinct_record(sim, hazard_class_record(key), episode, names(actions))
            for key, (episode, actions) in rec.classes.items()])),
    )


def _unsafe_row(sim: Simulator, actions: list[str]):
    trace = sim.run(actions)
    if trace.unsafe_row is None:
        raise SearchError(f"the episode {', '.join(actions)} does not reach an unsafe state")
    return trace, trace.records()


def hazard_record(sim: Simulator, episode: int, actions: list[str]) -> Hazard:
    """The first hazard's record: ``actions`` (names) replayed in ``sim``, summarised at the unsafe step. The
    search writes it, and ``replay`` makes it again to check every claim of a result file."""
    trace, records = _unsafe_row(sim, actions)
    hit = records[trace.unsafe_row]
    verdict = sim.verdict_at(trace, trace.unsafe_row)  # a criterion that judges contacts: its account
    return Hazard.model_construct(
        episode=episode, actions=tuple(actions), step=hit.step, time_s=hit.moment, robot_link=hit.robot_link,
        body_part=hit.body_part, point=hit.robot_point, human_point=hit.human_point, v_R=hit.v_R, d_HR=hit.d_HR,
        trace=records, why=explain(trace.layout, records, trace.unsafe_row),
        severity=severity(hit.v_R, None if verdict is None else verdict.as_dict()),
        **({} if verdict is None else {sim.criterion.type: verdict.as_dict()}))


def distinct_record(sim: Simulator, klass, episode: int, actions: list[str]) -> DistinctHazard:
    """The record of a distinct class's first hazard (see ``hazard_record``)."""
    trace, records = _unsafe_row(sim, actions)
    hit = records[trace.unsafe_row]
    verdict = sim.verdict_at(trace, trace.unsafe_row)
    return DistinctHazard.model_construct(
        klass=klass, episode=episode, actions=tuple(actions), step=hit.step, time_s=hit.moment,
        robot_link=hit.robot_link, body_part=hit.body_part, v_R=hit.v_R, trace=records,
        why=explain(trace.layout, records, trace.unsafe_row),
        severity=severity(hit.v_R, None if verdict is None else verdict.as_dict()))
