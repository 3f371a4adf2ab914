"""The Python API: plain functions with real signatures and docstrings, and docs/api.md's sweep runs as shown."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

import cellstress

DOC = (Path(__file__).resolve().parents[1] / "docs" / "api.md").read_text(encoding="utf-8")


@pytest.mark.parametrize(("name", "params"), [
    ("load_cell", ["path_or_name"]),
    ("parse_cell", ["text", "source", "directory"]),
    ("check", ["cell"]),
    ("search", ["cell", "searcher", "budget", "seed", "until", "top_k", "distinct", "criterion", "progress",
                "options"]),
    ("simulate", ["cell", "actions", "criterion"]),
    ("write_report", ["result", "out"]),
    ("verify", ["cell", "horizon", "phases", "moments", "time_limit", "workers", "out", "criterion", "progress",
                "starts", "backend", "address"]),
])
def test_functions_have_real_signatures(name, params) -> None:
    func = getattr(cellstress, name)
    assert inspect.isfunction(func)
    assert list(inspect.signature(func).parameters) == params
    assert func.__doc__ and len(func.__doc__) > 40
    assert name in DOC  # documented


def test_the_sweep_in_the_docs_prints_its_table(capsys) -> None:
    code = re.findall(r"```python\n(.*?)```", DOC, re.S)[0]
    shown = re.findall(r"```text\n(.*?)```", DOC, re.S)[0]
    exec(compile(code, "docs/api.md", "exec"), {})
    assert capsys.readouterr().out == shown
