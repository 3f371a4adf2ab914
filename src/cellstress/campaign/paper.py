"""The paper's published Table III (Huck et al. 2020), shipped as cited data: ``paper_table3.json``."""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from cellstress.core import registry

DATA_FILE = "paper_table3.json"


@dataclass(frozen=True)
class PaperRow:
    """One cell of Table III: successes out of ``runs`` and mean episodes (a failure counted as ``budget``)."""

    found: int
    runs: int
    mean_episodes: float
    budget: int


@dataclass(frozen=True)
class PaperTable:
    citation: str
    budget: int  # episodes per run in the paper's experiment
    rows: tuple[tuple[tuple[str, str], PaperRow], ...]  # ((cell, searcher), row), hashable for the cache
    algorithms: tuple[str, ...]  # the paper's names of its searchers, in its order (Random, MCTS1, MCTS2)

    def get(self, cell: str, searcher: str) -> PaperRow | None:
        return dict(self.rows).get((cell, searcher))


@lru_cache(maxsize=1)
def paper_table() -> PaperTable:
    """Table III keyed by our names: cells s1/s2/s3 are the paper's scenarios 1-3; the searchers are those
    registered with the paper's name of the algorithm (``Searcher.paper_name``: random, mcts and mcts-commit
    are its Random, MCTS1 and MCTS2)."""
    doc = json.loads(resources.files("cellstress.campaign").joinpath(DATA_FILE).read_text(encoding="utf-8"))
    cell_of = {n: c for c, n in doc["scenarios"].items()}
    searcher_of = {cls.paper_name: name for name, cls in registry.load_all("searchers").items()
                   if getattr(cls, "paper_name", None)}
    rows = tuple(((cell_of[r["scenario"]], searcher_of[r["algorithm"]]),
                  PaperRow(int(r["found"]), int(doc["runs"]), float(r["mean_episodes"]), int(doc["budget"])))
                 for r in doc["results"] if r["algorithm"] in searcher_of)
    algorithms = tuple(dict.fromkeys(r["algorithm"] for r in doc["results"]))
    return PaperTable(str(doc["citation"]), int(doc["budget"]), rows, algorithms)
