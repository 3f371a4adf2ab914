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
