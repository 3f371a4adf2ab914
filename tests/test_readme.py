"""Every command and Python example in the README runs, and the first two commands are what CI runs."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path


def expected_code(line: str) -> int:
    """A documented command exits 0 unless its line says otherwise (``# exit code 1: unsafe``)."""
    m = re.search(r"#\s*exit code (\d)", line)
    return int(m[1]) if m else 0

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```(\w+)\n(.*?)```", README, flags=re.S)


def _cli(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cellstress", *args], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)


def test_readme_starts_with_the_two_commands():
    assert README.startswith("# cellstress\n\n```bash\n")
    first, second = BLOCKS[0][1].strip(), BLOCKS[1][1].strip()
    assert "pip install . " in first and "&& cellstress " in first
    assert "pip install -e '.[test]'" in second and second.endswith("&& pytest")
    ci = (ROOT / ".ci" / "run").read_text()
    assert second in ci  # CI runs exactly the README's test command


def test_first_command_runs_the_main_job(tmp_path):
    job = shlex.split(BLOCKS[0][1].strip().split("&& cellstress ", 1)[1])
    job[job.index("--out") + 1] = str(tmp_path / "s3")
    out = _cli(job)
    assert out.returncode == 0, out.stderr
    assert "FOUND at episode" in out.stdout
    assert (tmp_path / "s3" / "result.json").is_file()


def test_cli_examples(tmp_path):
    """In order, in one folder: `replay` reads what `search` wrote."""
    lines = [ln for lang, body in BLOCKS[2:] if lang == "bash"
             for ln in body.strip().splitlines() if ln.startswith("cellstress ")]
    assert len(lines) >= 7
    for line in lines:
        out = subprocess.run([sys.executable, "-m", "cellstress", *shlex.split(line, comments=True)[1:]],
                         capture_output=True,
                             text=True, cwd=tmp_path, timeout=600)
        assert out.returncode == expected_code(line), (line, out.stderr)
        assert out.stdout.strip(), line


def test_python_examples(capsys):
    for lang, body in BLOCKS:
        if lang == "python":
            exec(compile(body, "README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert printed[:2] == ["True", "75"]
    assert printed[2:5] == ["0.6", "upper_arm_link", "left-reach"]  # the S2 witness (docs/cells.md)
