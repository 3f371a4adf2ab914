"""Tasks on a Ray cluster, one CPU each, as they finish: what ``campaign --backend ray`` and ``verify --backend
ray`` share. Ray is an optional dependency (``pip install 'cellstress[ray]'``): it is imported when a Ray
backend is asked for, and its absence is a user error, not a crash.

Joins the cluster at ``address``; without one, uses the Ray this process already joined, or starts a local Ray
on this machine's cores (and stops it afterwards). At most ``max_in_flight`` tasks run at a time (None: all);
tasks not finished when the caller stops reading (Ctrl-C, an error) are cancelled.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from cellstress.core.cpus import usable_cpus

RAY_HINT = "pip install 'cellstress[ray]'"


def import_ray(error: Callable[[str], Exception]) -> Any:
    """The ``ray`` module; ``error(message)`` raised when it is not installed."""
    try:
        import ray  # noqa: PLC0415  (optional: only a Ray backend needs it)
    except ImportError:
        raise error(f"--backend ray needs Ray, which is not installed ({RAY_HINT})") from None
    return ray


def ray_map(fn: Callable[[Any], Any], items: Sequence[Any], *, max_in_flight: int | None, address: str | None,
            error: Callable[[str], Exception]) -> Iterator[tuple[int, Any]]:
    """``(index, fn(items[index]))`` for every item, each as soon as its Ray task has finished. A task's own
    exception is raised as itself; ``error(message)`` for a cluster that cannot be joined."""
    ray = import_ray(error)
    started = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = {"address": address, "include_dashboard": False, "logging_level": logging.WARNING}
        if address is None:
            kwargs["num_cpus"] = max_in_flight or usable_cpus()
        try:
            ray.init(**kwargs)
        except (ConnectionError, ValueError, RuntimeError) as exc:
            raise error(f"--address {address}: cannot join the Ray cluster ({exc})") from None
        started = True
    task = ray.remote(num_cpus=1)(fn)
    limit = max_in_flight or len(items)
    queue = list(reversed(range(len(items))))
    running: dict[Any, int] = {}
    try:
        while queue or running:
            while queue and len(running) < limit:
                i = queue.pop()
                running[task.remote(items[i])] = i
            done, _ = ray.wait(list(running), num_returns=1)
            for ref in done:
                i = running.pop(ref)
                try:
                    yield i, ray.get(ref)
                except ray.exceptions.RayTaskError as exc:
                    cause = getattr(exc, "cause", None)
                    raise cause if isinstance(cause, Exception) else exc from None
    finally:
        for ref in running:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()
