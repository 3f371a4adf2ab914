"""The Table III campaign: cells × searchers × seeds, run in parallel, resumable, summarized as a table.

``DIR/campaign.json`` pins the options (``plan``), ``DIR/runs.jsonl`` holds one line per finished run
(``store``), ``DIR/table.md`` and ``DIR/table.csv`` summarize them next to the paper's numbers (``table``,
``paper``). Runs execute in this process, in local worker processes or on Ray (``backends``); a run is a pure
function of its options (``worker``), so all give the same lines.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from cellstress.campaign.backends import BACKENDS, Backend
from cellstress.campaign.plan import (
    DEFAULT_BUDGET,
    DEFAULT_CELLS,
    DEFAULT_SEEDS,
    CampaignError,
    CampaignPlan,
    paper_searchers,
    resolve,
)

if TYPE_CHECKING:  # table imports scipy: only when a table is written
    from cellstress.campaign.table import Row

__all__ = ["BACKENDS", "DEFAULT_BUDGET", "DEFAULT_CELLS", "DEFAULT_SEEDS", "Backend",
           "CampaignError", "CampaignPlan", "Outcome", "paper_searchers", "resolve", "run_campaign"]


@dataclass(frozen=True)
class Outcome:
    """What a call of ``run_campaign`` did: runs in the grid, found already done, run now; the table rows."""

    total: int
    done_before: int
    ran: int
    dropped_partial: bool
    rows: tuple[Row, ...]
    resumed: bool


def run_campaign(plan: CampaignPlan, out: str | Path, backend: Backend | None = None, *,
                 progress: Callable[[int, int], None] | None = None,
                 on_start: Callable[[int, int, bool], None] | None = None) -> Outcome:
    """Run the runs of ``plan`` not yet in ``out/runs.jsonl``; write the tables, ``discovery.png`` and
    ``report.html``.

    ``on_start(total, done_before, dropped_partial)`` is called once the folder has been read;
    ``progress(done, total)`` after every run appended. Raises ``CampaignError`` for a folder that holds
    another campaign (or is in use by one); KeyboardInterrupt leaves every finished run in the file.
    """
    from cellstress.campaign.store import RUNS, FolderLock, RunWriter, open_manifest, read_runs, record_key
    from cellstress.campaign.table import markdown, write_tables
    from cellstress.report.campaign import write_campaign_report

    backend = backend or Backend()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with FolderLock(out):
        resumed = open_manifest(out, plan)
        loaded = read_runs(out / RUNS, plan)
        records = dict(loaded.records)
        todo = [s for s in plan.runs() if s.key not in records]
        total = len(plan.runs())
        if on_start is not None:
            on_start(total, len(records), loaded.dropped_partial)
        wanted = {s.key for s in todo}
        ran = 0
        with RunWriter(out / RUNS) as writer:
            for rec in backend.run(todo):
                key = record_key(rec)
                if key not in wanted:  # a backend bug, not a user error: never write it
                    raise RuntimeError(f"backend returned an unexpected or repeated run {key}")
                wanted.discard(key)
                writer.append(rec)
                records[key] = rec
                ran += 1
                if progress is not None:
                    progress(len(records), total)
        rows = write_tables(out, list(records.values()), plan)
        # the report in the plan's order, not the order runs finished, so it is the same for any backend
        in_order = [records[s.key] for s in plan.runs() if s.key in records]
        write_campaign_report(in_order, markdown(rows, plan), out)
    return Outcome(total, total - len(todo), ran, loaded.dropped_partial, tuple(rows), resumed)
