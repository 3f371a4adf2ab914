"""What changed between two cells (``cellstress diff OLD NEW``), the gate a team puts on layout changes.

Three comparisons, each of what the tools computed, never of the files' text:

* **fields**: the two loaded, validated cell models (``CellSpec``, every default filled in, so a field written
  out with its default value is no change) walked side by side; lists of named things (devices, robots,
  obstacles) are matched by name, other lists by position. The files a cell reads (URDF, meshes, a trajectory
  CSV) are compared by their SHA-256. The description is free text and is left out.
* **check rows** (``analysis.check_rows``): rows added or gone, and rows whose verdict or value changed.
* **hazard classes**: the same search (searcher, seed, budget, ``--until budget --distinct``) on both cells; a
  class is the search's own key (``searchers.distinct.hazard_class``: device bypassed, robot link, body region,
  approach cell, and the robot's move where the arrival is searched). A class found on NEW and not on OLD is
  new, one found on OLD only is gone. A search that finds nothing proves nothing: the result says so.

The gate fails (exit 1) when NEW has a failing check row or a hazard class OLD did not have.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import PurePosixPath

from cellstress.analysis.check_rows import CheckRow, check_rows
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.cell.load import Cell, load_cell
from cellstress.searchers import search
from cellstress.sim.build import build_layout
from cellstress.sim.simulator import Simulator

MAX_VALUE_TEXT = 120  # characters of a changed value shown (the JSON file has it whole up to this too)

# which part of the cell a top-level field belongs to (the words: geometry, devices, program, stopping)
_SECTIONS = {"table": "geometry", "obstacles": "geometry", "fences": "geometry", "floor": "geometry",
             "devices": "devices", "human": "worker", "criterion": "criterion", "simulation": "simulation",
             "name": "name", "files": "files"}
_ROBOT_SECTIONS = {"task": "program", "stopping": "stopping", "stopping_time": "stopping"}


@dataclass(frozen=True)
class FieldChange:
    section: str  # geometry, devices, program, stopping, robot, worker, criterion, simulation, files, name
    path: str  # e.g. 'devices[front-mat].polygon[1]'
    old: str  # the value as compact JSON ('' where the field or item is absent)
    new: str


@dataclass(frozen=True)
class RowChange:
    name: str
    change: str  # 'added', 'removed', 'verdict', 'value'
    old_ok: bool | None  # None: no such row
    new_ok: bool | None
    old_value: str
    new_value: str


@dataclass(frozen=True)
class ClassKey:
    """A hazard class as the search keys it."""

    device: str
    robot_link: str
    body_region: str
    approach_cell: tuple[float, float, float, float]
    robot_move: int | None

    @classmethod
    def of(cls, k) -> ClassKey:
        return cls(k.device, k.robot_link, k.body_region, tuple(k.approach_cell), k.robot_move)


@dataclass(frozen=True)
class SearchSide:
    """One cell's search: its classes, in the search's order (worst first), and what was searched."""

    classes: tuple[ClassKey, ...]
    episodes: int
    hazardous_episodes: int


@dataclass(frozen=True)
class CellDiff:
    old: str  # the cells' names
    new: str
    searcher: str
    seed: int
    budget: int
    fields: tuple[FieldChange, ...]
    rows: tuple[RowChange, ...]
    new_rows: tuple[CheckRow, ...]  # NEW's rows, every one (the gate's failing rows are among them)
    old_search: SearchSide
    new_search: SearchSide

    @property
    def failing_rows(self) -> tuple[CheckRow, ...]:
        return tuple(r for r in self.new_rows if not r.ok)

    @property
    def new_classes(self) -> tuple[ClassKey, ...]:
        had = set(self.old_search.classes)
        return tuple(k for k in self.new_search.classes if k not in had)

    @property
    def gone_classes(self) -> tuple[ClassKey, ...]:
        has = set(self.new_search.classes)
        return tuple(k for k in self.old_search.classes if k not in has)

    @property
    def passes(self) -> bool:
        return not self.failing_rows and not self.new_classes


# ---- the models, field by field --------------------------------------------------------------------------
def _text(value) -> str:
    text = json.dumps(value, sort_keys=True, separators=(",", ":"))
    return text if len(text) <= MAX_VALUE_TEXT else text[:MAX_VALUE_TEXT - 3] + "..."


def _named(items: list) -> dict | None:
    """A list of records with unique names, as a dict by name (None if it is not one)."""
    if not items or not all(isinstance(i, dict) and isinstance(i.get("name"), str) for i in items):
        return None
    names = [i["name"] for i in items]
    return dict(zip(names, items, strict=True)) if len(set(names)) == len(names) else None


def _walk(path: str, a, b, out: list[tuple[str, str, str]]) -> None:
    if a == b:
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for key in [*a, *(k for k in b if k not in a)]:
            sub = f"{path}.{key}" if path else str(key)
            if key not in a or key not in b:
                out.append((sub, "" if key not in a else _text(a[key]), "" if key not in b else _text(b[key])))
            else:
                _walk(sub, a[key], b[key], out)
        return
    if isinstance(a, list) and isinstance(b, list):
        na, nb = _named(a), _named(b)
        if na is not None and nb is not None:
            for name in [*na, *(n for n in nb if n not in na)]:
                sub = f"{path}[{name}]"
                if name not in na or name not in nb:
                    out.append((sub, "" if name not in na else _text(na[name]),
                                "" if name not in nb else _text(nb[name])))
                else:
                    _walk(sub, na[name], nb[name], out)
            return
        if len(a) == len(b) and all(isinstance(x, (dict, list)) for x in a + b):
            for i, (x, y) in enumerate(zip(a, b, strict=True)):
                _walk(f"{path}[{i + 1}]", x, y, out)
            return
    out.append((path, _text(a), _text(b)))


def _section(path: str) -> str:
    head = path.split(".")[0].split("[")[0]
    if head == "robots":
        rest = path.split("].", 1)[1] if "]." in path else ""
        return _ROBOT_SECTIONS.get(rest.split(".")[0].split("[")[0], "robot")
    return _SECTIONS.get(head, head)


def _model(cell: Cell) -> dict:
    doc = cell.spec.model_dump(mode="json")
    doc.pop("description", None)
    doc.pop("robot", None)  # the validated model lists every robot under robots (robot is robots[0] again)
    files: dict[str, str] = {}
    for f in cell.files:
        if f.use != "cell":  # the cell file itself is what is being compared, field by field
            files[f"{f.use} {PurePosixPath(f.path).name}"] = f.sha256
    doc["files"] = files
    return doc


def field_changes(old: Cell, new: Cell) -> tuple[FieldChange, ...]:
    out: list[tuple[str, str, str]] = []
    _walk("", _model(old), _model(new), out)
    return tuple(FieldChange(_section(p), p, a, b) for p, a, b in out)


# ---- the check and the search -----------------------------------------------------------------------------
def row_changes(old: tuple[CheckRow, ...], new: tuple[CheckRow, ...]) -> tuple[RowChange, ...]:
    before, after = {r.name: r for r in old}, {r.name: r for r in new}
    out = []
    for name in [*before, *(n for n in after if n not in before)]:
        a, b = before.get(name), after.get(name)
        if a is None or b is None:
            out.append(RowChange(name, "added" if a is None else "removed", None if a is None else a.ok,
                                 None if b is None else b.ok, "" if a is None else a.value,
                                 "" if b is None else b.value))
        elif a.ok != b.ok or a.value != b.value:
            out.append(RowChange(name, "verdict" if a.ok != b.ok else "value", a.ok, b.ok, a.value, b.value))
    return tuple(out)


def cell_rows(cell: Cell) -> tuple[CheckRow, ...]:
    layout = build_layout(cell)
    return check_rows(check_cell(cell, layout), check_programs(layout))


def search_side(cell: Cell, searcher: str, budget: int, seed: int, **options) -> SearchSide:
    res = search(Simulator(cell), searcher, budget, seed, until="budget", distinct=True, **options)
    return SearchSide(tuple(ClassKey.of(d.klass) for d in res.distinct or ()), res.episodes, len(res.hazards))


def diff_cells(old: str | Cell, new: str | Cell, searcher: str = "mcts", budget: int = 200, seed: int = 0,
               **options) -> CellDiff:
    """Compare two cells (built-in names, paths or loaded cells): fields, check rows, hazard classes."""
    a = old if isinstance(old, Cell) else load_cell(old)
    b = new if isinstance(new, Cell) else load_cell(new)
    rows_a, rows_b = cell_rows(a), cell_rows(b)
    return CellDiff(a.spec.name, b.spec.name, searcher, seed, budget, field_changes(a, b), row_changes(rows_a, rows_b),
                    rows_b, search_side(a, searcher, budget, seed, **options),
                    search_side(b, searcher, budget, seed, **options))
