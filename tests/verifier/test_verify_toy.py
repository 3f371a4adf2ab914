"""Cells whose answer is known by hand, and the command's exit codes and files."""

from __future__ import annotations

import itertools
import json
import re

import numpy as np
import pytest

import cellstress
from cellstress.cell.load import builtin_text, load_cell, with_criterion
from cellstress.cli import main
from cellstress.report.verify import MAX_WITNESS_VIEWS
from cellstress.searchers.result import SearchResult
from cellstress.sim.simulator import Simulator
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.tree import decide


def _cell_file(tmp_path, name: str, start: str, phase: float):
    text = builtin_text("s3-fence-gap")
    lines = []
    for ln in text.splitlines():
        if ln.strip().startswith("start:") and "xy" in ln:
            ln = ln[: ln.index("start:")] + f"start: {start}"
        if ln.strip().startswith("phase:"):
            ln = ln[: ln.index("phase:")] + f"phase: {phase}"
        lines.append(ln)
    path = tmp_path / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_worker_far_from_the_robot_is_proved_safe(tmp_path) -> None:
    # two actions walk at most 8 strides (0.64 m): from the far corner nothing of the worker comes near the robot
    path = _cell_file(tmp_path, "far", "{xy: [-2.2, -2.6], heading_deg: 0.0}", 1.4)
    res = cellstress.verify(path, horizon=2, phases="cell")
    assert res.verdict == "PROVED-SAFE" and res.hazardous == 0 and res.sequences == 900 and res.exit_code == 0
    assert sum(p.sequences for p in res.pruned) == 900  # the distance bound proved it without a step


def test_worker_touching_the_moving_robot_at_the_start(tmp_path) -> None:
    # the worker starts with the robot's moving arm inside their reach: every sequence is hazardous
    path = _cell_file(tmp_path, "touch", "{xy: [-1.25, -0.2], heading_deg: 0.0}", 0.75)
    res = cellstress.verify(path, horizon=3, phases="cell", out=tmp_path / "out")
    assert res.verdict == "UNSAFE" and res.hazardous == 30 ** 3 and res.subtrees[0].probability == 1.0
    assert len(res.classes) == 1 and res.classes[0].actions == ("phase:0.75",)  # unsafe before any action
    assert SearchResult.load(tmp_path / "out" / res.classes[0].file).found


def test_criterion_that_judges_contacts_against_brute_force(tmp_path) -> None:
    # ISO/TS 15066 judges each contact in Python (no kernel test): the verifier steps those children again
    path = _cell_file(tmp_path, "touch", "{xy: [-1.25, -0.2], heading_deg: 0.0}", 0.75)
    sim = Simulator(with_criterion(load_cell(path), "iso15066"))
    out = decide(sim, 2, Bounds(sim, horizon=2))
    brute = sim.run_batch(np.array(list(itertools.product(range(30), repeat=2))))
    assert out.hazardous == int(brute.unsafe.sum())
    assert np.count_nonzero(brute.min_d <= 0.0) > 100  # many contacts were judged (here: all below the limits)


def test_command_exit_codes_and_replayable_witnesses(tmp_path, capsys) -> None:
    out = tmp_path / "s1"
    assert main(["verify", "s1-scanner-width", "--phases", "cell", "--horizon", "5", "--out", str(out)]) == 1
    doc = json.loads((out / "verify.json").read_text())
    assert doc["verdict"] == "UNSAFE" and doc["hazardous"] > 0 and (out / "verify.png").is_file()
    page = (out / "verify.html").read_text()
    assert doc["classes"][0]["file"] in page
    # every witness in the page's 3D view (report/verify.witness_view), each replayed to its contact
    view = json.loads(re.search(r'id="cs3d-data">(.*?)</script>', page, flags=re.S).group(1))
    assert len(view["episodes"]) == min(len(doc["classes"]), MAX_WITNESS_VIEWS)
    assert all(ep["marker"]["kind"] == "contact" and ep["marker"]["step"] == ep["n"] - 1 for ep in view["episodes"])
    witness = out / doc["classes"][0]["file"]
    assert main(["replay", str(witness)]) == 0
    assert "REPRODUCED bit-exactly" in capsys.readouterr().out
    assert main(["verify", "baseline", "--phases", "cell", "--horizon", "3", "--out", str(tmp_path / "b")]) == 0
    capsys.readouterr()
    for bad in (["--horizon", "13"], ["--horizon", "0"], ["--phases", "some"], ["--workers", "0"],
                ["--time-limit", "-1"], ["--criterion", "nope"]):
        assert main(["verify", "baseline", *bad, "--out", str(tmp_path / "c")]) == 2, bad
        err = capsys.readouterr().err
        assert err.startswith("error: ") and err.count("\n") == 1, (bad, err)
    assert main(["verify", str(tmp_path / "no-such-cell.yaml"), "--out", str(tmp_path / "c")]) == 2


def test_time_limit_leaves_subtrees_undecided(tmp_path) -> None:
    res = cellstress.verify("baseline", horizon=8, phases="all", time_limit=1e-3, out=tmp_path)
    assert res.verdict == "UNDECIDED" and res.exit_code == 3 and res.undecided > 0
    assert all(s.verdict != "PROVED-SAFE" for s in res.subtrees if s.undecided)


@pytest.mark.parametrize("workers", [1, 2])
def test_same_inputs_same_file(tmp_path, workers) -> None:
    a = cellstress.verify("all-flaws", horizon=2, phases="cell", workers=workers, out=tmp_path / "a")
    b = cellstress.verify("all-flaws", horizon=2, phases="cell", workers=1, out=tmp_path / "b")
    assert a.to_json() == b.to_json() and len(a.subtrees) == 3
