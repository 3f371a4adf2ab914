"""Shared helpers of the command modules: one-line errors, the --out folder check, number and step formatting.

User errors (a bad cell file, an unknown action, a bad option) end the program with exit code 2 and one line
``error: <message>`` on stderr. Command modules import only typer and this module at the top, and the heavy
parts (pydantic, pinocchio, numba) inside their commands, so that ``cellstress --help`` starts fast.
"""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import typer

from cellstress.core.errors import CellstressError
from cellstress.core.text import for_terminal

USER_ERROR = 2
INTERRUPTED = 130  # the shell's code for a program stopped by SIGINT
CELL_HELP = "A built-in cell name (see 'cellstress cells') or the path of a cell file."


def say(text: str = "", *, err: bool = False, nl: bool = True) -> None:
    """Print text whose parts may come from files other people wrote: each line with its control characters
    (terminal escape sequences, bidirectional overrides) shown as escapes, never obeyed."""
    typer.echo("\n".join(for_terminal(line) for line in str(text).split("\n")), err=err, nl=nl)


COMPILING = "compiling the simulator (first run only; numba caches it)"


@contextmanager
def spinner_while_compiling() -> Iterator[None]:
    """A spinner on a terminal's stderr while numba compiles kernels (a fresh installation's first run), so a
    long silent wait is never a mystery; nothing otherwise. Imported lazily: ``--help`` must not load numba."""
    from rich.console import Console

    from cellstress.sim.compiling import watching

    console = Console(stderr=True)
    status = console.status(COMPILING) if console.is_terminal else None

    def show(active: bool) -> None:
        if status is not None:
            status.start() if active else status.stop()

    try:
        with watching(show):
            yield
    finally:
        if status is not None:
            status.stop()


def fail(message: str) -> typer.Exit:
    """Print ``error: message`` as one line on stderr; the caller raises the returned Exit(2)."""
    one_line = " ".join(str(message).split())
    say(f"error: {one_line}", err=True)
    return typer.Exit(USER_ERROR)


@contextmanager
def user_errors(prefix: str = "") -> Iterator[None]:
    try:
        yield
    except CellstressError as exc:
        raise fail(prefix + str(exc)) from None


def num(x: float) -> str:
    """A short, exact-looking number: 1.25, 0.05, 12 (no float noise such as 1.2500000000000002)."""
    return f"{round(float(x), 6):g}"


def first_sentence(text: str) -> str:
    text = " ".join(text.split())
    match = re.search(r"(?<=[.!?])\s", text)
    return text[: match.start()] if match else text


def check_out_dir(out: str) -> Path:
    """The --out folder, created if needed; exit 2 when it cannot be written."""
    path = Path(out).expanduser()
    try:
        if path.exists() and not path.is_dir():
            raise fail(f"--out {out}: exists and is not a directory")
        path.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=path)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise fail(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
    return path


JUNIT_HELP = "Also write a JUnit XML test report (for CI) to this file (docs/ci.md)."


def check_junit_path(junit: str | None, flag: str = "--junit") -> Path | None:
    """The --junit file (or another output file's, named by ``flag``), its folder made if needed; exit 2 when it
    cannot be written there (checked before the work, so that a long search does not end in an error)."""
    if junit is None:
        return None
    path = Path(junit).expanduser()
    if path.is_dir():
        raise fail(f"{flag} {junit}: is a directory (give a file name)")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=path.parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise fail(f"{flag} {junit}: cannot write in its folder ({exc.strerror or exc})") from None
    return path


def write_junit_file(path: Path | None, suites) -> None:
    """Write the JUnit report (nothing without --junit); exit 2 when the write fails."""
    if path is None:
        return
    from cellstress.report.junit import write_junit

    try:
        write_junit(path, suites)
    except OSError as exc:
        raise fail(f"--junit {path}: cannot write ({exc.strerror or exc})") from None


HEADER = (f"{'step':>4} {'t[s]':>6} {'x[m]':>7} {'y[m]':>7} {'head[deg]':>9} {'fwd[deg]':>8} "
          f"{'lat[deg]':>8} {'d_HR[m]':>8} {'v_R[m/s]':>8}  {'phase':<12} {'action':<26} devices")


def step_line(r: dict) -> str:
    devices = ",".join(r["devices"]) or "-"
    return (f"{r['step']:>4} {r['t']:>6.2f} {r['x']:>7.3f} {r['y']:>7.3f} {r['heading_deg']:>9.1f} "
            f"{r['forward_flexion_deg']:>8.1f} {r['lateral_flexion_deg']:>8.1f} {r['d_HR']:>8.3f} "
            f"{r['v_R']:>8.3f}  {r['stop_phase']:<12} {r['action'] or '-':<26} {devices}")


def check_criterion(name: str | None) -> None:
    """CellstressError unless ``name`` is None or a registered criterion."""
    from cellstress.cell.schema import CRITERIA

    if name is not None and name not in CRITERIA:
        raise CellstressError(f"--criterion: unknown criterion {name!r} (choose from {', '.join(CRITERIA)})")


def criterion_help(what: str) -> str:
    """The --criterion option's help, naming the registered criteria."""
    from cellstress.core import registry

    return f"{' or '.join(registry.names('criteria'))}; default: {what}."
