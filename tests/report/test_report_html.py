"""report.html: parses, embeds every image, references no external URL and runs no script; renders in headless
Chromium; tells the hazard in words (or says that none was found)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest
from PIL import Image


class _Collect(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


def _parse(path) -> _Collect:
    p = _Collect()
    p.feed(path.read_text(encoding="utf-8"))
    p.close()
    return p


def test_html_is_self_contained(s3_report):
    page = _parse(s3_report / "report.html")
    tags = [t for t, _ in page.tags]
    assert tags[0] == "html" and "body" in tags and "table" in tags
    assert "script" not in tags and "link" not in tags and "iframe" not in tags
    imgs = [a for t, a in page.tags if t == "img"]
    assert len(imgs) == 5  # top view, contact, animation, risk, the robot's program
    assert sorted(a["src"].split(";")[0] for a in imgs) == ["data:image/gif"] + ["data:image/png"] * 4
    for _, attrs in page.tags:
        for key in ("src", "href", "action", "poster", "data"):
            value = attrs.get(key)
            assert value is None or value.startswith("data:"), (key, value[:80])
    raw = (s3_report / "report.html").read_text(encoding="utf-8")
    assert "http:" not in raw and "https:" not in raw and "url(" not in raw and "@import" not in raw


def test_html_tells_the_hazard(s3_report):
    import json

    doc = json.loads((s3_report / "result.json").read_text())
    h = doc["hazard"]
    text = " ".join(_parse(s3_report / "report.html").text)
    assert "Hazard found" in text
    assert h["robot_link"] in text and "within reach of the worker's" in text
    assert f"v_R = {h['v_R']:.2f} m/s" in text
    # S3's worker reaches through the fence gap without being seen
    assert "No safety device detects the worker before the contact." in text
    for action in h["actions"]:
        assert action in text  # the action table
    assert "agrees bit-exactly" in text
    assert "Judged by contact-while-moving: unsafe when the worker touches the robot" in text


def test_account_of_a_detected_worker(s1_witness_view):
    """S1's witness: the scanner sees the worker, the stop has not taken effect at the contact."""
    from cellstress.report.story import account

    view = s1_witness_view
    hit = view.records[view.key_row]
    acc = account(view)
    det = view.records[view.detection_row]
    assert det.devices and hit.devices
    assert f"At t = {det.t:.2f} s the worker walks into the field of the laser scanner" in " ".join(acc.details)
    assert f"{hit.t - det.t:.2f} s after detection" in acc.headline
    assert hit.stop_phase in ("stop-pending", "braking")
    assert "the stop is not complete" in acc.headline
    assert len([d for d in acc.details if d.startswith("Action ")]) == len(view.actions)


def test_no_hazard_report(safe_report):
    text = " ".join(_parse(safe_report / "report.html").text)
    assert "No hazard found" in text and "riskiest episode" in text
    assert "judged by contact-while-moving" in text and "A search is not a proof" in text
    assert re.search(r"Searched: \d+ episodes of up to 8 actions \(\d+ different action sequences\)", text)
    for name in ("topview.png", "contact.png", "replay.gif", "risk.png"):
        with Image.open(safe_report / name) as img:
            assert float(np.asarray(img.convert("L"), float).std()) > 8.0


def _chromium() -> str | None:
    return next((p for p in (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")) if p), None)


def test_html_renders_in_headless_chromium(s3_report, tmp_path):
    exe = _chromium()
    if exe is None:
        if os.environ.get("CELLSTRESS_REQUIRE_CHROMIUM"):
            pytest.fail("CELLSTRESS_REQUIRE_CHROMIUM is set but no chromium is installed")
        pytest.skip("chromium is not installed (apt-get install chromium; CI installs it)")
    shot = tmp_path / "shot.png"
    out = subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                          f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1200,1800",
                          f"--screenshot={shot}", (s3_report / "report.html").as_uri()],
                         capture_output=True, text=True, timeout=120)
    assert shot.is_file(), out.stderr[-2000:]
    with Image.open(shot) as img:
        grey = np.asarray(img.convert("L"), dtype=float)
    assert grey.shape == (1800, 1200)
    assert grey.std() > 20.0  # text and pictures, not a blank page
    assert (grey < 100).mean() > 0.005  # some dark pixels: text was drawn
