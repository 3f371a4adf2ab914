"""The command line: cells, check, simulate (table and JSON), exit codes and start-up cost."""

from __future__ import annotations

import copy
import json
import os
import re
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cellstress.cli import app, main

HAZARD_KEYS = {"t", "step", "robot_link", "body_part", "robot_point", "human_point", "d_HR", "v_R"}
UNSAFE_LINE = re.compile(
    r"^UNSAFE at t=(?P<t>[0-9.]+) s \(step (?P<step>\d+)\): (?P<link>\S+) / (?P<part>\S+)$"
)


def _run(args: list[str], capsys) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def _script() -> list[str]:
    exe = shutil.which("cellstress", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "cellstress.cli"]


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


@pytest.fixture(scope="module")
def unguarded(baseline, tmp_path_factory) -> tuple[Path, list[str]]:
    """The baseline without safety devices, and an action sequence that ends in an unsafe contact there."""
    from cellstress.cell.load import load_cell
    from cellstress.human.actions import ACTION_NAMES
    from cellstress.sim.simulator import Simulator

    cell = copy.deepcopy(baseline)
    cell["name"] = "unguarded"
    cell["devices"] = []
    path = tmp_path_factory.mktemp("cells") / "unguarded.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False), encoding="utf-8")
    sim = Simulator(load_cell(path))
    n = sim.actions_per_episode
    candidates = [
        [b] * n
        for b in ("walk+upright", "walk+bend-forward", "walk+bend-forward-left", "walk+bend-forward-right")
    ]
    for seq in candidates:
        if sim.run(seq).unsafe:
            return path, seq
    acts = np.random.default_rng(0).integers(0, 30, (5000, n))
    hits = np.flatnonzero(sim.run_batch(acts).unsafe)
    if not hits.size:
        pytest.fail("no unsafe sequence found in the baseline without devices; the test needs a new scenario")
    return path, [ACTION_NAMES[a] for a in acts[hits[0]]]


# ---- cells -------------------------------------------------------------------------------------------------
def test_cells_lists_every_builtin(capsys) -> None:
    from cellstress.cell.load import BUILTIN_CELLS

    code, out, err = _run(["cells"], capsys)
    assert code == 0 and err == ""
    lines = out.strip().splitlines()
    assert [ln.split()[0] for ln in lines[:-2]] == list(BUILTIN_CELLS)
    assert lines[-2].startswith("files in ")  # where the built-in cell files are
    assert lines[-1].startswith("robots: ur3, ur5, ur10") and "panda" in lines[-1]
    baseline_line = lines[0]
    assert len(baseline_line.split()) > 1  # a description follows the name


def test_cells_first_sentence_only(capsys, baseline) -> None:
    code, out, _ = _run(["cells"], capsys)
    line = next(ln for ln in out.splitlines() if ln.startswith("baseline "))
    first = " ".join(baseline["description"].split()).split(". ")[0]
    assert first in line
    assert line.rstrip().endswith(".")
    assert line.count(". ") == 0


def test_cells_marks_missing_builtin(capsys, monkeypatch) -> None:
    import cellstress.cell.load as load

    monkeypatch.setattr(load, "BUILTIN_CELLS", (*load.BUILTIN_CELLS, "no-such-builtin"))
    code, out, _ = _run(["cells"], capsys)
    assert code == 0
    assert re.search(r"^no-such-builtin\s+\(missing\)$", out, re.M)


# ---- check -------------------------------------------------------------------------------------------------
def test_check_baseline_summary(capsys, baseline) -> None:
    code, out, err = _run(["check", "baseline"], capsys)
    assert code == 0, err
    assert err == ""
    assert re.search(r"^cell\s+baseline\b", out, re.M)
    assert "ur10" in out and "6 joints" in out
    assert re.search(r"^capsules\s+\d+", out, re.M) and "forearm_link" in out
    assert re.search(r"cycle time \d+\.\d+ s", out)
    assert re.search(r"^obstacles\s+2$", out, re.M)  # the table and the robot's pedestal
    assert re.search(r"^\s+table\s+height 0.85 m, footprint of 8 corners$", out, re.M)
    assert re.search(rf"^fences\s+{len(baseline['fences'])}\b", out, re.M)
    assert re.search(rf"^devices\s+{len(baseline['devices'])}\b", out, re.M)
    for d in baseline["devices"]:
        assert re.search(rf"{re.escape(d['name'])}\s+{d['type']}\s+response {d['response_time']:g} s", out)
    x, y = baseline["human"]["start"]["xy"]
    assert f"start ({x:g}, {y:g}) heading {baseline['human']['start']['heading_deg']:g} deg" in out
    assert "contact-while-moving" in out
    assert code == 0
    assert out.strip().splitlines()[-1] == "PASS: the cell file is valid and the static check passes"


@pytest.mark.parametrize("cell", ["s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap"])
def test_check_exits_1_on_a_failed_static_check(capsys, cell) -> None:
    """A CI gate: a flawed design fails the static check with exit code 1, and the last line says what failed."""
    code, out, err = _run(["check", cell], capsys)
    assert code == 1, err
    assert out.strip().splitlines()[-1].startswith("FAIL: the cell file is valid, the static check fails (")


def test_check_witness_finds_each_rows_way_and_writes_replayable_results(capsys, tmp_path) -> None:
    """``check --witness``: one line per failing row after the static check, FOUND with the actions; each
    search's result file in search-N under --out, with the aim it was given; the exit code stays the check's."""
    from cellstress.searchers.result import SearchResult

    junit = tmp_path / "check.xml"
    code, out, err = _run(["check", "s3-fence-gap", "--witness", "--out", str(tmp_path / "w"), "--junit",
                           str(junit)], capsys)
    assert code == 1, err
    xml = junit.read_text(encoding="utf-8")
    assert xml.count("simulated: front-scanner: FOUND at episode") == 1
    assert xml.count("simulated: undetected-reach: FOUND at episode") == 1
    lines = out.splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("simulated witnesses (plan, 200 episodes"))
    rows = lines[head + 1: head + 3]
    assert rows[0].startswith("  front-scanner: FOUND at episode ") and "search-1" in rows[0]
    # its search's first hazard was unseen (the undetected reach's way): the witness is further into the budget
    assert ": among its hazards, episode " in rows[0]
    assert rows[1].startswith("  undetected-reach: FOUND at episode ") and "search-2" in rows[1]
    assert lines[-1].startswith("FAIL: the cell file is valid, the static check fails (")
    res = SearchResult.load(tmp_path / "w" / "search-1")
    assert res.searcher == "plan" and res.params["aim"].count(",") == 3
    witness = rows[0].split(": ", 2)[2].split(" (")[0].split(", ")
    assert list(res.hazards[[h.actions for h in res.hazards].index(tuple(witness))].actions) == witness


@pytest.mark.parametrize("args", [["--budget", "5"], ["--seed", "3"], ["--out", "x"]])
def test_check_witness_options_need_witness(capsys, args) -> None:
    code, out, err = _run(["check", "s3-fence-gap", *args], capsys)
    assert code == 2 and "--witness" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("args, said", [(["--budget", "0"], "budget"), (["--seed", "-1"], "seed"),
                                        (["--out", "FILE"], "--out")])
def test_check_witness_bad_options_are_one_line(capsys, tmp_path, args, said) -> None:
    (tmp_path / "FILE").write_text("x", encoding="utf-8")
    args = [str(tmp_path / a) if a == "FILE" else a for a in args]
    code, out, err = _run(["check", "s3-fence-gap", "--witness", *args], capsys)
    assert code == 2 and said in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "simulated witnesses" not in out


def test_check_witness_on_a_passing_cell_searches_nothing(capsys) -> None:
    code, out, err = _run(["check", "baseline", "--witness"], capsys)
    assert code == 0, err
    assert "simulated witnesses" not in out


def test_check_file_path(capsys, baseline, tmp_path) -> None:
    cell = copy.deepcopy(baseline)
    cell["name"] = "my-cell"
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(cell), encoding="utf-8")
    code, out, err = _run(["check", str(path)], capsys)
    assert code == 0, err
    assert re.search(r"^cell\s+my-cell\b", out, re.M) and str(path) in out


def test_check_prints_iso13855_static_check(capsys) -> None:
    from cellstress.analysis.iso13855 import static_check

    code, out, err = _run(["check", "baseline"], capsys)
    assert code == 0, err
    lines = static_check("baseline")
    assert len(lines) > 3 and "ISO 13855 static check:\n" + "".join(f"  {ln}\n" for ln in lines) in out


def test_check_iso13855_user_error_is_one_line(capsys, monkeypatch) -> None:
    from cellstress.analysis import iso13855
    from cellstress.core.errors import CellError

    def check_cell(cell, layout=None):
        raise CellError(cell.source, "devices[0]", "too close")

    monkeypatch.setattr(iso13855, "check_cell", check_cell)
    code, _, err = _run(["check", "baseline"], capsys)
    assert code == 2 and err == "error: baseline: devices[0]: too close\n"


# ---- simulate ----------------------------------------------------------------------------------------------
def test_simulate_safe_table(capsys) -> None:
    from cellstress.sim.simulator import Simulator

    actions = ["walk+upright", "turn-left-90+upright", "walk+bend-left"]
    code, out, err = _run(["simulate", "baseline", "--actions", ",".join(actions)], capsys)
    assert code == 0, err
    trace = Simulator("baseline").run(actions)
    assert not trace.unsafe
    lines = out.strip().splitlines()
    assert lines[-1] == "SAFE"
    header, rows = lines[0], lines[1:-1]
    for word in ("t[s]", "x[m]", "y[m]", "head", "fwd", "lat", "d_HR", "v_R", "phase", "devices"):
        assert word in header
    assert len(rows) == len(trace.rows)  # one line per time step, the initial state included
    for line, rec in zip(rows, trace.records(), strict=True):
        fields = line.split()
        assert int(fields[0]) == rec.step
        assert float(fields[1]) == pytest.approx(rec.t, abs=0.005)
        assert float(fields[2]) == pytest.approx(rec.x, abs=0.0005)
        assert float(fields[3]) == pytest.approx(rec.y, abs=0.0005)
        assert float(fields[7]) == pytest.approx(rec.d_HR, abs=0.0005)
        assert rec.stop_phase in fields


def test_simulate_unsafe_table(capsys, unguarded) -> None:
    from cellstress.cell.load import load_cell
    from cellstress.sim.simulator import Simulator

    path, actions = unguarded
    code, out, err = _run(["simulate", str(path), "--actions", ",".join(actions)], capsys)
    assert code == 1, err  # unsafe is a finding (1), not a user error (2)
    trace = Simulator(load_cell(path)).run(actions)
    hit = trace.record(trace.unsafe_row)
    last = out.strip().splitlines()[-1]
    m = UNSAFE_LINE.match(last)
    assert m, last
    assert float(m["t"]) == pytest.approx(hit.t, abs=1e-6)
    assert int(m["step"]) == hit.step
    assert (m["link"], m["part"]) == (hit.robot_link, hit.body_part)
    assert len(out.strip().splitlines()) == 1 + len(trace.rows) + 1


def test_simulate_json_safe(capsys) -> None:
    actions = ["walk+upright", "walk+bend-forward"]
    code, out, err = _run(["simulate", "baseline", "--actions", ",".join(actions), "--json"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc) == {"cell", "actions", "steps", "unsafe", "hazard"}
    assert doc["cell"] == "baseline" and doc["actions"] == actions
    assert doc["unsafe"] is False and doc["hazard"] is None
    first = doc["steps"][0]
    for key in (
        "t",
        "x",
        "y",
        "heading_deg",
        "forward_flexion_deg",
        "lateral_flexion_deg",
        "d_HR",
        "v_R",
        "devices",
        "stop_phase",
    ):
        assert key in first
    assert [s["step"] for s in doc["steps"]] == list(range(len(doc["steps"])))


def test_simulate_json_unsafe(capsys, unguarded) -> None:
    path, actions = unguarded
    code, out, err = _run(["simulate", str(path), "-a", ",".join(actions), "--json"], capsys)
    assert code == 1, err
    doc = json.loads(out)
    assert doc["cell"] == "unguarded" and doc["unsafe"] is True
    hazard = doc["hazard"]
    assert set(hazard) == HAZARD_KEYS
    last = doc["steps"][-1]
    assert last["unsafe"] is True
    for key in HAZARD_KEYS:
        assert hazard[key] == last[key]
    assert len(hazard["robot_point"]) == 3 and len(hazard["human_point"]) == 3


def test_simulate_json_is_strict_json(capsys) -> None:
    code, out, _ = _run(["simulate", "baseline", "--actions", "walk+upright", "--json"], capsys)
    assert code == 0
    assert "NaN" not in out and "Infinity" not in out
    json.loads(out, parse_constant=lambda c: pytest.fail(f"non-standard JSON constant {c}"))


def test_simulate_accepts_spaces_and_case(capsys) -> None:
    code, out, err = _run(
        ["simulate", "baseline", "--actions", " Walk+Upright , walk+bend-left ", "--json"], capsys
    )
    assert code == 0, err
    assert json.loads(out)["actions"] == ["walk+upright", "walk+bend-left"]


# ---- exit codes and error lines ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "args,words",
    [
        (["simulate", "baseline"], ["Missing option", "--actions"]),
        (["check"], ["Missing argument"]),
        (["frobnicate"], ["No such command"]),
        (["simulate", "baseline", "--actions", "walk+upright", "--fast"], ["No such option", "--fast"]),
        (["check", "baseline", "extra"], ["unexpected extra argument"]),
    ],
)
def test_usage_errors_exit_2_with_one_line(capsys, args, words) -> None:
    code, out, err = _run(args, capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    for w in words:
        assert w.lower() in lines[0].lower()


def test_help_exits_0(capsys) -> None:
    code, out, _ = _run(["--help"], capsys)
    assert code == 0
    assert "simulate" in out and "check" in out and "cells" in out


@pytest.mark.parametrize("command", ["cells", "check", "diff", "fix", "simulate", "search", "verify", "replay",
                                     "campaign", "report", "show"])
def test_command_help_names_values_plainly(capsys, command) -> None:
    """``--out OUT``, not ``--out <str>``; a flag such as ``--help`` or ``--json`` shows no value."""
    code, out, _ = _run([command, "--help"], capsys)
    assert code == 0 and "Usage: cellstress " + command in out
    assert "<str>" not in out and "<bool>" not in out and "<int>" not in out
    assert re.search(r"^\s+--help\s+Show this message", out, re.M)


def test_cli_runner_user_error_is_one_line() -> None:
    """Through typer's own runner (no main()): a CellstressError still gives exit 2 and one stderr line."""
    result = CliRunner().invoke(app, ["check", "/no/such/cell.yaml"])
    assert result.exit_code == 2
    assert result.stderr.strip() == (
        "error: /no/such/cell.yaml: no such file, and not a built-in cell "
        "(baseline, s1-scanner-width, s2-elbow-intrusion, s3-fence-gap, all-flaws, s2-deceptive, restart-auto, "
        "restart-manual, warning-field-short, warning-field-ok, mat-short, mat-ok, palletizing, palletizing-fixed, "
        "door-unlocked, door-locked, muting-long, muting-ok, "
        "two-robots, two-robots-fixed, ssm-latency, ssm-ok, reach-over, reach-over-ok, long-gripper, long-gripper-ok, "
        "machine-tending, machine-tending-delay, machine-tending-delay-ok, crawl-under, crawl-under-ok, "
        "curtain-reach-over, curtain-reach-over-ok)"
    )
    assert result.stdout == ""


def test_console_script_end_to_end(tmp_path) -> None:
    env = {**os.environ, "NO_COLOR": "1"}
    ok = subprocess.run(
        [*_script(), "simulate", "baseline", "--actions", "walk+upright"],
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
    )
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.strip().splitlines()[-1] == "SAFE"
    usage = subprocess.run(
        [*_script(), "simulate", "baseline"], capture_output=True, text=True, timeout=120, env=env
    )
    assert usage.returncode == 2
    assert len(usage.stderr.strip().splitlines()) == 1 and "Traceback" not in usage.stderr
    bad = subprocess.run(
        [*_script(), "simulate", "baseline", "--actions", "jump+upright"],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert bad.returncode == 2
    assert bad.stderr.startswith("error: --actions: unknown action 'jump+upright'")


def test_import_is_light() -> None:
    """`cellstress --help` must not pay for numba, pinocchio or the simulator."""
    code = (
        "import sys, cellstress.cli; heavy = [m for m in ('numba', 'pinocchio', 'cellstress.sim.simulator', "
        "'pydantic') if m in sys.modules]; print(','.join(heavy))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == ""


def test_check_declared_capsules(capsys, baseline, tmp_path) -> None:
    cell = copy.deepcopy(baseline)
    cell["robot"]["capsules"] = [{"link": "forearm_link", "p0": [0, 0, 0], "p1": [0, 0, 0.5], "radius": 0.08}]
    cell["robot"]["extra_capsules"] = []
    path = tmp_path / "declared.yaml"
    path.write_text(yaml.safe_dump(cell), encoding="utf-8")
    code, out, err = _run(["check", str(path)], capsys)
    assert code == 0, err
    assert re.search(r"^capsules\s+1 \(1 declared\)", out, re.M)
    assert re.search(r"forearm_link\s+on joint\s+\d+\s+radius 0\.080 m\s+length 0\.500 m", out)


def test_a_proof_and_a_search_keep_the_rows_check_fails(capsys, tmp_path) -> None:
    # door-locked with its front wall raised 0.35 m, the worker outside in front of it: check FAILs the slot under
    # the wall (the whole body passes, ISO 13857), which the paper's worker cannot crawl through. verify proves the
    # model safe and search finds nothing; both must say the static FAIL stands, and why they could not test it.
    data = yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", "door-locked.yaml").read_text())
    next(f for f in data["fences"] if f["points"] == [[-1.5, 3.2], [1.5, 3.2]])["bottom"] = 0.35
    data["human"]["start"] = {"xy": [0.0, 3.8], "heading_deg": -90.0}
    cell = tmp_path / "raised.yaml"
    cell.write_text(yaml.safe_dump(data), encoding="utf-8")
    code, out, _ = _run(["verify", str(cell), "--horizon", "1", "--phases", "cell", "--workers", "1",
                         "--out", str(tmp_path / "v")], capsys)
    assert code == 0 and "PROVED-SAFE" in out
    line = next(ln for ln in out.splitlines() if ln.startswith("static "))
    assert "check FAILs whole-body-opening" in line and "cannot crawl" in line and "this proof does not cover" in line
    saved = json.loads((tmp_path / "v" / "verify.json").read_text())
    assert [f["name"] for f in saved["static_failures"]] == ["whole-body-opening"]
    assert "cannot crawl" in (tmp_path / "v" / "verify.html").read_text()
    code, out, _ = _run(["search", str(cell), "--searcher", "random", "--budget", "2", "--out", str(tmp_path / "s")],
                        capsys)
    assert code == 0 and "no hazard found" in out
    assert any(ln.startswith("static    check FAILs whole-body-opening") and "this search does not cover" in ln
               for ln in out.splitlines())
    page = (tmp_path / "s" / "report.html").read_text()
    assert "check FAILs whole-body-opening" in page and "cannot crawl" in page
    # the baseline passes check: nothing to keep
    code, out, _ = _run(["verify", "baseline", "--horizon", "1", "--phases", "cell", "--workers", "1",
                         "--out", str(tmp_path / "b")], capsys)
    assert code == 0 and "static " not in out
    assert json.loads((tmp_path / "b" / "verify.json").read_text())["static_failures"] == []
