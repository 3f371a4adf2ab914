"""The ``cellstress`` command line: list, check and simulate cells; search for hazards and replay them.

User errors (a bad cell file, an unknown action, a bad option) end the program with exit code 2 and one line
``error: <message>`` on stderr. Heavy modules (pydantic, pinocchio, numba) are imported inside the commands so
that ``cellstress --help`` starts fast.
"""

from __future__ import annotations

import json
import math
import re
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Annotated

import typer

from cellstress.errors import CellstressError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="Find hidden human-robot hazards in industrial robot cells.",
)

USER_ERROR = 2
CELL_HELP = "A built-in cell name (see 'cellstress cells') or the path of a cell file."


def _fail(message: str) -> typer.Exit:
    """Print ``error: message`` as one line on stderr; the caller raises the returned Exit(2)."""
    one_line = " ".join(str(message).split())
    typer.echo(f"error: {one_line}", err=True)
    return typer.Exit(USER_ERROR)


@contextmanager
def _user_errors(prefix: str = "") -> Iterator[None]:
    try:
        yield
    except CellstressError as exc:
        raise _fail(prefix + str(exc)) from None


def _num(x: float) -> str:
    """A short, exact-looking number: 1.25, 0.05, 12 (no float noise such as 1.2500000000000002)."""
    return f"{round(float(x), 6):g}"


def _first_sentence(text: str) -> str:
    text = " ".join(text.split())
    match = re.search(r"(?<=[.!?])\s", text)
    return text[: match.start()] if match else text


# ---- cells ------------------------------------------------------------------------------------------------
@app.command()
def cells() -> None:
    """List the built-in cells with the first sentence of each description."""
    import yaml

    from cellstress.cell.load import BUILTIN_CELLS, builtin_text

    width = max(len(n) for n in BUILTIN_CELLS)
    for name in BUILTIN_CELLS:
        try:
            data = yaml.safe_load(builtin_text(name))
        except CellstressError:
            typer.echo(f"{name:<{width}}  (missing)")
            continue
        except yaml.YAMLError:
            typer.echo(f"{name:<{width}}  (unreadable YAML: run 'cellstress check {name}')")
            continue
        description = data.get("description", "") if isinstance(data, dict) else ""
        typer.echo(f"{name:<{width}}  {_first_sentence(str(description or '')) or '(no description)'}")


# ---- check ------------------------------------------------------------------------------------------------
def _static_check_lines(cell) -> list[str] | None:
    """Lines of ``cellstress.cell.iso13855.static_check(cell)``, or None while that module does not exist."""
    import importlib

    try:
        iso13855 = importlib.import_module("cellstress.cell.iso13855")
    except ModuleNotFoundError as exc:
        if exc.name == "cellstress.cell.iso13855":
            return None
        raise  # the module exists but one of its own imports is missing: a real bug, show it
    result = iso13855.static_check(cell)
    if result is None:
        return []
    if isinstance(result, str):
        return result.splitlines()
    if hasattr(result, "lines"):
        result = result.lines() if callable(result.lines) else result.lines
    return [str(line) for line in result]


@app.command()
def check(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
) -> None:
    """Validate a cell file and print a summary of it."""
    import numpy as np

    from cellstress.cell.load import BUILTIN_CELLS, load_cell
    from cellstress.robot.capsules import declared_capsule, fitted_capsules
    from cellstress.robot.model import load_robot, resolve_urdf
    from cellstress.robot.trajectory import build_trajectory

    with _user_errors():
        c = load_cell(cell)
        spec = c.spec
        urdf = resolve_urdf(spec.robot.urdf, c.directory)
        robot = load_robot(urdf)
        if spec.robot.capsules == "auto":
            caps = list(fitted_capsules(robot))
            cap_kind = "fitted to the collision meshes"
        else:
            caps = [declared_capsule(robot, k.link, k.link, k.p0, k.p1, k.radius)
                    for k in spec.robot.capsules]
            cap_kind = "declared"
        n_own = len(caps)
        for i, k in enumerate(spec.robot.extra_capsules):
            caps.append(declared_capsule(robot, f"{k.link}#extra{i}", k.link, k.p0, k.p1, k.radius))
        task = spec.robot.task
        traj = build_trajectory(task.waypoints_deg, task.dwell, task.speed_scale, robot.velocity_limits)
        static = _static_check_lines(c)

    out = typer.echo
    origin = "built-in" if cell in BUILTIN_CELLS else "file"
    out(f"cell        {spec.name}  ({origin}: {c.source}, sha256 {c.sha256[:12]})")
    if spec.description:
        out(f"            {_first_sentence(spec.description)}")
    base = spec.robot.base
    out(f"robot       {spec.robot.urdf} -> {urdf}")
    out(f"            {robot.n_joints} joints, base at ({', '.join(_num(v) for v in base.xyz)}) "
        f"yaw {_num(base.yaw_deg)} deg, stopping time {_num(spec.robot.stopping_time)} s")
    extra = f" + {len(caps) - n_own} extra" if len(caps) > n_own else ""
    out(f"capsules    {len(caps)} ({n_own} {cap_kind}{extra})")
    for k in caps:
        length = float(np.linalg.norm(np.subtract(k.p1, k.p0)))
        out(f"            {k.name:<18} on joint {k.joint:>2}  radius {k.radius:.3f} m  length {length:.3f} m")
    out(f"task        {len(task.waypoints_deg)} waypoints, dwell {_num(task.dwell)} s, speed scale "
        f"{_num(task.speed_scale)}, phase {_num(task.phase)} s, cycle time {traj.cycle:.2f} s")
    out(f"table       {len(spec.table.polygons)} polygon(s), height {_num(spec.table.height)} m")
    panels = sum(len(f.points) - 1 for f in spec.fences)
    out(f"fences      {len(spec.fences)} ({panels} straight segments)")
    fl = spec.floor
    out(f"floor       x {_num(fl.xmin)}..{_num(fl.xmax)} m, y {_num(fl.ymin)}..{_num(fl.ymax)} m")
    out(f"devices     {len(spec.devices)}")
    for d in spec.devices:
        if d.type == "laser-scanner":
            detail = f"{len(d.polygon)}-point field at {_num(d.height)} m"
        else:
            detail = (f"({_num(d.start[0])}, {_num(d.start[1])})-({_num(d.end[0])}, {_num(d.end[1])}), "
                      f"{_num(d.bottom)}..{_num(d.top)} m, {_num(d.resolution_mm)} mm")
        out(f"            {d.name:<18} {d.type:<14} response {_num(d.response_time)} s  {detail}")
    h = spec.human
    x, y = h.start.xy
    out(f"human       start ({_num(x)}, {_num(y)}) heading {_num(h.start.heading_deg)} deg, "
        f"height {_num(h.anthropometry.height)} m, walking {_num(h.walking_speed)} m/s")
    cr = spec.criterion
    out(f"criterion   {cr.type} (distance tolerance {_num(cr.distance_tolerance)} m, "
        f"speed tolerance {_num(cr.speed_tolerance)} m/s)")
    sim = spec.simulation
    out(f"simulation  dt {_num(sim.dt)} s, {sim.steps_per_action} steps per action, "
        f"{sim.actions_per_episode} actions per episode")
    if static is not None:
        out("ISO 13855 static check:")
        for line in static:
            out(f"  {line}")
    out("valid")


# ---- simulate ---------------------------------------------------------------------------------------------
def _json_ready(obj):
    """Replace non-finite floats (which json would write as the invalid NaN/Infinity) by null."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_ready(v) for v in obj]
    return obj


_HEADER = (f"{'step':>4} {'t[s]':>6} {'x[m]':>7} {'y[m]':>7} {'head[deg]':>9} {'fwd[deg]':>8} "
           f"{'lat[deg]':>8} {'d_HR[m]':>8} {'v_R[m/s]':>8}  {'phase':<12} {'action':<26} devices")


def _step_line(r: dict) -> str:
    devices = ",".join(r["devices"]) or "-"
    return (f"{r['step']:>4} {r['t']:>6.2f} {r['x']:>7.3f} {r['y']:>7.3f} {r['heading_deg']:>9.1f} "
            f"{r['forward_flexion_deg']:>8.1f} {r['lateral_flexion_deg']:>8.1f} {r['d_HR']:>8.3f} "
            f"{r['v_R']:>8.3f}  {r['stop_phase']:<12} {r['action'] or '-':<26} {devices}")


@app.command()
def simulate(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    actions: Annotated[str, typer.Option("--actions", "-a", help="Comma-separated actions, e.g. "
                                         "walk+upright,turn-left-45+bend-forward (WALK+BODY).")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON document instead of the table.")] \
        = False,
    criterion: Annotated[str | None, typer.Option("--criterion", help="contact-while-moving or iso15066; "
                                                  "default: the cell file's.")] = None,
) -> None:
    """Play a sequence of worker actions in a cell and report whether it ends in an unsafe contact."""
    from cellstress.human.actions import ACTION_NAMES, parse_actions

    with _user_errors("--actions: "):
        indices = parse_actions(actions)
    from cellstress.cell.load import load_cell

    with _user_errors():
        _check_criterion(criterion)
        from cellstress.criteria import with_criterion

        c = with_criterion(load_cell(cell), criterion)
        from cellstress.sim.simulator import Simulator

        sim = Simulator(c)
        trace = sim.run(indices)
    records = trace.records()
    hit = trace.unsafe_row
    hazard = None
    if hit is not None:
        r = records[hit]
        hazard = {k: r[k] for k in ("t", "step", "robot_link", "body_part", "robot_point", "human_point",
                                    "d_HR", "v_R")}
        if sim.forces is not None:
            hazard["iso15066"] = sim.forces.assess(trace.rows[hit]).as_dict()

    if as_json:
        doc = {"cell": c.name, "actions": [ACTION_NAMES[i] for i in indices], "steps": records,
               "unsafe": hazard is not None, "hazard": hazard}
        typer.echo(json.dumps(_json_ready(doc), indent=1, allow_nan=False))
        return
    typer.echo(_HEADER)
    for r in records:
        typer.echo(_step_line(r))
    if hazard is None:
        typer.echo("SAFE")
    else:
        typer.echo(f"UNSAFE at t={_num(hazard['t'])} s (step {hazard['step']}): "
                   f"{hazard['robot_link']} / {hazard['body_part']}")
        if "iso15066" in hazard:
            typer.echo(f"iso15066  {hazard['iso15066']['reason']}")


# ---- search -----------------------------------------------------------------------------------------------
def _check_out_dir(out: str):
    """The --out folder, created if needed; exit 2 when it cannot be written."""
    import os
    import tempfile
    from pathlib import Path

    path = Path(out).expanduser()
    try:
        if path.exists() and not path.is_dir():
            raise _fail(f"--out {out}: exists and is not a directory")
        path.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=path)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise _fail(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
    return path


def _check_criterion(name: str | None) -> None:
    from cellstress.cell.schema import CRITERIA

    if name is not None and name not in CRITERIA:
        raise CellstressError(f"--criterion: unknown criterion {name!r} (choose from {', '.join(CRITERIA)})")


def _params_text(params: dict) -> str:
    return ", ".join(f"{k} {'auto' if v is None else _num(v) if isinstance(v, float) else v}"
                     for k, v in params.items())


@app.command()
def search(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    out: Annotated[str, typer.Option("--out", "-o", help="Folder for result.json (created if needed).")],
    searcher: Annotated[str, typer.Option("--searcher", "-s", help="random, mcts (MCTS1: from s0 for the "
                                          "whole budget), mcts-commit (MCTS2: commit and re-root), evolve "
                                          "(ours: mutates the best episodes) or plan (ours: learns the robot "
                                          "and devices from the episodes, plans the worker).")] = "mcts",
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
    criterion: Annotated[str | None, typer.Option("--criterion", help="contact-while-moving (the paper) or "
                                                  "iso15066 (force limits per body region); default: the "
                                                  "cell file's.")] = None,
    distinct: Annotated[bool, typer.Option("--distinct", help="With --until budget: cluster the hazards "
                                           "into classes, steer away from classes found, list each (evolve, "
                                           "plan: the budget shared between the start points in slices).")] = False,
    settings: Annotated[list[str] | None, typer.Option("--set", help="Any other option of the searcher, "
                                                       "NAME=VALUE, repeated (e.g. --set pool=5 --set "
                                                       "score=risk for evolve; its docstring lists them).")] = None,
) -> None:
    """Search a cell for a sequence of worker actions that ends in an unsafe contact; write result.json
    and its report (see 'cellstress report')."""
    import time

    from cellstress.search import make_searcher, parse_options
    from cellstress.search import search as run
    from cellstress.search.common import check_common

    options = {name: v for name, v in (("ec", ec), ("k", k), ("alpha", alpha), ("n", n)) if v is not None}
    with _user_errors():
        extra = parse_options(settings)
        twice = sorted(set(extra) & set(options))
        if twice:
            raise CellstressError(f"--set {twice[0]}: given as --{twice[0]} too")
        options.update(extra)
        check_common(budget, seed, until, top_k)
        make_searcher(searcher, **options)
        _check_criterion(criterion)
        if distinct and until != "budget":
            raise CellstressError("--distinct needs --until budget")
    out_dir = _check_out_dir(out)
    from cellstress.cell.load import load_cell

    with _user_errors():
        from cellstress.criteria import with_criterion

        c = with_criterion(load_cell(cell), criterion)
        from cellstress.sim.simulator import Simulator

        sim = Simulator(c)

    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    progress = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                        TextColumn("{task.fields[rate]:>7.0f} episodes/s  best risk {task.fields[risk]:.3f}"),
                        TimeElapsedColumn(), console=console, transient=True,
                        disable=not console.is_terminal)
    task = progress.add_task(searcher, total=budget, rate=0.0, risk=0.0)
    t0 = time.perf_counter()

    def tick(done: int, best_risk: float) -> None:
        if done % 8 == 0 or done == budget:
            progress.update(task, completed=done, rate=done / max(time.perf_counter() - t0, 1e-9), risk=best_risk)

    with progress, _user_errors():
        result = run(sim, searcher, budget, seed, until=until, top_k=top_k, progress=tick, distinct=distinct,
                     **options)
    elapsed = time.perf_counter() - t0
    try:
        path = result.write(out_dir)
    except OSError as exc:
        raise _fail(f"--out {out}: cannot write result.json ({exc.strerror or exc})") from None
    rate = result.episodes / max(elapsed, 1e-9)
    report = None
    if not no_report:
        from cellstress.report.cli import after_search

        report = after_search(path, sim)
    if as_json:
        typer.echo(result.to_json(), nl=False)
        if report:
            typer.echo(report, err=True)
        typer.echo(f"{result.episodes} episodes in {elapsed:.2f} s ({rate:.0f} episodes/s); wrote {path}",
                   err=True)
        return
    echo = typer.echo
    echo(f"cell      {result.cell['name']}  searcher {result.searcher} ({_params_text(result.params)})  "
         f"seed {seed}  budget {budget}")
    best = max(result.risk_per_episode, default=0.0)
    h = result.hazard
    if h is None:
        echo(f"no hazard in {result.episodes} episodes (best risk {best:.3f}; {elapsed:.2f} s, "
             f"{rate:.0f} episodes/s)")
    else:
        extra = f", {len(result.hazards)} hazardous episodes in all" if until == "budget" else ""
        echo(f"FOUND at episode {h['episode']} of {budget}{extra} ({result.episodes} episodes in "
             f"{elapsed:.2f} s, {rate:.0f} episodes/s)")
        echo(f"actions   {', '.join(h['actions'])}")
        x, y, z = h["point"]
        echo(f"contact   t={_num(h['time_s'])} s (step {h['step']}): {h['robot_link']} / {h['body_part']} at "
             f"({x:.3f}, {y:.3f}, {z:.3f}) m, robot moving at v_R {h['v_R']:.3f} m/s")
    for i, d in enumerate(result.distinct or []):
        k = d["class"]
        x0, y0, x1, y1 = k["approach_cell"]
        echo(f"class {i}   episode {d['episode']}: {k['device']} / {k['robot_link']} / {k['body_region']} at "
             f"x {_num(x0)}..{_num(x1)}, y {_num(y0)}..{_num(y1)}  (cellstress replay {path} --hazard {i})")
    if report:
        echo(report)
    echo(f"wrote     {path}")


# ---- replay -----------------------------------------------------------------------------------------------
@app.command()
def replay(
    result_file: Annotated[str, typer.Argument(help="A result.json written by 'cellstress search' (or its "
                                               "folder).")],
    hazard_index: Annotated[int | None, typer.Option("--hazard", help="Replay the distinct hazard with this "
                                                     "index (search --distinct) instead of the first.")] = None,
) -> None:
    """Re-simulate the hazard of a search result and check it bit-exactly against the recorded trace.

    Exit code 0 if the replay agrees with the file, 1 if it does not."""
    from cellstress.search.result import SearchResult, json_ready

    with _user_errors():
        res = SearchResult.load(result_file)
    h = res.hazard
    if hazard_index is not None:
        hs = res.distinct or []
        if not 0 <= hazard_index < len(hs):
            raise _fail(f"--hazard {hazard_index}: the result lists {len(hs)} distinct hazards"
                        + (f" (0..{len(hs) - 1})" if hs else ""))
        h = hs[hazard_index]
    if h is None:
        raise _fail(f"{result_file}: the search found no hazard; there is nothing to replay")
    from cellstress.cell.load import load_cell

    with _user_errors():
        from cellstress.criteria import with_criterion

        c = with_criterion(load_cell(res.cell.get("source", res.cell["name"])),
                           res.cell.get("criterion", "contact-while-moving"))
        from cellstress.sim.simulator import Simulator

        trace = Simulator(c).run(h["actions"])
    records = json_ready(trace.records())
    for r in records:
        typer.echo(_step_line(r)) if r is not records[0] else (typer.echo(_HEADER), typer.echo(_step_line(r)))
    problems = []
    if c.sha256 != res.cell["sha256"]:
        problems.append(f"the cell differs from the one searched (sha256 {c.sha256[:12]} != "
                        f"{str(res.cell['sha256'])[:12]})")
    recorded = h["trace"]
    if len(records) != len(recorded):
        problems.append(f"the replay has {len(records)} rows, the file {len(recorded)}")
    for i, (a, b) in enumerate(zip(records, recorded, strict=False)):
        if json.dumps(a, sort_keys=True) != json.dumps(b, sort_keys=True):
            keys = sorted(k for k in set(a) | set(b) if json.dumps(a.get(k)) != json.dumps(b.get(k)))
            problems.append(f"row {i} differs in {', '.join(keys)}")
            break
    if not trace.unsafe:
        problems.append("the replayed episode does not reach an unsafe state")
    if problems:
        for p in problems:
            typer.echo(f"MISMATCH: {p}")
        raise typer.Exit(1)
    typer.echo(f"REPRODUCED bit-exactly: UNSAFE at t={_num(h['time_s'])} s (step {h['step']}): "
               f"{h['robot_link']} / {h['body_part']}, v_R {h['v_R']:.3f} m/s")


# ---- campaign (the command lives in cellstress/campaign/cli.py) -------------------------------------------
from cellstress.campaign.cli import campaign  # noqa: E402

app.command()(campaign)

# ---- report, show: cellstress.report.cli ------------------------------------------------------------------
from cellstress.report.cli import register as _register_report  # noqa: E402 (a light import: typer only)

_register_report(app)


# ---- entry point ------------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    """The ``cellstress`` console script. Returns the exit code (0 ok, 2 user error)."""
    command = typer.main.get_command(app)
    try:
        rv = command.main(args=argv, prog_name="cellstress", standalone_mode=False)
    except typer.TyperException as exc:  # click's usage errors and bad parameters
        message = exc.format_message() if hasattr(exc, "format_message") else str(exc)
        code = getattr(exc, "exit_code", USER_ERROR)
        if type(exc).__name__ == "NoArgsIsHelpError":  # bare `cellstress`: the help text, not an error
            typer.echo(message, err=True)
            return code
        ctx = getattr(exc, "ctx", None)
        hint = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        _fail(message.rstrip(".") + "." + hint if message else f"{type(exc).__name__}{hint}")
        return code
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        return 1
    except CellstressError as exc:  # normally caught inside the commands already
        _fail(str(exc))
        return USER_ERROR
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":
    sys.exit(main())
