"""The Python example of docs/verify.md runs as shown (its commands are run by tests/test_docs.py)."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "verify.md"


def test_python_example_runs(tmp_path, monkeypatch, capsys) -> None:
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        exec(compile(code, str(DOC), "exec"), {})  # noqa: S102 - our own documentation
    printed = capsys.readouterr().out
    assert printed.startswith("PROVED-SAFE 0 656100000000")
    assert (tmp_path / "out" / "verify-s1" / "verify.json").is_file()
