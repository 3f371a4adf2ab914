"""Plan pictures fit what they show (report/fit.py): a cell with many legend entries (four devices with long
names, a warning field, obstacles, named start points, dimension lines) gives a figure in which no text is cut
off, the legend covers neither the plan nor the enlarged inset, and no wide white margin is left."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
import yaml
from PIL import Image

from cellstress.analysis.iso13855 import check_cell
from cellstress.cell.load import load_cell
from cellstress.report import draw as D
from cellstress.report.hazard import StillOptions, layout_figure, topview_figure
from cellstress.sim.build import build_layout

MAX_MARGIN_IN = 0.3  # white border allowed on any side [in]


@pytest.fixture(scope="module")
def busy_cell(tmp_path_factory):
    builtin = resources.files("cellstress.cell.builtin")
    doc = yaml.safe_load(builtin.joinpath("warning-field-short.yaml").read_text(encoding="utf-8"))
    flaws = yaml.safe_load(builtin.joinpath("all-flaws.yaml").read_text(encoding="utf-8"))
    doc["name"] = "busy-cell-with-many-legend-entries"
    doc["devices"][0]["name"] = "front-scanner-protective-and-warning-fields"
    doc["devices"].append(dict(flaws["devices"][1], name="maintenance-bay-light-curtain-beside-the-conveyor"))
    doc["devices"].append({"type": "safety-mat", "name": "left-aisle-pressure-sensitive-safety-mat",
                           "polygon": [[-2.4, -1.0], [-1.6, -1.0], [-1.6, 1.0], [-2.4, 1.0]], "response_time": 0.1})
    doc["obstacles"] = [{"name": "parts-rack", "box": {"center": [2.0, 2.5], "size": [0.6, 0.8]}, "height": 1.6},
                        {"name": "conveyor", "polygon": [[-2.4, 3.0], [-1.7, 3.0], [-1.7, 4.0], [-2.4, 4.0]],
                         "height": 0.9}]
    doc["human"]["starts"] = [{"name": "upper-end", "xy": [0.7, 3.75], "heading_deg": -90.0},
                              {"name": "lower-end", "xy": [0.0, -2.5], "heading_deg": 90.0}]
    path = tmp_path_factory.mktemp("busy") / "busy.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return build_layout(load_cell(str(path)))


def _inside(box, w: float, h: float) -> bool:
    return box.x0 >= -0.5 and box.y0 >= -0.5 and box.x1 <= w + 0.5 and box.y1 <= h + 0.5


def _no_text_cut(fig) -> None:
    """Everything drawn (each axes with its title, tick labels, axis labels and annotations; each legend; the
    figure's own texts) lies inside the figure."""
    r = fig.canvas.get_renderer()
    fig.canvas.draw()
    w, h = fig.bbox.width, fig.bbox.height
    for ax in fig.axes:
        box = ax.get_tightbbox(r)
        assert _inside(box, w, h), (ax.get_title(), box, (w, h))
        assert sum(bool(t.get_text()) for t in ax.texts) >= 1
    for legend in fig.legends:
        assert _inside(legend.get_window_extent(r), w, h), (legend.get_window_extent(r), (w, h))
    for t in fig.texts:
        assert _inside(t.get_window_extent(r), w, h), t.get_text()


def _margins(fig, tmp_path) -> None:
    path = D.save_png(fig, tmp_path / "fig.png")
    with Image.open(path) as img:
        grey = np.asarray(img.convert("L"))
    ink = np.argwhere(grey < 250)
    (top, left), (bottom, right) = ink.min(axis=0), ink.max(axis=0)
    limit = MAX_MARGIN_IN * fig.dpi
    assert left <= limit and top <= limit
    assert grey.shape[1] - 1 - right <= limit and grey.shape[0] - 1 - bottom <= limit


def test_layout_picture_fits_many_legend_entries(busy_cell, tmp_path) -> None:
    fig, ax = layout_figure(busy_cell, StillOptions().layout, static=check_cell(busy_cell.cell, busy_cell))
    legend = fig.legends[0]
    labels = [t.get_text() for t in legend.get_texts()]
    assert len(labels) >= 12
    assert any("left-aisle-pressure-sensitive-safety-mat" in lb.replace("\n", "") for lb in labels)
    _no_text_cut(fig)
    r = fig.canvas.get_renderer()
    assert not legend.get_window_extent(r).overlaps(ax.get_window_extent(r))
    _margins(fig, tmp_path)


def test_topview_inset_never_covers_the_legend(s1_witness_view, tmp_path) -> None:
    fig, ax = topview_figure(s1_witness_view)
    r = fig.canvas.get_renderer()
    fig.canvas.draw()
    legend = fig.legends[0].get_window_extent(r)
    inset = next(a for a in fig.axes if a is not ax)
    assert not legend.overlaps(inset.get_tightbbox(r))
    assert not legend.overlaps(ax.get_window_extent(r))
    assert not inset.get_window_extent(r).overlaps(ax.get_window_extent(r))
    _no_text_cut(fig)
    _margins(fig, tmp_path)
