"""Where and when the worker arrives, as an episode's first decision: one of the start points (``human.starts``)
and one of the robot's phases at arrival (``human.arrival``; ``sim.starts.arrival_phases``).

``ArrivalProblem`` wraps the cell simulator: its state is (choice, simulator state), -1 before the first
decision. The first decision ``a`` is choice ``c = a % C`` of the C = m starts x P phases; ``c`` picks start
``c % m`` and phase ``c // m``. Searchers draw that decision from ``range(max(30, C))`` (``common.first_range``):
with one phase per start (``arrival: fixed``) and 2, 3, 5 or 6 starts a uniform action is a uniform start, as
before phases were searched. Later decisions are the worker's actions. An episode is then 1 + 8 decisions, and
the recorded action sequence begins with ``start:NAME`` (a cell with several start points) and ``phase:SECONDS``
(a cell whose arrival is searched), so that ``Simulator.run`` (and ``cellstress replay``) play exactly the same
episode. The tree searchers widen the root over the C choices only (``choices``: the
``core.protocols.StartChoices`` ability).
"""

from __future__ import annotations

from cellstress.sim.starts import START_PREFIX, arrival_phases, phase_token, start_simulator


class ArrivalProblem:
    """The first decision picks a start point and a phase (module docstring); ``only`` = i keeps the start point
    ``human.starts[i]`` alone (the phase is then the only choice: ``search.slices`` searches each start so)."""

    def __init__(self, sim, only: int | None = None):
        self.sim = sim
        starts = sim.cell.spec.human.starts
        self.starts = starts if only is None else (starts[only],)
        self.searched_phase = sim.cell.spec.human.arrival != "fixed"
        # per start point (or the one start pose): its phases; all starts have as many (1 when fixed)
        points = self.starts or (None,)
        self.phases = [arrival_phases(sim, s) for s in points]
        self.m = len(points)
        self.n_phases = len(self.phases[0])
        self.n_choices = self.m * self.n_phases
        self._sims: dict[int, object] = {}
        self.n_actions = sim.n_actions
        self.actions_per_episode = 1 + sim.actions_per_episode
        self.measures = sim.measures  # the same layout and criterion for every choice

    def choices(self, depth: int) -> int:
        return self.n_choices if depth == 0 else self.n_actions

    def arrival(self, choice: int) -> tuple[int, float]:
        """(start index, robot phase [s]) of a first decision."""
        c = int(choice) % self.n_choices
        i = c % self.m
        return i, self.phases[i][c // self.m]

    def simulator(self, choice: int):
        """The simulator of a first decision (made once, on first use)."""
        c = int(choice) % self.n_choices
        sim = self._sims.get(c)
        if sim is None:
            i, phase = self.arrival(c)
            if self.starts:
                sim = start_simulator(self.sim, self.starts[i], phase)
            else:
                sim = self.sim.with_start(self.sim.start, phase)
            sim = self._sims[c] = sim
        return sim

    @property
    def sims(self) -> list:
        """The simulator of each start point at its first phase (the slices of ``search.slices``)."""
        return [self.simulator(i) for i in range(self.m)]

    def reset(self):
        return (-1, None)

    def step(self, state, action: int):
        c, s = state
        if c < 0:
            c = int(action) % self.n_choices
            sim = self.simulator(c)
            return (c, sim.reset()), sim.initial_metrics()[None, :]
        nxt, rows = self.simulator(c).step(s, action)
        return (c, nxt), rows

    def is_unsafe(self, state) -> bool:
        return state[0] >= 0 and self.sim.is_unsafe(state[1])

    def run(self, actions):
        """The trace of a recorded episode (its first decision written by name or as an index)."""
        return self.sim.run(self.names(actions) if actions and not isinstance(actions[0], str) else actions)

    def names(self, actions) -> list[str]:
        """Recorded decisions as names: ``start:NAME``, ``phase:SECONDS`` and then the worker's actions."""
        acts = list(actions)
        if not acts:
            return []
        i, phase = self.arrival(acts[0])
        head = [START_PREFIX + self.starts[i].name] if self.starts else []
        if self.searched_phase:
            head.append(phase_token(phase))
        return [*head, *(self.sim.action_names[int(a)] for a in acts[1:])]


MultiStartProblem = ArrivalProblem  # its name before the arrival phase was searched


class PhaseProblem(ArrivalProblem):
    """An ``ArrivalProblem`` with one start point: only the robot's phase is chosen. The worker's own motion does
    not depend on the robot, so this problem knows it as the simulator does (``core.protocols.WorkerModel``:
    ``worker_paths`` of the worker's actions, without the first decision)."""

    def __init__(self, sim, only: int | None = None):
        super().__init__(sim, only)
        if self.m != 1:
            raise ValueError("a PhaseProblem has one start point")
        self.steps_per_action = sim.steps_per_action
        self.params = sim.params
        self.dt = sim.dt

    def initial_metrics(self):
        return self.sim.initial_metrics()

    def worker_paths(self, actions):
        return self.sim.worker_paths(actions)

    def worker_paths_from(self, actions, states=None, first=None):
        return self.sim.worker_paths_from(actions, states, first)

    def worker_distances(self, poses, points):
        return self.sim.worker_distances(poses, points)

    def worker_capsules(self, poses):
        return self.sim.worker_capsules(poses)

    def phase_step(self, choice: int) -> int:
        """The robot's phase of a first decision, in time steps."""
        return int(round(self.arrival(choice)[1] / self.dt))
