"""Many distinct hazards in one run (``until="budget"``, ``distinct=True``; CLI ``--until budget --distinct``).

**Classes.** A hazard's class is the key (device bypassed, robot link, body region, approach cell):

* device bypassed: the device whose stop came too late (the one that latched the stop), or ``none`` when no
  device saw the worker (a way around the safeguards, as in S3);
* robot link: the link whose capsule was touched;
* body region: the ISO/TS 15066 region of the contact point (``human.regions.body_region``; the reach
  volumes count as hand or forearm), so left and right hands are one class;
* approach cell: the 0.5 m floor cell under the worker at the unsafe step (``floor(x / 0.5), floor(y / 0.5)``),
  so the same flaw reached from two sides of the cell is two classes, but small changes of posture are not.

**Root causes.** Classes are fine-grained on purpose (the search steers away from each); for people they are
grouped by root cause (``root_cause``: the safeguard that failed and the body area), so one curtain standing
too close reads as one cause with several classes (links, hand or forearm, floor cells), not as several
findings.

**Moving on.** Once a class is found, reaching it again earns no hazard reward: the unsafe end is rewarded as a
safe end of the episode would be (the terminal penalty), both for new episodes (``DistinctReward``) and for the
tree nodes that already led there (their cached reward is lowered when the tree comes back to them, so the
subtree's Q value falls and the search turns elsewhere). Rediscoveries are still counted as hazardous episodes.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.protocols import StartChoices
from cellstress.core.records import Measures
from cellstress.human.regions import body_region, region_group
from cellstress.searchers.common import Recorder, Stop
from cellstress.searchers.result import HazardClass
from cellstress.sim.layout import M_HX, M_HZ, M_LINK, M_PART, M_TAU, M_X, M_Y, S_TRIG_DEV, row_pose
from cellstress.sim.scene import body_pose

CELL_SIZE = 0.5


def hazard_class(sim, state, row) -> tuple:
    """The class key of an unsafe step (``row``: its metric row; ``state``: the simulator state after it)."""
    lay = sim.layout
    dev = int(state[S_TRIG_DEV])
    device = lay.device_names[dev] if dev >= 0 else "none"
    link = lay.capsules[int(row[M_LINK])].name
    pose = body_pose(lay, row_pose(row))
    b = lay.body
    region = body_region(int(row[M_PART]), row[M_HX:M_HZ + 1], pose, b.height, b.upper_arm, b.forearm)
    key = (device, link, region, math.floor(row[M_X] / CELL_SIZE), math.floor(row[M_Y] / CELL_SIZE))
    if sim.cell.spec.human.arrival == "fixed":
        return key
    # the arrival is searched: the same contact in another move of the robot's program is another class
    traj = lay.trajectory
    move = int(np.searchsorted(traj.starts, float(row[M_TAU]) % traj.cycle, side="right"))
    return (*key, max(move, 1))


def link_group(layout, link: str) -> str:
    """Where along the robot's chain a link sits: ``base side``, ``middle`` or ``wrist and tool`` (thirds of the
    chain by the joint a capsule rides on), so that one flaw hit by the forearm in one episode and by the
    upper arm in the next is one root cause, on any serial robot."""
    joints = {c.name: c.joint for c in layout.capsules}
    # (several robots: the chain of the robot that owns the link)
    owner = next((p.model for p in layout.robots if any(c.name == link for c in p.capsules)), layout.robot)
    n = max(owner.n_joints, 1)
    j = joints.get(link, -1) + 1  # 0: the base, n: the last joint
    third = 3 * j / (n + 1)
    return "base side" if third < 1 else "middle" if third < 2 else "wrist and tool"


def root_cause(klass: HazardClass) -> tuple[str, str]:
    """A distinct class's root cause: the safeguard that failed (``none``: no device saw the worker) and the body
    area touched. Classes that share it differ only in detail (the robot link and where along the chain it sits,
    hand or forearm, where the worker stood); ``cellstress search --distinct`` lists them under their cause."""
    return klass.device, region_group(klass.body_region)


def hazard_class_record(key: tuple) -> HazardClass:
    """The class key of ``hazard_class`` as the result file's record."""
    device, link, region, cx, cy = key[:5]
    return HazardClass.model_construct(device=device, robot_link=link, body_region=region,
                                       approach_cell=(cx * CELL_SIZE, cy * CELL_SIZE, (cx + 1) * CELL_SIZE,
                                                      (cy + 1) * CELL_SIZE),
                                       robot_move=key[5] if len(key) > 5 else None)


class DistinctProblem:
    """Wraps a problem; its states are (inner state, class or None, reward if the class is already known)."""

    def __init__(self, problem, sim, reward):
        self.base = problem
        self.sim = sim
        self.reward = reward
        self.n_actions = problem.n_actions
        self.actions_per_episode = problem.actions_per_episode
        self.found: set = set()
        self.last_class = None

    def run(self, actions):
        return self.base.run(actions)

    def _sim_state(self, inner):
        return inner[1] if isinstance(inner, tuple) else inner

    def reset(self):
        return (self.base.reset(), None, 0.0)

    def step(self, state, action):
        inner = state[0]
        nxt, rows = self.base.step(inner, action)
        cls, r_known = None, 0.0
        if self.base.is_unsafe(nxt):
            cls = hazard_class(self.sim, self._sim_state(nxt), rows[-1])
            r_known = self.reward(self.base.measures(rows), True, False)[0]
        self.last_class = cls
        return (nxt, cls, r_known), rows

    def is_unsafe(self, state) -> bool:
        return self.base.is_unsafe(state[0])

    def measures(self, rows) -> Measures:
        return self.base.measures(rows)._replace(
            repeat=self.last_class is not None and self.last_class in self.found)

    def revisit(self, node) -> None:
        """The tree came back to an unsafe node: if its class is known by now, it no longer pays."""
        self.last_class = node.state[1]
        if node.state[1] in self.found:
            node.r = min(node.r, node.state[2])


class DistinctReward:
    """The base reward, except that an unsafe end of an already found class counts as a safe end."""

    def __init__(self, base):
        self.base = base

    def __call__(self, measures: Measures, last_action: bool, unsafe: bool) -> tuple[float, float]:
        if unsafe and measures.repeat:
            return self.base(measures, True, False)
        return self.base(measures, last_action, unsafe)


class DistinctRecorder(Recorder):
    """Also keeps the first episode of each hazard class, in the order found."""

    def __init__(self, *args, problem: DistinctProblem, **kwargs):
        super().__init__(*args, **kwargs)
        self.problem = problem
        self.classes: dict = {}

    def finish(self, actions, ret, risk, unsafe):
        if self.episodes >= self.budget:
            raise Stop
        if unsafe:
            cls = self.problem.last_class
            if cls is not None and cls not in self.classes:
                self.classes[cls] = (self.episodes + 1, tuple(int(a) for a in actions))
                self.problem.found.add(cls)
        return super().finish(actions, ret, risk, unsafe)


class DistinctStartProblem(DistinctProblem):
    """A ``DistinctProblem`` over a problem whose first decision picks a start point (``StartChoices``)."""

    def choices(self, depth: int) -> int:
        return self.base.choices(depth)


def distinct_problem(problem, sim, reward) -> DistinctProblem:
    """The distinct-mode wrapper of ``problem``, with its start-point choices if it has them."""
    cls = DistinctStartProblem if isinstance(problem, StartChoices) else DistinctProblem
    return cls(problem, sim, reward)
