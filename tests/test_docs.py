"""Every `cellstress ...` command shown in docs/*.md runs and exits 0 (the Python blocks of docs/cells.md are
run by tests/analysis/test_iso13855.py; docs/extending.md, whose commands need its plug-in package, by
tests/test_extending.py)."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest


def expected_code(line: str) -> int:
    """A documented command exits 0 unless its line says otherwise (``# exit code 1: unsafe``)."""
    m = re.search(r"#\s*exit code (\d)", line)
    return int(m[1]) if m else 0

DOCS = Path(__file__).resolve().parents[1] / "docs"
OWN_TESTS = {"extending.md"}
COMMANDS = [(p.name, ln.strip()) for p in sorted(DOCS.glob("*.md")) if p.name not in OWN_TESTS
            for lang, body in re.findall(r"```(\w*)\n(.*?)```", p.read_text(encoding="utf-8"), flags=re.S)
            if lang in ("bash", "console", "sh") for ln in body.splitlines() if ln.strip().startswith("cellstress ")]


def test_docs_show_commands():
    assert COMMANDS


@pytest.mark.parametrize(("doc", "line"), COMMANDS)
def test_doc_command_runs(doc, line, tmp_path):
    out = subprocess.run([sys.executable, "-m", "cellstress", *shlex.split(line, comments=True)[1:]],
                         capture_output=True,
                         text=True, cwd=tmp_path, timeout=600)
    assert out.returncode == expected_code(line), (doc, line, out.stderr)
    assert out.stdout.strip()
