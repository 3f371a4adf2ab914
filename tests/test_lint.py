"""The code passes ruff (the rules in pyproject.toml), so style problems fail CI like any other defect."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_passes():
    out = subprocess.run([sys.executable, "-m", "ruff", "check", "src", "tests", "benchmarks", "scripts"],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


def test_version_is_single():
    """The version the campaign manifest pins (cellstress.__version__) is the one the package is built with."""
    import tomllib

    import cellstress

    doc = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert doc["project"]["version"] == cellstress.__version__


def test_no_source_file_is_longer_than_500_lines():
    """The project's rule: a module a reader can hold in mind (split by concern, as sim/kernels/ is)."""
    long = {str(p.relative_to(ROOT)): n for p in sorted((ROOT / "src").rglob("*.py"))
            if (n := len(p.read_text().splitlines())) > 500}
    assert not long, long
