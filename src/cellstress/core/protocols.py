"""The four contracts cellstress and its plug-ins build on: Simulator, Device, Criterion and Searcher.

Each is a ``typing.Protocol``: a plug-in satisfies it by having the attributes and methods below, without
inheriting from anything of ours. A plug-in is registered under its kind's entry-point group
(``core.registry``); docs/extending.md shows a complete example of each.

* **Simulator**: what a searcher sees. A deterministic, episodic problem: ``reset`` gives s0, ``step`` is
  pure (it never changes the state it is given, so a search tree may keep states and branch from any),
  ``is_unsafe`` is the unsafe-set test, ``measures`` summarises an action for the reward, and ``run`` plays a
  whole action sequence and returns its trace. Optional abilities are separate protocols below (batches,
  start points, the worker model, lookahead, the rows of a cell, pictures); a searcher names those it needs
  (``Searcher.needs``) and tests the others with ``isinstance``.
* **Device**: a safety device kind. Its parameter model is the device record itself (a frozen pydantic model
  with a ``type`` tag that names it in cell files); it gives the compiled kernel its detection primitives
  (``core.records.ScanPlane``, ``VerticalField``), its ISO 13855 minimum distance, and how it is described
  and drawn.
* **Criterion**: what is unsafe, and the reward that steers a search there. Also a frozen pydantic model
  with a ``type`` tag. Either a kernel fast path (``kernel_test``: unsafe iff d_HR and v_R pass two
  tolerances, evaluated in the compiled loop) or ``judge(contact)`` for every contact.
* **Searcher**: a frozen dataclass whose fields are its options; ``run(problem, reward, recorder, seed)``
  plays episodes and reports each to the recorder, which stops it when the budget is spent.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from cellstress.core.records import (
    Channel,
    Contact,
    IsoDistance,
    KernelTest,
    Measures,
    Primitive,
    TimedPanel,
    WorkerPaths,
)


# ---- rewards and recorders ----------------------------------------------------------------------------------
@runtime_checkable
class Reward(Protocol):
    """The reward of one action: ``(reward, risk)`` from its measures; ``last_action`` says whether it ended the
    episode's horizon, ``unsafe`` whether it reached the unsafe set. Returns are undiscounted sums."""

    def __call__(self, measures: Measures, last_action: bool, unsafe: bool) -> tuple[float, float]: ...


@runtime_checkable
class SafetyIndexReward(Reward, Protocol):
    """A reward built on the paper's safety index c_S(d_HR, v_R): searchers may score time steps with it."""

    def safety_index(self, d_hr: float, v_r: float) -> float: ...


@runtime_checkable
class Recorder(Protocol):
    """Counts a searcher's episodes against the budget: ``finish`` once per episode (it raises
    ``search.common.Stop`` when the search is over); ``left`` is the number of episodes still allowed."""

    @property
    def left(self) -> int: ...

    def finish(self, actions: Sequence[int], ret: float, risk: float, unsafe: bool) -> Any: ...


# ---- the simulator and its optional abilities ---------------------------------------------------------------
@runtime_checkable
class Trace(Protocol):
    """A played episode: per-time-step ``rows``, whether it ended unsafe, and at which row."""

    rows: np.ndarray

    @property
    def unsafe(self) -> bool: ...

    @property
    def unsafe_row(self) -> int | None: ...


@runtime_checkable
class Simulator(Protocol):
    """What a searcher sees (see the module docstring)."""

    n_actions: int
    actions_per_episode: int

    def reset(self) -> Any: ...

    def step(self, state: Any, action: int) -> tuple[Any, np.ndarray]: ...

    def is_unsafe(self, state: Any) -> bool: ...

    def measures(self, rows: np.ndarray) -> Measures: ...

    def run(self, actions: Sequence[int]) -> Trace: ...


@runtime_checkable
class BatchMeasures(Protocol):
    """Many episodes' measures at every action end (``[episode, action]``; NaN after an unsafe end)."""

    d_end: np.ndarray
    v_end: np.ndarray

    @property
    def severity_end(self) -> np.ndarray | None: ...

    @property
    def played(self) -> np.ndarray: ...

    @property
    def unsafe(self) -> np.ndarray: ...


@runtime_checkable
class BatchSimulator(Protocol):
    """Plays many whole episodes from s0 at once (e.g. on all cores); the same outcome as stepping each."""

    def run_batch(self, actions: np.ndarray) -> BatchMeasures: ...


@runtime_checkable
class StartChoices(Protocol):
    """The first decision of an episode is not a worker action (e.g. a start point): ``choices(depth)`` is the
    number of decisions at that depth."""

    def choices(self, depth: int) -> int: ...


@runtime_checkable
class Lookahead(Protocol):
    """A predictive score per time step: how close the robot, moving on along its path, comes to the worker
    (``sim.lookahead``); it plays nothing."""

    def lookahead(self, state: Any, rows: np.ndarray, horizon: float | None, speed: float) -> np.ndarray: ...


@runtime_checkable
class CellRows(Protocol):
    """Its rows are the cell simulator's metric rows (``sim.layout``), one per time step, so a searcher may read
    d_HR, v_R, the stop phase and the robot point of every step."""

    steps_per_action: int

    def initial_metrics(self) -> np.ndarray: ...


@runtime_checkable
class WorkerModel(CellRows, Protocol):
    """The worker's own motion is known without playing: the poses of many action sequences, and the worker's
    side of d_HR to given points (``Simulator.worker_paths``, ``worker_distances``)."""

    def worker_paths(self, actions: np.ndarray) -> np.ndarray: ...

    def worker_distances(self, poses: np.ndarray, points: np.ndarray) -> np.ndarray: ...


@runtime_checkable
class ResumableWorker(WorkerModel, Protocol):
    """The worker's motion resumed part way: each sequence from the state an earlier call gave for the start of
    one of its actions (``WorkerPaths.states``), so a sequence that shares its first actions with one already
    computed does not walk them again (``Simulator.worker_paths_from``)."""

    def worker_paths_from(self, actions: np.ndarray, states: np.ndarray | None = None,
                          first: np.ndarray | None = None) -> WorkerPaths: ...


@runtime_checkable
class NoveltyAware(Protocol):
    """Distinct mode: tells whether an unsafe episode repeats a hazard class already found."""

    def known_hazard(self, actions: Sequence[int]) -> bool: ...


@runtime_checkable
class Revisiting(Protocol):
    """Distinct mode: a tree search calls ``revisit(node)`` when it comes back to an unsafe node."""

    def revisit(self, node: Any) -> None: ...


# ---- plug-in kinds ------------------------------------------------------------------------------------------
@runtime_checkable
class Searcher(Protocol):
    """A search strategy (see the module docstring). ``needs``: the ability protocols a problem must have
    (``plan`` needs ``WorkerModel``); ``whole_episodes``: it plays whole episodes from s0, so ``--distinct``
    may run it in slices per start point; ``paper_name``: its name in Huck et al. 2020 (the campaign's default
    experiment), or None; ``color``: its colour in reports, or None (one is picked)."""

    name: ClassVar[str]
    needs: ClassVar[tuple[type, ...]]
    whole_episodes: ClassVar[bool]
    paper_name: ClassVar[str | None]
    color: ClassVar[str | None]

    def run(self, problem: Simulator, reward: Reward, recorder: Recorder, seed: int) -> None: ...


@runtime_checkable
class WorkerKind(Protocol):
    """A model of the worker (registry group ``workers``; a cell picks one with ``human.model``): its actions,
    by name, and the table the compiled simulator moves it by (``human.actions.ACT_COLUMNS``). ``articulated``
    selects the kernels' pose of the arms: hanging arms with reach volumes (False) or jointed arms (True)."""

    articulated: ClassVar[bool]
    action_names: tuple[str, ...]

    def action_index(self, action: int | str) -> int: ...

    def action_table(self, max_forward_deg: float, max_lateral_deg: float, stature: float) -> np.ndarray: ...

    def action_words(self, action: str, short: bool = False) -> str: ...


@runtime_checkable
class Device(Protocol):
    """A safety device of a cell (see the module docstring). Upon detection it requests a stop that takes
    effect after ``response_time``."""

    type: str
    name: str
    response_time: float
    detection_phrase: ClassVar[str]  # what the worker does when it sees them, e.g. "breaks the light curtain"

    def primitives(self) -> tuple[Primitive, ...]: ...

    def required_distance(self, stopping_time: float) -> IsoDistance: ...

    def describe(self) -> str: ...

    def draw(self, ax: Any, color: str) -> Any: ...


@runtime_checkable
class Channels(Protocol):
    """A device whose detections do more than latch a stop for good (``devices.base.DeviceRecord``: an automatic
    restart, a warning field's speed reduction): what the kernel senses, primitive by primitive. A device
    without it gives its ``primitives``, each stopping the robot until a manual reset."""

    def channels(self) -> tuple[Channel, ...]: ...


@runtime_checkable
class TimedPanels(Protocol):
    """A device that brings moving material with it (a muted light curtain's pallet): panels that block like
    fence panels during windows of the cell's clock (``core.records.TimedPanel``)."""

    def timed_panels(self) -> tuple[TimedPanel, ...]: ...


@runtime_checkable
class Verdict(Protocol):
    """A criterion's judgement of one contact: unsafe or not, why, and its numbers for the result file."""

    @property
    def unsafe(self) -> bool: ...

    @property
    def reason(self) -> str | None: ...

    def summary(self) -> str: ...

    def as_dict(self) -> dict[str, Any]: ...


@runtime_checkable
class Criterion(Protocol):
    """What is unsafe (see the module docstring). ``distance_tolerance``: a contact is d_HR at or below it;
    ``speed_tolerance``: the robot moves when v_R is above it."""

    type: str
    distance_tolerance: float
    speed_tolerance: float

    def describe(self) -> str:
        """One sentence for people: what this criterion calls unsafe (reports and the command line name it)."""
        ...

    def kernel_test(self) -> KernelTest | None: ...

    def judge(self, contact: Contact) -> Verdict: ...

    def severity(self, contact: Contact) -> float | None: ...

    def reward(self, horizon: int) -> Reward: ...
