"""`cellstress report`, `cellstress show` and the report step of `cellstress search`: files, exit codes."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

from cellstress.cli import main
from cellstress.report.hazard import StillOptions


def _run(args, capsys):
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_report_command(s3_report, tmp_path, capsys):
    (tmp_path / "result.json").write_bytes((s3_report / "result.json").read_bytes())
    code, out, err = _run(["report", str(tmp_path / "result.json")], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == f"report    {tmp_path / 'report.html'}"
    assert lines[2].startswith("account   The worker ")
    for name in ("topview.png", "contact.png", "replay.gif", "risk.png", "report.html"):
        assert (tmp_path / name).read_bytes() == (s3_report / name).read_bytes()
    assert _run(["report", str(tmp_path)], capsys)[0] == 0  # the folder works too


@pytest.mark.parametrize("bad", ["missing/result.json", "notjson", "foreign", "lost-cell"])
def test_report_bad_input_is_one_line(bad, s3_report, tmp_path, capsys):
    (tmp_path / "notjson").write_text("{ not json")
    (tmp_path / "foreign").write_text(json.dumps({"hello": 1}))
    doc = json.loads((s3_report / "result.json").read_text())
    doc["cell"] = {**doc["cell"], "source": str(tmp_path / "gone.yaml"), "sha256": "0" * 64}
    (tmp_path / "lost-cell").mkdir()
    (tmp_path / "lost-cell" / "result.json").write_text(json.dumps(doc))
    code, out, err = _run(["report", str(tmp_path / bad)], capsys)
    assert code == 2
    assert err.startswith("error: ") and err.count("\n") == 1 and "Traceback" not in err


def test_search_writes_the_report_unless_told_not_to(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    code, out, err = _run(["search", "s3-fence-gap", "--searcher", "random", "--budget", "30", "--seed", "2",
                           "--out", str(a), "--no-report"], capsys)
    assert code == 0, err
    assert sorted(p.name for p in a.iterdir()) == ["result.json"]
    assert "report.html" not in out
    code, out, err = _run(["search", "s3-fence-gap", "--searcher", "random", "--budget", "30", "--seed", "2",
                           "--out", str(b), "--json"], capsys)
    assert code == 0, err
    assert out == (b / "result.json").read_text()  # --json: stdout is still exactly the file
    assert "report.html" in err
    assert (b / "report.html").is_file() and (b / "replay.gif").is_file()


def test_show(tmp_path, capsys, monkeypatch):
    code, out, err = _run(["show", "s2-elbow-intrusion", "--out", str(tmp_path / "pics" / "s2.png")], capsys)
    assert code == 0, err
    assert out.strip() == f"wrote     {tmp_path / 'pics' / 's2.png'}"
    with Image.open(tmp_path / "pics" / "s2.png") as img:
        width, height = StillOptions().layout.pixels  # the height; the width is fitted to the cell (report/fit.py)
        assert img.size[1] == height and 0.5 * width < img.size[0] < 1.6 * width
        assert float(np.asarray(img.convert("L"), float).std()) > 8.0
    monkeypatch.chdir(tmp_path)
    assert _run(["show", "baseline"], capsys)[0] == 0
    assert (tmp_path / "baseline.png").is_file()
    assert _run(["show", "baseline", "--3d"], capsys)[0] == 0  # the 3D page, named after the cell
    assert 'id="cs3d-data"' in (tmp_path / "baseline.html").read_text(encoding="utf-8")


@pytest.mark.parametrize("args", [["show", "no-such-cell"], ["show", "baseline", "--out", "x.txt"]])
def test_show_bad_input(args, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = _run(args, capsys)
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1
