"""The 3D view in real headless Chromium with the network off: report.html and ``show --3d`` load with no request
to a server, no failed load and no console error, draw a 3D scene that is not blank, and moving the slider to
the hazard's step shows the contact marker (the page's own state and the pixels agree)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from chromium_page import Page, need_chromium

SETTLED = ("document.getElementById('cs3d').csPending.then(() => new Promise(r => "
           "requestAnimationFrame(() => requestAnimationFrame(() => r(true)))))")


def slide_to(page: Page, step: int) -> None:
    """Move the slider as a person would (set its value, fire its input event) and wait until it is drawn."""
    page.js(f"(() => {{ const s = document.getElementById('cs3d-step'); s.value = '{step}'; "
            "s.dispatchEvent(new Event('input')); return true; })()")
    page.js(SETTLED)


def state(page: Page, name: str) -> str:
    return page.js(f"document.getElementById('cs3d').getAttribute('data-{name}')")


def plot_shot(page: Page) -> np.ndarray:
    page.js("document.getElementById('cs3d-plot').scrollIntoView(); true")
    page.js(SETTLED)
    r = page.js("(() => { const b = document.getElementById('cs3d-plot').getBoundingClientRect(); "
                "return [b.left + window.scrollX, b.top + window.scrollY, b.width, b.height]; })()")
    return page.screenshot({"x": r[0], "y": r[1], "width": r[2], "height": r[3]})


def magenta(img: np.ndarray) -> int:
    """Pixels of the contact marker's hue (#ff00ff, used by nothing else in the view), also where a translucent
    fence or reach volume in front of it tints it."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return int(((r > 150) & (b > 130) & (g < 110) & (np.abs(r - b) < 90)).sum())


def not_blank(img: np.ndarray, saturated: float = 0.01) -> None:
    grey = img.mean(axis=2)
    assert grey.std() > 12.0
    colours = np.unique((img // 16).reshape(-1, 3), axis=0)
    assert len(colours) > 40  # shaded solids, not a flat background
    assert ((img.max(axis=2) - img.min(axis=2)) > 60).mean() > saturated  # colour: robot, worker, fields


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    exe = need_chromium()
    p = Page(exe, tmp_path_factory.mktemp("profile"))
    yield p
    p.close()


@pytest.fixture
def page(browser):
    """The module's browser, its records of requests and failures cleared for this test."""
    browser.failures.clear()
    browser.requests.clear()
    return browser


def test_report_3d_view_offline(s3_report, page):
    page.open(s3_report / "report.html")
    page.wait_for("document.getElementById('cs3d') && document.getElementById('cs3d').dataset.ready === '1'")
    hazard = json.loads((s3_report / "result.json").read_text())["hazard"]
    key = len(hazard["trace"]) - 1  # the unsafe row ends the trace
    assert state(page, "step") == "0" and state(page, "marker") == ""
    first = plot_shot(page)
    not_blank(first)
    base = magenta(first)
    slide_to(page, key)
    assert state(page, "step") == str(key) and state(page, "marker") == "contact"
    info = page.js("document.getElementById('cs3d-info').textContent")
    assert f"CONTACT: {hazard['robot_link']} / {hazard['body_part']}" in info
    assert f"v_R = {hazard['v_R']:.2f} m/s" in info
    hit = plot_shot(page)
    not_blank(hit)
    assert magenta(hit) > base + 20  # the contact marker is drawn
    assert np.abs(hit - first).max(axis=2).__gt__(40).mean() > 0.002  # the robot and the worker moved
    slide_to(page, 0)
    assert state(page, "marker") == ""
    # the view buttons turn the camera (a top view differs from the 3D view)
    page.js("document.querySelector('button[data-view=top]').click(); true")
    page.js(SETTLED)
    top = plot_shot(page)
    assert np.abs(top - first).max(axis=2).__gt__(40).mean() > 0.05
    assert page.failures == [], page.failures
    assert all(u.startswith(("file:", "data:", "blob:", "about:")) for u in page.requests), page.requests


def test_show_3d_offline(tmp_path, page):
    from cellstress.cli import main

    out = tmp_path / "s3.html"
    assert main(["show", "s3-fence-gap", "--3d", "--out", str(out)]) == 0
    page.open(out)
    page.wait_for("document.getElementById('cs3d') && document.getElementById('cs3d').dataset.ready === '1'")
    n = int(page.js("document.getElementById('cs3d-step').max"))
    assert n > 20  # one cycle of the program
    first = plot_shot(page)
    not_blank(first, saturated=0.0003)  # (no worker: grey robot and fences, the table's beige)
    slide_to(page, n // 2)
    assert state(page, "step") == str(n // 2) and state(page, "marker") == ""
    later = plot_shot(page)
    assert np.abs(later - first).max(axis=2).__gt__(40).mean() > 0.001  # the robot moved along its program
    assert page.failures == [], page.failures


def test_devices_turn_active_when_they_see_the_worker(s1_witness_view, tmp_path, page):
    """S1's witness: the scanner sees the worker from some step on; its field is marked active from exactly
    that step (the page's state and the legend)."""
    from cellstress.report.scene3d import view_of_episodes
    from cellstress.report.view3d import view_page

    view = s1_witness_view
    det = view.detection_row
    name = view.records[det].devices[0]
    out = view_page(tmp_path / "s1.html", "s1", [], view_of_episodes(view.layout, [(view, "witness")]), "test")
    page.open(out)
    page.wait_for("document.getElementById('cs3d') && document.getElementById('cs3d').dataset.ready === '1'")
    slide_to(page, det - 1)
    assert name not in state(page, "active").split(",")
    slide_to(page, det)
    assert name in state(page, "active").split(",")
    assert page.js("document.querySelectorAll('#cs3d-legend li.active').length") >= 1
    assert page.failures == [], page.failures
