"""The episode a report shows, replayed through the simulator: per-step records plus the geometry behind them.

The report never trusts pictures to the numbers in result.json alone: it plays the actions again with
``Simulator.run`` (bit-exact, see ``cellstress replay``) and asks ``sim.scene`` for the robot and body capsules
of every step, so a picture shows exactly what the simulator measured.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from cellstress.core.io import json_ready
from cellstress.searchers.result import SearchResult
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.build import Layout
from cellstress.sim.records import StepRecord
from cellstress.sim.simulator import Simulator


@dataclass(frozen=True, eq=False)
class EpisodeView:
    """One replayed episode. ``records[i]`` is ``Trace.records()[i]``; row 0 is the start."""

    layout: Layout
    start: tuple[float, float, float]  # x, y, heading [deg]
    actions: tuple[str, ...]
    records: tuple[StepRecord, ...]
    taus: np.ndarray  # robot path time per row
    episode: int | None  # the episode's number in the search (1-based), None if not from a search
    kind: str  # "hazard" (the first hazard found) or "riskiest" (no hazard: the riskiest kept episode)
    matches_file: bool | None  # the replay agrees bit-exactly with the trace in result.json (None: no trace)

    @property
    def unsafe(self) -> bool:
        return bool(self.records[-1].unsafe)

    @property
    def dt(self) -> float:
        return float(self.layout.cell.spec.simulation.dt)

    @property
    def steps_per_action(self) -> int:
        return int(self.layout.cell.spec.simulation.steps_per_action)

    @cached_property
    def key_row(self) -> int:
        """The unsafe row; without one, the row of highest risk 1/c_S (the closest call)."""
        if self.unsafe:
            return len(self.records) - 1
        risks = [risk(r) for r in self.records]
        return int(np.argmax(risks))

    @cached_property
    def detection_row(self) -> int | None:
        """The first row at which a device sees the worker."""
        return next((i for i, r in enumerate(self.records) if r.devices), None)

    def action_rows(self, k: int) -> range:
        """Rows played by action k (0-based)."""
        spa = self.steps_per_action
        return range(1 + k * spa, min(1 + (k + 1) * spa, len(self.records)))

    def pose(self, i: int) -> scene.BodyPose:
        r = self.records[i]
        return scene.body_pose(self.layout, L.pose_vector(
            r.x, r.y, math.radians(r.heading_deg), math.radians(r.forward_flexion_deg),
            math.radians(r.lateral_flexion_deg), step_limbs(r)))

    def robot(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        return scene.robot_capsules(self.layout, self.taus[i])

    def reach(self, i: int, side: int, stride: int = 1, pose: scene.BodyPose | None = None) -> np.ndarray:
        nodes = self._nodes.get(stride)
        if nodes is None:  # the same nodes serve every step: computed once per episode
            nodes = self._nodes[stride] = scene.reach_nodes(self.layout, stride)
        return scene.reach_points(self.layout, pose if pose is not None else self.pose(i), side, stride, nodes)

    @cached_property
    def _nodes(self) -> dict[int, np.ndarray]:
        return {}

    @property
    def capsule_radii(self) -> np.ndarray:
        return self.layout.params.cap_r


def _json(records) -> str:
    return json.dumps(json_ready([r.model_dump() for r in records]), sort_keys=True)


def risk(record: StepRecord) -> float:
    """1/c_S of a step (the search's risk): exp(v_R) / (d_HR^2 + 1)."""
    d, v = record.d_HR, record.v_R
    if d is None or v is None:
        return 0.0
    return math.exp(v) / (d * d + 1.0)


def step_limbs(record: StepRecord) -> np.ndarray | None:
    """The articulated worker's drop [m] and arm joints [rad] of a step record (None: the paper's worker)."""
    if record.limbs is None:
        return None
    return np.array([record.limbs[0], *np.deg2rad(record.limbs[1:])])


def replay(sim: Simulator, actions, *, episode: int | None = None, kind: str = "hazard",
           recorded: tuple[StepRecord, ...] | None = None) -> EpisodeView:
    """Play ``actions`` from the simulator's start and keep what a report needs. A leading ``start:NAME``
    (a cell with several start points) is played from that start, with its robot phase."""
    from cellstress.sim.starts import split_start

    sim, actions = split_start(sim, actions)
    trace = sim.run(list(actions))
    records = trace.records()
    matches = None
    if recorded is not None:
        matches = _json(records) == _json(recorded)
    # the actions actually played: an unsafe step ends the episode and drops the actions after it
    n_played = -(-(len(records) - 1) // sim.steps_per_action)
    acts = tuple(sim.action_names[sim.action_index(a)] for a in list(actions)[:n_played])
    taus = scene.path_times(trace.rows, len(sim.layout.robots))
    return EpisodeView(sim.layout, sim.start, acts, tuple(records), taus, episode, kind,
                       matches)


def episode_of(result: SearchResult, sim: Simulator) -> EpisodeView:
    """The first hazard of a search; with none, the riskiest of its kept top episodes."""
    h = result.hazard
    if h is not None:
        return replay(sim, h.actions, episode=h.episode, kind="hazard", recorded=h.trace)
    if not result.top:
        raise ValueError("the result holds no episode to show")
    best = max(result.top, key=lambda e: (e.risk if e.risk is not None else -math.inf, -e.episode))
    return replay(sim, best.actions, episode=best.episode, kind="riskiest")
