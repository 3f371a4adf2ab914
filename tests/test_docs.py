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


# cellstress lines inside YAML examples (CI pipelines: `- run: cellstress ...`, `- cellstress ...`)
YAML_LINE = re.compile(r"^\s*(?:-\s+)?(?:run:\s+)?(cellstress .*)$")
COMMANDS += [(p.name, m[1].strip()) for p in sorted(DOCS.glob("*.md")) if p.name not in OWN_TESTS
             for lang, body in re.findall(r"```(\w*)\n(.*?)```", p.read_text(encoding="utf-8"), flags=re.S)
             if lang in ("yaml", "yml") for ln in body.splitlines() if (m := YAML_LINE.match(ln))]
# the files a page's examples name, as copies of built-in cells (docs/ci.md says which)
DOC_FILES = {"ci.md": {"cells/line1.yaml": "mat-ok", "old.yaml": "mat-short"}}


def _doc_files(doc: str, folder: Path) -> None:
    from cellstress.cell.load import builtin_file

    for name, cell in DOC_FILES.get(doc, {}).items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(Path(builtin_file(cell)).read_bytes())


def test_docs_show_commands():
    assert COMMANDS


@pytest.mark.parametrize(("doc", "line"), COMMANDS)
def test_doc_command_runs(doc, line, tmp_path):
    _doc_files(doc, tmp_path)
    out = subprocess.run([sys.executable, "-m", "cellstress", *shlex.split(line, comments=True)[1:]],
                         capture_output=True,
                         text=True, cwd=tmp_path, timeout=600)
    assert out.returncode == expected_code(line), (doc, line, out.stderr)
    assert out.stdout.strip()


def test_pre_commit_hook_runs(tmp_path):
    """.pre-commit-hooks.yaml's hook: its file pattern takes cell files under cells/, and its entry, given the
    changed files as pre-commit gives them, exits 0 when every cell passes check and non-zero when one fails."""
    import os

    import yaml

    hooks = yaml.safe_load((DOCS.parent / ".pre-commit-hooks.yaml").read_text(encoding="utf-8"))
    hook = next(h for h in hooks if h["id"] == "cellstress-check")
    assert {"id", "name", "entry", "language", "files"} <= set(hook)
    pattern = re.compile(hook["files"])
    assert pattern.search("cells/line1.yaml") and pattern.search("plant/cells/a.yml")
    assert not pattern.search(".github/workflows/ci.yml")
    _doc_files("ci.md", tmp_path)
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    good = subprocess.run([*shlex.split(hook["entry"]), "cells/line1.yaml", "cells/line1.yaml"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=600)
    assert good.returncode == 0, good.stderr
    assert good.stdout.count("PASS:") == 2
    bad = subprocess.run([*shlex.split(hook["entry"]), "old.yaml", "cells/line1.yaml"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 1 and "PASS:" in bad.stdout and "FAIL:" in bad.stdout
