"""``cellstress diff OLD NEW``, the gate on layout changes: a flawed built-in cell against its fixed twin passes
one way (exit 0) and fails the other (exit 1) naming the hazard class and the changed field; its JSON and JUnit
files; one ``error:`` line for a bad file.

The search is ``plan`` with a budget of 20 on ``mat-short`` / ``mat-ok``: docs/results.md measures ``plan`` finding
``mat-short``'s hazard in 3.5 episodes on average (10 of 10 seeds within 200); the twin is safe."""

from __future__ import annotations

import json
import time

import pytest
from junit_schema import validate_junit

from cellstress.cli import main

SEARCH = ["--searcher", "plan", "--budget", "20", "--seed", "0"]


@pytest.fixture(scope="module")
def worse(tmp_path_factory):
    """diff TWIN FLAWED: the change that breaks the cell."""
    out = tmp_path_factory.mktemp("diff")
    t0 = time.perf_counter()
    code = main(["diff", "mat-ok", "mat-short", *SEARCH, "--json", str(out / "d.json"), "--junit", str(out / "d.xml")])
    return code, out, time.perf_counter() - t0


def test_the_breaking_change_fails_the_gate(worse, capsys):
    code, out, seconds = worse
    assert code == 1
    doc = json.loads((out / "d.json").read_text())
    assert doc["passes"] is False
    assert {"part": "devices", "path": "devices[front-mat].polygon[1]", "old": "[-1.5,3.2]",
            "new": "[-1.5,2.3]"} in doc["fields"]
    assert doc["failing_rows"] == ["front-mat", "undetected-reach"]
    assert [c["device"] for c in doc["new_classes"]] == ["front-mat"] and doc["gone_classes"] == []
    rows = {r["name"]: r for r in doc["check_rows"]}
    assert rows["front-mat"]["change"] == "verdict" and rows["front-mat"]["new_ok"] is False
    suite = validate_junit((out / "d.xml").read_bytes())[0]
    failed = [(c.get("classname"), c.get("name")) for c in suite if c.find("failure") is not None]
    assert ("diff.hazard-class", "front-mat / wrist_2_link / hands @ (0.5, 2)") in failed
    assert {n for _, n in failed} >= {"front-mat", "undetected-reach"}
    assert seconds < 120  # measured about 6 s on 2 busy cores


def test_the_fix_passes_the_gate(tmp_path, capsys):
    code = main(["diff", "mat-short", "mat-ok", *SEARCH, "--json", str(tmp_path / "d.json"),
                 "--junit", str(tmp_path / "d.xml")])
    printed = capsys.readouterr().out
    assert code == 0
    assert "devices[front-mat].polygon[1]" in printed and "gone" in printed and printed.rstrip().endswith(
        "has no hazard class OLD did not have")
    doc = json.loads((tmp_path / "d.json").read_text())
    assert doc["passes"] is True and doc["failing_rows"] == [] and doc["new_classes"] == []
    assert [c["device"] for c in doc["gone_classes"]] == ["front-mat"]
    root = validate_junit((tmp_path / "d.xml").read_bytes())
    assert root.get("failures") == "0"


def test_same_inputs_same_bytes(worse, tmp_path):
    _, out, _ = worse
    assert main(["diff", "mat-ok", "mat-short", *SEARCH, "--json", str(tmp_path / "d.json"),
                 "--junit", str(tmp_path / "d.xml")]) == 1
    assert (tmp_path / "d.json").read_bytes() == (out / "d.json").read_bytes()
    assert (tmp_path / "d.xml").read_bytes() == (out / "d.xml").read_bytes()


@pytest.mark.parametrize("which", [0, 1])
def test_a_bad_file_is_one_error_line(tmp_path, capsys, which):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nfloor: 3\n", encoding="utf-8")
    args = ["mat-ok", str(bad)] if which else [str(bad), "mat-ok"]
    assert main(["diff", *args, *SEARCH, "--junit", str(tmp_path / "d.xml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "bad.yaml" in err[0]
    assert not (tmp_path / "d.xml").exists()
