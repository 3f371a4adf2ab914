"""The README's pictures are what the README's command makes: run the command, compare with the committed files
(the top view as a PNG; the 3D view of report.html as headless Chromium shows it at the hazard's step).

``CELLSTRESS_WRITE_PICTURES=1`` writes the 3D screenshot instead of comparing (after a change to the view)."""

from __future__ import annotations

import json
import os
import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from chromium_page import Page, need_chromium
from PIL import Image

from cellstress.cli import main

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
SECTION = README.split("## Reports", 1)[1].split("\n## ", 1)[0]
SHOT_SIZE = (1000, 640)  # the browser window for the 3D screenshot


@pytest.fixture(scope="module")
def readme_run(tmp_path_factory):
    """The README's report command, run in-process into a temporary folder: (that folder, the --out path)."""
    tmp_path = tmp_path_factory.mktemp("readme")
    command = next(ln for ln in SECTION.splitlines() if ln.startswith("cellstress search "))
    args = shlex.split(command)[1:]
    out_dir = args[args.index("--out") + 1]
    args[args.index("--out") + 1] = str(tmp_path / out_dir)
    assert main(args) == 0
    return tmp_path, out_dir


def _close_enough(made: np.ndarray, committed: np.ndarray, mean: float, share: float, edge: int = 0) -> None:
    """The pictures agree: same size (to ``edge`` pixels each way, then compared on their common part), a mean
    difference under ``mean`` and under ``share`` of the pixels off by more than 64 in a channel."""
    assert made.shape[2:] == committed.shape[2:]
    assert all(abs(a - b) <= edge for a, b in zip(made.shape[:2], committed.shape[:2], strict=True)), \
        (made.shape, committed.shape)
    rows, cols = min(made.shape[0], committed.shape[0]), min(made.shape[1], committed.shape[1])
    made, committed = made[:rows, :cols], committed[:rows, :cols]
    diff = np.abs(made.astype(float) - committed.astype(float))
    assert diff.mean() < mean
    assert (diff.max(axis=2) > 64).mean() < share


def test_readme_picture_is_regenerated(readme_run):
    tmp_path, out_dir = readme_run
    picture = re.search(r"!\[[^\]]*\]\((docs/images/[^)]+\.png)\)", SECTION).group(1)
    made_by = re.search(r"`(out/[^`]+\.png)` from the first command above", SECTION).group(1)
    assert made_by.startswith(out_dir + "/")
    made = tmp_path / made_by
    committed = ROOT / picture
    if made.read_bytes() == committed.read_bytes():
        return
    # another matplotlib or FreeType may rasterise text slightly differently: then the pixels must still agree
    a = np.asarray(Image.open(made).convert("RGB"), dtype=float)
    b = np.asarray(Image.open(committed).convert("RGB"), dtype=float)
    _close_enough(a, b, 2.0, 0.01)


def test_readme_3d_picture_is_regenerated(readme_run, tmp_path):
    exe = need_chromium()
    out, out_dir = readme_run
    picture, page_name = re.search(r"!\[[^\]]*\]\((docs/images/[^)]+\.png)\)\n\n`(out/[^`]+\.html)`'s 3D view",
                                   SECTION).groups()
    assert page_name.startswith(out_dir + "/")
    key = len(json.loads((out / out_dir / "result.json").read_text())["hazard"]["trace"]) - 1
    page = Page(exe, tmp_path / "profile", *SHOT_SIZE)
    try:
        page.open(out / page_name)
        page.wait_for("document.getElementById('cs3d') && document.getElementById('cs3d').dataset.ready === '1'")
        page.js(f"document.getElementById('cs3d').csStep({key}).then(() => true)")
        page.js("document.getElementById('cs3d').scrollIntoView(); new Promise(r => requestAnimationFrame(() => "
                "requestAnimationFrame(() => r(true))))")
        r = page.js("(() => { const b = document.getElementById('cs3d').getBoundingClientRect(); "
                    "return [b.left + window.scrollX, b.top + window.scrollY, b.width, b.height]; })()")
        shot = page.screenshot({"x": r[0], "y": r[1], "width": r[2], "height": r[3]})
        assert page.js("document.getElementById('cs3d').getAttribute('data-marker')") == "contact"
        assert page.failures == [], page.failures
    finally:
        page.close()
    committed = ROOT / picture
    if os.environ.get("CELLSTRESS_WRITE_PICTURES") == "1":
        Image.fromarray(shot.astype(np.uint8)).save(committed, optimize=True)
    # WebGL through SwiftShader: another Chromium may shade a few edges differently, never the scene; and it may
    # round the element's fractional height to a pixel more or less (Chromium 150: 849 rows, the picture 850)
    _close_enough(shot, np.asarray(Image.open(committed).convert("RGB"), dtype=np.int16), 4.0, 0.03, edge=2)
