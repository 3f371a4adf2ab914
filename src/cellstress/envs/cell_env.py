"""A cell as a Gymnasium env: the paper's worker acts, the cell's criterion rewards, the unsafe set terminates.

* **Action**: ``Discrete(n)``, the worker model's actions (``Simulator.action_names``: the paper's 30 ``WALK+BODY``,
  the articulated worker's 119 ``MOVE+CHANGE``; one action is 0.2 s).
* **Observation** (float64, 11 values): time [s], x, y [m], cos and sin of the heading, forward and lateral
  flexion [rad], the robot's stop phase (0 running, 1 stop requested, 2 braking, 3 stopped), d_HR [m], v_R
  [m/s] and the robot's path time [s], all at the action's last 50 ms step; for the articulated worker 11 more:
  its hip's drop [m] and the ten arm joints [rad].
* **Reward**: the cell criterion's (``Criterion.reward``): for the paper's, 1/c_S after each action and -c_S at
  the horizon.
* **terminated** when the episode reaches the unsafe set; **truncated** after ``actions_per_episode`` actions.
* **info**: ``d_HR``, ``v_R``, ``risk``, ``stop_phase``, ``devices`` (the devices that see the worker),
  ``unsafe``, and ``arrival``: the robot's path time [s] at the worker's arrival.
* **Arrival** (``human.arrival``): ``fixed`` arrives at the cell's phase (or the start point's) every episode;
  ``cycle`` or a window draws the arrival moment at each ``reset`` from the moments a search chooses from
  (``sim.starts.arrival_phases``: the time steps of the cycle or the window), uniformly, with the env's
  ``np_random``, so the same reset seed gives the same moment.

The env is deterministic given the reset's seed (with ``arrival: fixed`` the seed changes nothing), so
``gymnasium.utils.env_checker.check_env`` passes. ``CellVectorEnv`` steps ``num_envs`` copies with one call of
the simulator's batched step (``Simulator.step_many``); finished copies reset themselves on the next step
(Gymnasium's next-step autoreset).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv

from cellstress.cell.load import Cell, load_cell, with_criterion
from cellstress.sim import layout as L
from cellstress.sim.simulator import STOP_PHASES, Simulator
from cellstress.sim.starts import arrival_phases, start_simulator

N_OBS = 11


def _start(c: Cell, start: str | None):
    """The ``human.starts`` entry named ``start`` (None: the cell's ``human.start``)."""
    if start is None:
        return None
    for s in c.spec.human.starts:
        if s.name == start:
            return s
    known = ", ".join(s.name for s in c.spec.human.starts) or "none"
    raise ValueError(f"unknown start {start!r} (the cell's starts: {known})")


def _simulator(cell: str | Path | Cell, criterion: str | None, start: str | None) -> Simulator:
    c = cell if isinstance(cell, Cell) else load_cell(cell)
    sim = Simulator(with_criterion(c, criterion))
    s = _start(c, start)
    return sim if s is None else start_simulator(sim, s)


class Arrivals:
    """The simulators of a cell at each arrival moment ``reset`` may draw (made when first drawn, then kept)."""

    def __init__(self, cell: str | Path | Cell, criterion: str | None, start: str | None):
        c = cell if isinstance(cell, Cell) else load_cell(cell)
        self.base = Simulator(with_criterion(c, criterion))
        self.start = _start(c, start)
        self.fixed = c.spec.human.arrival == "fixed"
        self.default = self.base if self.start is None else start_simulator(self.base, self.start)
        self.phases = (self.default.phase,) if self.fixed else arrival_phases(self.base, self.start)
        self._sims: dict[float, Simulator] = {}

    def draw(self, rng: np.random.Generator) -> Simulator:
        """The default simulator (``arrival: fixed``), else the one at a moment drawn uniformly by ``rng``."""
        if self.fixed:
            return self.default
        phase = self.phases[int(rng.integers(len(self.phases)))]
        sim = self._sims.get(phase)
        if sim is None:
            sim = self._sims[phase] = start_simulator(self.base, self.start, phase) if self.start is not None \
                else self.base.with_start(self.base.start, phase)
        return sim


def observation_space(sim: Simulator, latest_phase: float | None = None) -> spaces.Box:
    """The bounds of every observation of this cell (see the module docstring). d_HR and v_R get sound bounds:
    no robot point is further from the base than the chain's length L (joint offsets and capsule ends), so
    d_HR <= the floor's diagonal + |base to floor| + L, and v_R <= L times the sum of the joint speed limits
    (the path never exceeds a joint's limit). ``latest_phase``: the latest arrival moment reset may draw (the
    path time's bound; default the simulator's own phase)."""
    fl, hs, lay = sim.cell.spec.floor, sim.cell.spec.human, sim.layout
    t_max = sim.dt * sim.steps_per_action * sim.actions_per_episode
    fwd, lat = np.deg2rad(hs.max_forward_flexion_deg), np.deg2rad(hs.max_lateral_flexion_deg)
    P = sim.params
    reach = float(np.linalg.norm(P.placements[:, :3, 3], axis=1).sum()
                  + max(np.linalg.norm(np.r_[P.cap_a, P.cap_b], axis=1).max(initial=0.0) + P.cap_r.max(initial=0.0),
                        0.0))
    bx, by, bz = P.base[:3, 3]
    corner = max(np.hypot(x - bx, y - by) for x in (fl.xmin, fl.xmax) for y in (fl.ymin, fl.ymax))
    d_max = float(np.hypot(corner, abs(bz) + 3.0) + reach)
    v_max = float(reach * np.abs(lay.robot.velocity_limits).sum())
    low = np.array([0.0, fl.xmin, fl.ymin, -1.0, -1.0, 0.0, -lat, 0.0, 0.0, 0.0, 0.0])
    last = sim.phase if latest_phase is None else latest_phase
    high = np.array([t_max, fl.xmax, fl.ymax, 1.0, 1.0, fwd, lat, 3.0, d_max, v_max, last + t_max])
    if sim.layout.worker.articulated:  # its stance [m] and arm joints [rad] (human.reach's ranges lie within)
        low = np.r_[low, -lay.body.height, np.full(10, -np.pi)]
        high = np.r_[high, 0.5, np.full(10, np.pi)]
    return spaces.Box(low, high, dtype=np.float64)


def observe(row: np.ndarray, limbs: bool = False) -> np.ndarray:
    """The observation of one metric row (``limbs``: with the articulated worker's stance and arm joints)."""
    h = row[L.M_HEADING]
    obs = np.array([row[L.M_T], row[L.M_X], row[L.M_Y], np.cos(h), np.sin(h), row[L.M_FWD], row[L.M_LAT],
                    row[L.M_PHASE], row[L.M_D], row[L.M_V], row[L.M_TAU]], dtype=np.float64)
    return np.r_[obs, row[L.M_DROP:L.M_DROP + 11]] if limbs else obs


class CellEnv(gymnasium.Env):
    """One cell (a built-in name, a cell file or a ``Cell``); ``criterion`` overrides the cell's, ``start``
    names one of the cell's ``human.starts`` (default: its ``human.start``)."""

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, cell: str | Path | Cell = "baseline", criterion: str | None = None,
                 start: str | None = None):
        self.arrivals = Arrivals(cell, criterion, start)
        self.sim = self.arrivals.default
        self._limbs = self.sim.layout.worker.articulated
        self.action_space = spaces.Discrete(self.sim.n_actions)
        self.observation_space = observation_space(self.sim, max(self.arrivals.phases))
        self.reward_of = self.sim.criterion.reward(self.sim.actions_per_episode)
        self._state = self.sim.reset()
        self._played = 0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        self.sim = self.arrivals.draw(self.np_random)
        self._state = self.sim.reset()
        self._played = 0
        row = self.sim.initial_metrics()
        return observe(row, self._limbs), self._info(row, 0.0)

    def step(self, action):
        if not self.action_space.contains(action):
            raise ValueError(f"action {action!r} is not in {self.action_space}")
        state, rows = self.sim.step(self._state, int(action))
        self._state = state
        self._played += 1
        unsafe = self.sim.is_unsafe(state)
        last = self._played >= self.sim.actions_per_episode
        reward, risk = self.reward_of(self.sim.measures(rows), last, unsafe)
        row = rows[-1]
        return observe(row, self._limbs), float(reward), bool(unsafe), bool(last and not unsafe), self._info(row, risk)

    def _info(self, row: np.ndarray, risk: float) -> dict[str, Any]:
        seen = int(row[L.M_SEEN])
        return {"d_HR": float(row[L.M_D]), "v_R": float(row[L.M_V]), "risk": float(risk),
                "stop_phase": STOP_PHASES[int(row[L.M_PHASE])], "unsafe": bool(row[L.M_UNSAFE]),
                "devices": [n for i, n in enumerate(self.sim.layout.device_names) if seen >> i & 1],
                "arrival": float(self.sim.phase)}


class CellVectorEnv(VectorEnv):
    """``num_envs`` copies of a cell, stepped together (see the module docstring). Every copy arrives at the
    cell's own moment (its phase), also where the cell says ``arrival: cycle``: copies at different moments would
    need a simulator each, not one batched step."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 1, cell: str | Path | Cell = "baseline", criterion: str | None = None,
                 start: str | None = None):
        self.sim = _simulator(cell, criterion, start)
        self._limbs = self.sim.layout.worker.articulated
        self.num_envs = int(num_envs)
        self.single_action_space = spaces.Discrete(self.sim.n_actions)
        self.action_space = spaces.MultiDiscrete(np.full(self.num_envs, self.sim.n_actions))
        self.single_observation_space = observation_space(self.sim)
        self.observation_space = gymnasium.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        self.reward_of = self.sim.criterion.reward(self.sim.actions_per_episode)
        self._states = np.repeat(self.sim.reset()[None, :], self.num_envs, axis=0)
        self._played = np.zeros(self.num_envs, dtype=np.int64)
        self._done = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        self._states[:] = self.sim.reset()
        self._played[:] = 0
        self._done[:] = False
        row = self.sim.initial_metrics()
        obs = np.repeat(observe(row, self._limbs)[None, :], self.num_envs, axis=0)
        return obs, {}

    def step(self, actions):
        acts = np.asarray(actions, dtype=np.int64).reshape(self.num_envs)
        if acts.min() < 0 or acts.max() >= self.sim.n_actions:
            raise ValueError(f"actions must be in 0..{self.sim.n_actions - 1}")
        s0, row0 = self.sim.reset(), self.sim.initial_metrics()
        restart = self._done.copy()
        self._states[restart] = s0
        self._played[restart] = 0
        moving = ~restart
        rows = np.full((self.num_envs, row0.shape[0]), np.nan)
        states = self._states[moving]
        rows[moving] = self.sim.step_many(states, acts[moving])  # the last row of each
        self._states[moving] = states
        self._played[moving] += 1
        obs = np.empty((self.num_envs, N_OBS))
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        horizon = self.sim.actions_per_episode
        for i in range(self.num_envs):
            if restart[i]:  # next-step autoreset: this step only resets the copy
                obs[i] = observe(row0, self._limbs)
                continue
            unsafe = self.sim.is_unsafe(self._states[i])
            last = self._played[i] >= horizon
            rewards[i] = self.reward_of(self.sim.measures(rows[i:i + 1]), bool(last), bool(unsafe))[0]
            terminated[i], truncated[i] = unsafe, last and not unsafe
            obs[i] = observe(rows[i], self._limbs)
        self._done = terminated | truncated
        return obs, rewards, terminated, truncated, {}
