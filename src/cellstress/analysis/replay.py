"""Check a result file: every claim it makes is computed again, none is taken on trust.

A result file comes from somebody else, so ``cellstress replay`` vouches for nothing it has not recomputed:
- the cell's text must hash to the sha256 recorded, and every file the cell reads (its URDFs, meshes,
  trajectory files) to the sha256 recorded for it: a difference names the file that changed;
- the hazard replayed (its actions, in that cell, under that criterion) must give the recorded summary (unsafe
  step, time, robot link, body part, points, d_HR, v_R, the criterion's verdict) and every trace row, bit for
  bit;
- the search run again with the recorded searcher, options, seed and budget must give the same file: the same
  episode numbers, hazards, kept episodes and risks (searches are deterministic, so any difference is a forged
  or damaged file, or another version of cellstress, which is then named).

The last step costs what the search cost; ``search_again=False`` leaves it out and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

from cellstress.cell.load import load_cell, with_criterion
from cellstress.cell.schema import DEFAULT_CRITERION
from cellstress.core.provenance import file_changes
from cellstress.core.version import __version__
from cellstress.searchers import distinct_record, hazard_record, search
from cellstress.searchers.common import SearchError
from cellstress.searchers.result import DistinctHazard, Hazard, SearchResult
from cellstress.sim.simulator import Simulator, Trace
from cellstress.verifier.witness import SEARCHER as WITNESS_SEARCHER
from cellstress.verifier.witness import witness_result

MAX_LISTED_DIFFERENCES = 4


@dataclass(frozen=True)
class ReplayCheck:
    """What replaying a result file showed: the replayed episode and every claim that did not hold."""

    hazard: Hazard | DistinctHazard
    trace: Trace
    problems: tuple[str, ...]
    searched_again: bool

    @property
    def reproduced(self) -> bool:
        return not self.problems


def check_result(res: SearchResult, index: int | None = None, *, search_again: bool = True) -> ReplayCheck:
    """Replay the first hazard of ``res`` (or its distinct hazard ``index``) and check every claim of the file.
    SearchError (a user error) when there is nothing to replay or the cell cannot be loaded."""
    listed = res.hazard if index is None else _distinct(res, index)
    if listed is None:
        raise SearchError("the search found no hazard; there is nothing to replay")
    cell = with_criterion(load_cell(res.cell.source), res.cell.criterion or DEFAULT_CRITERION)
    sim = Simulator(cell)
    problems: list[str] = []
    if cell.sha256 != res.cell.sha256:
        problems.append(f"cell.sha256: the cell differs from the one searched (sha256 {cell.sha256[:12]} != "
                        f"{res.cell.sha256[:12]})")
    if res.cell.files is not None:  # every file the cell read: which one changed (absent from older files)
        problems += [f"cell.files: {change}" for change in file_changes(res.cell.files, cell.files)]
    if cell.name != res.cell.name:
        problems.append(f"cell.name: the file says {res.cell.name!r}, the cell is {cell.name!r}")
    actions = list(listed.actions)
    trace = sim.run(actions)
    prefix = "hazard" if index is None else f"distinct[{index}]"
    if trace.unsafe_row is None:
        problems.append(f"{prefix}: the replayed episode does not reach an unsafe state")
    else:
        again = (hazard_record(sim, listed.episode, actions) if index is None
                 else distinct_record(sim, listed.klass, listed.episode, actions))
        computed = again.model_dump(by_alias=True)
        if listed.why is None:  # a file written before the timeline was recorded makes no claim about it
            computed["why"] = None
        if listed.severity is None:  # ... nor one written before severities were
            computed["severity"] = None
        problems += differences(listed.model_dump(by_alias=True), computed, prefix)
    if search_again and not problems:
        problems += _search_again(res, sim)
    return ReplayCheck(listed, trace, tuple(problems), search_again)


def _distinct(res: SearchResult, index: int) -> DistinctHazard:
    hs = res.distinct or ()
    if not 0 <= index < len(hs):
        raise SearchError(f"--hazard {index}: the result lists {len(hs)} distinct hazards"
                          + (f" (0..{len(hs) - 1})" if hs else ""))
    return hs[index]


def _search_again(res: SearchResult, sim: Simulator) -> list[str]:
    """The search re-run from the file's own settings, compared field by field with the file. A witness of
    ``cellstress verify`` is a one-episode file whose every claim follows from its sequence: it is made again
    from the sequence."""
    try:
        if res.searcher == WITNESS_SEARCHER and res.hazard is not None:
            again = witness_result(sim, list(res.hazard.actions), res.cell.source)
        else:
            again = search(sim, res.searcher, res.budget, res.seed, until=res.until, top_k=len(res.top),
                           distinct=res.distinct is not None, **res.params)
    except SearchError as exc:
        return [f"searcher, params: the recorded search cannot be run again ({exc})"]
    recorded, rerun = res.to_dict(), again.to_dict()
    recorded.pop("version"), rerun.pop("version")
    # files written before these fields existed make no claim about them
    if "distinct_sequences" not in recorded:
        rerun.pop("distinct_sequences", None)
    for key in ("criterion", "files"):
        if key not in recorded["cell"]:
            rerun["cell"].pop(key, None)
    old_distinct = recorded.get("distinct") or ()
    if old_distinct and "severity" not in old_distinct[0] and rerun.get("distinct"):
        rerun["distinct"].sort(key=lambda d: d["episode"])  # such files list the classes in the order found
    for old, new in zip((recorded.get("hazard"), *(recorded.get("distinct") or ())),
                        (rerun.get("hazard"), *(rerun.get("distinct") or ())), strict=False):
        for key in ("why", "severity"):
            if isinstance(old, dict) and isinstance(new, dict) and key not in old:
                new.pop(key, None)
    found = differences(recorded, rerun, "")
    if not found:
        return []
    how = (f"searcher {res.searcher}, seed {res.seed}, budget {res.budget}, until {res.until}"
           + (", distinct" if res.distinct is not None else ""))
    other = "" if res.version == __version__ else (f" (the file was written by cellstress {res.version}, "
                                                   f"this is {__version__})")
    return [f"the search run again ({how}) does not give this file{other}: {found[0]}"] + found[1:]


def differences(recorded, computed, path: str) -> list[str]:
    """The paths where two JSON-like values differ, with both values (shortened), at most a few."""
    out: list[str] = []
    _walk(recorded, computed, path, out)
    if len(out) > MAX_LISTED_DIFFERENCES:
        out = out[:MAX_LISTED_DIFFERENCES] + ["... and further differences"]
    return out


def _walk(a, b, path: str, out: list[str]) -> None:
    if len(out) > MAX_LISTED_DIFFERENCES:
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            _walk(a.get(k, _MISSING), b.get(k, _MISSING), f"{path}.{k}" if path else str(k), out)
    elif isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            out.append(f"{path}: the file lists {len(a)}, the replay gives {len(b)}")
        else:
            for i, (x, y) in enumerate(zip(a, b, strict=True)):
                _walk(x, y, f"{path}[{i}]", out)
    elif not _same(a, b):
        out.append(f"{path}: the file says {_short(a)}, the replay gives {_short(b)}")


def _same(a, b) -> bool:
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True  # NaN in both
    return type(a) is type(b) and a == b or (isinstance(a, (int, float)) and isinstance(b, (int, float))
                                              and float(a) == float(b))


class _Missing:
    def __repr__(self) -> str:
        return "nothing"


_MISSING = _Missing()


def _short(v) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."
