"""How long numba spends compiling the simulator's kernels, so that the command line can say so while it
happens and leave it out of its speed figures.

Kernels compile on their first call in a fresh installation (then they load from numba's on-disk cache); that
first compile takes far longer than the search itself, and a speed line that counted it ("1 episodes/s")
would mislead. numba announces every compile as a ``numba:compile`` event; ``watching`` listens while a
command runs.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from cellstress.core.jit import event


class CompileWatch(event.Listener):
    """Counts the seconds of outermost compiles (a kernel compiles its callees inside its own compile) and tells
    ``on_change(True)`` when compiling starts and ``on_change(False)`` when it stops."""

    def __init__(self, on_change: Callable[[bool], None] | None = None):
        self.on_change = on_change
        self.seconds = 0.0
        self.compiles = 0
        self._depth = 0
        self._t0 = 0.0

    def on_start(self, ev) -> None:
        if self._depth == 0:
            self._t0 = time.perf_counter()
            if self.on_change is not None:
                self.on_change(True)
        self._depth += 1

    def on_end(self, ev) -> None:
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._t0
            self.compiles += 1
            if self.on_change is not None:
                self.on_change(False)


@contextmanager
def watching(on_change: Callable[[bool], None] | None = None) -> Iterator[CompileWatch]:
    """A ``CompileWatch`` installed for the duration of the block."""
    watch = CompileWatch(on_change)
    event.register("numba:compile", watch)
    try:
        yield watch
    finally:
        event.unregister("numba:compile", watch)
