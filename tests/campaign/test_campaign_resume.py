"""runs.jsonl and campaign.json: resume without duplicates, a truncated last line, changed options (exit 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from cellstress.campaign.plan import MANIFEST
from cellstress.campaign.store import RUNS, FolderLock
from cellstress.cli import main

# a tiny grid: 2 searchers x 3 seeds on the fastest flawed cell, budget 12
OPTIONS = {"--cells": "s1-scanner-width", "--searchers": "random,mcts", "--seeds": "3", "--budget": "12",
           "--workers": "1"}


def _options(**change: str) -> list[str]:
    """The small grid's options, some replaced: _options(budget="13")."""
    opts = dict(OPTIONS, **{f"--{k}": v for k, v in change.items()})
    return [x for kv in opts.items() for x in kv]


SMALL = _options()
GRID = {("s1-scanner-width", s, seed) for s in ("random", "mcts") for seed in range(3)}


def _campaign(out: Path, *extra: str, capsys=None) -> tuple[int, str, str]:
    code = main(["campaign", *SMALL, "--out", str(out), *extra])
    o, e = capsys.readouterr() if capsys is not None else ("", "")
    return code, o, e


def _keys(out: Path) -> list[tuple[str, str, int]]:
    return [(r["cell"], r["searcher"], r["seed"]) for r in map(json.loads, (out / RUNS).read_text().splitlines())]


@pytest.fixture(scope="module")
def done(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("campaign") / "small"
    assert main(["campaign", *SMALL, "--out", str(out)]) == 0
    return out


def test_a_campaign_writes_its_files(done):
    assert sorted(_keys(done)) == sorted(GRID)
    manifest = json.loads((done / MANIFEST).read_text())
    assert manifest["budget"] == 12 and manifest["seeds"] == [0, 1, 2] and manifest["runs"] == 6
    assert [s["name"] for s in manifest["searchers"]] == ["random", "mcts"]
    assert manifest["searchers"][1]["params"] == {"alpha": 0.85, "ec": 0.5, "k": 1.0}
    line = (done / RUNS).read_text().splitlines()[0]
    rec = json.loads(line)
    assert line == json.dumps(rec, sort_keys=True, separators=(",", ":"))  # sorted keys, one compact line
    assert {"cell", "cell_sha256", "searcher", "params", "seed", "budget", "found", "episodes", "hazard",
            "version"} <= set(rec)
    assert not {k for k in rec if "time" in k or "elapsed" in k or "wall" in k}  # no wall-clock
    md = (done / "table.md").read_text()
    assert "| s1-scanner-width | mcts | " in md and "| s1-scanner-width | random | " in md
    assert (done / "table.csv").read_text().startswith("cell,searcher,runs,found,")


def _copy(src: Path, dst: Path) -> Path:
    dst.mkdir()
    for name in (MANIFEST, RUNS):
        (dst / name).write_bytes((src / name).read_bytes())
    return dst


def test_resume_of_a_finished_campaign_runs_nothing(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "again")
    before = (out / RUNS).read_bytes()
    code, stdout, err = _campaign(out, capsys=capsys)
    assert code == 0, err
    assert (out / RUNS).read_bytes() == before
    assert "(0 run now, 6 already done)" in stdout
    assert (out / "table.md").read_text() == (done / "table.md").read_text()


def test_resume_runs_only_what_is_missing(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "part")
    lines = (out / RUNS).read_text().splitlines(keepends=True)
    (out / RUNS).write_text("".join(lines[:2]))
    code, stdout, err = _campaign(out, capsys=capsys)
    assert code == 0, err
    assert "(4 run now, 2 already done)" in stdout and "resuming: 2 of 6 runs" in err
    keys = _keys(out)
    assert len(keys) == len(set(keys)) == 6 and set(keys) == GRID
    assert sorted((out / RUNS).read_text().splitlines()) == sorted((done / RUNS).read_text().splitlines())


@pytest.mark.parametrize("cut", [1, 25, -1])
def test_a_truncated_last_line_is_dropped_and_its_run_redone(done, tmp_path, capsys, cut):
    out = _copy(done, tmp_path / "cut")
    text = (out / RUNS).read_text()
    last = text.splitlines(keepends=True)[-1]
    (out / RUNS).write_text(text[: len(text) - len(last)] + last[:cut])  # a crash in the middle of a write
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 0, err
    assert "truncated line" in err
    assert sorted((out / RUNS).read_text().splitlines()) == sorted(text.splitlines())
    assert (out / RUNS).read_text().endswith("\n")


def test_a_damaged_line_in_the_middle_is_an_error(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "bad")
    lines = (out / RUNS).read_text().splitlines(keepends=True)
    lines[1] = "{not json\n"
    (out / RUNS).write_text("".join(lines))
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2
    assert err.count("\n") == 1 and "line 2 is not a run record" in err


def test_a_line_from_another_campaign_is_an_error(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "alien")
    rec = json.loads((out / RUNS).read_text().splitlines()[0])
    rec["budget"] = 99
    with (out / RUNS).open("a") as f:
        f.write(json.dumps(rec, sort_keys=True) + "\n")
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and "line 7" in err and "is not a run of the campaign" in err


@pytest.mark.parametrize(("change", "says"), [
    ({"budget": "13"}, "--budget differs: 12 there, 13 here"),
    ({"seeds": "4"}, "--seeds differs: 3 there, 4 here"),
    ({"searchers": "random"}, "--searchers differs: random,mcts there, random here"),
    ({"searchers": "mcts,random"}, "--searchers differs"),
    ({"cells": "s1-scanner-width,s3-fence-gap"}, "--cells differs: s1-scanner-width there, "
                                                 "s1-scanner-width,s3-fence-gap here"),
])
def test_changed_options_are_one_clear_error(done, tmp_path, capsys, change, says):
    out = _copy(done, tmp_path / "changed")
    before = (out / RUNS).read_bytes()
    code = main(["campaign", *_options(**change), "--out", str(out)])
    _, err = capsys.readouterr()
    assert code == 2
    assert err.startswith("error: ") and err.count("\n") == 1 and says in err, err
    assert (out / RUNS).read_bytes() == before


def test_set_goes_to_the_searchers_that_have_the_option_and_is_pinned(done, tmp_path, capsys):
    """--set ec=0.8 reaches mcts (it has ec), not random; the manifest and every run record it, and resuming
    with another value is refused."""
    out = tmp_path / "set"
    assert main(["campaign", *SMALL, "--set", "ec=0.8", "--out", str(out)]) == 0
    doc = json.loads((out / MANIFEST).read_text())
    params = {s["name"]: s["params"] for s in doc["searchers"]}
    assert params["mcts"]["ec"] == 0.8 and "ec" not in params["random"]
    runs = [json.loads(line) for line in (out / RUNS).read_text().splitlines()]
    assert {r["params"].get("ec") for r in runs if r["searcher"] == "mcts"} == {0.8}
    default = [json.loads(line) for line in (done / RUNS).read_text().splitlines()]
    assert {r["params"]["ec"] for r in default if r["searcher"] == "mcts"} == {0.5}
    capsys.readouterr()
    code = main(["campaign", *SMALL, "--set", "ec=0.9", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "searcher mcts's options differ" in err and "ec 0.8 there, 0.9 here" in err, err


def test_workers_and_backend_are_not_options_of_the_experiment(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "w2")
    code = main(["campaign", *_options(workers="2"), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err


def test_a_changed_cell_file_is_detected(tmp_path, capsys):
    from importlib import resources

    text = resources.files("cellstress.cell").joinpath("builtin", "s1-scanner-width.yaml").read_text()
    cell = tmp_path / "mycell.yaml"
    cell.write_text(text)
    args = ["campaign", "--cells", str(cell), "--searchers", "mcts", "--seeds", "1", "--budget", "5",
            "--workers", "1", "--out", str(tmp_path / "out")]
    assert main(args) == 0
    doc = yaml.safe_load(text)
    doc["description"] = "edited"
    cell.write_text(yaml.safe_dump(doc))
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "cell s1-scanner-width has changed since the campaign started" in err and err.count("\n") == 1


def test_an_unreadable_manifest_or_runs_without_one(tmp_path, capsys):
    out = tmp_path / "junk"
    out.mkdir()
    (out / MANIFEST).write_text("[1, 2")
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and "campaign.json: not a campaign manifest: (file): invalid JSON" in err
    out2 = tmp_path / "orphan"
    out2.mkdir()
    (out2 / RUNS).write_text("")
    code, _, err = _campaign(out2, capsys=capsys)
    assert code == 2 and "no campaign.json" in err


@pytest.mark.parametrize(("change", "says"), [
    (lambda m: m.update(cells=["s1-scanner-width"]), "cells[0]: Input should be an object"),  # the crash of issue 29
    (lambda m: m.update(searchers="random"), "searchers: Input should be a valid array"),
    (lambda m: m["cells"][0].update(sha256="x" * 64), "cells[0].sha256: String should match pattern"),
    (lambda m: m.update(budget=True), "budget: Input should be a valid integer"),
    (lambda m: m.update(seeds=list(range(200_000))), "seeds: Tuple should have at most 100000 items"),
    (lambda m: m["searchers"][0].update(params={"ec": [1] * 5}), "searchers[0].params.ec"),
    (lambda m: m.update(evil=1), "evil: Extra inputs are not permitted"),
])
def test_a_forged_manifest_is_one_clear_error(done, tmp_path, capsys, change, says):
    """campaign.json comes from the folder, which may come from anyone: checked as a typed record (issue 29)."""
    out = _copy(done, tmp_path / "forged")
    doc = json.loads((out / MANIFEST).read_text())
    change(doc)
    (out / MANIFEST).write_text(json.dumps(doc))
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1, err
    assert f"{out / MANIFEST}: not a campaign manifest: {says}" in err, err


def test_a_manifest_with_a_repeated_key_is_refused(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "twice")
    text = (out / MANIFEST).read_text()
    (out / MANIFEST).write_text(text.replace('"budget": 12', '"budget": 99, "budget": 12'))
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and "campaign.json: not a campaign manifest: the key 'budget' appears twice" in err, err


@pytest.mark.parametrize(("change", "says"), [
    (lambda r: r.update(episodes="many"), "episodes: Input should be a valid integer"),
    (lambda r: r.update(episodes=10**6), "episodes: 1,000,000 played, more than the budget of 12"),
    (lambda r: r.update(found=True, hazard=None), "found: true, but the line has no hazard"),
    (lambda r: r.update(hazard="boom"), "hazard: Input should be an object"),
])
def test_a_forged_run_line_is_one_clear_error(done, tmp_path, capsys, change, says):
    out = _copy(done, tmp_path / "forged-run")
    lines = (out / RUNS).read_text().splitlines()
    rec = json.loads(lines[0])
    change(rec)
    lines[0] = json.dumps(rec, sort_keys=True)
    (out / RUNS).write_text("\n".join(lines) + "\n")
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and err.count("\n") == 1 and "line 1 is not a run record" in err and says in err, err


@pytest.mark.parametrize("name", [MANIFEST, RUNS])
def test_a_link_planted_in_the_folder_is_refused(done, tmp_path, capsys, name):
    out = _copy(done, tmp_path / "linked")
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    (out / name).replace(tmp_path / f"moved-{name}")
    (out / name).symlink_to(victim)
    code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and err.count("\n") == 1 and f"{out / name}: is a symbolic link" in err, err
    assert victim.read_text() == "keep me\n"


def test_two_campaigns_cannot_share_a_folder(done, tmp_path, capsys):
    out = _copy(done, tmp_path / "locked")
    with FolderLock(out):
        code, _, err = _campaign(out, capsys=capsys)
    assert code == 2 and "another campaign is running there" in err


@pytest.mark.parametrize(("args", "says"), [
    (["--searchers", "nope"], "unknown searcher 'nope' (choose from evolve, mcts, mcts-commit, plan, random"),
    (["--searchers", "mcts,mcts"], "mcts listed more than once"),
    (["--cells", "no-such-cell"], "--cells: no-such-cell: no such file"),
    (["--seeds", "0"], "--seeds must be a whole number in 1..100,000"),
    (["--budget", "0"], "--budget must be a whole number in 1..10,000,000"),
    (["--workers", "0"], "--workers must be a whole number in 1.."),
    (["--backend", "dask"], "--backend must be one of processes, ray"),
    (["--address", "auto"], "use it with --backend ray"),
    (["--set", "ec"], "--set 'ec': expected NAME=VALUE"),
    (["--set", "pool=5"], "--set pool: none of the searchers (random, mcts, mcts-commit) has this option"),
    (["--set", "ec=-1"], "--set: "),
    (["--set", "ec=1", "--set", "ec=2"], "option 'ec' given twice"),
])
def test_bad_options(tmp_path, capsys, args, says):
    code = main(["campaign", "--out", str(tmp_path / "x"), *args])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1 and says in err, err
    assert not (tmp_path / "x" / MANIFEST).exists()


def test_ray_missing_is_a_clear_error(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    code = main(["campaign", *SMALL, "--backend", "ray", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 2 and "pip install 'cellstress[ray]'" in err and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()
