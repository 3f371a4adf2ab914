"""``cellstress fix CELL --out DIR``: proposals that make a cell pass check and its re-test, ranked by cost."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    JUNIT_HELP,
    check_criterion,
    check_junit_path,
    check_out_dir,
    criterion_help,
    fail,
    say,
    spinner_while_compiling,
    user_errors,
    write_junit_file,
)


def fix(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    out: Annotated[str, typer.Option("--out", "-o", help="Folder for fix.json, fix.html, every candidate "
                                     "(candidate-N.yaml) and each kept proposal, cheapest first "
                                     "(proposal-N.yaml).")],
    budget: Annotated[int, typer.Option("--budget", "-b", help="Episodes of the search (plan) that re-tests a "
                                        "candidate where verify does not decide.")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Seed (>= 0) of that search.")] = 0,
    time_limit: Annotated[float, typer.Option("--time-limit", help="Seconds verify may take on one candidate "
                                              "before the search re-tests it instead.")] = 30.0,
    criterion: Annotated[str | None, typer.Option("--criterion", help=criterion_help("the cell file's") + " With "
                                                  "iso15066, also each move's largest safe speed (docs/fix.md).")]
        = None,
    junit: Annotated[str | None, typer.Option("--junit", help=JUNIT_HELP + " One test case per candidate and one "
                                              "for the verdict.")] = None,
) -> None:
    """Propose changes that make the cell pass 'check' and its re-test: devices moved to the ISO 13855
    distance, the device settings a failing row names, or a slower program; each written as a cell file,
    re-checked and re-tested ('verify' at the cell's horizon where it decides within --time-limit, else the
    search), with its cost (cycle time, floor area, parts added), ranked cheapest first (docs/fix.md).

    Exit code 0 if the cell needs nothing or a proposal works, 1 if none works, 2 for a bad input."""
    import math
    from pathlib import Path

    from rich.console import Console

    from cellstress.analysis.fix import fix_cell
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.core.io import atomic_write_text
    from cellstress.report.fix import fix_json, fix_page, fix_suite, print_fix
    from cellstress.searchers.common import check_common

    with user_errors():
        check_common(budget, seed, "budget", 10)
        check_criterion(criterion)
    if not (math.isfinite(time_limit) and 0 < time_limit <= 3600):
        raise fail(f"--time-limit {time_limit:g}: give seconds between 0 and 3600")
    junit_path = check_junit_path(junit)
    with user_errors():
        loaded = with_criterion(load_cell(cell), criterion)
    out_dir = check_out_dir(out)
    with spinner_while_compiling(), user_errors():
        res = fix_cell(loaded, out_dir, budget, seed, time_limit, safe_speeds=loaded.spec.criterion.type == "iso15066")
    print_fix(res, Console(highlight=False, soft_wrap=False))
    try:
        for old in sorted(Path(out_dir).glob("proposal-*.yaml")):
            if old.name.removeprefix("proposal-").removesuffix(".yaml").isdigit():
                old.unlink()  # a previous run's proposals would read as this run's
        for i, p in enumerate(res.kept):
            atomic_write_text(out_dir / f"proposal-{i + 1}.yaml", p.text)
        atomic_write_text(out_dir / "fix.json", fix_json(res))
        atomic_write_text(out_dir / "fix.html", fix_page(res))
    except OSError as exc:
        raise fail(f"--out {out}: cannot write ({exc.strerror or exc})") from None
    write_junit_file(junit_path, [fix_suite(res)])
    say(f"wrote     {out_dir / 'fix.json'}, fix.html, {len(res.candidates)} candidates, {len(res.kept)} proposals")
    raise typer.Exit(res.exit_code)
