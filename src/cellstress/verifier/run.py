"""A verification: every (start point, arrival phase) decided, in worker processes if asked, and assembled into
one ``VerifyResult`` in a fixed order (start points as the cell lists them, phases ascending), so the result
does not depend on the number of workers or on which finished first."""

from __future__ import annotations

import multiprocessing
import re
import signal
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from cellstress.cell.load import Cell
from cellstress.core.cpus import check_workers, usable_cpus
from cellstress.core.errors import CellstressError
from cellstress.core.io import OutputPathError
from cellstress.core.jit import numba
from cellstress.core.ray_pool import import_ray, ray_map
from cellstress.core.version import __version__
from cellstress.searchers.distinct import hazard_class, hazard_class_record, root_cause
from cellstress.searchers.result import CellRef
from cellstress.searchers.severity import worst_first
from cellstress.sim.layout import M_STEP, M_T
from cellstress.sim.simulator import Simulator
from cellstress.verifier.arrival import ArrivalCover, arrival_cover, confirm_phases, inflated
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.checkpoint import (
    CHECKPOINT,
    CheckpointWriter,
    DecidedLine,
    FoundLine,
    head_of,
    read_checkpoint,
    remove_checkpoint,
)
from cellstress.verifier.phases import (
    StartPoint,
    arrival_phases,
    chosen_starts,
    parse_phases,
    phases_are_grid,
)
from cellstress.verifier.records import (
    PROVED_SAFE,
    UNDECIDED,
    UNSAFE,
    ClassCount,
    Pruned,
    StaticFailure,
    Subtree,
    VerifyOptions,
    VerifyResult,
    Witness,
)
from cellstress.verifier.scope import build_scope
from cellstress.verifier.tree import MAX_ACTIONS, TreeOutcome, decide
from cellstress.verifier.witness import witness_actions, witness_severity, write_witness

WITNESS_DIR = "witness-{:02d}"
BACKENDS = ("processes", "ray")
MAX_RAY_TASKS = 100_000


class VerifyError(CellstressError):
    """A bad option of a verification (a user error: exit code 2)."""


@dataclass(frozen=True)
class Task:
    """One sub-tree to decide: the cell, a start point, an arrival phase; ``cover``: how the moments within
    its ``window`` (s; 0: the phase alone) are covered."""

    cell: Cell
    start: StartPoint
    phase: float
    options: VerifyOptions
    deadline: float | None  # time.time() after which it is left undecided
    cover: ArrivalCover
    window: float = 0.0


@dataclass(frozen=True)
class Found:
    """A hazard class as one sub-tree found it: its first hit and the sequences of the class there; ``phase``:
    the arrival moment it was played at (the sub-tree's, or one within its window)."""

    key: tuple
    actions: tuple[int, ...]
    step: int
    time_s: float
    sequences: int
    phase: float


@dataclass(frozen=True)
class Decided:
    subtree: Subtree
    found: tuple[Found, ...]


# A per-process cache of the cell's simulators (the model, and the arrival-window model), keyed by the cell's hash
# and criterion: a worker builds the layout (robot, reach field) once for all its sub-trees. A Simulator's
# results never depend on what it ran before.
_SIMS: dict[tuple[str, str, str], Simulator] = {}


def _simulator(cell: Cell, cover: ArrivalCover | None = None) -> Simulator:
    key = (cell.sha256, cell.spec.criterion.type, "" if cover is None else "window")
    sim = _SIMS.get(key)
    if sim is None:
        sim = Simulator(cell) if cover is None else Simulator(inflated(_simulator(cell).layout, cover))
        _SIMS[key] = sim
    return sim


def _found(sim: Simulator, out: TreeOutcome, phase: float) -> dict[tuple, list]:
    """The hazard classes of a tree's hits: key -> [key, first actions, step, time, sequences, phase]."""
    found: dict[tuple, list] = {}
    for hit in out.hits:
        key = hazard_class(sim, hit.state, hit.row)
        if key in found:
            found[key][4] += hit.sequences
        else:
            found[key] = [key, hit.actions, int(hit.row[M_STEP]), round(float(hit.row[M_T]), 9), hit.sequences,
                          phase]
    return found


def _confirm(task: Task, wide: TreeOutcome, found: dict[tuple, list]) -> tuple[int, int]:
    """Replay each hazardous sequence of the arrival-window model at moments across the window, in the model
    itself; one hazardous there is a hazard (its class found at that moment). Returns (confirmed, alarms)."""
    base = _simulator(task.cell)
    cycle = float(base.layout.trajectory.cycle)
    sims = [(p, base.with_start(task.start.pose, p)) for p in confirm_phases(task.phase, task.cover, cycle)]
    confirmed = alarms = 0
    for hit in wide.hits:
        for p, sim in sims:
            trace = sim.run(list(hit.actions))
            if trace.unsafe:
                row = trace.rows[-1]
                state = sim.reset()
                for a in hit.actions:
                    state, _ = sim.step(state, int(a))
                key = hazard_class(sim, state, row)
                if key not in found:
                    found[key] = [key, hit.actions, int(row[M_STEP]), round(float(row[M_T]), 9), 0, p]
                found[key][4] += hit.sequences
                confirmed += hit.sequences
                break
        else:
            alarms += hit.sequences
    return confirmed, alarms


def decide_task(task: Task, progress: Callable[[int], None] | None = None) -> Decided:
    """Decide one sub-tree (runs in a worker process). With an arrival window, the window's model is decided
    first: nothing hazardous there proves the whole window safe; otherwise the phase itself is decided
    exactly, and the window model's hazardous sequences are replayed across the window (``verifier.arrival``)."""
    opts = task.options
    if task.deadline is not None and time.time() > task.deadline:  # not begun: all of it undecided
        total = _simulator(task.cell).n_actions ** opts.horizon
        return Decided(Subtree(start=task.start.name, phase=task.phase, window=task.window, verdict=UNDECIDED,
                               sequences=total, hazardous=0, undecided=total, probability=0.0, states=(),
                               expanded=0, pruned=(), classes=()), ())
    deadline = None if task.deadline is None else time.monotonic() + (task.deadline - time.time())
    sim = _simulator(task.cell).with_start(task.start.pose, task.phase)
    confirmed = alarms = 0
    margin = 0.0
    if task.window > 0.0:
        margin = task.cover.largest
        wide_sim = _simulator(task.cell, task.cover).with_start(task.start.pose, task.phase)
        wide = decide(wide_sim, opts.horizon, Bounds(wide_sim, opts.bounds, opts.horizon), deadline=deadline,
                      progress=progress)
        out = wide
        found: dict[tuple, list] = {}
        if wide.hazardous:  # the phase itself exactly, then the window's alarms replayed
            out = decide(sim, opts.horizon, Bounds(sim, opts.bounds, opts.horizon), deadline=deadline)
            found = _found(sim, out, task.phase)
            if not out.hazardous and not out.timed_out:
                confirmed, alarms = _confirm(task, wide, found)
    else:
        out = decide(sim, opts.horizon, Bounds(sim, opts.bounds, opts.horizon), deadline=deadline,
                     progress=progress)
        found = _found(sim, out, task.phase)
    hazardous = out.hazardous
    verdict = UNSAFE if hazardous or confirmed else UNDECIDED if out.undecided or alarms else PROVED_SAFE
    sub = Subtree(start=task.start.name, phase=task.phase, window=task.window, margin=margin, confirmed=confirmed,
                  alarms=alarms, verdict=verdict, sequences=out.total, hazardous=hazardous, undecided=out.undecided,
                  probability=hazardous / out.total, states=tuple(out.states), expanded=out.expanded,
                  pruned=tuple(Pruned(bound=b, states=out.pruned_states[b], sequences=out.pruned_sequences[b])
                               for b in opts.bounds if b in out.pruned_states),
                  classes=())
    return Decided(sub, tuple(Found(*f) for f in found.values()))


def decide_on_one_thread(task: Task) -> Decided:
    """``decide_task`` in a Ray task, which has no initializer: one numba thread, as a local worker process."""
    numba.set_num_threads(1)
    return decide_task(task)


def _init_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the main process handles Ctrl-C and stops the pool
    numba.set_num_threads(1)  # one thread per worker process: N workers on N cores


def tasks_of(sim: Simulator, options: VerifyOptions, deadline: float | None, cover: ArrivalCover) -> list[Task]:
    """The sub-trees of a verification, in the order of the result."""
    window = cover.half_window if cover.covered and options.moments == "all" and \
        phases_are_grid(sim.cell, options.phases) else 0.0
    return [Task(sim.cell, s, p, options, deadline, cover, window) for s in chosen_starts(sim.cell, options.starts)
            for p in arrival_phases(sim, s, options.phases, options.window)]


def _line(d: Decided) -> DecidedLine:
    """A decided sub-tree as its checkpoint line (``verifier.checkpoint``)."""
    return DecidedLine(task=0, subtree=d.subtree,
                       found=tuple(FoundLine(key=f.key, actions=tuple(int(a) for a in f.actions), step=int(f.step),
                                             time_s=float(f.time_s), sequences=int(f.sequences), phase=float(f.phase))
                                   for f in d.found))


def _decided(line: DecidedLine) -> Decided:
    return Decided(line.subtree, tuple(Found(tuple(f.key), tuple(f.actions), f.step, f.time_s, f.sequences, f.phase)
                                       for f in line.found))


def run_verify(sim: Simulator, options: VerifyOptions, *, workers: int | None = 1, out: str | Path | None = None,
               progress: Callable[[int, int], None] | None = None,
               static_failures: tuple[StaticFailure, ...] = (),
               resumed: Callable[[int, int], None] | None = None, backend: str = "processes",
               address: str | None = None) -> VerifyResult:
    """Decide ``sim``'s cell (see ``cellstress.api.verify``). ``backend``: ``processes`` (``workers`` local
    processes) or ``ray`` (``workers`` Ray tasks at a time, None: the cluster's CPUs; ``address`` of a cluster,
    None: a local one), with the same result. ``progress(sequences decided, of)``; ``out``: a folder
    for ``verify.json`` and one witness per hazard class (``witness-NN/result.json``), and for the checkpoint of
    the sub-trees decided so far (``verifier.checkpoint``), from which a stopped run resumes;
    ``resumed(sub-trees taken from it, of)`` is called once when it held some."""
    cell = sim.cell
    _SIMS[(cell.sha256, cell.spec.criterion.type, "")] = sim
    deadline = None if options.time_limit is None else time.time() + options.time_limit
    cover = arrival_cover(sim, sim.contacts is not None)
    tasks = tasks_of(sim, options, deadline, cover)
    total = len(tasks) * sim.n_actions ** options.horizon
    journal = None if out is None else Path(out) / CHECKPOINT
    head = head_of(cell.sha256, cell.spec.criterion.type, options, len(tasks), __version__)
    done: dict[int, Decided] = {}
    if journal is not None:
        journal.parent.mkdir(parents=True, exist_ok=True)
        done = {i: _decided(line) for i, line in
                read_checkpoint(journal, head, [(t.start.name, t.phase) for t in tasks], sim.n_actions).items()}
        if done and resumed is not None:
            resumed(len(done), len(tasks))
    decided_sequences = [sum(d.subtree.sequences for d in done.values())]

    def tick(n: int) -> None:
        decided_sequences[0] += n
        if progress is not None:
            progress(decided_sequences[0], total)

    if done:
        tick(0)
    todo = [i for i in range(len(tasks)) if i not in done]
    if backend != "ray" and workers is None:
        workers = usable_cpus()
    writer = None if journal is None else CheckpointWriter(journal, head)

    def keep(i: int, d: Decided) -> None:
        done[i] = d
        if writer is not None:
            writer.add(i, _line(d))

    try:
        if backend == "ray":
            # workers: Ray tasks at a time (None: as many as the cluster has CPUs)
            for k, d in ray_map(decide_on_one_thread, [tasks[i] for i in todo], max_in_flight=workers,
                                address=address, error=VerifyError):
                keep(todo[k], d)
                tick(d.subtree.sequences)
        elif min(workers or 1, len(todo)) <= 1:
            for i in todo:
                keep(i, decide_task(tasks[i], tick))
        else:
            # spawned, not forked: numba's thread pool in this process makes a fork unsafe. Never a process without
            # a sub-tree to decide.
            with ProcessPoolExecutor(max_workers=min(workers, len(todo)), initializer=_init_worker,
                                     mp_context=multiprocessing.get_context("spawn")) as pool:
                futures = {pool.submit(decide_task, tasks[i]): i for i in todo}
                try:
                    for f in as_completed(futures):
                        keep(futures[f], f.result())
                        tick(done[futures[f]].subtree.sequences)
                except BaseException:
                    pool.shutdown(wait=True, cancel_futures=True)  # the sub-trees under way finish; none begins
                    raise
    finally:
        if writer is not None:
            writer.close()
    result = assemble(sim, options, tasks, [done[i] for i in range(len(tasks))], out, static_failures)
    if journal is not None and not result.undecided:
        remove_checkpoint(journal)
    return result


def assemble(sim: Simulator, options: VerifyOptions, tasks: list[Task], decided: list[Decided],
             out: str | Path | None, static_failures: tuple[StaticFailure, ...] = ()) -> VerifyResult:
    """The result of the decided sub-trees: hazard classes numbered worst first (``searchers.severity``; ties in
    the order first found), their witnesses written (if ``out``)."""
    cell = sim.cell
    classes: dict[tuple, dict[str, Any]] = {}
    for task, d in zip(tasks, decided, strict=True):
        for f in d.found:
            c = classes.get(f.key)
            if c is None:
                c = classes[f.key] = {"task": task, "found": f, "sequences": 0}
                c["actions"] = witness_actions(sim, task.start, f.phase, f.actions)
                c["severity"] = witness_severity(sim, c["actions"])
            c["sequences"] += f.sequences
    for i, c in enumerate(worst_first(list(classes.values()), key=lambda c: c["severity"])):
        c["index"] = i
    subtrees = [d.subtree.model_copy(update={"classes": tuple(
        ClassCount(klass=classes[f.key]["index"], sequences=f.sequences) for f in d.found)}) for d in decided]
    witnesses = []
    for c in sorted(classes.values(), key=lambda c: c["index"]):
        task, f, actions = c["task"], c["found"], c["actions"]
        rel = f"{WITNESS_DIR.format(c['index'] + 1)}/result.json"
        if out is not None:
            write_witness(sim, actions, Path(out), WITNESS_DIR.format(c["index"] + 1))
        klass = hazard_class_record(f.key)
        witnesses.append(Witness.model_construct(
            klass=klass, root_cause=root_cause(klass), start=task.start.name, phase=f.phase,
            actions=actions, step=f.step, time_s=f.time_s, sequences=c["sequences"], file=rel,
            severity=c["severity"]))
    hazardous = sum(s.hazardous for s in subtrees)
    undecided = sum(s.undecided for s in subtrees)
    alarms = sum(s.alarms for s in subtrees)
    unsafe = any(s.verdict == UNSAFE for s in subtrees)
    starts = tuple(dict.fromkeys(t.start.name for t in tasks))
    grid = bool(tasks) and phases_are_grid(cell, options.phases)
    scope = build_scope(sim, options, tasks[0].cover if tasks else arrival_cover(sim, sim.contacts is not None),
                        grid, starts, tuple(sorted({t.phase for t in tasks})))
    pruned: dict[str, list[int]] = {}
    for s in subtrees:
        for p in s.pruned:
            acc = pruned.setdefault(p.bound, [0, 0])
            acc[0] += p.states
            acc[1] += p.sequences
    source = cell.source if cell.directory is None else str(Path(cell.source).expanduser().resolve())
    result = VerifyResult(
        cell=CellRef(name=cell.name, sha256=cell.sha256, source=source, criterion=cell.spec.criterion.type,
                     files=cell.files),
        options=options, dt=sim.dt, cycle=float(sim.layout.trajectory.cycle), scope=scope,
        verdict=UNSAFE if unsafe else UNDECIDED if undecided or alarms else PROVED_SAFE,
        sequences=sum(s.sequences for s in subtrees), hazardous=hazardous, undecided=undecided, alarms=alarms,
        states=sum(sum(s.states) for s in subtrees),
        pruned=tuple(Pruned(bound=b, states=v[0], sequences=v[1]) for b, v in pruned.items()),
        subtrees=tuple(subtrees), classes=tuple(witnesses), version=__version__,
        static_failures=tuple(static_failures))
    if out is not None:
        result.write(out)
    return result



def check_witness_folders(out: Path) -> None:
    """Refuse, before any work, an output folder whose witness folders are links or files (planted there: a
    witness is never written through one, ``core.io.write_in_folder``); OutputPathError naming it."""
    if not out.is_dir():
        return
    for entry in sorted(out.iterdir()):
        if re.fullmatch(r"witness-\d+", entry.name) and (entry.is_symlink() or not entry.is_dir()):
            kind = "a symbolic link" if entry.is_symlink() else "not a folder"
            raise OutputPathError(f"{entry}: is {kind}; cellstress never writes through a link or over a file "
                                  f"inside its output folder {out} (remove it, or use another folder)")


def check_backend(backend: str, address: str | None, workers: int | None) -> None:
    """VerifyError (one line) for a backend, cluster address or number of workers that cannot be used here."""
    if backend not in BACKENDS:
        raise VerifyError(f"--backend must be one of {', '.join(BACKENDS)}, not {backend[:40]!r}")
    if address is not None and backend != "ray":
        raise VerifyError("--address is the address of a Ray cluster: use it with --backend ray")
    if backend == "ray":
        import_ray(VerifyError)
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                    or not 1 <= workers <= MAX_RAY_TASKS):
            raise VerifyError(f"--workers must be a whole number in 1..{MAX_RAY_TASKS} (Ray tasks at a time), not "
                              f"{workers!r}")
        return
    try:
        check_workers(workers, "--workers")
    except CellstressError as exc:
        raise VerifyError(str(exc)) from None


def verify_cell(sim: Simulator, *, horizon: int | None = None, phases: str = "all", moments: str = "all",
                starts: tuple[str, ...] | None = None,
                time_limit: float | None = None, bounds: tuple[str, ...] | None = None, workers: int | None = 1,
                out: str | Path | None = None, progress: Callable[[int, int], None] | None = None,
                static_failures: tuple[StaticFailure, ...] = (),
                resumed: Callable[[int, int], None] | None = None, backend: str = "processes",
                address: str | None = None) -> VerifyResult:
    """``run_verify`` with its options checked: VerifyError (a user error) for a bad one. ``phases``: ``all``,
    ``cell`` or a window ``A:B`` [s] of the robot's cycle; ``starts``: the start points to decide (None: every
    one). ``static_failures``: the cell's failing ``check`` rows (``cellstress.analysis.check_rows
    .static_failures``), kept in the result. ``backend``, ``address``: as ``run_verify``."""
    try:
        mode, window = parse_phases(phases)
        fields: dict[str, Any] = {"horizon": sim.actions_per_episode if horizon is None else horizon,
                                  "phases": mode, "moments": moments, "window": window,
                                  "starts": tuple(starts or ())}
    except ValueError as exc:
        raise VerifyError(str(exc)) from None
    if time_limit is not None:
        fields["time_limit"] = time_limit
    if bounds is not None:
        fields["bounds"] = tuple(bounds)
    try:
        options = VerifyOptions.model_validate(fields, strict=False)
    except ValidationError as exc:
        e = exc.errors(include_url=False)[0]
        where = ".".join(str(p) for p in e["loc"])
        raise VerifyError(f"{where + ': ' if where else ''}{e['msg'].removeprefix('Value error, ')}") from None
    check_backend(backend, address, workers)
    try:
        for s in chosen_starts(sim.cell, options.starts):
            arrival_phases(sim, s, options.phases, options.window)
    except (CellstressError, ValueError) as exc:
        raise VerifyError(str(exc)) from None
    if out is not None:
        check_witness_folders(Path(out))
    if sim.n_actions > MAX_ACTIONS:  # (no built-in worker has more: the paper's 30, the articulated 119)
        raise VerifyError(f"verify decides at most {MAX_ACTIONS} actions per decision; this cell's worker has "
                          f"{sim.n_actions} (human.model)")
    return run_verify(sim, options, workers=workers, out=out, progress=progress, static_failures=static_failures,
                      resumed=resumed, backend=backend, address=address)
