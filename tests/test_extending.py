"""docs/extending.md works as written: its plug-in package is installed from the blocks of the page, and its
commands and Python examples run (the searcher, device and criterion plug-ins, and Gymnasium both ways)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from cellstress.cell.load import builtin_text

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "extending.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```(\w+)\n(.*?)```", DOC, flags=re.S)


def _tagged(tag: str) -> dict[str, str]:
    """Blocks whose first line is ``# tag: NAME``, by NAME."""
    out = {}
    for _, body in BLOCKS:
        first, _, rest = body.partition("\n")
        m = re.fullmatch(rf"# {tag}: (\S+)", first.strip())
        if m:
            out[m.group(1)] = rest
    return out


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict[str, str]:
    """The page's package, installed into a folder of its own: the environment that sees it."""
    tmp = tmp_path_factory.mktemp("plugins")
    pkg = tmp / "my-plugins"
    files = _tagged("file")
    assert {"pyproject.toml", "my_plugins/sticky.py", "my_plugins/mat.py", "my_plugins/clearance.py"} <= set(files)
    for name, text in files.items():
        (pkg / name).parent.mkdir(parents=True, exist_ok=True)
        (pkg / name).write_text(text, encoding="utf-8")
    site = tmp / "site"
    out = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
                          "--target", str(site), str(pkg)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return {**os.environ, "PYTHONPATH": str(site)}


def _my_cell(folder: Path) -> Path:
    """The built-in S1 cell with the page's mat added and its criterion in place of the cell's."""
    edits = {**_tagged("insert"), **_tagged("replace")}
    text = builtin_text("s1-scanner-width")
    text = text.replace("devices:\n", "devices:\n" + edits["devices"], 1)
    text = re.sub(r"^criterion:.*$", edits["criterion"].strip(), text, count=1, flags=re.M)
    path = folder / "my-cell.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _run(line: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cellstress", *shlex.split(line, comments=True)[1:]],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=600)


def test_the_plugins_show_up_and_run(installed, tmp_path):
    _my_cell(tmp_path)
    lines = [ln for lang, body in BLOCKS if lang == "bash" for ln in body.splitlines() if ln.startswith("cellstress ")]
    assert len(lines) == 4
    outs = {}
    for line in lines:
        out = _run(line, tmp_path, installed)
        expected = int(m[1]) if (m := re.search(r"#\s*exit code (\d)", line)) else 0
        assert out.returncode == expected, (line, out.stderr)
        outs[line.split()[1]] = outs.get(line.split()[1], "") + out.stdout
    assert re.search(r"front-mat\s+example-mat\s+response 0\.1 s\s+4-point mat", outs["check"])
    assert "front-mat (example-mat): T = 0.10 + 0.15 s, S = 1600*0.25 + 1200 = 1600 mm" in outs["check"]
    assert "criterion   clearance (distance tolerance 0.05 m" in outs["check"]
    assert "searcher sticky-random (repeat 0.8)" in outs["search"]
    assert "searcher sticky-random (repeat 0.9)" in outs["search"]
    assert re.search(r"\| s3-fence-gap \| sticky-random \| \d+/3 \|", outs["campaign"])
    # the device and the searcher are in the help and the choices, without any change to cellstress
    help_text = _run("cellstress search --help", tmp_path, installed).stdout
    assert "sticky-random" in help_text
    bad = _run("cellstress search s1-scanner-width --searcher nope --out x", tmp_path, installed)
    assert bad.returncode == 2 and "sticky-random" in bad.stderr


def test_without_the_package_they_are_unknown(tmp_path):
    path = _my_cell(tmp_path)
    out = _run(f"cellstress check {path}", tmp_path, {k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    assert out.returncode == 2 and "unknown device type 'example-mat'" in out.stderr


def test_python_examples_run(installed, tmp_path):
    code = "\n\n".join(body for lang, body in BLOCKS if lang == "python" and not body.startswith("# file:"))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=installed,
                         timeout=600)
    assert out.returncode == 0, out.stderr
    printed = out.stdout.split("\n")
    assert printed[0] == "True 0.0 running"  # the S3 witness ends in the unsafe set, the robot still running
    assert printed[1] == "(64, 11)"
    assert printed[2].startswith("True (")  # a hole in FrozenLake
