"""Where runs execute: in this process, in local worker processes, or on a Ray cluster.

Each backend takes the runs still to do and yields their records as they finish (in any order); the caller
appends each one to ``runs.jsonl`` at once. A run is a pure function of its ``RunSpec``, so the backends give
the same records; only the order differs, and ``runs.jsonl`` lines are compared sorted.

Worker processes are started with ``spawn``, not ``fork``: numba's thread pool (and the threads of a Ray
driver) do not survive a fork, and a forked child could inherit a half-held lock.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from cellstress.campaign.plan import CampaignError, RunSpec
from cellstress.campaign.worker import execute, execute_on_one_thread, init_worker
from cellstress.core.cpus import check_workers, usable_cpus
from cellstress.core.errors import CellstressError
from cellstress.core.ray_pool import import_ray, ray_map

BACKENDS = ("processes", "ray")
MAX_RAY_TASKS = 100_000


@dataclass(frozen=True)
class Backend:
    """How to execute: ``name`` in BACKENDS; ``workers`` (None: all cores, or the Ray cluster's CPUs);
    ``address`` of a Ray cluster (None: start a local one, or use the one this process already joined)."""

    name: str = "processes"
    workers: int | None = None
    address: str | None = None

    def __post_init__(self) -> None:
        if self.name not in BACKENDS:
            raise CampaignError(f"--backend must be one of {', '.join(BACKENDS)}, not {self.name!r}")
        if self.name == "ray":
            if self.workers is not None and (isinstance(self.workers, bool) or not isinstance(self.workers, int)
                                             or not 1 <= self.workers <= MAX_RAY_TASKS):
                raise CampaignError(f"--workers must be a whole number in 1..{MAX_RAY_TASKS} (Ray tasks at a "
                                    f"time), not {self.workers!r}")
        else:
            try:  # local workers: the bound every --workers shares (core.cpus)
                check_workers(self.workers)
            except CellstressError as exc:
                raise CampaignError(str(exc)) from None
        if self.address is not None and self.name != "ray":
            raise CampaignError("--address is the address of a Ray cluster: use it with --backend ray")

    def check(self) -> None:
        """Fail early (before the --out folder is touched) when the backend cannot run here."""
        if self.name == "ray":
            import_ray(CampaignError)

    def describe(self, n_runs: int) -> str:
        if self.name == "ray":
            return "Ray" + (f" at {self.address}" if self.address else "") + \
                (f", at most {self.workers} tasks at a time" if self.workers else "")
        w = self.local_workers(n_runs)
        return "1 worker (this process)" if w == 1 else f"{w} worker processes"

    def local_workers(self, n_runs: int) -> int:
        return max(1, min(self.workers or usable_cpus(), n_runs))

    def run(self, specs: list[RunSpec]) -> Iterator[dict[str, Any]]:
        """The records of ``specs``, each as soon as its run has finished."""
        if not specs:
            return iter(())
        if self.name == "ray":
            return run_ray(specs, self.workers, self.address)
        w = self.local_workers(len(specs))
        return run_serial(specs) if w == 1 else run_processes(specs, w)


def run_serial(specs: Iterable[RunSpec]) -> Iterator[dict[str, Any]]:
    """In this process, one after the other (numba keeps its default threads: random search batches use
    every core)."""
    for spec in specs:
        yield execute(spec)


def run_processes(specs: list[RunSpec], workers: int) -> Iterator[dict[str, Any]]:
    """A pool of ``workers`` spawned processes, one numba thread each; each keeps its simulators."""
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(workers, mp_context=ctx, initializer=init_worker, initargs=(1,)) as pool:
        pending = {pool.submit(execute, s) for s in specs}
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in sorted(done, key=id):
                    yield f.result()
        finally:
            # interrupted, or a run failed: drop what has not started; the pool's exit waits for the
            # runs in progress (well under a second each) and stops the workers
            for f in pending:
                f.cancel()


def run_ray(specs: list[RunSpec], max_in_flight: int | None, address: str | None) -> Iterator[dict[str, Any]]:
    """Ray tasks of one CPU each, one numba thread each (``core.ray_pool``)."""
    for _, record in ray_map(execute_on_one_thread, specs, max_in_flight=max_in_flight, address=address,
                             error=CampaignError):
        yield record
