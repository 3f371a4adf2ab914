"""One run of a campaign, as executed inside a worker (the main process, a worker process or a Ray task).

``execute(spec)`` is a pure function of the ``RunSpec``: it returns the run's record (a JSON-ready dict with
no wall-clock field), so the same grid gives the same records on one worker, many workers or Ray.
"""

from __future__ import annotations

import os
from typing import Any

from cellstress.campaign.plan import CampaignError, RunSpec

RECORD_FORMAT = 1

# Per-process cache of simulators, keyed by (source, sha256). It is a cache, not shared state: a worker
# builds each cell's Simulator (layout, robot tables, reach field) once and reuses it for all its runs; a
# Simulator's results never depend on what it ran before (its state is passed in and out of ``step``).
_SIMS: dict[tuple[str, str], Any] = {}


def init_worker(threads: int | None = 1) -> None:
    """Worker start-up: one numba thread each (so N workers do not oversubscribe N cores), and no SIGINT.

    Ctrl-C reaches the whole process group; the main process handles it and stops the pool, so a worker
    ignores it instead of printing a traceback mid-run."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _exit_with_parent()
    set_threads(threads)


def _exit_with_parent() -> None:
    """End this worker when the main process dies (e.g. SIGKILL), instead of waiting for work forever.

    A pool worker holds both ends of its task queue's pipe, so it never sees end-of-file when the main process
    is killed; the parent's sentinel becomes ready when it exits, whatever the cause."""
    import multiprocessing
    import threading
    from multiprocessing.connection import wait

    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        wait([parent.sentinel])
        os._exit(1)  # no clean-up to do: the main process owns runs.jsonl

    threading.Thread(target=watch, name="cellstress-parent-watch", daemon=True).start()


def set_threads(threads: int | None) -> None:
    if threads is None:
        return
    from cellstress.core.jit import numba

    # numba's thread count is per calling thread; workers run their tasks on the thread that calls this
    if numba.get_num_threads() != threads:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))


def simulator(source: str, sha256: str):
    """The cached Simulator of a cell; CampaignError if the cell file changed since the campaign began."""
    key = (source, sha256)
    sim = _SIMS.get(key)
    if sim is None:
        from cellstress.cell.load import load_cell
        from cellstress.sim.simulator import Simulator

        cell = load_cell(source)
        if cell.sha256 != sha256:
            raise CampaignError(f"cell {source} changed while the campaign ran (sha256 {cell.sha256[:12]}, "
                                f"expected {sha256[:12]})")
        sim = _SIMS[key] = Simulator(cell)
    return sim


def execute(spec: RunSpec) -> dict[str, Any]:
    """Run one search and return its record for ``runs.jsonl``."""
    from cellstress.searchers import search

    sim = simulator(spec.cell.source, spec.cell.sha256)
    result = search(sim, spec.searcher.name, spec.budget, spec.seed, **spec.searcher.params_dict)
    h = result.hazard
    hazard = None if h is None else {
        "episode": h.episode,
        "actions": list(h.actions),
        "step": h.step,
        "time_s": h.time_s,
        "robot_link": h.robot_link,
        "body_part": h.body_part,
    }
    return {
        "format": RECORD_FORMAT,
        "cell": spec.cell.name,
        "cell_sha256": spec.cell.sha256,
        "searcher": spec.searcher.name,
        "params": result.params,
        "seed": spec.seed,
        "budget": spec.budget,
        "until": result.until,
        "found": result.found,
        "episodes": result.episodes,
        "hazard": hazard,
        "version": result.version,
    }


def execute_on_one_thread(spec: RunSpec) -> dict[str, Any]:
    """``execute`` for Ray tasks, which have no initializer: one numba thread first (cheap if set)."""
    set_threads(1)
    return execute(spec)
