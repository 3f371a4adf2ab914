"""The cell simulator: reset, step, snapshot/restore, whole episodes and batches.

It is the ``core.protocols.Simulator`` that searchers see, with the optional abilities ``BatchSimulator``,
``Lookahead``, ``CellRows`` and ``WorkerModel``. A state is a small float64 array (``NS`` entries): copying it
is a snapshot. ``step`` never changes the state it is given, so a search tree can keep states in its nodes and
branch from any of them.

The criterion is the cell's (``cell.spec.criterion``). One with a kernel fast path (``kernel_test``) is
evaluated inside the compiled loop; for any other, every contact of a step is handed to ``criterion.judge``
(``sim.contacts``), and the first unsafe one ends the episode there, exactly as the kernel would.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cellstress.cell.load import Cell, load_cell
from cellstress.core.records import Measures, WorkerPaths
from cellstress.human.body import BODY_PARTS
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.build import Layout, build_layout, with_phase
from cellstress.sim.contacts import ContactModel, step_end_pose
from cellstress.sim.lookahead import Lookahead
from cellstress.sim.records import STOP_PHASES, StepRecord
from cellstress.sim.starts import is_arrival_token, split_start


@dataclass(frozen=True)
class Trace:
    """Per-step metrics of an episode: ``rows[i]`` is laid out as ``sim.layout.ROW``; row 0 is the initial state."""

    rows: np.ndarray
    actions: tuple[int, ...]
    layout: Layout

    @property
    def unsafe(self) -> bool:
        return bool(self.rows[-1, L.M_UNSAFE])

    @property
    def unsafe_row(self) -> int | None:
        hits = np.flatnonzero(self.rows[:, L.M_UNSAFE])
        return int(hits[0]) if hits.size else None

    def record(self, i: int) -> StepRecord:
        return step_record(self.rows[i], self.layout)

    def records(self) -> tuple[StepRecord, ...]:
        return tuple(step_record(r, self.layout) for r in self.rows)


def step_record(row: np.ndarray, layout: Layout) -> StepRecord:
    """One metric row as a named record (made without validation: the row is the simulator's own)."""
    seen = int(row[L.M_SEEN])
    link = int(row[L.M_LINK])
    part = int(row[L.M_PART])
    act = int(row[L.M_ACTION])
    return StepRecord.model_construct(
        step=int(row[L.M_STEP]),
        t=round(float(row[L.M_T]), 9),  # k * dt carries float noise (0.6000000000000001)
        action=layout.worker.action_names[act] if act >= 0 else None,
        x=float(row[L.M_X]),
        y=float(row[L.M_Y]),
        heading_deg=float(np.rad2deg(row[L.M_HEADING])),
        forward_flexion_deg=float(np.rad2deg(row[L.M_FWD])),
        lateral_flexion_deg=float(np.rad2deg(row[L.M_LAT])),
        d_HR=float(row[L.M_D]),
        v_R=float(row[L.M_V]),
        devices=tuple(n for i, n in enumerate(layout.device_names) if seen >> i & 1),
        stop_phase=STOP_PHASES[int(row[L.M_PHASE] if row[L.M_ROBOT] < 1
                                   else row[L.M_XPHASE + int(row[L.M_ROBOT]) - 1])],  # the touched robot's
        robot_link=layout.capsules[link].name if link >= 0 else None,
        body_part=BODY_PARTS[part] if part >= 0 else None,
        robot_point=tuple(float(v) for v in row[L.M_RX:L.M_RZ + 1]),
        human_point=tuple(float(v) for v in row[L.M_HX:L.M_HZ + 1]),
        unsafe=bool(row[L.M_UNSAFE]),
        limbs=limbs_record(row) if layout.worker.articulated else None,
        between=BETWEEN.get(int(row[L.M_SWEPT])),
        contact_t=round(float(row[L.M_TC]), 9) if int(row[L.M_SWEPT]) in BETWEEN else None,
    )


BETWEEN = {1: "contact", 2: "not-ruled-out"}  # M_SWEPT's values (sim.layout.ROW) as StepRecord.between says them


def limbs_record(row: np.ndarray) -> tuple[float, ...]:
    """The articulated worker's drop [m] and arm joints [deg] of a metric row, as StepRecord.limbs keeps them."""
    return (float(row[L.M_DROP]), *(float(np.rad2deg(row[L.M_ARM + j])) for j in range(10)))


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Summary of many episodes: per action end d_HR / v_R (NaN after the episode ended unsafe), the first unsafe
    time step (-1: none), the least d_HR; for a criterion that judges contacts, its severity at each action end."""

    d_end: np.ndarray
    v_end: np.ndarray
    unsafe_step: np.ndarray
    min_d: np.ndarray
    steps_per_action: int
    severity_end: np.ndarray | None = None

    @property
    def unsafe(self) -> np.ndarray:
        return self.unsafe_step >= 0

    @property
    def played(self) -> np.ndarray:
        """Actions played per episode: all of them, or up to the one that reached the unsafe set."""
        return np.where(self.unsafe, -(-self.unsafe_step // self.steps_per_action), self.d_end.shape[1])


class Simulator:
    """The cell's physics. ``Simulator("s1-scanner-width")`` or ``Simulator(load_cell(path))``."""

    def __init__(self, cell: Cell | str | Path | Layout, start: tuple[float, float, float] | None = None):
        """``start`` = (x, y, heading_deg) replaces the cell's start pose (e.g. to test other entry points).

        ``cell`` may also be the ``layout`` of another Simulator, to share its (costly) set-up.
        """
        if isinstance(cell, Layout):
            self.layout = cell
            cell = cell.cell
        else:
            if not isinstance(cell, Cell):
                cell = load_cell(cell)
            self.layout = build_layout(cell)
        self.params = self.layout.params
        self._work = K.make_work(self.params)
        self._handle = K.make_handle(self.params, self._work)
        if start is None:
            s = cell.spec.human.start
            start = (s.xy[0], s.xy[1], s.heading_deg)
        self.start = tuple(float(v) for v in start)
        self._s0 = np.zeros(L.NS)
        self._row0 = np.zeros(L.NM)
        K.reset_state(self.params, self.start[0], self.start[1], float(np.deg2rad(self.start[2])),
                      self._s0, self._work, self._row0)
        self._s0.setflags(write=False)
        self._rows = np.zeros((self.params.spa, L.NM))
        self.criterion = cell.spec.criterion
        # a criterion without a kernel fast path judges the contacts here (sim.contacts)
        self.contacts = None if self.criterion.kernel_test() is not None else ContactModel(self.layout)
        self._worker_w = None
        self._lookahead: dict[tuple[float | None, float], Lookahead] = {}

    def with_start(self, start: tuple[float, float, float], phase: float | None = None) -> Simulator:
        """The same cell with another start pose (x, y, heading_deg) and, if ``phase`` is given, the robot's
        cycle at ``phase`` s when the episode starts; shares this simulator's set-up."""
        if phase is None:
            return Simulator(self.layout, start=start)
        return Simulator(with_phase(self.layout, phase), start=start)

    @property
    def phase(self) -> float:
        """The robot's path time at t = 0 (the cell's ``robot.task.phase`` or a start point's own)."""
        return float(self.params.scal[L.C_PHASE0])

    # ---- facts ------------------------------------------------------------------------------------------
    @property
    def cell(self) -> Cell:
        return self.layout.cell

    @property
    def n_actions(self) -> int:
        return len(self.layout.worker.action_names)

    @property
    def action_names(self) -> tuple[str, ...]:
        """The worker model's actions, in index order."""
        return self.layout.worker.action_names

    def action_index(self, action: int | str) -> int:
        """The index of an action of this cell's worker given by name or index (ActionError otherwise)."""
        return self.layout.worker.action_index(action)

    @property
    def steps_per_action(self) -> int:
        return self.params.spa

    @property
    def actions_per_episode(self) -> int:
        return self.cell.spec.simulation.actions_per_episode

    @property
    def dt(self) -> float:
        return float(self.params.scal[L.C_DT])

    # ---- stepping ---------------------------------------------------------------------------------------
    def reset(self) -> np.ndarray:
        """The initial state s0 (a fresh, writable copy)."""
        return self._s0.copy()

    def initial_metrics(self) -> np.ndarray:
        return self._row0.copy()

    def step(self, state: np.ndarray, action: int | str) -> tuple[np.ndarray, np.ndarray]:
        """Play one action from ``state``: (next state, metric rows of its time steps)."""
        a = action if type(action) is int and 0 <= action < self.n_actions else self.action_index(action)
        nxt = state.copy()
        n = K.step_with_handle(self._handle, nxt, a, self._rows)
        rows = self._rows[:n].copy()
        if self.contacts is not None and n:
            i = self.first_unsafe(rows, state[_POSE_STATE])
            if i is not None:  # the criterion's unsafe step ends the episode there, as the kernel's would
                rows = rows[:i + 1]
                rows[i, L.M_UNSAFE] = 1.0
                nxt[L.S_UNSAFE] = 1.0
                if i < n - 1:
                    _state_at(nxt, state, rows, self.params)
        return nxt, rows

    def step_many(self, states: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """Play one action from each of ``states`` ((n, NS), changed in place: each becomes its next state);
        returns the metric row of each one's last time step ((n, NM); NaN for a state that was already unsafe
        and does not move). The same as ``step`` on each."""
        acts = np.asarray(actions, dtype=np.int64).reshape(-1)
        if states.ndim != 2 or states.shape != (len(acts), L.NS):
            raise ValueError(f"states must be (n, {L.NS}) for n actions")
        out = np.full((len(acts), L.NM), np.nan)
        for i, a in enumerate(acts):
            nxt, rows = self.step(states[i], int(a))
            states[i] = nxt
            if len(rows):
                out[i] = rows[-1]
        return out

    def first_unsafe(self, rows: np.ndarray, before: np.ndarray | None = None) -> int | None:
        """Index of the first row the criterion judges unsafe (contacts only: they are rare). ``before``: the
        worker's pose vector one step before ``rows[0]`` (the state the rows were played from), for the worker's
        speed at a contact in the first row."""
        tol = self.criterion.distance_tolerance
        start = before  # the worker's pose at the start of row i's step
        for i in range(len(rows)):
            if rows[i, L.M_D] <= tol and self.criterion.judge(self.contacts.contact(rows[i], start)).unsafe:
                return i
            start = L.row_pose(rows[i]) if start is None else step_end_pose(rows[i], start, self.dt)
        return None

    def verdict(self, row: np.ndarray, prev: np.ndarray | None = None):
        """The criterion's verdict on a row's closest points (``core.protocols.Verdict``), for a criterion that
        judges contacts; None for one with a kernel fast path. ``prev`` is the metric row one step earlier (the
        worker's speed at the contact comes from the pose change; give it wherever the trace has it, as
        ``Trace.rows[i - 1]``, so that the verdict is the one the simulator judged)."""
        if self.contacts is None:
            return None
        return self.criterion.judge(self.contacts.contact(row, None if prev is None else L.row_pose(prev)))

    def verdict_at(self, trace: Trace, i: int):
        """The verdict on row ``i`` of ``trace``, with the worker's pose at the start of its step as ``first_unsafe``
        has it (a row before it that holds a contact within its step holds that moment's pose, not its step's
        end: ``contacts.step_end_pose``), so that the verdict is the one the simulator judged."""
        if self.contacts is None:
            return None
        start = None
        for j in range(i):
            start = L.row_pose(trace.rows[j]) if start is None else step_end_pose(trace.rows[j], start, self.dt)
        return self.criterion.judge(self.contacts.contact(trace.rows[i], start))

    def measures(self, rows: np.ndarray) -> Measures:
        """What the reward sees of an action: d_HR and v_R at its last step (and the criterion's severity there)."""
        last = rows[-1]
        if self.contacts is None:
            return Measures(float(last[L.M_D]), float(last[L.M_V]))
        prev = L.row_pose(rows[-2]) if len(rows) > 1 else None
        return Measures(float(last[L.M_D]), float(last[L.M_V]),
                        float(self.criterion.severity(self.contacts.contact(last, prev))))

    @staticmethod
    def is_unsafe(state: np.ndarray) -> bool:
        return state[L.S_UNSAFE] != 0.0

    @staticmethod
    def time(state: np.ndarray) -> float:
        return float(state[L.S_K])

    @staticmethod
    def snapshot(state: np.ndarray) -> bytes:
        return state.tobytes()

    @staticmethod
    def restore(snapshot: bytes) -> np.ndarray:
        return np.frombuffer(snapshot, dtype=np.float64).copy()

    def lookahead_model(self, horizon: float | None = None, speed: float = 1.6) -> Lookahead:
        """The predictive-gap score of this cell (``sim.lookahead.Lookahead``): how close the robot, moving on
        along its path for ``horizon`` seconds, comes to a worker's pose, less ``speed`` times the delay."""
        return Lookahead(self.params, horizon, speed)

    def lookahead(self, state: np.ndarray, rows: np.ndarray, horizon: float | None = None,
                  speed: float = 1.6) -> np.ndarray:
        """The predictive gap of each of ``rows`` (``state``: the state after them); plays nothing."""
        key = (horizon, speed)
        la = self._lookahead.get(key)
        if la is None:
            la = self._lookahead[key] = self.lookahead_model(horizon, speed)
        return la.gaps(rows, state[L.S_TSTOP])

    # ---- episodes ---------------------------------------------------------------------------------------
    def run(self, actions) -> Trace:
        """Play a whole action sequence from s0 (stopping at the first unsafe step). A leading ``start:NAME``
        plays it from that start point of the cell's ``human.starts`` (see ``search.multistart``)."""
        if len(actions) and is_arrival_token(actions[0]):
            sim, rest = split_start(self, actions)
            return sim.run(rest)
        acts = np.asarray([self.action_index(a) for a in actions], dtype=np.int64)
        if self.contacts is not None:  # step by step, so that the criterion ends the episode
            state, parts = self.reset(), [self._row0[None, :].copy()]
            for a in acts:
                state, rows = self.step(state, int(a))
                parts.append(rows)
                if self.is_unsafe(state):
                    break
            return Trace(np.concatenate(parts), tuple(int(a) for a in acts), self.layout)
        out = np.zeros((1 + len(acts) * self.params.spa, L.NM))
        n = K.run_episode(self.params, self._s0, acts, out)
        return Trace(out[:n], tuple(int(a) for a in acts), self.layout)

    def run_batch(self, actions: np.ndarray) -> BatchResult:
        """Many episodes at once on all cores; ``actions`` is (episodes, actions) of action indices."""
        acts = _action_array(actions, self.n_actions)
        n_ep, n_act = acts.shape
        d_end = np.empty((n_ep, n_act))
        v_end = np.empty((n_ep, n_act))
        unsafe_step = np.empty(n_ep, dtype=np.int64)
        min_d = np.empty(n_ep)
        if self.contacts is not None:
            return self._judged_batch(acts, d_end, v_end, unsafe_step, min_d)
        K.run_batch(self.params, self._s0, acts, d_end, v_end, unsafe_step, min_d)
        return BatchResult(d_end, v_end, unsafe_step, min_d, self.params.spa)

    def _judged_batch(self, acts, d_end, v_end, unsafe_step, min_d) -> BatchResult:
        """``run_batch`` for a criterion that judges contacts: each episode stepped (the criterion ends it at its
        first unsafe contact), with the criterion's severity at every action end. The numbers are the kernel
        batch's (the determinism check holds stepping and batches to the same bits)."""
        severity = np.full(d_end.shape, np.nan)
        d_end[:], v_end[:] = np.nan, np.nan
        for e in range(len(acts)):
            state, lo = self.reset(), np.inf
            unsafe_step[e] = -1
            for k, a in enumerate(acts[e]):
                state, rows = self.step(state, int(a))
                m = self.measures(rows)
                d_end[e, k], v_end[e, k], severity[e, k] = m.d_hr, m.v_r, m.severity
                lo = min(lo, float(rows[:, L.M_D].min()))
                if self.is_unsafe(state):
                    unsafe_step[e] = int(rows[-1, L.M_STEP])
                    break
            min_d[e] = lo
        return BatchResult(d_end, v_end, unsafe_step, min_d, self.params.spa, severity)

    def worker_paths(self, actions: np.ndarray) -> np.ndarray:
        """The worker's pose vectors (``layout.POSE_ROW``'s order: x, y, heading [rad], forward and lateral
        flexion [rad], the articulated worker's drop and arm joints) at every 50 ms step of each episode of
        ``actions`` (episodes, actions), as if no contact ended it: (episodes, actions * spa, N_POSE).

        The worker's motion depends on the actions and the fixed layout (walls, table, floor) only, never on
        the robot or the devices, so this is exact and plays no episode: the rows of ``run`` hold the same poses
        up to the step where the episode ended."""
        return self.worker_paths_from(actions).poses

    def worker_paths_from(self, actions: np.ndarray, states: np.ndarray | None = None,
                          first: np.ndarray | None = None) -> WorkerPaths:
        """``worker_paths`` with the worker's state as each action begins and as the last ends. Given ``states``
        and ``first``, episode e resumes at its action first[e] from states[e], the state as that action begins
        (a ``WorkerPaths.states`` row of an earlier call): its steps before are NaN, the rest the same poses as
        from s0."""
        acts = _action_array(actions, self.n_actions)
        n, h = acts.shape
        if states is None:
            states, first = np.broadcast_to(self._s0, (n, L.NS)), np.zeros(n, np.int64)
        first = np.ascontiguousarray(first, dtype=np.int64)
        states = np.ascontiguousarray(states, dtype=np.float64)
        if first.shape != (n,) or states.shape != (n, L.NS) or (n and (first.min() < 0 or first.max() > h)):
            raise ValueError(f"first must be (n,) in 0..{h} and states (n, {L.NS}) for n = {n} episodes")
        poses = np.full((n, h * self.params.spa, L.N_POSE), np.nan)
        ends = np.full((n, h + 1, L.NS), np.nan)
        K.worker_paths(self.params, states, first, acts, poses, ends)
        return WorkerPaths(poses, ends)

    def worker_capsules(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The worker's body capsules at each of ``poses`` (n, N_POSE pose vectors): axis ends a, b (n, c, 3) and
        radii r (n, c), c = 6 for the paper's worker (its reach volumes are not capsules), 10 for the
        articulated one (``human.body.CAPSULE_PART`` names them)."""
        poses = np.ascontiguousarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != L.N_POSE:
            raise ValueError(f"poses must be (n, {L.N_POSE})")
        n_caps = int(self.params.body[L.B_N_CAPS])
        a, b = np.empty((len(poses), n_caps, 3)), np.empty((len(poses), n_caps, 3))
        r = np.empty((len(poses), n_caps))
        K.pose_capsules(self.params, poses, self._worker_work(), a, b, r)
        return a, b, r

    def worker_distances(self, poses: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Distance from the worker at each of ``poses`` (n, N_POSE pose vectors, as ``worker_paths`` gives them
        and ``layout.row_pose`` reads them from metric rows) to each of its ``points`` (n, m, 3; NaN rows are
        skipped and give inf): the paper worker's side of d_HR (reach volumes around the walls, body capsules),
        without the robot; for the articulated worker, its reach volumes are the conservative envelope. (n, m)."""
        poses = np.ascontiguousarray(poses, dtype=np.float64)
        points = np.ascontiguousarray(points, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != L.N_POSE or points.ndim != 3 or \
                points.shape[::2] != (len(poses), 3):
            raise ValueError(f"poses must be (n, {L.N_POSE}) and points (n, m, 3)")
        out = np.empty(points.shape[:2])
        K.worker_point_distances(self.params, poses, points, out)
        return out

    def _worker_work(self):
        """Work arrays of the worker-only kernels, made once: separate from the stepping ones, which keep the
        robot's standstill pose between calls."""
        if self._worker_w is None:
            self._worker_w = K.make_work(self.params)
        return self._worker_w


_POSE_STATE = list(L.POSE_STATE)


def _action_array(actions, n_actions: int) -> np.ndarray:
    """``actions`` as a contiguous (episodes, actions) int64 array; ValueError for anything else."""
    acts = np.ascontiguousarray(actions, dtype=np.int64)
    if acts.ndim != 2 or acts.size and (acts.min() < 0 or acts.max() >= n_actions):
        raise ValueError(f"actions must be a 2-D array of indices in 0..{n_actions - 1}")
    return acts


def _state_at(nxt: np.ndarray, before: np.ndarray, rows: np.ndarray, params) -> None:
    """Turn ``nxt``, the state at the end of an action played from ``before``, into the state at the step of
    ``rows[-1]``, where a criterion ended the episode: the clock from that row, the pose at its step's end
    (``contacts.step_end_pose``), and the latches (stops,
    speed reductions, releases) replayed from the devices each row saw, by the kernel's own code
    (``kernels.latch_seen``, as ``kernels.sense_and_measure`` latches them)."""
    row = rows[-1]
    nxt[L.S_K] = row[L.M_STEP]
    nxt[L.S_TSTOP], nxt[L.S_TRIG_DEV], nxt[L.S_TRIG_T] = before[L.S_TSTOP], before[L.S_TRIG_DEV], before[L.S_TRIG_T]
    nxt[L.S_LIVE:] = before[L.S_LIVE:]  # the safeguard slots, appended after ACTIONS
    # the pose at the end of that step (a row holding a contact within its step holds that moment's pose)
    dt = float(params.scal[L.C_DT])
    pose = before[_POSE_STATE]
    for r in rows:
        pose = step_end_pose(r, pose, dt)
    nxt[_POSE_STATE] = pose
    # where a swept test of the next step would start (the row's d_HR, clipped at 0; no step is played from an
    # unsafe state, so the clipping and a contact row's own moment do not matter)
    nxt[L.S_D_SEP] = row[L.M_D]
    for r in rows:
        K.latch_seen(params, nxt, np.int64(r[L.M_SEEN]), float(r[L.M_T]))
