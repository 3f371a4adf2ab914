"""``cellstress verify``: decide every sequence of worker actions, at every arrival phase and start point."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    INTERRUPTED,
    JUNIT_HELP,
    check_criterion,
    check_junit_path,
    check_out_dir,
    criterion_help,
    say,
    user_errors,
    write_junit_file,
)


def verify(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    out: Annotated[str, typer.Option("--out", "-o", help="Folder for verify.json, verify.png, verify.html and "
                                     "one witness per hazard class (witness-NN/result.json).")],
    horizon: Annotated[int | None, typer.Option("--horizon", help="Actions per episode (default: the cell's "
                                                "simulation.actions_per_episode; at most 12).")] = None,
    phases: Annotated[str, typer.Option("--phases", help="all: every arrival phase of the robot's cycle on the "
                                        "time-step grid; cell: only the phases the cell's "
                                        "human.arrival allows; A:B: the grid phases from A to B seconds of the "
                                        "cycle (e.g. 1.0:2.5).")] = "all",
    starts: Annotated[str | None, typer.Option("--starts", help="Start points to decide, by name, comma-separated "
                                               "(default: every one; the single human.start is named 'start')."
                                               )] = None,
    moments: Annotated[str, typer.Option("--moments", help="all: each grid phase also stands for every arrival "
                                         "moment within half a time step of it, where the cell allows the argument "
                                         "(docs/verify.md); grid: the grid moments alone (faster).")] = "all",
    time_limit: Annotated[float | None, typer.Option("--time-limit", help="Seconds; what is not decided by "
                                                     "then is reported as undecided (exit code 3).")] = None,
    workers: Annotated[int | None, typer.Option("--workers", help="Processes deciding sub-trees in parallel "
                                                "(default: all usable cores; at most 4 per core); with --backend "
                                                "ray, Ray tasks at a time (default: the cluster's CPUs).")] = None,
    backend: Annotated[str, typer.Option("--backend", help="processes: on this machine; ray: as Ray tasks, on "
                                         "the cluster at --address or a local Ray (pip install 'cellstress[ray]'); "
                                         "the same verify.json either way.")] = "processes",
    address: Annotated[str | None, typer.Option("--address", help="A Ray cluster's address (--backend ray; "
                                                "default: start a local one).")] = None,
    criterion: Annotated[str | None, typer.Option("--criterion", help=criterion_help("the cell file's"))] = None,
    junit: Annotated[str | None, typer.Option("--junit", help=JUNIT_HELP + " A test case for the verdict and a "
                                              "failing one per hazard class.")] = None,
) -> None:
    """Decide exactly whether any sequence of the worker's actions reaches the unsafe set: every sequence, from
    every start point, at every arrival phase of the robot's cycle (a proof within the model, not a search).

    Exit code 0 PROVED-SAFE, 1 UNSAFE (one witness per hazard class, replayable), 2 a bad input, 3 UNDECIDED
    (the time limit left sequences undecided)."""
    import time

    from rich.console import Console
    from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from cellstress.analysis.check_rows import static_failures
    from cellstress.analysis.iso13855 import check_cell
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.core.cpus import usable_cpus
    from cellstress.report.junit import verify_suite
    from cellstress.report.scope import judged_by
    from cellstress.report.verify import HTML_NAME, PNG_NAME, hazard_map, summary_lines, verify_page, witness_view
    from cellstress.sim.simulator import Simulator
    from cellstress.verifier.checkpoint import CHECKPOINT
    from cellstress.verifier.run import check_backend, verify_cell

    with user_errors():
        check_criterion(criterion)
        check_backend(backend, address, workers)
    out_dir = check_out_dir(out)
    junit_path = check_junit_path(junit)
    console = Console(stderr=True)
    bar = Progress(SpinnerColumn(), TextColumn("[bold]deciding"), BarColumn(),
                   TextColumn("{task.percentage:>5.1f} % of {task.fields[of]} sequences"), TimeElapsedColumn(),
                   TextColumn("left"), TimeRemainingColumn(),
                   console=console, transient=True, disable=not console.is_terminal)
    task = bar.add_task("verify", total=1, of="?")

    def tick(done: int, total: int) -> None:
        bar.update(task, completed=done, total=total, of=f"{total:.3g}")

    def resumed(n: int, of: int) -> None:
        say(f"resumed   {n} of {of} sub-trees decided before, from {out_dir / CHECKPOINT}", err=True)

    t0 = time.perf_counter()
    try:
        with bar, user_errors():
            sim = Simulator(with_criterion(load_cell(cell), criterion))
            res = verify_cell(sim, horizon=horizon, phases=phases, moments=moments, time_limit=time_limit,
                              starts=None if starts is None else tuple(n.strip() for n in starts.split(",")),
                              workers=usable_cpus() if workers is None and backend != "ray" else workers,
                              backend=backend, address=address, out=out_dir,
                              progress=tick, static_failures=static_failures(check_cell(sim.cell)),
                              resumed=resumed)
    except KeyboardInterrupt:
        say(f"interrupted: the sub-trees decided so far are kept in {out_dir / CHECKPOINT}; run the same command "
            "again to go on from there", err=True)
        raise typer.Exit(INTERRUPTED) from None
    elapsed = time.perf_counter() - t0
    write_junit_file(junit_path, [verify_suite(res)])
    png = hazard_map(res, out_dir / PNG_NAME)
    page = verify_page(res, png, out_dir / HTML_NAME, judged_by(sim.criterion), witness_view(res, sim))
    for line in summary_lines(res, judged_by(sim.criterion), str(out_dir)):
        say(line)
    say(f"wrote     {out_dir / 'verify.json'}, {png.name}, {page.name} ({elapsed:.1f} s)")
    raise typer.Exit(res.exit_code)
