"""Every command and Python example in the README runs, and the first two commands are what CI runs."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

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


def test_first_command_runs_the_main_job():
    job = BLOCKS[0][1].strip().split("&& cellstress ", 1)[1]
    out = _cli(shlex.split(job))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1].startswith("UNSAFE at t=0.6 s (step 12)")


@pytest.mark.parametrize("line", [ln for lang, body in BLOCKS[2:] if lang == "bash"
                                  for ln in body.strip().splitlines() if ln.startswith("cellstress ")])
def test_cli_examples(line):
    out = _cli(shlex.split(line)[1:])
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip()


def test_python_examples(capsys):
    for lang, body in BLOCKS:
        if lang == "python":
            exec(compile(body, "README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert printed[:3] == ["0.6", "upper_arm_link", "left-reach"]
