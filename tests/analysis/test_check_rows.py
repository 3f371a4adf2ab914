"""The check's rows (``analysis.check_rows``): on every built-in cell, the rows that fail are exactly the checks
``StaticCheck.failures`` and ``ProgramCheck.failures`` name (computed apart), and the names are unique."""

from __future__ import annotations

import pytest
import yaml

from cellstress.analysis.check_rows import check_rows, static_failures
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.cell.load import BUILTIN_CELLS, builtin_text, load_cell
from cellstress.sim.build import build_layout


@pytest.mark.parametrize("name", BUILTIN_CELLS)
def test_failing_rows_are_the_failures(name):
    cell = load_cell(name)
    layout = build_layout(cell)
    static, programs = check_cell(cell, layout), check_programs(layout)
    rows = check_rows(static, programs)
    names = [r.name for r in rows]
    assert len(names) == len(set(names))
    failed = sorted({r.name.split("#")[0] for r in rows if not r.ok})
    assert failed == sorted(set([f for p in programs for f in p.failures()] + static.failures()))
    assert any(n.startswith("undetected-reach") for n in names) and any(n.startswith("program") for n in names)
    assert all(r.kind and (r.ok or r.value) for r in rows)
    # a failing row's limit is the one its rule prints (one declaration, two outputs); a passing row has none
    assert all(r.limit in r.detail for r in rows) and all(not r.limit for r in rows if r.ok)


def _raised_front(tmp_path, bottom: float) -> str:
    """door-locked with its front wall raised ``bottom`` m and the worker outside in front of it (a way in under the
    wall that only a crawling body takes)."""
    data = yaml.safe_load(builtin_text("door-locked"))
    data["name"] = f"raised-{bottom}"
    next(f for f in data["fences"] if f["points"] == [[-1.5, 3.2], [1.5, 3.2]])["bottom"] = bottom
    data["human"]["start"] = {"xy": [0.0, 3.8], "heading_deg": -90.0}
    path = tmp_path / f"raised-{bottom}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return str(path)


def test_static_failures_are_the_failing_rows_with_what_the_worker_cannot_do(tmp_path):
    cell = load_cell(_raised_front(tmp_path, 0.35))
    rows = check_rows(check_cell(cell))
    failures = static_failures(check_cell(cell))
    assert [f.name for f in failures] == [r.name for r in rows if not r.ok] == ["whole-body-opening"]
    assert "cannot crawl" in failures[0].limit and failures[0].value
    # a row the worker can take keeps no limit; a passing cell has no failure
    assert all(not r.limit for r in rows if r.ok)
    assert static_failures(check_cell(load_cell("door-locked"))) == ()
    short = static_failures(check_cell(load_cell("door-unlocked")))
    assert [f.name for f in short] == ["bay-door"] and short[0].limit == ""
