"""Choosing what to decide without editing the cell (``--starts``, ``--phases A:B``), and the summary of what was
left undecided as ranges of phases."""

from __future__ import annotations

import json

import pytest

from cellstress.cli import main
from cellstress.report.verify import runs
from cellstress.verifier.records import Subtree


def test_starts_and_a_window_of_phases(tmp_path, capsys):
    code = main(["verify", "all-flaws", "--horizon", "1", "--phases", "1.4:1.5", "--starts",
                 "lower-end-right,upper-end", "--workers", "1", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code in (0, 1) and "phases 1.4:1.5 (6 sub-trees: 2 start points, 3 arrival phases)" in out
    saved = json.loads((tmp_path / "verify.json").read_text())
    # the cell's order of start points, whatever the option's; the window's ends included
    assert [(s["start"], s["phase"]) for s in saved["subtrees"]] == [
        (name, p) for name in ("upper-end", "lower-end-right") for p in (1.4, 1.45, 1.5)]
    assert saved["options"]["window"] == [1.4, 1.5] and saved["options"]["starts"] == ["lower-end-right", "upper-end"]
    assert "from 1.4 to 1.5 s of the robot's" in saved["scope"]["arrival"]


@pytest.mark.parametrize("args, words", [
    (["--starts", "nowhere"], "no start point 'nowhere' (it has upper-end, lower-end, lower-end-right)"),
    (["--phases", "2:1"], "ends before it begins"),
    (["--phases", "1.41:1.42"], "no arrival phase of the 0.05 s grid lies in 1.41..1.42 s"),
    (["--phases", "-1:2"], "finite and >= 0"),
    (["--phases", "inf:inf"], "finite and >= 0"),
    (["--phases", "1:2:3"], "a window A:B"),
    (["--phases", "soon"], "a window A:B"),
])
def test_a_bad_choice_is_one_line(tmp_path, capsys, args, words):
    code = main(["verify", "all-flaws", "--horizon", "1", *args, "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and words in err[0], err


def _sub(start: str, phase: float, undecided: int = 0, alarms: int = 0) -> Subtree:
    return Subtree(start=start, phase=phase, window=0.025 if alarms else 0.0, margin=0.05 if alarms else 0.0,
                   alarms=alarms, verdict="UNDECIDED" if undecided or alarms else "PROVED-SAFE", sequences=30,
                   hazardous=0, undecided=undecided, probability=0.0, states=(1,), expanded=0, pruned=(), classes=())


def test_undecided_sub_trees_are_summarised_as_ranges():
    subs = [_sub("a", 0.0, 30), _sub("a", 0.05, 30), _sub("a", 0.1), _sub("a", 0.15, 10), _sub("b", 0.0, 30),
            _sub("b", 0.05, 0, 30), _sub("b", 0.1, 30)]
    got = [(r.start, r.first, r.last, r.subtrees, r.count) for r in runs(subs, lambda s: s.undecided)]
    assert got == [("a", 0.0, 0.05, 2, 60), ("a", 0.15, 0.15, 1, 10), ("b", 0.0, 0.0, 1, 30), ("b", 0.1, 0.1, 1, 30)]
    assert [r.where() for r in runs(subs, lambda s: s.alarms)] == ["b at phase 0.05 s"]
    assert runs(subs, lambda s: s.undecided)[0].where() == "a at phases 0..0.05 s (2 sub-trees)"
    # a start point's ranges never run into the next start point's
    assert runs([_sub("a", 0.1, 5), _sub("b", 0.0, 5)], lambda s: s.undecided)[1].start == "b"
