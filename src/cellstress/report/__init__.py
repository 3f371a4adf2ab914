"""Hazard reports people can look at: the cell's top view, the contact from above and the side, the episode
animated, the search's risk curve and a self-contained HTML page; ``cellstress show`` draws a cell; the
campaign's discovery plot and page.

Modules: ``draw`` (figures without pyplot, capsules, the cell plan), ``episode`` (the replayed episode and its
geometry), ``story`` (the plain-language account), ``hazard`` (still pictures), ``animate`` (the GIF), ``html``
(self-contained pages), ``make`` (a search result's report), ``campaign`` (a campaign's report), ``cli`` (the
``report`` and ``show`` commands). Data flows one way: report imports cell/sim/search, never the reverse.
matplotlib is imported only when a picture is made, so that the command line starts fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

__all__ = ["ReportFiles", "ReportOptions", "show_cell", "write_report"]

if TYPE_CHECKING:
    from cellstress.report.make import ReportFiles, ReportOptions, show_cell, write_report


def __getattr__(name: str):
    if name in __all__:
        from cellstress.report import make

        return getattr(make, name)
    raise AttributeError(f"module 'cellstress.report' has no attribute {name!r}")
