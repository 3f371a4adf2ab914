"""How many worker processes a command may start: the one bound every ``--workers`` option shares.

Each worker is a process with its own compiled simulators (a few hundred MB), so a typo such as ``--workers
1000000`` must not fork the machine to a standstill: more than ``MAX_WORKERS_PER_CORE`` per usable core is an
error (exit code 2), and no command starts more processes than it has tasks.
"""

from __future__ import annotations

import os

from cellstress.core.errors import CellstressError

MAX_WORKERS_PER_CORE = 4  # a little oversubscription helps while a worker waits on its disk; more only thrashes


def usable_cpus() -> int:
    """Cores this process may use (the affinity mask, not the machine's total, where the OS tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def max_workers() -> int:
    return MAX_WORKERS_PER_CORE * usable_cpus()


def check_workers(value: object, option: str = "--workers") -> int | None:
    """``value`` if it is None (the default: every usable core) or a whole number in 1..max_workers();
    CellstressError (one line naming ``option``) otherwise."""
    most = max_workers()
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= most:
        raise CellstressError(f"{option} must be a whole number in 1..{most} ({MAX_WORKERS_PER_CORE} per usable "
                              f"core, {usable_cpus()} here; each worker is a process of its own), not {value!r}")
    return value
