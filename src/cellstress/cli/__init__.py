"""The ``cellstress`` command line: one module per command, shared helpers in ``cli.common``.

Exit codes: 0 success, 1 a finding or a failed check the user asked about, 2 a user error (one line
``error: ...`` on stderr, no traceback), 3 ``verify`` left sequences undecided (its time limit).
"""

from __future__ import annotations

import sys

import typer

from cellstress.cli.campaign import campaign
from cellstress.cli.cells import cells
from cellstress.cli.check import check
from cellstress.cli.common import USER_ERROR, fail
from cellstress.cli.diff import diff
from cellstress.cli.fix import fix
from cellstress.cli.new import new
from cellstress.cli.replay import replay
from cellstress.cli.report import report, show
from cellstress.cli.schema import schema
from cellstress.cli.search import search
from cellstress.cli.simulate import simulate
from cellstress.cli.verify import verify
from cellstress.core.errors import CellstressError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="Find hidden human-robot hazards in industrial robot cells.",
)
for command in (cells, check, diff, fix, simulate, search, verify, replay, campaign, report, show, schema, new):
    app.command()(command)


def _name_the_values(command) -> None:
    """Help shows ``--out OUT`` and ``CELL``, as argparse would, instead of typer's ``<str>`` on every line; a
    flag shows no value at all (typer would print ``<bool>``)."""
    for sub in getattr(command, "commands", {}).values():
        for param in sub.params:
            if param.param_type_name == "argument":  # its help line would read "CELL <str>"
                param.display_type_rich = lambda ctx: None
            if param.metavar is not None:
                continue
            if getattr(param, "is_flag", False):
                param.metavar = ""
            else:
                param.metavar = param.name.upper()


def main(argv: list[str] | None = None) -> int:
    """The ``cellstress`` console script. Returns the exit code (0 ok, 1 a finding, 2 user error)."""
    command = typer.main.get_command(app)
    _name_the_values(command)
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
        fail(message.rstrip(".") + "." + hint if message else f"{type(exc).__name__}{hint}")
        return code
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        return 1
    except CellstressError as exc:  # normally caught inside the commands already
        fail(str(exc))
        return USER_ERROR
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":
    sys.exit(main())
