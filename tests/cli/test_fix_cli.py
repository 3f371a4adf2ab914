"""``cellstress fix``: a flawed cell (mat-short, its front mat renamed to a hostile name) gets a kept proposal
whose file passes ``check``; the same command twice gives the same fix.json and proposal bytes; the hostile name
is escaped in fix.html; the safe baseline needs nothing (exit 0, no proposal); a bad input is one error line.

The module fixture runs fix twice on the same cell (about 20 s each on a quiet machine: the check of the cell
and of two candidates, and verify at horizon 8 on each candidate, which decides mat-short's in about 1 s); every
test reads those two runs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from junit_schema import validate_junit

from cellstress.cell.load import builtin_file
from cellstress.cli import main

HOSTILE = 'mat<script>alert(1)</script>&"x'
ARGS = ["--budget", "10", "--seed", "0", "--time-limit", "30"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fix")
    text = Path(builtin_file("mat-short")).read_text().replace("front-mat", f"'{HOSTILE}'", 1)
    cell = folder / "cell.yaml"
    cell.write_text(text)
    out = []
    for k in (1, 2):
        code = main(["fix", str(cell), "--out", str(folder / f"out{k}"), *ARGS, "--junit", str(folder / f"j{k}.xml")])
        out.append((code, folder / f"out{k}"))
    return out


def test_a_flawed_cell_gets_a_proposal_that_passes_check(runs):
    code, out = runs[0]
    assert code == 0
    doc = json.loads((out / "fix.json").read_text())
    assert doc["failing_before"] == [HOSTILE, "undetected-reach"]
    kept = sorted((c for c in doc["candidates"] if c["kept"]), key=lambda c: c["proposal"])
    assert kept and kept[0]["retest"]["method"] == "verify" and kept[0]["retest"]["proved"]
    assert kept[0]["floor_added_m2"] <= kept[-1]["floor_added_m2"]  # ranked by cost
    for c in kept:
        assert main(["check", str(out / f"proposal-{c['proposal']}.yaml")]) == 0
    assert not (out / f"proposal-{len(kept) + 1}.yaml").exists()


def test_same_inputs_same_bytes(runs):
    (_, a), (_, b) = runs
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    assert "fix.json" in names and "fix.html" in names and "proposal-1.yaml" in names
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_hostile_name_is_escaped_in_the_page(runs):
    _, out = runs[0]
    page = (out / "fix.html").read_text()
    assert "<script>" not in page and "&lt;script&gt;" in page
    assert "&amp;&quot;x" in page


def test_junit_has_a_passing_verdict(runs):
    data = (runs[0][1].parent / "j1.xml").read_bytes()
    root = validate_junit(data)
    cases = {c.get("name"): c for c in root.iter("testcase")}
    assert set(cases) == {"fix", "candidate 1: move-device", "candidate 2: move-cell"}
    assert not list(root.iter("failure")) and b"&lt;script&gt;" in data


def test_a_safe_cell_needs_nothing(tmp_path, capsys):
    assert main(["fix", "baseline", "--out", str(tmp_path), *ARGS]) == 0
    doc = json.loads((tmp_path / "fix.json").read_text())
    assert doc["needs_nothing"] and doc["candidates"] == []
    assert not list(tmp_path.glob("proposal-*.yaml"))
    assert "NOTHING TO FIX" in capsys.readouterr().out


@pytest.mark.parametrize("args", [["no-such-cell"], ["baseline", "--time-limit", "0"],
                                  ["baseline", "--budget", "0"]])
def test_bad_input_is_one_error_line(args, tmp_path, capsys):
    assert main(["fix", *args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:")


def test_a_row_no_candidate_answers_exits_1(tmp_path, capsys):
    """The baseline's second waypoint with the shoulder lifted to -10 deg: the program sweeps the arm through
    the table (its own check fails) and no candidate kind changes a program's path (docs/fix.md): exit 1, no
    proposal, the JUnit verdict case fails."""
    text = Path(builtin_file("baseline")).read_text()
    old = "[37.1, -44.8, 78.4, -123.6, -90.0, 0.0]"
    assert text.count(old) == 1
    cell = tmp_path / "through-table.yaml"
    cell.write_text(text.replace(old, "[37.1, -10.0, 78.4, -123.6, -90.0, 0.0]"))
    out = tmp_path / "out"
    assert main(["fix", str(cell), "--out", str(out), *ARGS, "--junit", str(tmp_path / "j.xml")]) == 1
    doc = json.loads((out / "fix.json").read_text())
    assert doc["failing_before"] == ["program"] and doc["candidates"] == []
    assert not doc["needs_nothing"] and not list(out.glob("proposal-*.yaml"))
    root = validate_junit((tmp_path / "j.xml").read_bytes())
    assert [c.get("name") for c in root.iter("testcase")] == ["fix"] and len(list(root.iter("failure"))) == 1
    assert "NO PROPOSAL WORKS" in capsys.readouterr().out


def test_a_scanner_too_coarse_for_its_plane_gets_a_finer_resolution(tmp_path):
    """The baseline's scanner given a 150 mm resolution: ISO 13855 6.3 wants its plane at least 15 (150 - 50) =
    1500 mm high and at most 300 mm, so no height works (device-height proposes none); the resolution
    candidate sets 70 mm, and the re-test keeps it."""
    text = Path(builtin_file("baseline")).read_text()
    assert text.count("    height: 0.3\n") == 1
    cell = tmp_path / "coarse.yaml"
    cell.write_text(text.replace("    height: 0.3\n", "    height: 0.3\n    resolution_mm: 150\n"))
    out = tmp_path / "out"
    assert main(["fix", str(cell), "--out", str(out), *ARGS]) == 0
    doc = json.loads((out / "fix.json").read_text())
    assert doc["failing_before"] == ["front-scanner-mounting"]
    (c,) = doc["candidates"]
    assert c["kind"] == "scanner-resolution" and c["kept"] and "from 150 to 70 mm" in c["change"]
    assert main(["check", str(out / "proposal-1.yaml")]) == 0


def test_a_curtain_a_body_crawls_under_gets_its_beam_lowered(tmp_path):
    """The baseline with its bay curtain's lowest beam raised to 0.6 m: only its crawl-under row fails (ISO
    13855 6.2: at most 300 mm); the device-height candidate puts the beam at 300 mm and is kept."""
    text = Path(builtin_file("baseline")).read_text()
    assert text.count("    bottom: 0.2") == 1
    cell = tmp_path / "crawl.yaml"
    cell.write_text(text.replace("    bottom: 0.2", "    bottom: 0.6"))
    out = tmp_path / "out"
    assert main(["fix", str(cell), "--out", str(out), *ARGS]) == 0
    doc = json.loads((out / "fix.json").read_text())
    assert doc["failing_before"] == ["bay-curtain-crawl-under"]
    (c,) = doc["candidates"]
    assert c["kind"] == "device-height" and c["kept"] and c["answers"] == ["bay-curtain-crawl-under"]
    assert "from 600 to 300 mm" in c["change"]
    assert main(["check", str(out / "proposal-1.yaml")]) == 0


def test_with_files_confined_a_cell_reading_its_own_robot_is_fixed(tmp_path, monkeypatch):
    """long-gripper (its robot a URDF file beside it) copied with that file into a folder of its own, under
    CELLSTRESS_FILES=inside: the candidates keep the file's relative name and are read as if beside the
    original (a copy in --out may read only that folder), so a proposal is kept; put beside the original,
    it passes check in the same strict mode."""
    monkeypatch.setenv("CELLSTRESS_FILES", "inside")
    cell_dir = tmp_path / "cell"
    cell_dir.mkdir()
    for name in ("long-gripper.yaml", "boxarm.urdf"):
        (cell_dir / name).write_bytes(Path(builtin_file("long-gripper")).with_name(name).read_bytes())
    out = tmp_path / "out"
    assert main(["fix", str(cell_dir / "long-gripper.yaml"), "--out", str(out), *ARGS]) == 0
    doc = json.loads((out / "fix.json").read_text())
    kept = [c for c in doc["candidates"] if c["kept"]]
    assert kept and not any("outside" in f for c in doc["candidates"] for f in c["failing_after"])
    text = (out / "proposal-1.yaml").read_text()
    assert "urdf: boxarm.urdf" in text
    (cell_dir / "proposal-1.yaml").write_text(text)
    assert main(["check", str(cell_dir / "proposal-1.yaml")]) == 0


def test_two_rows_no_single_change_answers_get_a_pair(tmp_path):
    """The baseline with its bay curtain's lowest beam at 0.6 m and its scanner at a 150 mm resolution: each
    candidate answers one of the two rows and leaves the other failing, so none works alone; the pair (the
    beam lowered, then the resolution set) is one candidate, kept, with both changes in its file."""
    text = Path(builtin_file("baseline")).read_text()
    assert text.count("    bottom: 0.2") == 1 and text.count("    height: 0.3\n") == 1
    cell = tmp_path / "two-rows.yaml"
    cell.write_text(text.replace("    bottom: 0.2", "    bottom: 0.6").replace(
        "    height: 0.3\n", "    height: 0.3\n    resolution_mm: 150\n"))
    out = tmp_path / "out"
    assert main(["fix", str(cell), "--out", str(out), *ARGS]) == 0
    doc = json.loads((out / "fix.json").read_text())
    assert doc["failing_before"] == ["front-scanner-mounting", "bay-curtain-crawl-under"]
    singles = [c for c in doc["candidates"] if "+" not in c["kind"]]
    assert singles and not any(c["kept"] for c in singles)
    (pair,) = [c for c in doc["candidates"] if c["kept"]]
    assert pair["kind"] == "device-height+scanner-resolution"
    assert set(pair["answers"]) == {"front-scanner-mounting", "bay-curtain-crawl-under"}
    proposal = (out / "proposal-1.yaml").read_text()
    assert "bottom: 0.3" in proposal and "resolution_mm: 70" in proposal
    assert main(["check", str(out / "proposal-1.yaml")]) == 0
