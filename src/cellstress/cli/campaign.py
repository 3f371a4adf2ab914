"""``cellstress campaign``: the Table III experiment (cells x searchers x seeds), resumable."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import INTERRUPTED, check_out_dir, fail, say, user_errors


def campaign(
    out: Annotated[str, typer.Option("--out", "-o", help="Folder for campaign.json, runs.jsonl, table.md, "
                                     "table.csv, discovery.png and report.html. Run the same command again to "
                                     "resume.")],
    cells: Annotated[list[str] | None, typer.Option("--cells", help="Cells (built-in names or cell files), "
                                                    "comma-separated or repeated. Default: s1-scanner-width, "
                                                    "s2-elbow-intrusion, s3-fence-gap.")] = None,
    searchers: Annotated[list[str] | None, typer.Option("--searchers", help="Searchers, comma-separated or "
                                                        "repeated, with their default options (see --set). Default: "
                                                        "random, mcts, mcts-commit.")] = None,
    seeds: Annotated[int, typer.Option("--seeds", help="Seeds per cell and searcher: 0 .. N-1.")] = 10,
    budget: Annotated[int, typer.Option("--budget", "-b", help="Episodes per run; a run stops at its first "
                                        "hazard, and a failed run counts as the budget.")] = 200,
    workers: Annotated[int | None, typer.Option("--workers", "-w", help="Worker processes (default: all "
                                                "cores; 1 runs in this process). With Ray: tasks at a "
                                                "time.")] = None,
    backend: Annotated[str, typer.Option("--backend", help="processes (local) or ray.")] = "processes",
    address: Annotated[str | None, typer.Option("--address", help="Ray cluster address (e.g. auto, "
                                                "ray://head:10001); default: a local Ray.")] = None,
    settings: Annotated[list[str] | None, typer.Option("--set", help="A searcher option, NAME=VALUE, "
                                                       "repeated; it applies to every listed searcher that "
                                                       "has it (e.g. --set score=all for evolve).")] = None,
) -> None:
    """Run the Table III experiment (cells x searchers x seeds) in parallel; write runs.jsonl and the table.

    Defaults: the paper's experiment, 3 flawed cells x random, mcts, mcts-commit x 10 seeds, budget 200."""
    import time
    from concurrent.futures.process import BrokenProcessPool
    from pathlib import Path

    from cellstress.campaign import DEFAULT_CELLS, Backend, paper_searchers, resolve, run_campaign
    from cellstress.campaign.plan import split_names
    from cellstress.campaign.table import TABLE_CSV, TABLE_MD, markdown
    from cellstress.searchers import parse_options

    with user_errors():
        how = Backend(backend, workers, address)
        how.check()
        plan = resolve(split_names(cells, DEFAULT_CELLS, "cells"), split_names(searchers, paper_searchers(),
                       "searchers"), seeds, budget, parse_options(settings))
    out_dir: Path = check_out_dir(out)

    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    bar = Progress(TextColumn("[bold]campaign"), BarColumn(), MofNCompleteColumn(), TextColumn("runs"),
                   TimeElapsedColumn(), console=console, transient=True, disable=not console.is_terminal)
    task = bar.add_task("runs", total=len(plan.runs()))
    state = {"done": 0, "before": 0}
    t0 = time.perf_counter()

    def started(total: int, before: int, dropped: bool) -> None:
        state["done"] = state["before"] = before
        bar.update(task, completed=before)
        if dropped:
            say(f"note: {out_dir / 'runs.jsonl'} ended in a truncated line (a run cut short by a crash); "
                       "dropped it, the run is done again", err=True)
        if before:
            say(f"resuming: {before} of {total} runs already in {out_dir / 'runs.jsonl'}", err=True)
        if total > before:
            say(f"running {total - before} runs on {how.describe(total - before)}", err=True)

    def tick(done: int, total: int) -> None:
        state["done"] = done
        bar.update(task, completed=done)

    try:
        with bar, user_errors():
            outcome = run_campaign(plan, out_dir, how, progress=tick, on_start=started)
    except KeyboardInterrupt:
        say(f"interrupted: {state['done']} of {len(plan.runs())} runs are in {out_dir / 'runs.jsonl'}; "
                   "run the same command again to resume", err=True)
        raise typer.Exit(INTERRUPTED) from None
    except BrokenProcessPool as exc:  # a worker was killed (out of memory, a signal): not the user's fault
        say(f"error: a worker process died ({exc}); {state['done']} of {len(plan.runs())} runs are in "
                   f"{out_dir / 'runs.jsonl'}; run the same command again to resume", err=True)
        raise typer.Exit(1) from None
    except OSError as exc:
        raise fail(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
    elapsed = time.perf_counter() - t0
    say(markdown(list(outcome.rows), plan), nl=False)
    say(f"\n{outcome.total} runs ({outcome.ran} run now, {outcome.done_before} already done) in "
               f"{elapsed:.1f} s; wrote {out_dir / TABLE_MD}, {out_dir / TABLE_CSV}, "
               f"{out_dir / 'discovery.png'}, {out_dir / 'report.html'}")
