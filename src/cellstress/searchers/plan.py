"""``plan``: model-based search (issue 4, part 6). Learn the robot and its safety devices from the episodes
played, and play the action sequence the model expects to bring the worker closest to the moving robot.

Not one of the paper's searchers (those stay as specified: ``mcts``, ``mcts-commit``). ``evolve`` treats the
simulator as a black box; ``plan`` separates what the searcher controls from what it tests:

* **The worker is the searcher's own agent.** Where an action sequence takes the worker, and how far the
  worker's body and reach volumes are from a given point, depend on the actions and the fixed layout (walls,
  table, floor) only, so they are computed without playing anything (``Simulator.worker_paths``,
  ``Simulator.worker_distances``). For the articulated worker (issue 20), whose d_HR is measured to the body
  capsules and whose arms are posed by its actions, the distance is to those capsules at the pose
  (``Simulator.worker_capsules``), not to the reach volumes: the volumes are the same whatever the arms do, so
  with them every arm action of a candidate predicted alike and the search could not tell a reach over a panel
  from hanging arms. A candidate that begins with a played prefix resumes the worker's path where that prefix
  left it (``ResumableWorker``): its steps are neither walked nor looked up again.
* **The robot system under test is learned** from the metric rows of the episodes played, and from nothing
  else:

  - *the robot*: until a stop takes effect it runs its programmed path, so its pose is a function of time
    alone. The robot point a row names (the one closest to the worker) at time step k therefore lies on the
    robot at step k in every episode that has not been stopped by then. The model keeps these points per
    step, each with its *offset* (the worker's distance to it at the row's pose, less the row's d_HR), and the
    robot's speed v_R at each step. A warning field's reduced speed is taken as part of that path (exact when
    the field trips at the same step in every episode); rows from the first braking on are not (an automatic
    restart resumes the path later than the clock);
  - *the devices*: whether a device sees the worker at a pose (the nearest pose of any row decides), and, per
    device, the time steps from the first detection to braking and to standstill (medians over the episodes
    that showed them; unknown: the robot is taken to keep moving);
  - a played prefix of a sequence is not predicted: its real rows (d_HR, v_R, detections, stop phase) are used.

1. **Start**: ``n_init`` episodes of sticky random actions (each action repeats the previous one with
   probability ``init_sticky``), none played twice, as in ``evolve``.
2. **Candidates**: ``candidates`` sequences not played yet: with probability ``explore`` a sticky random one
   (repeat probability ``sticky``), else a mutation of one of the ``pool`` played episodes whose worker came
   closest to the robot before any device reacted: one action changed at a random position, and the parent's
   remaining actions kept (probability ``keep_tail``) or drawn afresh.
3. **Prediction**: a candidate's *predicted clearance* is the smallest, over its steps after the played prefix,
   before the predicted standstill and at which the robot moves (its v_R above the criterion's tolerance), of the
   worker's distance to the robot points of that step (while braking: of the step the braking began) less their
   offsets. Since those points lie on the robot, a prediction of 0 or less says the worker's reach contains a
   point of the moving robot. The played prefix is not scored: its outcome is known (no hazard), and scoring it
   kept an early version replaying the tails of one close but already stopped prefix.
4. **Play** the candidate with the smallest predicted clearance (ties: at random); learn from its rows; repeat
   from 2 until the budget is used up or the first hazard is found.

Every episode is one action sequence played from s0 and counted, as for the other searchers; what the model
computes plays no episode. It needs a cell's simulator (``SimProblem``) with one start point; on a cell with
several (``all-flaws``) it runs with ``--distinct``, whose slices give each start point its own searches
(``search.slices``). It does not use the slices' ``known_hazard`` hook: a class already found is not steered
away from, so most of a ``--until budget`` run's episodes rediscover known classes.

Defaults (``n_init`` = 2, ``init_sticky`` = 0.9, ``candidates`` = 200, ``explore`` = 0.3, ``sticky`` = 0.3,
``pool`` = 5, ``keep_tail`` = 0.5) were chosen on the three flawed cells, seeds 0-39, budget 200;
docs/results.md gives the numbers and the settings tried.

**Aimed** (``aim``, used by ``cellstress check --witness``): a point the robot sweeps at a known moment, given
beforehand, as the static check finds it (``"T,X,Y,Z"``: at episode time T [s] from the cell's own phase, modulo
the robot's cycle, the robot's surface passes through (X, Y, Z) m; ``"T,X,Y,Z,R"`` for robot R of a cell of
several). The model starts out knowing that point, at offset 0 and moving, at every step of the path that meets
that moment (the nearest step); the rows played teach the rest as before, and replace its speed where they show
the robot's real one there. The ``n_init`` start episodes are then each the best predicted of ``candidates``
sticky random ones instead of the first drawn: a point to go for is known before anything is played. A searched
arrival phase moves robot R's clock with robot 0's (``sim.build.with_phase``).

Randomness: one numpy Generator from ``SeedSequence(seed, spawn_key=(9,))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from cellstress.core.protocols import ResumableWorker, StartChoices, WorkerModel
from cellstress.searchers.common import Recorder, SearchError, number, whole
from cellstress.searchers.evolve import REDRAWS
from cellstress.sim import layout as L

PLAN_KEY = 9
POINT_GRID = 0.02  # robot points closer than this (per coordinate, rounded) are kept as one, with the least offset
POSE_WEIGHTS = (1.0, 1.0, 0.3, 0.4)  # nearest-pose metric: x, y [m]; heading as 0.3 (cos, sin); flexions 0.4/rad
CHUNK = 1_000_000  # capsule-point pairs measured at once (memory of the articulated worker's distances)


@dataclass(frozen=True)
class Aim:
    """A point (x, y, z) [m] on robot ``robot``'s surface at episode time ``time`` [s] from the cell's own phase,
    modulo the robot's cycle (``Plan.aim``)."""

    robot: int
    time: float
    point: tuple[float, float, float]


@dataclass(frozen=True)
class Plan:
    """Options of ``plan``: ``n_init`` start episodes with repeat probability ``init_sticky``; per episode,
    ``candidates`` unplayed sequences, a share ``explore`` of them sticky random (repeat probability
    ``sticky``), the others mutations of the ``pool`` closest played episodes with the tail kept with
    probability ``keep_tail``. See the module docstring."""

    n_init: int = 2
    init_sticky: float = 0.9
    candidates: int = 200
    explore: float = 0.3
    sticky: float = 0.3
    pool: int = 5
    keep_tail: float = 0.5
    aim: str = ""  # "T,X,Y,Z" or "T,X,Y,Z,R": a robot point known beforehand (module docstring); "": none

    name: ClassVar[str] = "plan"
    needs: ClassVar[tuple[type, ...]] = (WorkerModel,)
    whole_episodes: ClassVar[bool] = True  # with --distinct it runs in slices per start point
    paper_name: ClassVar[str | None] = None
    color: ClassVar[str | None] = "#9467bd"

    def __post_init__(self):
        whole("n_init", self.n_init, 1, 1_000_000)
        whole("candidates", self.candidates, 1, 100_000)  # each is a worker path predicted per episode
        whole("pool", self.pool, 1, 10_000)
        for k in ("init_sticky", "explore", "sticky", "keep_tail"):
            number(k, getattr(self, k), 0.0, 1.0)
        self.aimed()

    def aimed(self) -> Aim | None:
        """``aim`` read (SearchError for a malformed one), or None."""
        if not isinstance(self.aim, str):
            raise SearchError(f"aim must be text such as '1.46,0.79,0.75,1.10', not {self.aim!r}")
        if not self.aim.strip():
            return None
        parts = self.aim.split(",")
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(parts) not in (4, 5) or not all(math.isfinite(v) for v in values) or len(values) != len(parts):
            raise SearchError(f"aim must be T,X,Y,Z or T,X,Y,Z,ROBOT (numbers), not {self.aim[:80]!r}")
        t, x, y, z = values[:4]
        number("aim's time", t, 0.0, 1e6)
        for name, v in (("x", x), ("y", y), ("z", z)):
            number(f"aim's {name}", v, -1e4, 1e4)
        robot = values[4] if len(values) == 5 else 0.0
        if robot != int(robot):
            raise SearchError(f"aim's robot must be a whole number, not {parts[4][:20]!r}")
        whole("aim's robot", int(robot), 0, 1000)
        return Aim(int(robot), t, (x, y, z))

    def run(self, problem, reward, rec: Recorder, seed: int) -> None:
        if not isinstance(problem, WorkerModel):
            raise SearchError("plan searches a cell's simulator from one start point (search() gives each start "
                              "point of a cell with several its own searches)")
        rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(PLAN_KEY,)))
        horizon, n_actions = problem.actions_per_episode, problem.n_actions
        # a cell whose arrival phase is searched: the first decision is the phase (multistart.PhaseProblem)
        lead = 1 if isinstance(problem, StartChoices) else 0
        n_first = problem.choices(0) if lead else 0
        model = _Model(problem, lead)
        aim = self.aimed()
        if aim is not None:
            model.know(aim)
        # played sequence -> its least d_HR before any device reacted; a key shorter than the horizon is an
        # episode cut short by a hazard (with until="budget"), which any sequence beginning with it would replay
        closest: dict[tuple[int, ...], float] = {}

        def replays(seq: tuple[int, ...]) -> bool:
            return any(seq[:p] in closest for p in range(1, len(seq) + 1))

        def sticky_tail(actions: list[int], repeat: float) -> list[int]:
            while len(actions) < horizon:
                if len(actions) < lead:
                    actions.append(int(rng.integers(n_first)))
                    continue
                prev = actions[-1] if len(actions) > lead else -1
                actions.append(prev if prev >= 0 and rng.random() < repeat else int(rng.integers(n_actions)))
            return actions

        def play(actions: list[int]) -> None:
            state, ret, risk, unsafe, rows, played = problem.reset(), 0.0, 0.0, False, [], []
            for k, a in enumerate(actions):
                state, r = problem.step(state, a)
                rows.append(np.array(r))
                played.append(a)
                unsafe = bool(problem.is_unsafe(state))
                rw, rk = reward(problem.measures(r), k == horizon - 1, unsafe)
                ret, risk = ret + rw, max(risk, rk)
                if unsafe:
                    break
            rows = np.concatenate(rows)
            model.learn(played, rows)
            running = rows[model.owner_phase(rows) == L.PHASE_RUNNING, L.M_D]
            closest[tuple(played)] = float(running.min()) if len(running) else math.inf
            rec.finish(played, ret, risk, unsafe)  # raises Stop at the end

        def best(cands: set[tuple[int, ...]]) -> list[int]:
            order = np.array(sorted(cands), dtype=np.int64)
            score = model.predict(order)
            ties = np.flatnonzero(score <= score.min())
            return [int(a) for a in order[ties[int(rng.integers(len(ties)))]]]

        for _ in range(self.n_init):
            if aim is not None:  # the model knows a point of the robot already: the start episodes go for it
                starts = {tuple(sticky_tail([], self.init_sticky)) for _ in range(self.candidates)}
                play(best({c for c in starts if not replays(c)} or {tuple(sticky_tail([], 0.0))}))
                continue
            for _ in range(REDRAWS):  # very sticky episodes are often constant sequences: play each once
                actions = sticky_tail([], self.init_sticky)
                if not replays(tuple(actions)):
                    break
            play(actions)
        while True:
            parents = [list(a) for a, _ in sorted(closest.items(), key=lambda kv: kv[1])[: self.pool]]
            cands: set[tuple[int, ...]] = set()
            for _ in range(20 * self.candidates):
                if rng.random() < self.explore:
                    child = sticky_tail([], self.sticky)
                else:
                    parent = parents[int(rng.integers(len(parents)))]
                    j = int(rng.integers(horizon))
                    child = parent[:j] + [int(rng.integers(n_first if j < lead else n_actions))]
                    if rng.random() < self.keep_tail:
                        child += parent[j + 1:]
                    child = sticky_tail(child, self.sticky)
                if not replays(tuple(child)):
                    cands.add(tuple(child))
                    if len(cands) >= self.candidates:
                        break
            if not cands:  # (every sequence near the played ones has been played: a tiny action space)
                cands.add(tuple(sticky_tail([], 0.0)))
            play(best(cands))


class _Model:
    """What ``plan`` has learned of the robot and the devices, and its predictions (module docstring)."""

    def __init__(self, sim, lead: int = 0):
        self.sim = sim
        # ``lead`` = 1: a sequence's first decision is the robot's phase at arrival (``PhaseProblem``); the robot's
        # path then runs from that phase, so what is learned of it is kept per phase step + time step
        self.lead = lead
        self.spa, self.horizon = sim.steps_per_action, sim.actions_per_episode - lead
        self.n_steps = self.horizon * self.spa
        self.offsets = np.asarray([sim.phase_step(c) for c in range(sim.choices(0))] if lead else [0], dtype=np.int64)
        n_path = int(self.offsets.max()) + self.n_steps + 1
        self.v_tol = float(sim.params.scal[L.C_VTOL])
        self.pose_cols = list(L.POSE_ROW)
        # the articulated worker's stance and arms tell apart poses that devices see differently
        self.limb_features = float(sim.params.body[L.B_MODEL]) != 0.0
        # per robot (a cell of several robots: each has its own path, speed and stop)
        self.n_robots = 1 + int(sim.params.x_scal.shape[0])
        # path step -> {cell: (point, offset)}
        self.points: list[list[dict]] = [[{} for _ in range(n_path)] for _ in range(self.n_robots)]
        self.speed = [np.full(n_path, np.nan) for _ in range(self.n_robots)]  # v_R on the path, per path step
        # device mask -> [(to braking, to standstill)]
        self.delays: list[dict[int, list[tuple[int, int]]]] = [{} for _ in range(self.n_robots)]
        # played prefix -> (its rows' count, devices seen per row, first braking and standstill row or -1)
        self.prefixes: dict[tuple[int, ...], tuple[int, np.ndarray, int, int]] = {}
        self.feats: list[np.ndarray] = []
        self.seen: list[np.ndarray] = []
        self._tree = self._by_step = None
        # the worker's actions of a played prefix -> its state as the next action begins: a candidate that shares
        # a played prefix resumes its path there (``ResumableWorker``; about a third of a candidate's steps)
        self.walked: dict[tuple[int, ...], np.ndarray] | None = {} if isinstance(sim, ResumableWorker) else None

    def know(self, aim: Aim) -> None:
        """Take ``aim``'s point as on the moving robot at each path step of its moment (module docstring)."""
        if aim.robot >= self.n_robots:
            raise SearchError(f"aim names robot {aim.robot}; the cell has {self.n_robots}")
        p = self.sim.params
        scal = p.scal if aim.robot == 0 else p.x_scal[aim.robot - 1]
        cycle, dt = float(scal[L.C_CYCLE]), float(p.scal[L.C_DT])
        # path step i is episode time i dt from the cell's phase; with a searched phase (lead), i dt is robot 0's
        # own path time, which the cell's phase is the origin of
        origin = float(p.scal[L.C_PHASE0]) if self.lead else 0.0
        i = np.arange(len(self.points[aim.robot]))
        lag = np.mod(i * dt - origin - aim.time + 0.5 * cycle, cycle) - 0.5 * cycle
        point = np.asarray(aim.point, dtype=float)
        cell = tuple(np.round(point / POINT_GRID).astype(int))
        for k in np.flatnonzero(np.abs(lag) <= 0.5 * dt + 1e-9):
            self.points[aim.robot][k][cell] = (point, 0.0)
            if np.isnan(self.speed[aim.robot][k]):
                self.speed[aim.robot][k] = np.inf  # moving, until a row shows its speed there
        self._by_step = None

    def distances(self, poses: np.ndarray, points: np.ndarray) -> np.ndarray:
        """The worker's side of d_HR from each of ``poses`` (n, N_POSE) to its ``points`` (n, m, 3; NaN: inf): the
        paper worker's reach volumes and body (``worker_distances``); the articulated worker's body capsules."""
        if not self.limb_features:
            return self.sim.worker_distances(poses, points)
        a, b, r = self.sim.worker_capsules(poses)
        out = np.empty(points.shape[:2])
        rows = max(1, CHUNK // max(1, a.shape[1] * points.shape[1]))
        for i in range(0, len(poses), rows):
            out[i:i + rows] = capsule_distances(a[i:i + rows], b[i:i + rows], r[i:i + rows], points[i:i + rows])
        return out

    def _features(self, poses: np.ndarray) -> np.ndarray:
        wx, wy, wh, wf = POSE_WEIGHTS
        cols = [wx * poses[:, 0], wy * poses[:, 1], wh * np.cos(poses[:, 2]), wh * np.sin(poses[:, 2]),
                wf * poses[:, 3], wf * poses[:, 4]]
        if self.limb_features:  # (the drop in metres weighs as x and y; the joints as the trunk's angles)
            cols += [wx * poses[:, L.POSE_EXT], *(wf * poses[:, j] for j in range(L.POSE_EXT + 1, L.N_POSE))]
        return np.column_stack(cols)

    def owner_phase(self, rows: np.ndarray) -> np.ndarray:
        """The stop phase, in each row, of the robot that owns the row's nearest point (robot 0's: one robot)."""
        if self.n_robots == 1:
            return rows[:, L.M_PHASE]
        owner = np.maximum(rows[:, L.M_ROBOT], 0).astype(np.int64)
        cols = np.where(owner == 0, L.M_PHASE, L.M_XPHASE + owner - 1)
        return rows[np.arange(len(rows)), cols]

    def _phase(self, rows: np.ndarray, r: int) -> np.ndarray:
        """Robot r's stop phase in each row (robot 0's is PHASE; the others' are appended)."""
        return rows[:, L.M_PHASE] if r == 0 else rows[:, L.M_XPHASE + r - 1]

    def learn(self, actions: list[int], rows: np.ndarray) -> None:
        if self.walked is not None:
            self._walk(tuple(actions[self.lead:]))
        base = int(self.offsets[actions[0] % len(self.offsets)]) if self.lead else 0
        rows = rows[self.lead:]  # (a first decision's row is the initial state's)
        seen = rows[:, L.M_SEEN].astype(np.int64)
        # (not ``>=``: REDUCED, a warning field's slower running, comes after STOPPED in the phase list)
        phases = [self._phase(rows, r) for r in range(self.n_robots)]
        braking = [np.flatnonzero((ph == L.PHASE_BRAKING) | (ph == L.PHASE_STOPPED)) for ph in phases]
        stopped = [np.flatnonzero(ph == L.PHASE_STOPPED) for ph in phases]
        for p in range(1 + self.lead, len(actions) + 1):
            n = min((p - self.lead) * self.spa, len(rows))
            b = tuple(int(br[0]) if len(br) and br[0] < n else -1 for br in braking)
            s = tuple(int(st[0]) if len(st) and st[0] < n else -1 for st in stopped)
            self.prefixes[tuple(actions[:p])] = (n, seen[:n], b, s)
        # the robot on its path: running (at full or, behind a warning field, reduced speed: taken as part of the
        # path, which is exact when the field trips at the same step in every episode) or with a stop pending,
        # and before any braking (after a stop, an automatic restart resumes the path later than the clock). With
        # several robots, each row teaches about the robot that owns its nearest point, on that robot's own clock.
        for r in range(self.n_robots):
            phase = phases[r]
            upto = int(braking[r][0]) if len(braking[r]) else len(rows)
            keep = (phase[:upto] <= L.PHASE_PENDING) | (phase[:upto] == L.PHASE_REDUCED)
            keep &= rows[:upto, L.M_SWEPT] == 0.0  # a contact between the steps holds the robot at its own moment
            if self.n_robots > 1:
                keep &= rows[:upto, L.M_ROBOT] == r
            on_path = rows[:upto][keep]
            if len(on_path):
                pts = on_path[:, [L.M_RX, L.M_RY, L.M_RZ]]
                reach = self.distances(on_path[:, self.pose_cols], pts[:, None, :])[:, 0]
                for row, point, dist in zip(on_path, pts, reach, strict=True):
                    k = base + int(row[L.M_STEP])
                    self.speed[r][k] = row[L.M_V]
                    cell = tuple(np.round(point / POINT_GRID).astype(int))
                    offset = float(dist - row[L.M_D])
                    old = self.points[r][k].get(cell)
                    if old is None or offset < old[1]:
                        self.points[r][k][cell] = (point, offset)
            if seen.any():
                first = int(np.argmax(seen > 0))
                if len(stopped[r]):
                    self.delays[r].setdefault(int(seen[first]), []).append((int(braking[r][0]) - first,
                                                                            int(stopped[r][0]) - first))
        self.feats.append(self._features(rows[:, self.pose_cols]))
        self.seen.append(seen)
        self._tree = self._by_step = None

    def _walk(self, worker: tuple[int, ...]) -> None:
        """Keep the worker's state as each action of ``worker`` (actions played) begins, and as the last ends."""
        q = len(worker)
        if not q:
            return  # (an episode that ended at its first decision: the worker has not moved)
        while q >= 0 and worker[:q] not in self.walked:
            q -= 1
        if q == len(worker):
            return
        if q < 0:
            paths, q = self.sim.worker_paths_from(np.array([worker], dtype=np.int64)), 0
        else:
            paths = self.sim.worker_paths_from(np.array([worker], dtype=np.int64), self.walked[worker[:q]][None, :],
                                               np.array([q]))
        for a in range(q, len(worker) + 1):
            self.walked[worker[:a]] = paths.states[0, a]

    def _paths(self, seqs: np.ndarray, walked: np.ndarray) -> np.ndarray:
        """The worker's poses for the worker's actions ``seqs`` (n, actions), each resumed after its first
        walked[i] actions where their state is known (the steps before are not needed: NaN)."""
        if not self.walked:
            return self.sim.worker_paths(seqs)
        first = walked.copy()
        states = np.empty((len(seqs), len(self.walked[()])))
        for i, seq in enumerate(seqs.tolist()):
            state = self.walked.get(tuple(seq[: first[i]]))
            if state is None:
                first[i], state = 0, self.walked[()]
            states[i] = state
        return self.sim.worker_paths_from(seqs, states, first).poses

    def _step_points(self, r: int) -> tuple[np.ndarray, np.ndarray]:
        """Robot r's points and offsets of every step, padded with NaN points: (steps + 1, m, 3), (steps + 1, m)."""
        if self._by_step is None:
            self._by_step = [None] * self.n_robots
        if self._by_step[r] is None:
            points = self.points[r]
            m = max(1, max(len(p) for p in points))
            pts = np.full((len(points), m, 3), np.nan)
            off = np.zeros((len(points), m))
            for k, found in enumerate(points):
                for i, (point, offset) in enumerate(found.values()):
                    pts[k, i], off[k, i] = point, offset
            self._by_step[r] = pts, off
        return self._by_step[r]

    def predict(self, seqs: np.ndarray) -> np.ndarray:
        """The predicted clearance of each sequence (module docstring, 3.)."""
        from scipy.spatial import cKDTree

        n, steps = len(seqs), self.n_steps
        seen = np.zeros((n, steps), dtype=np.int64)
        known = np.zeros(n, dtype=np.int64)
        played_brake = np.full((self.n_robots, n), -1)
        played_stop = np.full((self.n_robots, n), -1)
        for i, seq in enumerate(map(tuple, seqs.tolist())):
            p = len(seq) - 1
            while p > 0 and seq[:p] not in self.prefixes:
                p -= 1
            if p:
                known[i], seen_k, played_brake[:, i], played_stop[:, i] = self.prefixes[seq[:p]]
                seen[i, : known[i]] = seen_k
        poses = self._paths(seqs[:, self.lead:], known // self.spa).reshape(-1, L.N_POSE)
        if self.feats:  # (nothing played yet, an aimed start: no device is known to see anything)
            if self._tree is None:
                self._tree = (cKDTree(np.concatenate(self.feats)), np.concatenate(self.seen))
            tree, seen_at = self._tree
            # a played prefix's detections are known: the tree is asked about the steps after it only
            ask = np.flatnonzero((np.arange(steps)[None, :] >= known[:, None]).ravel())
            # (a pose met again, standing at a wall or on a shared path, is asked once: a third of them)
            feats, again = np.unique(self._features(poses[ask]), axis=0, return_inverse=True)
            seen.ravel()[ask] = seen_at[tree.query(feats)[1]][again.ravel()]
        detected = seen.any(axis=1)
        first = (seen > 0).argmax(axis=1)
        mask = seen[np.arange(n), first]
        k = np.arange(steps)[None, :]
        dist = np.full(n * steps, np.inf)
        for r in range(self.n_robots):
            # the stop after the first detection, by the delays learned for the devices that saw the worker first
            # (unknown devices: the robot is taken to keep moving); where the played prefix shows it, as it happened
            brake = np.full(n, steps)
            stop = np.full(n, steps)
            for m in np.unique(mask[detected]):
                delays = self.delays[r].get(int(m))
                if delays:
                    sel = detected & (mask == m)
                    brake[sel] = first[sel] + int(np.median([b for b, _ in delays]))
                    stop[sel] = first[sel] + int(np.median([s for _, s in delays]))
            brake = np.where(played_brake[r] >= 0, played_brake[r], brake)
            stop = np.where(played_stop[r] >= 0, played_stop[r], stop)
            # the robot step each candidate step meets (0-based step k -> row step k + 1; braking: its first step)
            robot_step = np.minimum(k, brake[:, None]) + 1
            if self.lead:
                robot_step = robot_step + self.offsets[seqs[:, 0] % len(self.offsets)][:, None]
            use = (k >= known[:, None]) & (k < stop[:, None]) & (np.nan_to_num(self.speed[r][robot_step]) > self.v_tol)
            pts, off = self._step_points(r)
            which = np.flatnonzero(use.ravel())
            if len(which):
                rs = robot_step.ravel()[which]
                d = self.distances(poses[which], pts[rs]) - off[rs]
                dist[which] = np.minimum(dist[which], d.min(axis=1))
        return dist.reshape(n, steps).min(axis=1)


def capsule_distances(a: np.ndarray, b: np.ndarray, r: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Distance from the surface of the nearest of the capsules (axis ``a``-``b``, (n, c, 3); radii (n, c)) to each
    of ``points`` (n, m, 3), less than 0 inside one: (n, m); inf for a NaN point."""
    ab = b - a
    length2 = np.maximum(np.einsum("ncx,ncx->nc", ab, ab), 1e-18)
    rel = points[:, None, :, :] - a[:, :, None, :]  # (n, c, m, 3)
    t = np.clip(np.einsum("ncmx,ncx->ncm", rel, ab) / length2[:, :, None], 0.0, 1.0)
    gap = rel - t[..., None] * ab[:, :, None, :]
    d = (np.sqrt(np.einsum("ncmx,ncmx->ncm", gap, gap)) - r[:, :, None]).min(axis=1)
    return np.where(np.isnan(d), np.inf, d)
