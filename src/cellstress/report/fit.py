"""Fit a plan picture (``show``'s layout, the report's top view) to what it shows: the plan sized to the cell's
aspect, the legend (its long labels wrapped) and the enlarged inset in a column beside it, the figure exactly
as wide as that. No text runs off the figure, the inset never covers the legend, and there are no wide empty
margins. Everything is measured with the figure's own renderer, so the result is the same on every run.
"""

from __future__ import annotations

import textwrap

from matplotlib.figure import Figure

MARGIN = 0.12  # in, around everything
GAP = 0.25  # in, between the plan and the legend column, and between the legend and the inset
LEGEND_WRAP = 46  # characters per legend line
MAX_PLAN_WIDTH = 8.5  # in: a very wide cell is drawn lower instead
INSET_SIDE = (2.6, 3.6)  # in: the enlarged view's smallest and largest side


def wrap_labels(handles, width: int = LEGEND_WRAP) -> None:
    for h in handles:
        parts = str(h.get_label()).split("\n")
        h.set_label("\n".join(textwrap.fill(p, width, break_long_words=True) for p in parts))


def _pads(fig: Figure, ax) -> tuple[float, float, float, float]:
    """How far an axes' decorations (title, tick labels, axis labels, annotations) reach beyond its box, in
    inches: left, bottom, right, top."""
    r = fig.canvas.get_renderer()
    ax.apply_aspect()
    box, tight = ax.get_window_extent(r), ax.get_tightbbox(r)
    dpi = fig.dpi
    return (max(0.0, box.x0 - tight.x0) / dpi, max(0.0, box.y0 - tight.y0) / dpi,
            max(0.0, tight.x1 - box.x1) / dpi, max(0.0, tight.y1 - box.y1) / dpi)


def fit_plan(fig: Figure, ax, handles, height: float, inset=None, fontsize: float = 8):
    """Size ``fig`` and place ``ax`` (equal aspect, limits set), its legend and ``inset`` (or none); returns the
    legend. ``height`` [in] is the figure's height unless the legend and the inset need more."""
    wrap_labels(handles)
    legend = fig.legend(handles=handles, loc="upper left", fontsize=fontsize, frameon=False, borderaxespad=0.0)
    r = fig.canvas.get_renderer()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    aspect = abs(x1 - x0) / max(abs(y1 - y0), 1e-9)
    for _ in range(3):  # measure, place, measure again (annotations reach further once the plan is larger)
        pl, pb, pr, pt = _pads(fig, ax)
        ext = legend.get_window_extent(r)
        lw, lh = ext.width / fig.dpi, ext.height / fig.dpi
        ax_h = height - 2 * MARGIN - pb - pt
        ax_w = ax_h * aspect
        if ax_w > MAX_PLAN_WIDTH:
            ax_w, ax_h = MAX_PLAN_WIDTH, MAX_PLAN_WIDTH / aspect
        col_w, col_h = lw, lh
        side = ipl = ipb = 0.0
        if inset is not None:
            ipl, ipb, ipr, ipt = _pads(fig, inset)
            room = max(height, ax_h + pb + pt + 2 * MARGIN) - 2 * MARGIN - lh - GAP - ipb - ipt
            side = min(max(room, INSET_SIDE[0]), INSET_SIDE[1])
            col_w = max(lw, ipl + side + ipr)
            col_h = lh + GAP + ipt + side + ipb
        H = max(ax_h + pb + pt, col_h) + 2 * MARGIN
        W = MARGIN + pl + ax_w + pr + GAP + col_w + MARGIN
        fig.set_size_inches(W, H)
        top = H - MARGIN - pt
        ax.set_position(((MARGIN + pl) / W, (top - ax_h) / H, ax_w / W, ax_h / H))
        col_x = MARGIN + pl + ax_w + pr + GAP
        legend.set_bbox_to_anchor((col_x / W, (H - MARGIN) / H), transform=fig.transFigure)
        if inset is not None:
            inset.set_position(((col_x + ipl) / W, (MARGIN + ipb) / H, side / W, side / H))
    return legend
