"""The check's rows (``analysis.check_rows``): on every built-in cell, the rows that fail are exactly the checks
``StaticCheck.failures`` and ``ProgramCheck.failures`` name (computed apart), and the names are unique."""

from __future__ import annotations

import pytest

from cellstress.analysis.check_rows import check_rows
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.cell.load import BUILTIN_CELLS, load_cell
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
