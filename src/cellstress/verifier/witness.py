"""Witnesses as result files that ``cellstress replay`` and ``cellstress report`` read.

A witness is a hazardous action sequence from one start point at one arrival phase. Its actions are written as
a search records an episode of a cell whose worker may arrive at any phase: ``start:NAME`` (on a cell with
``human.starts``), ``phase:SECONDS``, then the worker's actions (``sim.starts``), so they replay in the cell
itself. The result file records the sequence as the hazard of a one-episode "search" by ``verify``: every claim
of the file follows from the sequence alone, so ``replay`` re-checks it by making it again from the sequence
(``witness_result``), bit for bit.
"""

from __future__ import annotations

from pathlib import Path

from cellstress.core.version import __version__
from cellstress.searchers import hazard_record
from cellstress.searchers.result import FORMAT, CellRef, EpisodeRef, SearchResult, Severity, TopEpisode
from cellstress.searchers.severity import severity
from cellstress.sim.layout import M_V
from cellstress.sim.starts import START_PREFIX, phase_token, split_start
from cellstress.verifier.phases import StartPoint

SEARCHER = "verify"  # the ``searcher`` of a witness's result file


def witness_actions(sim, start: StartPoint, phase: float, actions: tuple[int, ...]) -> tuple[str, ...]:
    """A witness's recorded actions: its start point (on a cell with several), its phase, its actions' names
    (``sim``'s worker's: the paper's 30 or the articulated worker's)."""
    head = (f"{START_PREFIX}{start.name}",) if sim.cell.spec.human.starts else ()
    return (*head, phase_token(phase), *(sim.action_names[a] for a in actions))


def witness_result(sim, actions: list[str], source: str) -> SearchResult:
    """The result file of a witness: ``actions`` (``witness_actions``) played in ``sim`` as episode 1 of 1."""
    c = sim.cell
    played, rest = split_start(sim, actions)
    reward = played.criterion.reward(played.actions_per_episode)
    state, ret, risk = played.reset(), 0.0, 0.0
    for k, a in enumerate(rest):
        state, rows = played.step(state, a)
        unsafe = played.is_unsafe(state)
        r, rk = reward(played.measures(rows), k == played.actions_per_episode - 1, unsafe)
        ret, risk = ret + r, max(risk, rk)
        if unsafe:
            break
    acts = tuple(actions)
    return SearchResult.model_construct(
        cell=CellRef.model_construct(name=c.name, sha256=c.sha256, source=source, criterion=c.spec.criterion.type,
                                     files=c.files),
        searcher=SEARCHER, params={}, seed=0, budget=1, until="first", found=True, episodes=1,
        hazard=hazard_record(sim, 1, list(acts)),
        hazards=(EpisodeRef.model_construct(episode=1, actions=acts),),
        top=(TopEpisode.model_construct(episode=1, actions=acts, ret=ret, risk=risk, unsafe=True),),
        risk_per_episode=(risk,), distinct_sequences=1, version=__version__, format=FORMAT, distinct=None)


def witness_severity(sim, actions: tuple[str, ...]) -> Severity:
    """How bad a witness's contact is (``searchers.severity``), from its sequence played in ``sim``'s cell."""
    trace = sim.run(list(actions))
    row = trace.rows[trace.unsafe_row]
    verdict = sim.verdict_at(trace, trace.unsafe_row)
    return severity(float(row[M_V]), None if verdict is None else verdict.as_dict())


def write_witness(sim, actions: tuple[str, ...], out: Path, folder: str) -> Path:
    """Write ``out/folder/result.json`` for a witness of ``sim``'s cell; returns its path. ``folder`` is made
    inside the output folder ``out`` without following a link planted there (``core.io.write_in_folder``)."""
    c = sim.cell
    source = c.source if c.directory is None else str(Path(c.source).expanduser().resolve())
    return witness_result(sim, list(actions), source).write(Path(out) / folder, inside=out)
