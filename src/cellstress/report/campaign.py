"""A campaign's report: ``discovery.png`` (the share of runs that have found the hazard against the episodes
spent, one line per searcher, one panel per cell) and a self-contained ``report.html`` with the campaign's
table and that plot.

The input is one record per run, a dict with at least ``cell``, ``searcher``, ``seed``, ``budget``, ``found``
and ``episodes`` (the episodes used up to and including the first hazard; for a run that found nothing, its
budget), so that any campaign runner can call this.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cellstress.core import registry
from cellstress.report import draw as D
from cellstress.report import html as H

REQUIRED = ("cell", "searcher", "seed", "budget", "found", "episodes")
_EXTRA_COLORS = ("#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf")


@dataclass(frozen=True)
class CampaignOptions:
    panel_width: float = 4.2  # inches per cell panel
    height: float = 4.2
    dpi: int = 100
    title: str = "cellstress campaign"


@dataclass(frozen=True)
class CampaignFiles:
    discovery: Path
    html: Path
    curves: dict[str, dict[str, np.ndarray]] = field(repr=False)  # cell -> searcher -> share found per episode


def check_records(records: Iterable[Mapping]) -> list[Mapping]:
    out = list(records)
    if not out:
        raise ValueError("no run records")
    for i, r in enumerate(out):
        missing = [k for k in REQUIRED if k not in r]
        if missing:
            raise ValueError(f"run record {i} lacks {', '.join(missing)}")
    return out


def discovery_curves(records: Iterable[Mapping]) -> dict[str, dict[str, np.ndarray]]:
    """cell -> searcher -> array s where s[e - 1] is the share of runs that found the hazard within e episodes,
    for e = 1 .. the largest budget of that cell. Cells and searchers keep their first-seen order."""
    recs = check_records(records)
    groups: dict[str, dict[str, list[Mapping]]] = {}
    for r in recs:
        groups.setdefault(str(r["cell"]), {}).setdefault(str(r["searcher"]), []).append(r)
    curves: dict[str, dict[str, np.ndarray]] = {}
    for cell, by_searcher in groups.items():
        horizon = max(int(r["budget"]) for rs in by_searcher.values() for r in rs)
        e = np.arange(1, horizon + 1)
        curves[cell] = {}
        for searcher, rs in by_searcher.items():
            found_at = np.array([int(r["episodes"]) if r["found"] else np.iinfo(np.int64).max for r in rs])
            curves[cell][searcher] = (found_at[None, :] <= e[:, None]).mean(axis=1)
    return curves


def searcher_colors() -> dict[str, str]:
    """Each registered searcher's own colour (``Searcher.color``), so the same searcher looks the same in every
    panel and every campaign; a searcher without one gets one of ``_EXTRA_COLORS`` by its place in the plot."""
    return {name: cls.color for name, cls in registry.load_all("searchers").items() if getattr(cls, "color", None)}


def _color(searcher: str, order: list[str]) -> str:
    fixed = searcher_colors()
    if searcher in fixed:
        return fixed[searcher]
    others = [s for s in order if s not in fixed]
    return _EXTRA_COLORS[others.index(searcher) % len(_EXTRA_COLORS)]


def discovery_figure(curves: dict[str, dict[str, np.ndarray]], counts: dict[tuple[str, str], int],
                     options: CampaignOptions = CampaignOptions()):
    cells = list(curves)
    size = D.FigureSize(options.panel_width * len(cells), options.height, options.dpi)
    fig = D.new_figure(size)
    searchers: list[str] = []
    for c in cells:
        searchers += [s for s in curves[c] if s not in searchers]
    n = len(cells)
    left, right, gap = 0.6 / size.width, 0.15 / size.width, 0.45 / size.width
    w = (1.0 - left - right - gap * (n - 1)) / n
    for k, cell in enumerate(cells):
        ax = fig.add_axes((left + k * (w + gap), 0.14, w, 0.78))
        for s in searchers:
            if s not in curves[cell]:
                continue
            y = curves[cell][s]
            x = np.arange(0, len(y) + 1)
            ax.step(x, np.concatenate([[0.0], y]), where="post", color=_color(s, searchers), lw=1.8,
                    label=f"{s} ({counts[(cell, s)]} runs)")
        ax.set_ylim(-0.02, 1.02)
        ax.set_xlim(0, max(len(v) for v in curves[cell].values()))
        ax.set_title(cell, fontsize=10)
        ax.set_xlabel("episodes spent")
        if k == 0:
            ax.set_ylabel("share of runs that found the hazard")
        ax.grid(True, color="#dddddd", lw=0.5)
        ax.legend(fontsize=7, loc="lower right")
    return fig


@D.plain_text
def write_campaign_report(records: Iterable[Mapping], table_text: str, out_dir: str | Path,
                          options: CampaignOptions = CampaignOptions()) -> CampaignFiles:
    """Write ``discovery.png`` and ``report.html`` into ``out_dir``; ``table_text`` is the campaign's table as
    printed (shown verbatim)."""
    recs = check_records(records)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    curves = discovery_curves(recs)
    counts: dict[tuple[str, str], int] = {}
    for r in recs:
        key = (str(r["cell"]), str(r["searcher"]))
        counts[key] = counts.get(key, 0) + 1
    png = D.save_png(discovery_figure(curves, counts, options), out / "discovery.png")
    rows = []
    for cell, by_searcher in curves.items():
        for s in by_searcher:
            rs = [r for r in recs if str(r["cell"]) == cell and str(r["searcher"]) == s]
            found = [r for r in rs if r["found"]]
            mean_found = f"{np.mean([int(r['episodes']) for r in found]):.1f}" if found else "-"
            mean_all = np.mean([int(r["episodes"]) if r["found"] else int(r["budget"]) for r in rs])
            rows.append([cell, s, len(rs), f"{len(found)}/{len(rs)}", mean_found, f"{mean_all:.1f}",
                         ", ".join(str(r["seed"]) for r in rs)])
    body = [f"<h1>{H.escape(options.title)}</h1>",
            "<h2>Table</h2>", f"<pre>{H.escape(table_text.rstrip())}</pre>",
            "<h2>Discovery</h2>",
            H.figure(png, "Share of runs that have found the hazard against the episodes spent, one line per "
                     "searcher, one panel per cell.", "discovery plot"),
            "<h2>Runs</h2>",
            H.table(["cell", "searcher", "runs", "found", "mean episodes (found)", "mean episodes (failed = budget)",
                     "seeds"], rows, numeric={2, 4, 5})]
    html = H.write_page(out / "report.html", H.page(options.title, body, f"Made by cellstress from {len(recs)} runs."))
    return CampaignFiles(png, html, curves)
