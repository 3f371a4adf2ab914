"""Wall time of ``cellstress verify``: a cell at its own start point and phase, and over all arrival phases.

    python benchmarks/verify_speed.py [--repeats 3] [--cells baseline s1-scanner-width] [--all-phases baseline]
                                      [--workers 2] [--fraction 1.0]
    python benchmarks/verify_speed.py --growth s3-fence-gap baseline [--horizon 8]

In this process (the numba cache must be warm: run any command once after changing the simulator), for each
cell: the median and minimum over repeats of ``run_verify`` at the cell's own phases (``--phases cell``; the
Simulator is built once, outside the timing), with the states visited and what each bound pruned; then, for
the cells of ``--all-phases``, one timed run over every arrival phase on the time-step grid with ``--workers``
processes (``--fraction`` < 1 decides only that share of the phases, evenly spaced, and extrapolates). Prints
the ratios to the targets (own phase <= 60 s, all phases <= 30 min on the project's 2-core machine) and the
CPU time used.

``--growth``: for each cell, one tree (its own start point and phase, ``--horizon`` actions, one process): the
living states after each action, their growth per action, the children expanded and the wall time of each
action's layer, and what the bounds cut.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from cellstress.sim.simulator import Simulator  # noqa: E402
from cellstress.verifier.bounds import Bounds  # noqa: E402
from cellstress.verifier.records import VerifyOptions  # noqa: E402
from cellstress.verifier.run import assemble, decide_task, run_verify, tasks_of  # noqa: E402
from cellstress.verifier.tree import decide  # noqa: E402

OWN_TARGET_S = 60.0
ALL_TARGET_S = 30 * 60.0


def _cpu() -> float:
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def own_phase(cell: str, repeats: int) -> None:
    sim = Simulator(cell)
    run_verify(sim, VerifyOptions(phases="cell", horizon=2))  # loads the compiled kernels
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = run_verify(sim, VerifyOptions(phases="cell"))
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    pruned = ", ".join(f"{p.bound} {p.states:,} states" for p in res.pruned)
    print(f"{cell:<20} own phase: median {med:7.2f} s, min {min(times):7.2f} s ({med / OWN_TARGET_S:.3f} x target); "
          f"{res.verdict}, {res.hazardous:,} hazardous, {res.states:,} states; pruned {pruned}")


def all_phases(cell: str, workers: int, fraction: float) -> None:
    sim = Simulator(cell)
    options = VerifyOptions(phases="all")
    tasks = tasks_of(sim, options, None)
    step = max(1, round(1 / fraction))
    chosen = tasks[::step]
    cpu0, t0 = _cpu(), time.perf_counter()
    if workers > 1:
        res = run_verify(sim, options, workers=workers) if step == 1 else None
    else:
        res = assemble(sim, options, chosen, [decide_task(t) for t in chosen], None)
    wall = time.perf_counter() - t0
    cpu = _cpu() - cpu0
    full = wall * len(tasks) / len(chosen)
    verdict = res.verdict if res is not None else "(fraction: run with --workers 1)"
    print(f"{cell:<20} all {len(tasks)} phases ({len(chosen)} decided, {workers} workers): {wall:7.1f} s wall, "
          f"{cpu:7.1f} s CPU; whole sweep {full:7.1f} s ({full / ALL_TARGET_S:.3f} x target); {verdict}")


def growth(cell: str, horizon: int) -> None:
    sim = Simulator(cell)
    decide(sim, 2, Bounds(sim, horizon=2))  # loads the compiled kernels
    t0 = time.perf_counter()
    out = decide(sim, horizon, Bounds(sim, horizon=horizon))
    wall = time.perf_counter() - t0
    print(f"\n{cell}, own start point and phase, {horizon} actions: {wall:.1f} s, {out.expanded:,} children expanded, "
          f"{out.hazardous:,} of {out.total:,} sequences hazardous; cut: "
          + (", ".join(f"{k} {v:,} states" for k, v in out.pruned_states.items()) or "nothing"))
    print("| action | living states after it | growth | layer wall time [s] |")
    print("|---:|---:|---:|---:|")
    for n, secs in enumerate(out.seconds, start=1):
        living = out.states[n] if n < len(out.states) else None
        grow = f"{living / out.states[n - 1]:.2f}" if living is not None and out.states[n - 1] else "-"
        print(f"| {n} | {'-' if living is None else f'{living:,}'} | {grow} | {secs:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cells", nargs="*", default=["baseline", "s1-scanner-width"])
    ap.add_argument("--all-phases", nargs="*", default=["baseline"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--fraction", type=float, default=1.0)
    ap.add_argument("--growth", nargs="*", default=None, help="cells: states and time per action of one tree")
    ap.add_argument("--horizon", type=int, default=8)
    args = ap.parse_args()
    if args.growth is not None:
        for cell in args.growth:
            growth(cell, args.horizon)
        return
    for cell in args.cells:
        own_phase(cell, args.repeats)
    for cell in args.all_phases:
        all_phases(cell, args.workers if args.fraction >= 1.0 else 1, args.fraction)


if __name__ == "__main__":
    main()
