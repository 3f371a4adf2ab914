"""`cellstress search` and `cellstress replay`: files, summary, --json, exit codes."""

from __future__ import annotations

import json
import math
import re

import pytest

from cellstress.cli import main


def _run(args, capsys):
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_search_summary_and_replay(tmp_path, capsys) -> None:
    code, out, err = _run(["search", "s3-fence-gap", "--searcher", "mcts-commit", "--out", str(tmp_path)], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "result.json").read_text())
    h = doc["hazard"]
    lines = out.splitlines()
    assert lines[0].startswith("cell      s3-fence-gap  searcher mcts-commit (n auto, ec 0.5, k 1, alpha 0.85)")
    assert lines[1].startswith("criterion contact-while-moving: unsafe when the worker touches the robot")
    assert lines[2].startswith(f"FOUND at episode {h['episode']} of 200 ")
    assert "episodes/s" in lines[2]
    assert lines[3] == "actions   " + ", ".join(h["actions"])
    assert lines[4].startswith(f"contact   t={h['time_s']:g} s (step {h['step']}): {h['robot_link']} / "
                               f"{h['body_part']} at (")
    assert lines[-1] == f"wrote     {tmp_path / 'result.json'}"
    assert doc["cell"]["criterion"] == "contact-while-moving"  # the file names its criterion too
    code, out, err = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 0, err
    rows = out.splitlines()
    assert rows[0].split()[:3] == ["step", "t[s]", "x[m]"]
    assert len(rows) == 1 + len(h["trace"]) + 1
    assert rows[-1].startswith("REPRODUCED bit-exactly")
    code, out, _ = _run(["replay", str(tmp_path)], capsys)  # the folder works too
    assert code == 0


def test_search_json_is_the_file(tmp_path, capsys) -> None:
    code, out, err = _run(["search", "s3-fence-gap", "--budget", "30", "--seed", "2", "--searcher", "random",
                           "--out", str(tmp_path), "--json", "--until", "budget"], capsys)
    assert code == 0
    assert out == (tmp_path / "result.json").read_text()
    doc = json.loads(out)
    assert doc["episodes"] == 30 and doc["until"] == "budget" and doc["seed"] == 2
    assert "episodes/s" in err  # timing goes to the console, never into the file
    assert not any("time" in k or "clock" in k or "date" in k for k in doc)


def test_replay_detects_a_changed_trace(tmp_path, capsys) -> None:
    assert _run(["search", "s3-fence-gap", "--out", str(tmp_path)], capsys)[0] == 0
    path = tmp_path / "result.json"
    doc = json.loads(path.read_text())
    row = doc["hazard"]["trace"][-2]
    row["d_HR"] = math.nextafter(row["d_HR"], math.inf)  # one ulp off
    path.write_text(json.dumps(doc))
    code, out, _ = _run(["replay", str(path)], capsys)
    assert code == 1
    assert f"MISMATCH: hazard.trace[{len(doc['hazard']['trace']) - 2}].d_HR: the file says" in out


def test_replay_detects_a_changed_cell(tmp_path, capsys) -> None:
    assert _run(["search", "s3-fence-gap", "--out", str(tmp_path)], capsys)[0] == 0
    path = tmp_path / "result.json"
    doc = json.loads(path.read_text())
    doc["cell"]["sha256"] = "0" * 64
    path.write_text(json.dumps(doc))
    code, out, _ = _run(["replay", str(path)], capsys)
    assert code == 1 and "MISMATCH: cell.sha256: the cell differs" in out


@pytest.fixture(scope="module")
def plan_result(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("plan")
    assert main(["search", "s3-fence-gap", "--searcher", "plan", "--budget", "40", "--out", str(out),
                 "--no-report"]) == 0
    return json.loads((out / "result.json").read_text())


@pytest.mark.parametrize(("field", "value", "named"), [
    ("hazard.time_s", 0.5, "hazard.time_s"),
    ("hazard.step", 3, "hazard.step"),
    ("hazard.robot_link", "wrist_1_link", "hazard.robot_link"),
    ("hazard.body_part", "head", "hazard.body_part"),
    ("hazard.v_R", 0.01, "hazard.v_R"),
    ("hazard.d_HR", 0.2, "hazard.d_HR"),
    ("hazard.point", [0.0, 0.0, 0.0], "hazard.point[0]"),
    ("hazard.episode", 40, "hazard.episode"),
    ("seed", 7, "the search run again (searcher plan, seed 7"),
    ("found", False, "found"),
])
def test_replay_recomputes_every_claim(plan_result, tmp_path, capsys, field, value, named) -> None:
    """A forged value anywhere in the file is a MISMATCH that names it, never 'REPRODUCED'."""
    doc = json.loads(json.dumps(plan_result))
    *parents, last = field.split(".")
    node = doc
    for p in parents:
        node = node[p]
    assert node[last] != value
    node[last] = value
    (tmp_path / "result.json").write_text(json.dumps(doc))
    code, out, err = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 1, err
    assert "REPRODUCED" not in out
    mismatches = [line for line in out.splitlines() if line.startswith("MISMATCH: ")]
    assert mismatches and named in mismatches[0], out


@pytest.mark.parametrize(("field", "value"), [("episodes", 39), ("risk_per_episode", [0.5])])
def test_replay_refuses_a_file_that_disagrees_with_itself(plan_result, tmp_path, capsys, field, value) -> None:
    """A file whose lists do not match the episodes it claims is not a result at all (issue 29): exit 2, one line
    naming the file and the list, before anything is replayed."""
    doc = json.loads(json.dumps(plan_result))
    assert doc[field] != value
    doc[field] = value
    (tmp_path / "result.json").write_text(json.dumps(doc))
    code, out, err = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 2 and "REPRODUCED" not in out
    assert err.count("\n") == 1 and "result.json" in err and "risk_per_episode" in err, err


def test_replay_of_a_file_from_before_the_criterion_and_sequence_count(plan_result, tmp_path, capsys) -> None:
    """Files written before result.json named its criterion and counted distinct sequences make no claim about
    them: they still replay."""
    doc = json.loads(json.dumps(plan_result))
    del doc["distinct_sequences"], doc["cell"]["criterion"]
    (tmp_path / "result.json").write_text(json.dumps(doc))
    code, out, _ = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 0 and "REPRODUCED bit-exactly" in out, out


def test_replay_unforged_and_no_search(plan_result, tmp_path, capsys) -> None:
    (tmp_path / "result.json").write_text(json.dumps(plan_result))
    code, out, _ = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 0 and "REPRODUCED bit-exactly" in out and "the search run again gives the same file" in out
    doc = json.loads(json.dumps(plan_result))
    doc["seed"] = 7  # not checked without the search, and the line says so
    (tmp_path / "result.json").write_text(json.dumps(doc))
    code, out, _ = _run(["replay", str(tmp_path / "result.json"), "--no-search"], capsys)
    assert code == 0 and "the search was not run again (--no-search)" in out


def test_replay_without_hazard_or_file_is_a_user_error(tmp_path, capsys) -> None:
    assert _run(["search", "baseline", "--budget", "3", "--out", str(tmp_path)], capsys)[0] == 0
    code, _, err = _run(["replay", str(tmp_path / "result.json")], capsys)
    assert code == 2 and err.startswith("error: ") and "no hazard" in err and err.count("\n") == 1
    code, _, err = _run(["replay", str(tmp_path / "nope.json")], capsys)
    assert code == 2 and "no such result file" in err and err.count("\n") == 1
    (tmp_path / "bad.json").write_text("{}")
    code, _, err = _run(["replay", str(tmp_path / "bad.json")], capsys)
    assert code == 2 and "not a cellstress result file" in err


@pytest.mark.parametrize(
    "extra,words",
    [
        (["--searcher", "annealing"], ["unknown searcher 'annealing'", "evolve, mcts, mcts-commit, plan, random"]),
        (["--budget", "0"], ["budget", "1..10,000,000"]),
        (["--seed", "-1"], ["seed", "whole number in 0.."]),
        (["--until", "never"], ["until", "first, budget"]),
        (["--searcher", "random", "--ec", "2"], ["'random' has no option ec"]),
        (["--ec", "-1"], ["ec must be"]),
        (["--searcher", "mcts-commit", "--n", "0"], ["n must be"]),
        (["--budget", "ten"], ["budget"]),
    ],
)
def test_bad_options_exit_2_with_one_line(tmp_path, capsys, extra, words) -> None:
    code, out, err = _run(["search", "s1-scanner-width", "--out", str(tmp_path), *extra], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for w in words:
        assert w in lines[0]
    assert not (tmp_path / "result.json").exists()


def test_unwritable_out_exits_2(tmp_path, capsys) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, _, err = _run(["search", "s1-scanner-width", "--out", str(blocker / "sub")], capsys)
    assert code == 2 and err.startswith(f"error: --out {blocker / 'sub'}: cannot write there")
    code, _, err = _run(["search", "s1-scanner-width", "--out", str(blocker)], capsys)
    assert code == 2 and "exists and is not a directory" in err


def test_unknown_cell_exits_2(tmp_path, capsys) -> None:
    code, _, err = _run(["search", "no-such-cell", "--out", str(tmp_path)], capsys)
    assert code == 2 and err.startswith("error: no-such-cell: no such file")


def test_search_and_replay_a_cell_file_from_another_folder(tmp_path, capsys, monkeypatch) -> None:
    from importlib import resources

    text = resources.files("cellstress.cell").joinpath("builtin", "s3-fence-gap.yaml").read_text(encoding="utf-8")
    (tmp_path / "cells").mkdir()
    (tmp_path / "cells" / "mine.yaml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(["search", "cells/mine.yaml", "--out", "out"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "out" / "result.json").read_text())
    assert doc["cell"]["source"] == str(tmp_path / "cells" / "mine.yaml") and doc["found"]
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    code, out, err = _run(["replay", "../out/result.json"], capsys)
    assert code == 0, err
    assert out.splitlines()[-1].startswith("REPRODUCED bit-exactly")


def test_out_is_required(capsys) -> None:
    code, _, err = _run(["search", "s1-scanner-width"], capsys)
    assert code == 2 and err.startswith("error: Missing option '--out'") and err.count("\n") == 1


def test_set_passes_any_searcher_option(tmp_path, capsys) -> None:
    """--set NAME=VALUE reaches the searcher (JSON values, else text) and is recorded in result.json."""
    code, _, err = _run(["search", "s1-scanner-width", "-s", "evolve", "--budget", "30", "--no-report",
                         "--set", "pool=2", "--set", "score=risk", "--set", "sticky=0.5", "--out", str(tmp_path)],
                        capsys)
    assert code == 0, err
    params = json.loads((tmp_path / "result.json").read_text())["params"]
    assert (params["pool"], params["score"], params["sticky"]) == (2, "risk", 0.5)


@pytest.mark.parametrize(("args", "says"), [
    (["-s", "evolve", "--set", "pool=abc"], "pool must be a whole number in 1..100,000, not 'abc'"),
    (["-s", "mcts", "--set", "pool=2"], "searcher 'mcts' has no option pool"),
    (["-s", "mcts", "--set", "ec=1", "--ec", "2"], "--set ec: given as --ec too"),
    (["--set", "oops"], "--set 'oops': expected NAME=VALUE"),
])
def test_bad_set_options(tmp_path, capsys, args, says) -> None:
    code, _, err = _run(["search", "s1-scanner-width", *args, "--out", str(tmp_path / "x")], capsys)
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1 and says in err, err
    assert not (tmp_path / "x" / "result.json").exists()


def test_no_hazard_says_what_was_searched_and_that_it_is_no_proof(tmp_path, capsys) -> None:
    code, out, err = _run(["search", "baseline", "--searcher", "random", "--budget", "30", "--out", str(tmp_path),
                           "--no-report"], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1].startswith("criterion contact-while-moving: ")
    assert lines[2].startswith("no hazard found in 30 episodes")
    doc = json.loads((tmp_path / "result.json").read_text())
    assert 1 <= doc["distinct_sequences"] <= 30
    assert lines[3] == (f"searched  30 episodes of up to 8 actions ({doc['distinct_sequences']} different action "
                        "sequences), from the start point (0.7, 3.35) with the robot 1.4 s into its cycle (cycle "
                        "5.71 s; other arrival moments were not searched)")
    assert lines[4].startswith("note      A search is not a proof")


def test_iso15066_names_force_and_limit(tmp_path, capsys) -> None:
    """Under a criterion that judges contacts, the hazard's force, limit, case and why are printed (S3 under
    iso15066: a free hand contact over the transient limit once the worker's own speed counts, docs/criteria.md;
    the strongest contact of a search that finds nothing: tests/criteria/test_clamping_cell.py)."""
    code, out, err = _run(["search", "s3-fence-gap", "--criterion", "iso15066", "--searcher", "plan", "--budget",
                           "100", "--out", str(tmp_path), "--no-report"], capsys)
    assert code == 0, err  # (search exits 0 whether or not it finds a hazard)
    assert "criterion iso15066: unsafe when a contact's estimated peak force exceeds" in out
    line = next(ln for ln in out.splitlines() if ln.startswith("iso15066 "))
    assert re.search(r"\d+ N > 280 N transient limit \(hands\): no fixed surface behind the body region; v_rel "
                     r"[\d.]+ m/s with the worker's [\d.]+ m/s towards the robot$", line), line
    doc = json.loads((tmp_path / "result.json").read_text())
    assert doc["cell"]["criterion"] == "iso15066" and doc["hazard"]["iso15066"]["case"] == "transient"
