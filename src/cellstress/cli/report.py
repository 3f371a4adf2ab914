"""``cellstress report`` and ``cellstress show``, and the report step of ``search``.

A bad path or a foreign file ends with exit code 2 and one line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cellstress.cli.common import fail, say, spinner_while_compiling
from cellstress.core.errors import CellstressError
from cellstress.core.text import slug

RESULT_HELP = "A result.json written by 'cellstress search' (or its folder)."


def report(
    result_file: Annotated[str, typer.Argument(help=RESULT_HELP)],
) -> None:
    """Write the hazard report next to a search result: topview.png, contact.png, replay.gif, risk.png and a
    self-contained report.html. Without a hazard, the riskiest episode is shown."""
    from cellstress.report.make import write_report

    try:
        with spinner_while_compiling():
            files = write_report(result_file)
    except CellstressError as exc:
        raise fail(str(exc)) from None
    except OSError as exc:
        raise fail(f"{result_file}: cannot write the report ({exc.strerror or exc})") from None
    folder = files.html.parent
    say(f"report    {files.html}")
    say(f"          {', '.join(p.name for p in files.paths[:-1])} in {folder}")
    say(f"account   {files.account.headline}")
    if files.cell_changed:
        say("warning   the cell file, or a file it reads, has changed since the search (cellstress replay names it); "
            "the pictures show the current cell")


def show(
    cell: Annotated[str, typer.Argument(help="A built-in cell name (see 'cellstress cells') or the path of a "
                                        "cell file.")],
    out: Annotated[str | None, typer.Option("--out", "-o", help="PNG file to write (default: the cell's name "
                                            "as a plain file name, .png, in the current folder).")] = None,
    program: Annotated[bool, typer.Option("--program", help="Draw the robot's program alone instead: its moves "
                                          "over one cycle from above and the side, with the program check.")] = False,
) -> None:
    """Draw a cell's layout to scale (fences, table, devices, the robot's swept area, the start) as a PNG; with
    --program, the robot's program over one cycle (no worker)."""
    from cellstress.cell.load import load_cell

    try:
        c = load_cell(cell)
    except CellstressError as exc:
        raise fail(str(exc)) from None
    default = f"{slug(c.spec.name)}-program.png" if program else f"{slug(c.spec.name)}.png"
    path = Path(out) if out is not None else Path(default)
    if path.suffix.lower() != ".png":
        raise fail(f"--out {out}: the picture is a PNG file, give a name ending in .png")
    from cellstress.report.make import show_cell
    from cellstress.report.program import show_program

    try:
        if path.parent != Path(""):
            path.parent.mkdir(parents=True, exist_ok=True)
        with spinner_while_compiling():
            (show_program if program else show_cell)(c, path)
    except CellstressError as exc:
        raise fail(str(exc)) from None
    except OSError as exc:
        raise fail(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
    say(f"wrote     {path}")


def after_search(result_path: Path, sim) -> str:
    """The report step of ``cellstress search``: writes the report next to result.json; returns the line
    to print."""
    from cellstress.report.make import write_report

    try:
        files = write_report(result_path, sim=sim)
    except OSError as exc:
        raise fail(f"cannot write the report into {result_path.parent} ({exc.strerror or exc})") from None
    return f"report    {files.html} (and {', '.join(p.name for p in files.paths[:-1])})"
