"""``cellstress diff OLD NEW``: what changed between two cells, and whether NEW passes the gate."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    JUNIT_HELP,
    check_junit_path,
    fail,
    spinner_while_compiling,
    user_errors,
    write_junit_file,
)


def diff(
    old: Annotated[str, typer.Argument(help="The cell before the change. " + CELL_HELP)],
    new: Annotated[str, typer.Argument(help="The cell after the change. " + CELL_HELP)],
    searcher: Annotated[str, typer.Option("--searcher", "-s", help="The searcher run on both cells (as 'search').")]
        = "mcts",
    budget: Annotated[int, typer.Option("--budget", "-b", help="Episodes of the search on each cell.")] = 200,
    seed: Annotated[int, typer.Option("--seed", help="Seed (>= 0) of the search on each cell.")] = 0,
    json_file: Annotated[str | None, typer.Option("--json", help="Also write the diff as JSON to this file.")]
        = None,
    junit: Annotated[str | None, typer.Option("--junit", help=JUNIT_HELP + " One test case per check row of NEW "
                                              "and per hazard class.")] = None,
) -> None:
    """Compare two cells: the fields that changed (geometry, devices, program, stopping, ...), the check rows
    that changed verdict or value, and the hazard classes that are new or gone (the same search, '--until budget
    --distinct', on both).

    Exit code 0 if NEW passes the gate, 1 if NEW fails a check row or has a hazard class OLD did not have, 2 for
    a file that is not a valid cell."""
    from pathlib import Path

    from rich.console import Console

    from cellstress.analysis.cell_diff import diff_cells
    from cellstress.cell.load import load_cell
    from cellstress.core.io import atomic_write_text
    from cellstress.report.diff import diff_json, diff_suite, print_diff
    from cellstress.searchers import make_searcher
    from cellstress.searchers.common import check_common

    with user_errors():
        check_common(budget, seed, "budget", 10)
        make_searcher(searcher)
    junit_path = check_junit_path(junit)
    json_path = check_junit_path(json_file, "--json")
    with spinner_while_compiling(), user_errors():
        a, b = load_cell(old), load_cell(new)
        d = diff_cells(a, b, searcher, budget, seed)
    print_diff(d, Console(highlight=False, soft_wrap=False))
    if json_path is not None:
        try:
            atomic_write_text(Path(json_path), diff_json(d))
        except OSError as exc:
            raise fail(f"--json {json_path}: cannot write ({exc.strerror or exc})") from None
    write_junit_file(junit_path, [diff_suite(d)])
    if not d.passes:
        raise typer.Exit(1)
