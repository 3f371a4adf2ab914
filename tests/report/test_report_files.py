"""The files of a hazard report: every image decodes, has its size and is not blank; the animation has one frame
per simulation step; the same result gives the same bytes; the top view puts the contact marker on the contact."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image, ImageSequence

from cellstress.report import draw as D
from cellstress.report.animate import AnimationOptions
from cellstress.report.hazard import StillOptions
from cellstress.report.make import NAMES
from cellstress.report.program import ProgramPicture

MIN_STD = 8.0  # grey-level standard deviation: a blank or single-colour image is far below this

SIZES = {"topview.png": StillOptions().topview.pixels, "contact.png": StillOptions().contact.pixels,
         "risk.png": StillOptions().risk.pixels, "replay.gif": AnimationOptions().size.pixels,
         "program.png": ProgramPicture().size.pixels}


def _not_blank(img: Image.Image) -> float:
    return float(np.asarray(img.convert("L"), dtype=float).std())


@pytest.mark.parametrize("name", sorted(SIZES))
def test_images_decode_with_size_and_content(s3_report, name):
    with Image.open(s3_report / name) as img:
        img.load()
        assert img.size == SIZES[name]
        assert _not_blank(img) > MIN_STD


def test_pngs_carry_no_version_or_date(s3_report):
    for name in ("topview.png", "contact.png", "risk.png", "program.png"):
        with Image.open(s3_report / name) as img:
            assert not any("matplotlib" in str(v).lower() for v in img.info.values()), img.info


def test_animation_has_one_frame_per_step(s3_report):
    trace = json.loads((s3_report / "result.json").read_text())["hazard"]["trace"]
    with Image.open(s3_report / "replay.gif") as gif:
        frames = [f.copy().convert("RGB") for f in ImageSequence.Iterator(gif)]
    assert len(frames) == len(trace)
    assert all(_not_blank(f) > MIN_STD for f in frames)
    # the frames differ: something moves
    assert np.abs(np.asarray(frames[0], float) - np.asarray(frames[-1], float)).mean() > 0.5


def test_same_result_gives_same_bytes(s3_report, s3_sim, tmp_path):
    from cellstress.report import write_report

    write_report(s3_report / "result.json", tmp_path, sim=s3_sim)
    for name in NAMES:
        assert (tmp_path / name).read_bytes() == (s3_report / name).read_bytes(), name


def test_contact_marker_is_at_the_contact(s3_report, s3_sim):
    """Find the contact marker's colour in topview.png and compare with the contact point mapped through the
    plot's own data-to-pixel transform."""
    from cellstress.report.episode import episode_of
    from cellstress.report.hazard import topview_figure
    from cellstress.searchers.result import SearchResult

    res = SearchResult.load(s3_report / "result.json")
    view = episode_of(res, s3_sim)
    assert view.unsafe and view.matches_file
    fig, ax = topview_figure(view)
    fig.canvas.draw()
    cx, cy, _ = res.hazard.point
    px, py = ax.transData.transform((cx, cy))
    height = fig.canvas.get_width_height()[1]
    expected = np.array([px, height - py])  # image rows run downwards
    rgb = np.asarray(Image.open(s3_report / "topview.png").convert("RGB"), dtype=int)
    # only inside the axes: the legend shows the same marker
    x0, y0, x1, y1 = ax.bbox.x0, height - ax.bbox.y1, ax.bbox.x1, height - ax.bbox.y0
    target = np.array([int(D.CONTACT[i:i + 2], 16) for i in (1, 3, 5)])
    near = np.abs(rgb - target).sum(axis=2) < 60
    rows, cols = np.nonzero(near)
    inside = (cols >= x0) & (cols <= x1) & (rows >= y0) & (rows <= y1)
    assert inside.sum() > 20
    centre = np.array([cols[inside].mean(), rows[inside].mean()])
    assert np.linalg.norm(centre - expected) < 3.0, (centre, expected)


def test_contact_point_lies_on_the_drawn_robot_link(s3_report, s3_sim):
    """The robot drawn at the contact step (from sim.scene) carries the contact point on its named link."""
    from cellstress.report.episode import episode_of
    from cellstress.searchers.result import SearchResult

    res = SearchResult.load(s3_report / "result.json")
    view = episode_of(res, s3_sim)
    a, b = view.robot(view.key_row)
    names = [c.name for c in view.layout.capsules]
    c = names.index(res.hazard.robot_link)
    p = np.asarray(res.hazard.point)
    t = np.clip(np.dot(p - a[c], b[c] - a[c]) / np.dot(b[c] - a[c], b[c] - a[c]), 0.0, 1.0)
    assert abs(np.linalg.norm(p - (a[c] + t * (b[c] - a[c]))) - view.capsule_radii[c]) < 1e-6
