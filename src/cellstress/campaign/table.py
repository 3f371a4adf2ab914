"""``DIR/table.md`` and ``DIR/table.csv``: Table III from the runs of a campaign, next to the paper's.

Per cell and searcher:

- success rate k/n with a 95 % Wilson score interval (it stays inside [0, 1] and is sensible at k = 0 or n,
  where the normal-approximation interval collapses to a point);
- mean episodes to the first hazard, a failed run counted as the budget (as in the paper), with a 95 %
  Student-t interval for the mean (mean ± t(0.975, n − 1)·s/√n, clipped to [1, budget], the range a run's
  count can take; no interval for n = 1). The t-interval is exact arithmetic that anyone can check by hand;
  with runs censored at the budget it is approximate, which the clip makes visible;
- the median (the mean of the two middle values for even n);
- the mean as a ratio of random's mean in the same cell (the paper's claim is about this ratio);
- Huck et al. 2020, Table III: the published success count, mean, and the same ratio (only when the campaign's
  budget is the paper's, 200: at another budget they are not comparable).
"""

from __future__ import annotations

import csv
import io
import math
import statistics
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cellstress.campaign.paper import PaperRow, paper_table
from cellstress.campaign.plan import CampaignPlan
from cellstress.core.io import atomic_write_text
from cellstress.core.text import for_csv, for_markdown

CONFIDENCE = 0.95
BASELINE = "random"
TABLE_MD = "table.md"
TABLE_CSV = "table.csv"


@dataclass(frozen=True)
class Interval:
    lo: float
    hi: float


@dataclass(frozen=True)
class Row:
    """One line of the table: a cell and searcher over all their runs."""

    cell: str
    searcher: str
    runs: int
    found: int
    success_rate: float
    success_ci: Interval
    mean_episodes: float
    mean_ci: Interval | None  # None for a single run
    median_episodes: float
    ratio_to_random: float | None  # None when the campaign has no random runs in this cell
    paper: PaperRow | None
    paper_ratio_to_random: float | None


def _z(confidence: float) -> float:
    from scipy.stats import norm

    return float(norm.ppf(0.5 + confidence / 2))


def wilson(k: int, n: int, confidence: float = CONFIDENCE) -> Interval:
    """Wilson score interval for k successes in n trials."""
    if n < 1:
        raise ValueError("wilson: n must be >= 1")
    z = _z(confidence)
    p = k / n
    denom = 1 + z * z / n
    center = (p + z * z / (2 * n)) / denom
    half = z / denom * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    # k = 0 and k = n give exactly 0 and 1 in exact arithmetic; clamp the float noise
    return Interval(max(0.0, center - half), min(1.0, center + half))


def t_interval(values: list[float], lo: float, hi: float, confidence: float = CONFIDENCE) -> Interval | None:
    """Student-t interval for the mean of ``values``, clipped to [lo, hi]; None for fewer than two values."""
    n = len(values)
    if n < 2:
        return None
    from scipy.stats import t

    mean = statistics.fmean(values)
    half = float(t.ppf(0.5 + confidence / 2, n - 1)) * statistics.stdev(values) / math.sqrt(n)
    return Interval(max(lo, mean - half), min(hi, mean + half))


def episodes_of(rec: dict[str, Any]) -> int:
    """Episodes to the first hazard; a failed run counts as the whole budget (the paper's rule)."""
    return int(rec["episodes"]) if rec["found"] else int(rec["budget"])


def summarize(records: list[dict[str, Any]], cells: list[str], searchers: list[str], budget: int) -> list[Row]:
    """The table's rows, in the order of ``cells`` then ``searchers`` (pairs without runs are left out)."""
    by: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in records:
        by.setdefault((r["cell"], r["searcher"]), []).append(r)
    paper = paper_table()
    rows = []

    def published(cell: str, searcher: str) -> PaperRow | None:
        # the paper's numbers are for its budget; at another budget they are not comparable
        row = paper.get(cell, searcher)
        return row if row is not None and row.budget == budget else None

    for cell in cells:
        base = by.get((cell, BASELINE))
        base_mean = statistics.fmean(episodes_of(r) for r in base) if base else None
        paper_base = published(cell, BASELINE)
        for s in searchers:
            runs = sorted(by.get((cell, s), []), key=lambda r: r["seed"])
            if not runs:
                continue
            eps = [float(episodes_of(r)) for r in runs]
            k = sum(bool(r["found"]) for r in runs)
            mean = statistics.fmean(eps)
            pr = published(cell, s)
            rows.append(Row(
                cell=cell,
                searcher=s,
                runs=len(runs),
                found=k,
                success_rate=k / len(runs),
                success_ci=wilson(k, len(runs)),
                mean_episodes=mean,
                mean_ci=t_interval(eps, 1.0, float(budget)),
                median_episodes=float(statistics.median(eps)),
                ratio_to_random=mean / base_mean if base_mean else None,
                paper=pr,
                paper_ratio_to_random=(pr.mean_episodes / paper_base.mean_episodes
                                       if pr is not None and paper_base is not None else None),
            ))
    return rows


def _f(x: float | None, digits: int) -> str:
    return "–" if x is None else f"{x:.{digits}f}"


def _criteria(plan: CampaignPlan) -> list[str]:
    """A line per criterion: which cells it judged and what it calls unsafe (each cell's own criterion)."""
    by: dict[str, list[str]] = {}
    for c in plan.cells:
        if c.criterion:
            by.setdefault(c.criterion, []).append(c.name)
    return [f"Criterion of {', '.join(for_markdown(n) for n in names)}: {for_markdown(text)}.\n"
            for text, names in by.items()]


def markdown(rows: list[Row], plan: CampaignPlan) -> str:
    seeds = f"seeds 0–{plan.seeds - 1}" if plan.seeds > 1 else "seed 0"
    lines = [
        "# Table III: episodes to the first hazard",
        "",
        f"{len(plan.cells)} cell(s) × {len(plan.searchers)} searcher(s) × {seeds}, budget {plan.budget} episodes, "
        f"each run stopped at its first hazard; a failed run counts as {plan.budget} episodes (as in the paper). "
        "Success rate: 95 % Wilson interval. Mean: 95 % Student-t interval, clipped to "
        f"[1, {plan.budget}]. Ratio: the mean over random's mean in the same cell. "
        f"Paper (at its budget, {paper_table().budget}, only): {paper_table().citation}",
        "",
        *_criteria(plan),
        "| cell | searcher | found | success rate (95 % CI) | mean episodes (95 % CI) | median | mean / random "
        "| paper found | paper mean | paper mean / random |",
        "|---|---|---:|---|---|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        ci = "" if r.mean_ci is None else f" ({r.mean_ci.lo:.1f}–{r.mean_ci.hi:.1f})"
        p = r.paper
        lines.append(
            f"| {for_markdown(r.cell)} | {for_markdown(r.searcher)} | {r.found}/{r.runs} | {r.success_rate:.2f} "
            f"({r.success_ci.lo:.2f}–{r.success_ci.hi:.2f}) | {r.mean_episodes:.1f}{ci} | "
            f"{r.median_episodes:.1f} | {_f(r.ratio_to_random, 2)} | "
            f"{'–' if p is None else f'{p.found}/{p.runs}'} | {_f(None if p is None else p.mean_episodes, 1)} | "
            f"{_f(r.paper_ratio_to_random, 2)} |")
    return "\n".join(lines) + "\n"


CSV_COLUMNS = ("cell", "searcher", "runs", "found", "success_rate", "success_ci_lo", "success_ci_hi",
               "mean_episodes", "mean_ci_lo", "mean_ci_hi", "median_episodes", "ratio_to_random",
               "paper_runs", "paper_found", "paper_mean_episodes", "paper_ratio_to_random")


def _c(x: float | None) -> str:
    # six decimals: enough for any reader, and free of float noise (0.30000000000000004)
    return "" if x is None else f"{round(x, 6):g}" if abs(x) < 1e6 else repr(x)


def csv_text(rows: list[Row]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for r in rows:
        p = r.paper
        w.writerow([for_csv(r.cell), for_csv(r.searcher), r.runs, r.found, _c(r.success_rate), _c(r.success_ci.lo),
                    _c(r.success_ci.hi), _c(r.mean_episodes), _c(r.mean_ci and r.mean_ci.lo),
                    _c(r.mean_ci and r.mean_ci.hi), _c(r.median_episodes), _c(r.ratio_to_random),
                    "" if p is None else p.runs, "" if p is None else p.found,
                    _c(None if p is None else p.mean_episodes), _c(r.paper_ratio_to_random)])
    return buf.getvalue()


def write_tables(out: Path, records: list[dict[str, Any]], plan: CampaignPlan) -> list[Row]:
    """Write ``table.md`` and ``table.csv`` (atomically) from the records; returns the rows."""
    rows = summarize(records, [c.name for c in plan.cells], [s.name for s in plan.searchers], plan.budget)
    atomic_write_text(out / TABLE_MD, markdown(rows, plan))
    atomic_write_text(out / TABLE_CSV, csv_text(rows))
    return rows
