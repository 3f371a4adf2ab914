"""The campaign's options, its run grid and its manifest (``DIR/campaign.json``).

A run is a pure function of (cell, searcher, seed, budget, searcher options): the same inputs give the same
record on any worker, so the grid can be cut into tasks in any order and a campaign can be resumed. The
manifest pins everything a run's outcome depends on (cell hashes, searcher options, budget, seeds, the
cellstress version); a resumed campaign must match it, or its runs would silently mix two experiments.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field

from cellstress.campaign.paper import paper_table
from cellstress.cell.load import BUILTIN_CELLS, load_cell
from cellstress.core import registry
from cellstress.core.errors import CellstressError
from cellstress.core.fields import Name, Record
from cellstress.core.version import __version__
from cellstress.searchers import make_searcher, searcher_class, searcher_names
from cellstress.searchers.common import MAX_BUDGET
from cellstress.searchers.result import Option

FORMAT = 1
MANIFEST = "campaign.json"
# the paper's experiment (Huck et al. 2020, Sec. V): three flawed scenarios, MCTS1/MCTS2 against random
DEFAULT_CELLS: tuple[str, ...] = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
DEFAULT_SEEDS = 10
DEFAULT_BUDGET = 200
UNTIL = "first"  # the paper stops a run at its first hazard; a failed run counts as the budget


def paper_searchers() -> tuple[str, ...]:
    """The searchers of the paper's experiment, the default ``--searchers``: those registered with a
    ``paper_name``, in the order of the paper's Table III (Random, MCTS1, MCTS2)."""
    order = paper_table().algorithms
    named = {cls.paper_name: n for n, cls in registry.load_all("searchers").items()
             if getattr(cls, "paper_name", None)}
    return tuple(named[a] for a in order if a in named) + tuple(n for a, n in named.items() if a not in order)


class CampaignError(CellstressError):
    """A bad campaign option, or an --out folder that holds another campaign."""


@dataclass(frozen=True)
class CellRef:
    """A cell as the workers load it: ``source`` is a built-in name or an absolute path."""

    name: str
    source: str
    sha256: str
    # what the cell calls unsafe, in words (its file, pinned by sha256, fixes it: not part of the manifest)
    criterion: str = ""


@dataclass(frozen=True)
class SearcherRef:
    """A searcher by its registry name, with its options (the defaults, filled in)."""

    name: str
    params: tuple[tuple[str, Any], ...]  # sorted (option, value) pairs: hashable and picklable

    @property
    def params_dict(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class RunKey:
    cell: str
    searcher: str
    seed: int


@dataclass(frozen=True)
class RunSpec:
    """Everything a worker needs for one run (pickled to worker processes and Ray tasks)."""

    cell: CellRef
    searcher: SearcherRef
    seed: int
    budget: int

    @property
    def key(self) -> RunKey:
        return RunKey(self.cell.name, self.searcher.name, self.seed)


@dataclass(frozen=True)
class CampaignPlan:
    """The resolved options of a campaign: what it runs, not how (workers and backend are not part of it)."""

    cells: tuple[CellRef, ...]
    searchers: tuple[SearcherRef, ...]
    seeds: int
    budget: int
    version: str

    def runs(self) -> list[RunSpec]:
        """The grid in table order: cell, searcher, seed."""
        return [RunSpec(c, s, seed, self.budget) for c in self.cells for s in self.searchers
                for seed in range(self.seeds)]

    def manifest(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "cellstress_version": self.version,
            "cells": [{"name": c.name, "source": c.source, "sha256": c.sha256} for c in self.cells],
            "searchers": [{"name": s.name, "params": s.params_dict} for s in self.searchers],
            "seeds": list(range(self.seeds)),
            "budget": self.budget,
            "until": UNTIL,
            "runs": len(self.cells) * len(self.searchers) * self.seeds,
        }


def split_names(values: list[str] | tuple[str, ...] | None, default: tuple[str, ...], what: str) -> tuple[str, ...]:
    """``--cells a,b --cells c`` -> (a, b, c); the default when not given; duplicates are an error."""
    if not values:
        return default
    names = tuple(n.strip() for v in values for n in str(v).split(",") if n.strip())
    if not names:
        raise CampaignError(f"--{what}: no names given")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CampaignError(f"--{what}: {', '.join(twice)} listed more than once")
    return names


MAX_SEEDS = 100_000  # every run is a line of runs.jsonl and a row of the plan held in memory
MAX_CELLS = 100


def resolve(cells: tuple[str, ...], searchers: tuple[str, ...], seeds: int, budget: int,
            options: dict[str, Any] | None = None) -> CampaignPlan:
    """Check the options and pin them: load every cell (its hash) and fill in each searcher's defaults.
    ``options`` (``--set``) go to every searcher that has them; each must belong to at least one.

    Raises ``CampaignError`` (or the cell's ``CellError``) for anything the user must fix."""

    for opt, value, most in (("seeds", seeds, MAX_SEEDS), ("budget", budget, MAX_BUDGET)):
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= most:
            raise CampaignError(f"--{opt} must be a whole number in 1..{most:,}, not {value!r}")
    if len(cells) > MAX_CELLS or len(searchers) > MAX_CELLS:
        raise CampaignError(f"at most {MAX_CELLS} cells and {MAX_CELLS} searchers in one campaign")
    known = searcher_names()
    unknown = [s for s in searchers if s not in known]
    if unknown:
        raise CampaignError(f"--searchers: unknown searcher {unknown[0]!r} (choose from {', '.join(known)})")
    refs = []
    for ref in cells:
        try:
            c = load_cell(ref)
        except CellstressError as exc:
            raise CampaignError(f"--cells: {exc}") from None
        # a file by its absolute path, so that workers (and a resume from another folder) find it
        source = ref if ref in BUILTIN_CELLS else str(Path(ref).expanduser().resolve())
        refs.append(CellRef(c.name, source, c.sha256, f"{c.spec.criterion.type}: {c.spec.criterion.describe()}"))
    names = [r.name for r in refs]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CampaignError(f"--cells: two cells are named {twice[0]!r}; rows of the table are keyed by name")
    options = dict(options or {})
    has = {s: {f.name for f in fields(searcher_class(s))} for s in searchers}
    orphans = sorted(o for o in options if not any(o in has[s] for s in searchers))
    if orphans:
        raise CampaignError(f"--set {orphans[0]}: none of the searchers ({', '.join(searchers)}) has this option")
    srefs = []
    for s in searchers:
        try:
            searcher = make_searcher(s, **{o: v for o, v in options.items() if o in has[s]})
        except CellstressError as exc:
            raise CampaignError(f"--set: {exc}") from None
        srefs.append(SearcherRef(s, tuple(sorted(asdict(searcher).items()))))
    srefs = tuple(srefs)
    return CampaignPlan(tuple(refs), srefs, int(seeds), int(budget), __version__)


def _show(value: Any) -> str:
    if isinstance(value, list):
        return ",".join(_show(v) for v in value) or "(none)"
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True)
    return str(value)


class ManifestCell(Record):
    name: Name
    source: Annotated[str, Field(max_length=4096)]
    sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]


class ManifestSearcher(Record):
    name: Name
    params: Annotated[dict[Name, Option], Field(max_length=1000)]


class Manifest(Record):
    """``campaign.json`` as read back: a file in a folder that may come from anywhere (a shared drive), so it is
    checked with strict types and bounded sizes before a resumed campaign compares it with its own options."""

    format: Annotated[int, Field(ge=0, le=10**6)]
    cellstress_version: Name
    cells: Annotated[tuple[ManifestCell, ...], Field(max_length=MAX_CELLS)]
    searchers: Annotated[tuple[ManifestSearcher, ...], Field(max_length=MAX_CELLS)]
    seeds: Annotated[tuple[Annotated[int, Field(ge=0, le=MAX_SEEDS)], ...], Field(max_length=MAX_SEEDS)]
    budget: Annotated[int, Field(ge=1, le=MAX_BUDGET)]
    until: Name
    runs: Annotated[int, Field(ge=0, le=MAX_CELLS * MAX_CELLS * MAX_SEEDS)]


def manifest_difference(old: dict[str, Any], new: dict[str, Any]) -> str | None:
    """The first option in which two manifests differ, as one readable phrase; None if they agree."""
    if old.get("format") != new["format"]:
        return f"the folder's campaign.json has format {old.get('format')!r}, this cellstress writes {new['format']}"
    old_cells, new_cells = old.get("cells", []), new["cells"]
    if [c.get("name") for c in old_cells] != [c["name"] for c in new_cells]:
        return (f"--cells differs: {_show([c.get('name') for c in old_cells])} there, "
                f"{_show([c['name'] for c in new_cells])} here")
    for a, b in zip(old_cells, new_cells, strict=True):
        if a.get("sha256") != b["sha256"]:
            return (f"cell {b['name']} has changed since the campaign started (sha256 "
                    f"{str(a.get('sha256'))[:12]} there, {b['sha256'][:12]} here)")
    old_s, new_s = old.get("searchers", []), new["searchers"]
    if [s.get("name") for s in old_s] != [s["name"] for s in new_s]:
        return (f"--searchers differs: {_show([s.get('name') for s in old_s])} there, "
                f"{_show([s['name'] for s in new_s])} here")
    for a, b in zip(old_s, new_s, strict=True):
        if a.get("params") != b["params"]:
            pa, pb = a.get("params") or {}, b["params"]
            diff = sorted(k for k in set(pa) | set(pb) if pa.get(k, "(none)") != pb.get(k, "(none)"))
            return (f"searcher {b['name']}'s options differ (--set, or a changed default): "
                    + ", ".join(f"{k} {_show(pa.get(k, '(none)'))} there, {_show(pb.get(k, '(none)'))} here"
                                for k in diff))
    if old.get("seeds") != new["seeds"]:
        return f"--seeds differs: {len(old.get('seeds') or [])} there, {len(new['seeds'])} here"
    for key, label in (("budget", "--budget"), ("until", "until"), ("cellstress_version", "cellstress version")):
        if old.get(key) != new[key]:
            return f"{label} differs: {_show(old.get(key))} there, {_show(new[key])} here"
    return None
