"""The result record of a search and its JSON file.

``result.json`` holds no wall-clock fields: the same inputs give a byte-identical file (keys sorted, floats
written with Python's shortest round-trip repr, non-finite floats as null, written atomically through a
temporary file and ``os.replace``). Timing goes to the console only.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from cellstress.core.io import atomic_write, canonical_json, json_ready
from cellstress.searchers.common import SearchError

FORMAT = 1
FILE_NAME = "result.json"


@dataclass(frozen=True)
class SearchResult:
    """What ``cellstress.search`` returns and ``result.json`` holds."""

    cell: dict[str, Any]  # name, sha256, source
    searcher: str
    params: dict[str, Any]  # the searcher's options (defaults filled in)
    seed: int
    budget: int
    until: str
    found: bool
    episodes: int  # used, up to and including the first hazard (until=first) or the whole budget
    hazard: dict[str, Any] | None  # the first hazardous episode, with its trace
    hazards: list[dict[str, Any]]  # every hazardous episode: {episode, actions}
    top: list[dict[str, Any]]  # the top-k episodes by return: {episode, actions, return, risk, unsafe}
    risk_per_episode: list[float]  # max 1/c_S of each episode
    version: str
    format: int = FORMAT
    # distinct mode only (absent from the file otherwise): the first hazard of each class, in the order found:
    # {class, episode, actions, step, time_s, robot_link, body_part, v_R, trace}
    distinct: list[dict[str, Any]] | None = None

    def to_dict(self) -> dict[str, Any]:
        doc = asdict(self)
        if doc["distinct"] is None:
            del doc["distinct"]
        return json_ready(doc)

    def to_json(self) -> str:
        return canonical_json(self.to_dict())

    def write(self, out_dir: str | Path) -> Path:
        """Write ``out_dir/result.json`` atomically; returns its path."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        path = out / FILE_NAME
        atomic_write(path, self.to_json().encode("utf-8"))
        return path

    @classmethod
    def from_dict(cls, doc: dict[str, Any]) -> SearchResult:
        return cls(**doc)

    @classmethod
    def load(cls, path: str | Path) -> SearchResult:
        p = Path(path)
        if p.is_dir():
            p = p / FILE_NAME
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise SearchError(f"{p}: no such result file") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise SearchError(f"{p}: not a readable result file ({exc})") from None
        fields = set(cls.__dataclass_fields__)
        if not isinstance(doc, dict) or not {"cell", "hazard", "searcher"} <= set(doc) or set(doc) - fields:
            raise SearchError(f"{p}: not a cellstress result file")
        try:
            return cls.from_dict(doc)
        except TypeError as exc:
            raise SearchError(f"{p}: not a cellstress result file ({exc})") from None
