"""A stopped verification resumes from its checkpoint (``verifier.checkpoint``) and ends with the bytes of a run
never stopped: after Ctrl-C, after SIGKILL, after a time limit, with another number of workers; a checkpoint of
another verification, or a damaged one, is refused with one line."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest

import cellstress
from cellstress.cell.load import builtin_text
from cellstress.cli import main
from cellstress.report.verify import summary_lines
from cellstress.sim.simulator import Simulator
from cellstress.verifier.checkpoint import CHECKPOINT
from cellstress.verifier.run import verify_cell

HORIZON = 1
PHASES = "1.5:3.2"  # 35 arrival phases, three of them safe (2.75..2.85 s)
N = 35


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """s3-fence-gap with the worker starting beside the robot's path, decided at the arrival phases of a window of
    its cycle (some hazardous, some not): the cell file and the bytes of an uninterrupted run."""
    root = tmp_path_factory.mktemp("resume")
    text = builtin_text("s3-fence-gap")
    lines = [ln[: ln.index("start:")] + "start: {xy: [-1.25, -0.2], heading_deg: 0.0}"
             if ln.strip().startswith("start:") and "xy" in ln else ln for ln in text.splitlines()]
    cell = root / "near.yaml"
    cell.write_text("\n".join(lines) + "\n")
    res = cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=root / "whole")
    assert res.verdict == "UNSAFE" and 0 < sum(s.hazardous > 0 for s in res.subtrees) < len(res.subtrees) == N
    assert not (root / "whole" / CHECKPOINT).exists()  # a finished verification leaves none
    return cell, (root / "whole" / "verify.json").read_bytes()


def _stop_after(subtrees: int):
    """A progress callback that stops the run (as Ctrl-C does) once ``subtrees`` sub-trees are decided."""
    def stop(done: int, total: int) -> None:
        if done >= subtrees * 30 ** HORIZON:
            raise KeyboardInterrupt

    return stop


def _lines(out) -> int:
    try:
        return len((out / CHECKPOINT).read_bytes().splitlines())
    except FileNotFoundError:
        return 0


def test_ctrl_c_then_resume_gives_the_same_bytes(whole, tmp_path):
    cell, expected = whole
    out = tmp_path / "out"

    stop = _stop_after(10)

    with pytest.raises(KeyboardInterrupt):
        cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, progress=stop)
    kept = _lines(out) - 1
    assert kept >= 9 and not (out / "verify.json").exists()
    told = []
    cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out)
    assert (out / "verify.json").read_bytes() == expected and not (out / CHECKPOINT).exists()
    # the callback says how much was taken over
    with pytest.raises(KeyboardInterrupt):
        cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=tmp_path / "again", progress=stop)
    verify_cell(Simulator(str(cell)), horizon=HORIZON, phases=PHASES, out=tmp_path / "again",
                resumed=lambda n, of: told.append((n, of)))
    assert told == [(kept, N)]


def test_sigkill_then_resume_with_other_workers_gives_the_same_bytes(whole, tmp_path):
    cell, expected = whole
    out = tmp_path / "out"
    args = [sys.executable, "-m", "cellstress", "verify", str(cell), "--horizon", str(HORIZON), "--phases", PHASES,
            "--workers", "1", "--out", str(out)]
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while _lines(out) < 5 and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    assert p.returncode == -signal.SIGKILL and 5 <= _lines(out) and not (out / "verify.json").exists()
    done = subprocess.run([*args[:-4], "--workers", "2", "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    assert "resumed " in done.stderr and (out / "verify.json").read_bytes() == expected
    assert not (out / CHECKPOINT).exists()


def test_a_time_limit_keeps_the_checkpoint_for_the_next_run(whole, tmp_path):
    cell, expected = whole
    out = tmp_path / "out"
    res = cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, time_limit=1e-6)
    # the limit passed before the first sub-tree began: all undecided, summarised as one range of phases (every
    # sub-tree stays in verify.json), and the checkpoint (empty of sub-trees) stays for the next run
    assert res.verdict == "UNDECIDED" and res.undecided == N * 30 ** HORIZON and (out / CHECKPOINT).exists()
    ranges = [ln for ln in summary_lines(res, "") if ln.startswith("  undecided: ")]
    assert ranges == [f"  undecided: start at phases 1.5..3.2 s ({N} sub-trees): {N * 30:,} sequences"]
    cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out)
    assert (out / "verify.json").read_bytes() == expected


def test_a_line_cut_short_is_dropped(whole, tmp_path):
    cell, expected = whole
    out = tmp_path / "out"

    stop = _stop_after(8)

    with pytest.raises(KeyboardInterrupt):
        cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, progress=stop)
    raw = (out / CHECKPOINT).read_bytes()
    (out / CHECKPOINT).write_bytes(raw[:-40])  # a crash in the middle of the last line
    cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out)
    assert (out / "verify.json").read_bytes() == expected


@pytest.mark.parametrize("change, words", [
    (lambda lines: [lines[0].replace(b'"horizon":1', b'"horizon":2')] + lines[1:], "another verification"),
    (lambda lines: lines[:1] + [lines[1].replace(b'"task":', b'"tusk":')] + lines[2:], "line 2 is not a checkpoint"),
    (lambda lines: lines[:1] + [lines[1].replace(b'"task":0', b'"task":7')] + lines[2:], "not a sub-tree of this"),
    (lambda lines: lines[:1] + [lines[1].replace(b'"undecided":0', b'"undecided":3')] + lines[2:],
     "not decided whole"),
    # a witness naming an action the cell's worker does not have (the paper worker has 30)
    (lambda lines: lines[:1] + [re.sub(rb'"actions":\[\d+', b'"actions":[99', lines[1], count=1)] + lines[2:],
     "an action this cell's worker does not have"),
])
def test_a_foreign_or_damaged_checkpoint_is_refused(whole, tmp_path, capsys, change, words):
    cell, _ = whole
    out = tmp_path / "out"

    stop = _stop_after(3)

    with pytest.raises(KeyboardInterrupt):
        cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, progress=stop)
    lines = (out / CHECKPOINT).read_bytes().splitlines()
    assert b'"task":0' in lines[1] and b'"actions":[' in lines[1]  # (the first sub-tree is hazardous)
    (out / CHECKPOINT).write_bytes(b"\n".join(change(lines)) + b"\n")
    code = main(["verify", str(cell), "--horizon", str(HORIZON), "--phases", PHASES, "--workers", "1", "--out",
                 str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and words in err[0], err
    assert CHECKPOINT in err[0] and not (out / "verify.json").exists()
    json.loads(lines[0])  # (the head is JSON: the refusal is about its content)


def test_on_ray_the_same_bytes_and_resumes_from_a_local_run(whole, tmp_path):
    """Interrupted on local processes, finished as Ray tasks on a local Ray: the bytes of one uninterrupted local
    run (a sub-tree is a pure function of its task; the order of the result does not depend on who finished
    first)."""
    pytest.importorskip("ray")
    cell, expected = whole
    out = tmp_path / "out"

    stop = _stop_after(10)

    with pytest.raises(KeyboardInterrupt):
        cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, progress=stop)
    res = cellstress.verify(cell, horizon=HORIZON, phases=PHASES, out=out, backend="ray", workers=2)
    assert res.verdict == "UNSAFE" and (out / "verify.json").read_bytes() == expected
    assert not (out / CHECKPOINT).exists()


@pytest.mark.parametrize("args, words", [
    (["--backend", "cloud"], "--backend must be one of processes, ray"),
    (["--address", "10.0.0.1:6379"], "--address is the address of a Ray cluster"),
    (["--backend", "ray", "--workers", "0"], "--workers must be a whole number in 1..100000"),
])
def test_a_bad_backend_is_one_line_before_anything_is_written(tmp_path, capsys, args, words):
    code = main(["verify", "baseline", "--horizon", "1", *args, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and words in err[0] and not (tmp_path / "out").exists(), err
