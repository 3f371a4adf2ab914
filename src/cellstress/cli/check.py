"""``cellstress check``: validate a cell file, summarise it and run the static ISO 13855 check."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    JUNIT_HELP,
    CellstressError,
    check_junit_path,
    check_out_dir,
    fail,
    first_sentence,
    num,
    say,
    spinner_while_compiling,
    user_errors,
    write_junit_file,
)


def check(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    junit: Annotated[str | None, typer.Option("--junit", help=JUNIT_HELP + " One test case per check row.")] = None,
    witness: Annotated[bool, typer.Option("--witness", help="For each row the static check fails, search for a "
                                          "simulated worker who takes that way in: plan, aimed at the robot point "
                                          "and moment the row names. Each row: FOUND (the actions), not "
                                          "reproduced, or what the simulated worker cannot do.")] = False,
    budget: Annotated[int, typer.Option("--budget", "-b", help="With --witness: episodes per search.")] = 200,
    seed: Annotated[int, typer.Option("--seed", help="With --witness: the searches' seed (>= 0).")] = 0,
    out: Annotated[str | None, typer.Option("--out", "-o", help="With --witness: write each search's result.json "
                                            "into a folder search-N here (replay, report).")] = None,
) -> None:
    """Validate a cell file, print a summary of it and run the static ISO 13855 / ISO 13857 check.

    Exit code 0 if the static check passes, 1 if it fails (a gate for a design in CI), 2 for a file that is not
    a valid cell. --witness also searches the simulation for each failing row's way in (docs/cells.md)."""
    from cellstress.analysis.check_rows import check_rows
    from cellstress.analysis.iso13855 import check_cell
    from cellstress.analysis.program_check import check_programs
    from cellstress.analysis.robot_audit import audit_robot
    from cellstress.cell.load import BUILTIN_CELLS, builtin_file, load_cell
    from cellstress.report.junit import check_suite
    from cellstress.robot.geometry import robot_geometry
    from cellstress.searchers.common import check_common
    from cellstress.sim.build import build_layout

    junit_path = check_junit_path(junit)
    with user_errors():
        check_common(budget, seed, "first", 0)
        if (out is not None or budget != 200 or seed != 0) and not witness:
            raise CellstressError("--budget, --seed and --out go with --witness")
    out_dir = check_out_dir(out) if out is not None else None
    with spinner_while_compiling(), user_errors():
        c = load_cell(cell)
        spec = c.spec
        layout = build_layout(c)
        static = check_cell(c, layout)
        audits = [audit_robot(robot_geometry(p.model.urdf), p.capsules, p.joints) for p in layout.robots]
        programs = check_programs(layout)

    out = say
    where = f"built-in: {builtin_file(cell)}" if cell in BUILTIN_CELLS else f"file: {c.source}"
    out(f"cell        {spec.name}  ({where}, sha256 {c.sha256[:12]})")
    if spec.description:
        out(f"            {first_sentence(spec.description)}")
    _file_lines(c)
    for part, audit in zip(layout.robots, audits, strict=True):
        _robot_lines(part, c.files_dir, len(layout.robots) > 1)
        out("robot audit " + "\n            ".join(audit.lines(part.model.joint_names)))
    obstacles = layout.obstacles
    out(f"obstacles   {len(obstacles)}" + ("" if obstacles else " (nothing on the floor)"))
    for o in obstacles:
        out(f"            {o.name:<18} height {num(o.height)} m, footprint of {len(o.footprint())} corners")
    panels = sum(len(f.points) - 1 for f in spec.fences)
    out(f"fences      {len(spec.fences)} ({panels} straight segments)")
    fl = spec.floor
    out(f"floor       x {num(fl.xmin)}..{num(fl.xmax)} m, y {num(fl.ymin)}..{num(fl.ymax)} m")
    out(f"devices     {len(spec.devices)}")
    for d in spec.devices:
        out(f"            {d.name:<18} {d.type:<14} response {num(d.response_time)} s  {d.describe()}")
    h = spec.human
    x, y = h.start.xy
    out(f"human       start ({num(x)}, {num(y)}) heading {num(h.start.heading_deg)} deg, "
        f"height {num(h.anthropometry.height)} m, walking {num(h.walking_speed)} m/s")
    cr = spec.criterion
    out(f"criterion   {cr.type} (distance tolerance {num(cr.distance_tolerance)} m, "
        f"speed tolerance {num(cr.speed_tolerance)} m/s)")
    sim = spec.simulation
    out(f"simulation  dt {num(sim.dt)} s, {sim.steps_per_action} steps per action, "
        f"{sim.actions_per_episode} actions per episode")
    out("robot program check:")
    for line in (line for p in programs for line in p.lines()):
        out(f"  {line}")
    out("ISO 13855 static check:")
    for line in static.lines():
        out(f"  {line}")
    failures = [f for p in programs for f in p.failures()] + static.failures()
    rows = check_rows(static, programs)
    said = _witness_lines(c, rows, budget, seed, out_dir) if witness and failures else {}
    write_junit_file(junit_path, [check_suite(spec.name, rows, said)])
    if not failures:
        out("PASS: the cell file is valid and the static check passes")
    else:
        out(f"FAIL: the cell file is valid, the static check fails ({', '.join(failures)})")
        raise typer.Exit(1)


def _witness_lines(c, rows, budget: int, seed: int, out_dir) -> dict[str, str]:
    """``--witness``: a simulated worker's way in for each failing row (analysis.witness), one line per row;
    returns each row's line (for the JUnit file)."""
    from rich.console import Console
    from rich.markup import escape

    from cellstress.analysis.witness import SEARCHER, witness_searches
    from cellstress.core.text import for_terminal
    from cellstress.sim.simulator import Simulator

    console = Console(stderr=True)
    with spinner_while_compiling(), user_errors(), console.status("", spinner="dots") as status:
        def progress(row: str) -> None:  # (a terminal only: rich shows nothing elsewhere)
            status.update(f"searching for a simulated witness of {escape(for_terminal(row))}")

        found = witness_searches(Simulator(c), rows, budget, seed, progress if console.is_terminal else None)
    say(f"simulated witnesses ({SEARCHER}, {budget} episodes per search, seed {seed}; aimed at each row's robot "
        "point and moment where it names one):")
    folders: dict[int, str] = {}
    said = {}
    for w in found:
        where = ""
        if out_dir is not None and w.result is not None:
            key = id(w.result)
            if key not in folders:
                try:
                    folders[key] = str(w.result.write(out_dir / f"search-{len(folders) + 1}", inside=out_dir))
                except OSError as exc:
                    raise fail(f"--out {out_dir}: cannot write result.json ({exc.strerror or exc})") from None
            first = w.result.hazard
            later = w.witness is not None and first is not None and w.witness.episode != first.episode
            # (the file's ``hazard`` is its search's first; a witness further into the budget is one of its hazards)
            where = f" ({folders[key]}" + (f": among its hazards, episode {w.witness.episode}" if later else "") + ")"
        said[w.row] = w.line() + where
        say(f"  {said[w.row]}")
    return said


def _file_lines(c) -> None:
    """Every file the cell reads, with its size and SHA-256 (result files record them, replay compares them);
    those outside the cell's folder (and the robots shipped with cellstress and example-robot-data) marked."""
    from cellstress.cell.files import CONFINE_VAR, outside_paths

    outside = outside_paths(c)
    note = f"; {len(outside)} outside the cell's folder ({CONFINE_VAR}=inside refuses them)" if outside else ""
    say(f"files       {len(c.files)} read{note}")
    for f in c.files:
        mark = "  OUTSIDE the cell's folder" if f.path in outside else ""
        say(f"            {f.use:<24} {f.path}  ({f.bytes:,} bytes, sha256 {f.sha256}){mark}")


def _robot_lines(part, files_dir, several: bool) -> None:
    """The robot, its capsules and its program (in a cell of several robots, each headed by its name)."""
    import numpy as np

    from cellstress.analysis.stopping import stop_lines
    from cellstress.robot.model import resolve_urdf

    out, rs, robot, caps, traj = say, part.spec, part.model, part.capsules, part.trajectory
    urdf = resolve_urdf(rs.urdf, files_dir)
    n_own = len(caps) - len(rs.extra_capsules)
    cap_kind = "fitted to the links' shapes" if rs.capsules == "auto" else "declared"
    task = rs.task
    base = rs.base
    out(f"robot       {rs.name + ': ' if several else ''}{rs.urdf} -> {urdf}")
    n_mimic = int((robot.mimic_master >= 0).sum())
    follow = [f"{n} {what}" for n, what in ((len(rs.hold), "held"), (n_mimic, "mimic")) if n]
    joints = f"{robot.n_joints} joints" + (f" ({', '.join(follow)})" if follow else "")
    out(f"            {joints}, base at ({', '.join(num(v) for v in base.xyz)}) "
        f"yaw {num(base.yaw_deg)} deg, stopping time {part.stop.describe()}")
    for line in stop_lines(part.stop, part.model, part.capsules):
        out(f"            {line}")
    extra = f" + {len(caps) - n_own} extra" if len(caps) > n_own else ""
    out(f"capsules    {len(caps)} ({n_own} {cap_kind}{extra})")
    for k in caps:
        length = float(np.linalg.norm(np.subtract(k.p1, k.p0)))
        out(f"            {k.name:<18} on joint {k.joint:>2}  radius {k.radius:.3f} m  length {length:.3f} m")
    if task.trajectory_csv:
        out(f"task        trajectory file {task.trajectory_csv}, {traj.n_segments + 1} rows, linear moves, "
            f"phase {num(task.phase)} s, cycle time {traj.cycle:.2f} s")
    else:
        what = f"{len(task.poses)} tool poses of {task.tool_frame}" if task.poses else \
            f"{len(task.waypoints_deg)} waypoints"
        dwell = "per waypoint" if task.dwells else f"{num(task.dwell)} s"
        scale = "per move" if task.speed_scales else num(task.speed_scale)
        out(f"task        {what}, dwell {dwell}, speed scale {scale}, phase {num(task.phase)} s, "
            f"cycle time {traj.cycle:.2f} s")
