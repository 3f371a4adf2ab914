"""``cellstress new``: a commented starter cell that passes ``check``."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path
from typing import Annotated

import typer

from cellstress.cli.common import fail, say, user_errors

HEADER = """\
# yaml-language-server: $schema=cell.schema.json
# A starter cell written by 'cellstress new'. Make the schema above with: cellstress schema > cell.schema.json
# Every field: docs/cell-format.md (or: cellstress schema --markdown). Units: m, deg, s; +y is the front.
# It starts as the built-in 'baseline', a cell laid out to ISO 13855 (docs/cells.md explains each number):
# move the fences, the devices and the robot's waypoints to your cell's, then run: cellstress check {file}
"""


# How the robot stops: to be filled in from the robot's own manual. The values are the paper's placeholder.
STOPPING = """\
  stopping:   # FILL IN from the robot's manual: these values are a placeholder (the paper's), not your robot's
    category: 1            # IEC 60204-1 stop category of its protective stop: 0, 1 or 2 (the manual says which)
    controller_delay: 0.0  # s from the stop signal at the robot to the start of braking not in the maker's data
                           # (a safety PLC or a network in between)
    time: 0.15             # s of braking to standstill; or the maker's stopping distances and times per joint
                           # (ISO 10218-1 Annex B, in the manual): data: FILE.csv with payload_kg (docs/robot.md)
"""


def robot_block(short_name: str) -> str:
    """The ``robot:`` section of a starter cell for a built-in robot: joint waypoints derived from its joint
    limits (the middle of every range, then the first joint turned by a quarter of its range, at most 90 deg),
    so the program is within limits for any arm; the user replaces them with the cell's own."""
    import numpy as np

    from cellstress.robot.joints import joint_map, user_value
    from cellstress.robot.model import load_robot, resolve_urdf

    robot = load_robot(resolve_urdf(short_name, None))
    jmap = joint_map(robot, {})
    lo, hi = robot.sampling_range()
    mid = 0.5 * (lo + hi)
    turned = mid.copy()
    j0 = jmap.driven[0]
    turned[j0] += min(0.25 * (hi[j0] - lo[j0]), float(np.deg2rad(90.0)))

    def row(q) -> str:
        # rounded to 0.1 deg / 0.1 mm: the middle of a range and a quarter of it stay well within the limits
        digits = {j: 1 if robot.unit(j) == "deg" else 4 for j in jmap.driven}
        return "[" + ", ".join(f"{round(user_value(robot, j, q[j]), digits[j]):g}" for j in jmap.driven) + "]"

    names = textwrap.fill(", ".join(jmap.driven_names), 100, initial_indent="    # ", subsequent_indent="    # ")
    stopping = STOPPING
    return f"""robot:
  urdf: {short_name}
  base: {{xyz: [0.0, 0.0, 0.85], yaw_deg: 0.0}}
  capsules: auto
{stopping}  task:
    # one value per joint the program drives, in degrees (metres for a prismatic joint):
{names}
    # A starting point within the joint limits: replace it by the cell's own program (or give tool poses:
    # poses + tool_frame, and the robot's home as ik_seed_deg; or a joint-trajectory file: trajectory_csv; see
    # docs/cell-format.md and docs/programs.md). `cellstress check` prints each move; `show --program` draws it.
    waypoints_deg:
      - {row(mid)}
      - {row(turned)}
    dwell: 0.2
    speed_scale: 0.5
    phase: 1.4
"""


def new(
    name: Annotated[str, typer.Argument(help="The new cell's name (letters, digits, '. _ -').")],
    out: Annotated[str | None, typer.Option("--out", "-o", help="The file to write (default: NAME.yaml in the "
                                            "current folder); an existing file is never overwritten.")] = None,
    robot: Annotated[str | None, typer.Option("--robot", help="A built-in robot for the cell (ur3, ur5, ur10, "
                                              "panda, ...: 'cellstress cells' lists them); default: the "
                                              "baseline's UR10 and its program.")] = None,
) -> None:
    """Write a commented starter cell (a copy of the built-in 'baseline' under a new name) that passes 'check'."""

    import yaml

    from cellstress.cell.load import builtin_text, parse_cell
    from cellstress.core.io import atomic_write_text
    from cellstress.robot.model import BUILTIN_ROBOTS

    if not re.fullmatch(r"[A-Za-z0-9_.-]{1,100}", name) or name.strip(".") == "":
        raise fail(f"NAME {name!r}: use 1 to 100 letters, digits, '.', '_' or '-'")
    path = Path(out) if out is not None else Path(f"{name}.yaml")
    if path.suffix.lower() not in (".yaml", ".yml"):
        raise fail(f"--out {out}: a cell file's name ends in .yaml")
    if path.exists() or path.is_symlink():
        raise fail(f"{path}: exists; give another --out (nothing was written)")
    if robot is not None and robot not in BUILTIN_ROBOTS:
        raise fail(f"--robot {robot}: not a built-in robot ({', '.join(BUILTIN_ROBOTS)}); for a URDF file of "
                   "your own, write its path into robot.urdf")
    text = builtin_text("baseline")
    body = text[text.index("\nname:") + 1:]  # the built-in's own header comment is replaced
    if robot not in (None, "ur10"):  # (the baseline's own robot keeps its program)
        body = body.replace("a UR10 on the base", f"a robot ({robot}) on the base", 1)
        with user_errors():
            block = robot_block(robot)
        body = body[:body.index("robot:\n")] + block + body[body.index("table:\n"):]
    body = body.replace("  stopping_time: 0.15\n", STOPPING, 1)  # (the UR10's; another robot's block has it)
    body = body.replace("name: baseline\n", f"name: {yaml.safe_dump(name).splitlines()[0]}\n", 1)
    # a new cell is searched over the robot's whole cycle (the built-in keeps the paper's fixed arrival)
    body = re.sub(r"(?m)^  arrival: fixed .*$", "  arrival: cycle    # any moment of the robot's cycle, chosen by the "
                  "search (fixed: robot.task.phase)", body, count=1)
    cell_text = HEADER.format(file=path.name) + body
    with user_errors():
        parse_cell(cell_text, str(path), path.parent)  # the starter must be valid before it is written
    try:
        atomic_write_text(path, cell_text)
    except OSError as exc:
        raise fail(f"{path}: cannot write there ({exc.strerror or exc})") from None
    say(f"wrote     {path} (check it with: cellstress check {path})")
