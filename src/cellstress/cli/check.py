"""``cellstress check``: validate a cell file, summarise it and run the static ISO 13855 check."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import CELL_HELP, first_sentence, num, say, spinner_while_compiling, user_errors


def check(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
) -> None:
    """Validate a cell file, print a summary of it and run the static ISO 13855 / ISO 13857 check.

    Exit code 0 if the static check passes, 1 if it fails (a gate for a design in CI), 2 for a file that is not
    a valid cell."""
    import numpy as np

    from cellstress.analysis.iso13855 import check_cell
    from cellstress.cell.load import BUILTIN_CELLS, builtin_file, load_cell
    from cellstress.robot.capsules import declared_capsule, fitted_capsules
    from cellstress.robot.model import load_robot, resolve_urdf
    from cellstress.robot.trajectory import build_trajectory
    from cellstress.sim.build import pedestal

    with spinner_while_compiling(), user_errors():
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
        static = check_cell(c)

    out = say
    where = f"built-in: {builtin_file(cell)}" if cell in BUILTIN_CELLS else f"file: {c.source}"
    out(f"cell        {spec.name}  ({where}, sha256 {c.sha256[:12]})")
    if spec.description:
        out(f"            {first_sentence(spec.description)}")
    base = spec.robot.base
    out(f"robot       {spec.robot.urdf} -> {urdf}")
    out(f"            {robot.n_joints} joints, base at ({', '.join(num(v) for v in base.xyz)}) "
        f"yaw {num(base.yaw_deg)} deg, stopping time {num(spec.robot.stopping_time)} s")
    extra = f" + {len(caps) - n_own} extra" if len(caps) > n_own else ""
    out(f"capsules    {len(caps)} ({n_own} {cap_kind}{extra})")
    for k in caps:
        length = float(np.linalg.norm(np.subtract(k.p1, k.p0)))
        out(f"            {k.name:<18} on joint {k.joint:>2}  radius {k.radius:.3f} m  length {length:.3f} m")
    out(f"task        {len(task.waypoints_deg)} waypoints, dwell {num(task.dwell)} s, speed scale "
        f"{num(task.speed_scale)}, phase {num(task.phase)} s, cycle time {traj.cycle:.2f} s")
    obstacles = spec.solid_obstacles() + tuple(p for p in (pedestal(spec, robot),) if p is not None)
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
    out("ISO 13855 static check:")
    for line in static.lines():
        out(f"  {line}")
    if static.ok:
        out("PASS: the cell file is valid and the static check passes")
    else:
        out(f"FAIL: the cell file is valid, the static check fails ({', '.join(static.failures())})")
        raise typer.Exit(1)
