"""Kill a campaign mid-way (SIGKILL, SIGINT), then resume: every run of the grid exactly once."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cellstress.campaign.store import RUNS
from cellstress.cli import main

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

# 3 cells x 3 searchers x 4 seeds = 36 runs of about 50 ms each: long enough to stop in the middle
ARGS = ["--seeds", "4", "--budget", "200"]
GRID = {(c, s, seed) for c in ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
        for s in ("random", "mcts", "mcts-commit") for seed in range(4)}
SRC = str(Path(__file__).resolve().parents[2] / "src")


def _start(out: Path, workers: int) -> subprocess.Popen:
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")  # this checkout, installed or not
    # a session of its own: the test's signals reach only the processes it started
    return subprocess.Popen([sys.executable, "-m", "cellstress", "campaign", *ARGS, "--workers", str(workers),
                             "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True)


def _lines(out: Path) -> int:
    try:
        return (out / RUNS).read_bytes().count(b"\n")
    except FileNotFoundError:
        return 0


def _wait_for_lines(proc: subprocess.Popen, out: Path, k: int, timeout: float = 300) -> int:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        n = _lines(out)
        if n >= k:
            return n
        if proc.poll() is not None:
            pytest.fail(f"the campaign ended (code {proc.returncode}) before {k} runs: {proc.stderr.read()}")
        time.sleep(0.005)
    proc.kill()
    pytest.fail(f"fewer than {k} runs after {timeout} s")


def _group_alive(pgid: int) -> list[int]:
    """Processes (not zombies) left in the campaign's process group (Linux /proc)."""
    alive = []
    for d in Path("/proc").glob("[0-9]*"):
        try:
            stat = (d / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[2]) == pgid and fields[0] != "Z":
            alive.append(int(d.name))
    return alive


def _resume_and_check(out: Path, capsys) -> None:
    code = main(["campaign", *ARGS, "--workers", "2", "--out", str(out)])
    _, err = capsys.readouterr()
    assert code == 0, err
    keys = [(r["cell"], r["searcher"], r["seed"]) for r in map(json.loads, (out / RUNS).read_text().splitlines())]
    assert len(keys) == len(set(keys)) == len(GRID)  # each once
    assert set(keys) == GRID


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> list[str]:
    out = tmp_path_factory.mktemp("reference")
    assert main(["campaign", *ARGS, "--workers", "1", "--out", str(out)]) == 0
    return sorted((out / RUNS).read_text().splitlines())


ATTEMPTS = 3  # a loaded machine may finish the whole grid before the signal lands: then try again


def _interrupted(tmp_path: Path, workers: int, sig: int) -> tuple[Path, subprocess.Popen, str]:
    """Start a campaign, send ``sig`` once it has written 3 runs; (its folder, the process, its stderr). Tries
    again in a fresh folder when the campaign had already finished (the signal came too late to test anything)."""
    for attempt in range(ATTEMPTS):
        out = tmp_path / f"try{attempt}"
        out.mkdir()
        proc = _start(out, workers)
        try:
            _wait_for_lines(proc, out, 3)
            os.kill(proc.pid, sig)
            _, err = proc.communicate(timeout=60)
        finally:
            if proc.poll() is None:
                proc.kill()
        if _lines(out) < len(GRID):
            return out, proc, err
    pytest.fail(f"the campaign finished before the signal in {ATTEMPTS} attempts")


@pytest.mark.parametrize("workers", [1, 2])
def test_sigkill_then_resume(tmp_path, capsys, reference, workers):
    out, proc, _ = _interrupted(tmp_path, workers, signal.SIGKILL)
    assert proc.returncode == -signal.SIGKILL
    n = _lines(out)
    assert 3 <= n < len(GRID)
    if Path("/proc").is_dir():  # worker processes notice that the main process is gone and end
        end = time.monotonic() + 20
        while _group_alive(proc.pid) and time.monotonic() < end:
            time.sleep(0.1)
        assert not _group_alive(proc.pid)
    _resume_and_check(out, capsys)
    assert sorted((out / RUNS).read_text().splitlines()) == reference


@pytest.mark.parametrize("workers", [1, 2])
def test_sigint_stops_cleanly_then_resume(tmp_path, capsys, reference, workers):
    out, proc, err = _interrupted(tmp_path, workers, signal.SIGINT)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted: " in err and "run the same command again to resume" in err
    text = (out / RUNS).read_text()
    assert text.endswith("\n") and 3 <= text.count("\n") < len(GRID)
    assert not (out / "table.md").exists()  # the table is written when the grid is complete
    _resume_and_check(out, capsys)
    assert sorted((out / RUNS).read_text().splitlines()) == reference


def _workers_of(pid: int) -> list[int]:
    """Pool worker processes of ``pid`` (Linux /proc): children running multiprocessing's spawn_main."""
    found = []
    for d in Path("/proc").glob("[0-9]*"):
        try:
            stat = (d / "stat").read_text()
            cmd = (d / "cmdline").read_bytes()
        except OSError:
            continue
        if int(stat[stat.rindex(")") + 2:].split()[1]) == pid and b"spawn_main" in cmd:
            found.append(int(d.name))
    return found


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="finds the worker through /proc")
def test_a_dead_worker_stops_the_campaign_with_its_runs_saved(tmp_path, capsys, reference):
    proc = _start(tmp_path, 2)
    try:
        _wait_for_lines(proc, tmp_path, 3)
        workers = _workers_of(proc.pid)
        assert workers
        os.kill(workers[0], signal.SIGKILL)  # as the out-of-memory killer would
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 1, err
    assert "a worker process died" in err and "run the same command again to resume" in err
    assert "Traceback" not in err
    assert (tmp_path / RUNS).read_text().endswith("\n")
    _resume_and_check(tmp_path, capsys)
    assert sorted((tmp_path / RUNS).read_text().splitlines()) == reference
