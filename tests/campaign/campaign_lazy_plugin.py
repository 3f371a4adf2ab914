"""A searcher plug-in for test_campaign_backends: random search with a smaller default chunk."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from cellstress.searchers.random_search import RandomSearch


@dataclass(frozen=True)
class Lazy(RandomSearch):
    chunk: int = 8
    name: ClassVar[str] = "lazy-random"
    paper_name: ClassVar[str | None] = None
    color: ClassVar[str | None] = None
