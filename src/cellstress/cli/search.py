"""``cellstress search``: run one searcher on a cell, write result.json and its report."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    COMPILING,
    INTERRUPTED,
    JUNIT_HELP,
    check_criterion,
    check_junit_path,
    check_out_dir,
    criterion_help,
    fail,
    num,
    say,
    user_errors,
    write_junit_file,
)
from cellstress.core.errors import CellstressError


def _searcher_help() -> str:
    from cellstress.core import registry

    return (f"One of {', '.join(registry.names('searchers'))} (mcts is the paper's MCTS1, mcts-commit its MCTS2; "
            "evolve and plan are ours; see docs/results.md).")


def _params_text(params: dict) -> str:
    return ", ".join(f"{k} {'auto' if v is None else num(v) if isinstance(v, float) else v}"
                     for k, v in params.items() if v != "")  # (an empty text option is one not given: plan's aim)


def search(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    out: Annotated[str, typer.Option("--out", "-o", help="Folder for result.json (created if needed).")],
    searcher: Annotated[str, typer.Option("--searcher", "-s", help=_searcher_help())] = "mcts",
    budget: Annotated[int, typer.Option("--budget", "-b", help="Episodes (one iteration = one episode of "
                                        "up to 8 actions from s0).")] = 200,
    seed: Annotated[int, typer.Option("--seed", help="Seed (>= 0) of numpy's SeedSequence.")] = 0,
    until: Annotated[str, typer.Option("--until", help="first: stop at the first unsafe state; budget: play "
                                       "the whole budget and record every hazardous episode.")] = "first",
    top_k: Annotated[int, typer.Option("--top-k", help="How many of the best episodes to keep.")] = 10,
    ec: Annotated[float | None, typer.Option("--ec", help="MCTS exploration constant (default 0.5; "
                                        "returns here differ by about 1 between good and bad prefixes).")] = None,
    k: Annotated[float | None, typer.Option("--k", help="MCTS widening factor k: a node tries a "
                                      "new action while children <= k N^alpha (default 1.0).")] = None,
    alpha: Annotated[float | None, typer.Option("--alpha", help="MCTS widening exponent (default 0.85).")] \
        = None,
    n: Annotated[int | None, typer.Option("--n", help="mcts-commit: iterations per decision "
                                          "(default budget // 8).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print result.json to stdout instead of the "
                                          "summary.")] = False,
    no_report: Annotated[bool, typer.Option("--no-report", help="Do not write the report (pictures, "
                                            "report.html) next to result.json.")] = False,
    criterion: Annotated[str | None, typer.Option("--criterion", help=criterion_help("the cell file's"))] = None,
    distinct: Annotated[bool, typer.Option("--distinct", help="With --until budget: cluster the hazards "
                                           "into classes, steer away from classes found, list each (evolve, "
                                           "plan: the budget shared between the start points in slices).")] = False,
    settings: Annotated[list[str] | None, typer.Option("--set", help="Any other option of the searcher, "
                                                       "NAME=VALUE, repeated (e.g. --set pool=5 --set "
                                                       "score=risk for evolve; its docstring lists them).")] = None,
    junit: Annotated[str | None, typer.Option("--junit", help=JUNIT_HELP + " One failing test case per hazard "
                                              "class (--distinct) or for the hazard found, else one passing case.")]
        = None,
) -> None:
    """Search a cell for a sequence of worker actions that ends in an unsafe contact; write result.json
    and its report (see 'cellstress report')."""
    import time

    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from cellstress.analysis.check_rows import static_failures
    from cellstress.analysis.iso13855 import check_cell
    from cellstress.analysis.shortfall import shortfall
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.cli.report import after_search
    from cellstress.criteria.iso15066 import CREEP_SPEED
    from cellstress.report.junit import search_suite
    from cellstress.report.scope import NOT_A_PROOF, judged_by, search_scope, static_lines, strongest_contact
    from cellstress.searchers import make_searcher, parse_options
    from cellstress.searchers import search as run
    from cellstress.searchers.common import check_common
    from cellstress.searchers.distinct import link_group, root_cause
    from cellstress.searchers.severity import words as severity_words
    from cellstress.sim.compiling import watching
    from cellstress.sim.simulator import Simulator

    options = {name: v for name, v in (("ec", ec), ("k", k), ("alpha", alpha), ("n", n)) if v is not None}
    with user_errors():
        extra = parse_options(settings)
        twice = sorted(set(extra) & set(options))
        if twice:
            raise CellstressError(f"--set {twice[0]}: given as --{twice[0]} too")
        options.update(extra)
        check_common(budget, seed, until, top_k)
        make_searcher(searcher, **options)
        check_criterion(criterion)
        if distinct and until != "budget":
            raise CellstressError("--distinct needs --until budget")
    out_dir = check_out_dir(out)
    junit_path = check_junit_path(junit)

    console = Console(stderr=True)
    progress = Progress(SpinnerColumn(), TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                        TextColumn("{task.fields[rate]:>7.0f} episodes/s  best risk {task.fields[risk]:.3f}"),
                        TimeElapsedColumn(), console=console, transient=True,
                        disable=not console.is_terminal)
    task = progress.add_task("loading the cell", total=budget, rate=0.0, risk=0.0)

    def compiling(active: bool) -> None:
        progress.update(task, description=COMPILING if active else searcher)

    played = [0]
    t0 = time.perf_counter()

    def tick(done: int, best_risk: float) -> None:
        played[0] = done
        if done % 8 == 0 or done == budget:
            busy = time.perf_counter() - t0 - watch.seconds
            progress.update(task, completed=done, rate=done / max(busy, 1e-9), risk=best_risk)

    try:
        with watching(compiling) as watch, progress, user_errors():
            sim = Simulator(with_criterion(load_cell(cell), criterion))
            progress.update(task, description=searcher)
            setup = watch.seconds
            t0 = time.perf_counter()
            result = run(sim, searcher, budget, seed, until=until, top_k=top_k, progress=tick, distinct=distinct,
                         **options)
    except KeyboardInterrupt:
        say(f"interrupted after {played[0]} of {budget} episodes; nothing was written to {out_dir} (a search "
            "is replayable only whole: run the same command again)", err=True)
        raise typer.Exit(INTERRUPTED) from None
    compiled = watch.seconds
    elapsed = time.perf_counter() - t0 - (compiled - setup)  # the search's own time, without compiling
    try:
        path = result.write(out_dir)
    except OSError as exc:
        raise fail(f"--out {out}: cannot write result.json ({exc.strerror or exc})") from None
    write_junit_file(junit_path, [search_suite(result)])
    if compiled >= 1.0:
        say(f"compiled  the simulator's kernels in {compiled:.0f} s (once: numba keeps them in its cache)", err=True)
    rate = result.episodes / max(elapsed, 1e-9)
    report = None if no_report else after_search(path, sim)
    if as_json:
        say(result.to_json(), nl=False)
        if report:
            say(report, err=True)
        say(f"{result.episodes} episodes in {elapsed:.2f} s ({rate:.0f} episodes/s); wrote {path}",
                   err=True)
        return
    echo = say
    echo(f"cell      {result.cell.name}  searcher {result.searcher} ({_params_text(result.params)})  "
         f"seed {seed}  budget {budget}")
    echo(f"criterion {judged_by(sim.criterion)}")
    best = max(result.risk_per_episode, default=0.0)
    h = result.hazard
    static = check_cell(sim.cell)  # the distances a failed safeguard fell short by; the rows a search did not clear
    if h is None:
        echo(f"no hazard found in {result.episodes} episodes (best risk {best:.3f}; {elapsed:.2f} s, "
             f"{rate:.0f} episodes/s)")
        echo(f"searched  {search_scope(result, sim.cell.spec, sim.layout.trajectory.cycle)}")
        strongest = strongest_contact(sim, result.top[0].actions) if result.top else None
        if strongest is not None:
            echo(f"strongest contact of the riskiest episode ({result.top[0].episode}): {strongest}")
        for line in static_lines(static_failures(static), "this search"):
            echo(line)
        echo(f"note      {NOT_A_PROOF}")
    else:
        extra_text = f", {len(result.hazards)} hazardous episodes in all" if until == "budget" else ""
        echo(f"FOUND at episode {h.episode} of {budget}{extra_text} ({result.episodes} episodes in "
             f"{elapsed:.2f} s, {rate:.0f} episodes/s)")
        echo(f"actions   {', '.join(h.actions)}")
        x, y, z = h.point
        creep = " (creeping)" if h.severity is not None and h.severity.creeping else ""
        echo(f"contact   t={num(h.time_s)} s (step {h.step}): {h.robot_link} / {h.body_part} at "
             f"({x:.3f}, {y:.3f}, {z:.3f}) m, robot moving at v_R {h.v_R:.3f} m/s{creep}")
        hit = h.trace[h.step] if h.step < len(h.trace) else None
        if hit is not None and hit.between is not None:
            echo("between   " + ("the contact lies between two time steps (the swept test found it)"
                                 if hit.between == "contact" else
                                 "the swept test could not rule out a contact between two time steps: the bodies "
                                 f"came within {hit.d_HR * 1000:.0f} mm of each other (counted, conservatively)"))
        if h.why is not None:
            echo(f"why       {shortfall(h.why, static)}")
        if h.verdict is not None:  # a criterion that judges contacts: its account of this one
            name, numbers = h.verdict
            echo(f"{name:<9} {numbers.get('reason')}")
    # the classes come worst first (searchers.severity); those while the robot creeps are shown apart, after
    listed = list(enumerate(result.distinct or ()))
    n = 0
    for creeping in (False, True):
        group = [i for i, d in listed if (d.severity is not None and d.severity.creeping) == creeping]
        if creeping and group:
            echo(f"creeping  contacts while the robot moves slower than {CREEP_SPEED:.3f} m/s (no transient contact "
                 "can exceed an ISO/TS 15066 limit but the head's), listed apart:")
        causes: dict[tuple[str, str], list[int]] = {}
        for i in group:
            causes.setdefault(root_cause(result.distinct[i].klass), []).append(i)
        for (device, area), members in causes.items():
            n += 1
            failed = "no device saw the worker" if device == "none" else f"{device} stopped the robot too late"
            echo(f"cause {n}   {failed}; {area} touched ({len(members)} "
                 f"{'class' if len(members) == 1 else 'classes'})")
            first = result.distinct[members[0]]
            if first.why is not None:
                echo(f"  why     {shortfall(first.why, static)}")
            for i in members:
                d = result.distinct[i]
                cls = d.klass
                x0, y0, x1, y1 = cls.approach_cell
                move = "" if cls.robot_move is None else f", robot's move {cls.robot_move}"
                echo(f"  class {i}  episode {d.episode}: {cls.robot_link} ({link_group(sim.layout, cls.robot_link)}) "
                     f"/ {cls.body_region}, worker at x {num(x0)}..{num(x1)}, y {num(y0)}..{num(y1)}{move}, "
                     f"{severity_words(d.severity)}  (cellstress replay {path} --hazard {i})")
    if report:
        echo(report)
    echo(f"wrote     {path}")
