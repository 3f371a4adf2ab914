"""``cellstress new``: a commented starter cell that passes ``check``."""

from __future__ import annotations

import re
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


def new(
    name: Annotated[str, typer.Argument(help="The new cell's name (letters, digits, '. _ -').")],
    out: Annotated[str | None, typer.Option("--out", "-o", help="The file to write (default: NAME.yaml in the "
                                            "current folder); an existing file is never overwritten.")] = None,
) -> None:
    """Write a commented starter cell (a copy of the built-in 'baseline' under a new name) that passes 'check'."""

    import yaml

    from cellstress.cell.load import builtin_text, parse_cell
    from cellstress.core.io import atomic_write_text

    if not re.fullmatch(r"[A-Za-z0-9_.-]{1,100}", name) or name.strip(".") == "":
        raise fail(f"NAME {name!r}: use 1 to 100 letters, digits, '.', '_' or '-'")
    path = Path(out) if out is not None else Path(f"{name}.yaml")
    if path.suffix.lower() not in (".yaml", ".yml"):
        raise fail(f"--out {out}: a cell file's name ends in .yaml")
    if path.exists() or path.is_symlink():
        raise fail(f"{path}: exists; give another --out (nothing was written)")
    text = builtin_text("baseline")
    body = text[text.index("\nname:") + 1:]  # the built-in's own header comment is replaced
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
