"""Simulated witnesses of the static check's failing rows (issue 34, part 5: ``check`` and the search agree).

For every row the check fails, one of three answers:

* the row's ``limit`` names what the simulated worker cannot do to take that way in: no search; the static
  verdict stands on the standard's arithmetic alone;
* a ``plan`` search aimed at the row's own geometric witness (``check_rows.RowPoint``: the robot capsule and the
  moment of the cycle where the check found the zone too close, seen from where the worker stands or reaches
  from): ``Plan.aim`` gives the model that point of the moving robot before the first episode. Rows with no such
  point (openings, muting, a configured speed, beam heights) get the same search unaimed;
* a robot program's own faults (``program`` rows) are no way in for a worker and are not searched; where no
  episode can reach the robot at all from the start points (``out_of_reach``), no row is searched and each says
  so.

A hazard witnesses a row only if it takes the row's way in (``CheckRow.way``, ``takes_way``): a device too close
to the zone is witnessed by a contact after that device saw the worker (its stop came too late); an undetected
reach, a reach over a fence and a whole-body opening by a contact no stopping device saw coming; crawling under,
stepping over, a low scanner plane and a short mat by a contact that device did not see; an automatic restart by
a contact after the robot restarted by itself. The search runs to its first hazard; when that one takes another
way in, it runs its whole budget and the first of its hazards that takes the row's way is the witness. Searches
are shared between rows with the same aim, and a row its own search leaves without a witness takes one from
another row's search where one takes its way (a hazard is a hazard, whoever found it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.check_rows import CheckRow, RowPoint
from cellstress.analysis.hazard_zone import SAMPLE_DT, hazard_zone, robot_poses
from cellstress.analysis.plane import point_segment
from cellstress.searchers import search
from cellstress.searchers.plan import Aim
from cellstress.searchers.result import EpisodeRef, SearchResult
from cellstress.searchers.why import STOPPING
from cellstress.sim import layout as L
from cellstress.sim.starts import arrival_phases

SEARCHER = "plan"
AXIS_SAMPLES = 41  # points along the capsule's axis where the one nearest the worker's side is picked


@dataclass(frozen=True)
class RowWitness:
    """A failing check row and what the simulation made of it."""

    row: str  # the check row's name
    limit: str  # what the simulated worker cannot do ('' : searched, or not a way in)
    aim: Aim | None  # the robot point and moment searched for (None: unaimed, or not searched)
    result: SearchResult | None  # the search that decided it (None: not searched)
    witness: EpisodeRef | None  # its first hazard that takes the row's way in (None: none in the budget)
    hazards: int = 0  # hazardous episodes of that search in all (those not this way in included)

    def line(self) -> str:
        res, w = self.result, self.witness
        if res is None:
            return f"{self.row}: {self.limit}" if self.limit else \
                f"{self.row}: a fault of the robot's program, no way in for a worker: not searched"
        if w is None:
            other = f" ({self.hazards} hazardous episodes, none of them this way in)" if self.hazards else ""
            return f"{self.row}: not reproduced in {res.episodes} episodes{other}: the static verdict stands"
        return f"{self.row}: FOUND at episode {w.episode} of {res.budget}: {', '.join(w.actions)}"


def _robot_index(layout, name: str) -> int:
    """The index of the robot ``name`` (a row's ``RowPoint.robot``) in ``layout.robots``; -1 for none ('' : a cell of
    one robot)."""
    names = [p.name for p in layout.robots]
    return names.index(name) if name and name in names else -1


def takes_way(row: CheckRow, layout, records, unsafe_row: int) -> bool:
    """Whether a hazardous episode (its step records, unsafe at ``unsafe_row``) takes ``row``'s way in
    (``CheckRow.way``); in a cell of several robots, a row about one of them asks for a contact with it."""
    before = records[: unsafe_row + 1]
    seen = {name for r in before for name in r.devices}
    robot = _robot_index(layout, row.point.robot) if row.point is not None else -1
    if robot >= 0 and len(layout.robots) > 1 and records[unsafe_row].robot_link not in \
            {c.name for c in layout.robots[robot].capsules}:
        return False  # a row about one robot of several: the contact must be with that one
    if row.way == "late":
        return row.device in seen
    if row.way == "unseen":
        if row.device:
            return row.device not in seen
        # the devices that stop the row's robot (any robot, for a row that names none)
        P = layout.params
        stopping = {n for i, n in enumerate(layout.device_names)
                    if P.dev_speed[i] == 0.0 and (robot < 0 or int(P.dev_robots[i]) >> robot & 1)}
        return not seen & stopping
    if row.way == "restart":
        phases = [r.stop_phase in STOPPING for r in before]
        return any(a and not b for a, b in zip(phases, phases[1:], strict=False))
    return row.way == "any"


def episode_times(sim, ts: np.ndarray, cycle: float) -> np.ndarray:
    """Which of the episode times ``ts`` (from the cell's phase, modulo ``cycle``) some episode meets: those within
    one episode's length after an arrival phase the search can choose (``sim.starts.arrival_phases``, every start
    point's)."""
    spec = sim.cell.spec
    ep = spec.simulation
    length = ep.dt * ep.steps_per_action * ep.actions_per_episode
    phase0 = float(spec.robot.task.phase)
    meets = np.zeros(len(ts), dtype=bool)
    for start in spec.human.starts or (None,):
        for phase in arrival_phases(sim, start):
            meets |= np.mod(ts - (phase - phase0), cycle) <= length + 1e-9
    return meets


def aim_of(sim, point: RowPoint) -> Aim:
    """The robot point of a row's witness: on the axis of its capsule at its moment, the point nearest (across
    the floor) to the worker's side, moved out to the capsule's surface towards it. A moment no episode meets (a
    fixed arrival, and the row's closest approach later in the cycle than one episode reaches), or one at which
    that capsule stands still, would aim at nothing the search can touch: then the nearest point over every
    capsule of that robot at the moments an episode meets and it moves is taken instead (10 ms samples)."""
    layout = sim.layout
    robot = max(_robot_index(layout, point.robot), 0)
    part = [c.name for c in layout.capsules].index(point.part)
    ts, caps, ra, rb = robot_poses(layout.params, SAMPLE_DT, robot=robot)[0]
    cycle = float(layout.robots[robot].trajectory.cycle)
    # (time, capsule) pairs an episode meets with the capsule moving faster than the criterion's standstill (a
    # contact with a robot at rest is none): its ends' speed over the next 10 ms
    speed = np.maximum(np.linalg.norm(np.roll(ra, -1, axis=0) - ra, axis=2),
                       np.linalg.norm(np.roll(rb, -1, axis=0) - rb, axis=2)) / SAMPLE_DT
    usable = episode_times(sim, ts, cycle)[:, None] & (speed > float(layout.params.scal[L.C_VTOL]))
    k = int(np.argmin(np.abs(ts - point.t)))
    j = int(np.flatnonzero(caps == part)[0])
    (x0, y0), (x1, y1) = point.toward
    s = np.linspace(0.0, 1.0, AXIS_SAMPLES)[None, None, :, None]
    times, parts = np.array([k]), np.array([j])
    if not usable[k, j] and usable.any():
        times, parts = np.arange(len(ts)), np.arange(len(caps))
    axis = ra[times][:, parts, None, :] + s * (rb[times][:, parts, None, :] - ra[times][:, parts, None, :])
    d, qx, qy = point_segment(axis[..., 0], axis[..., 1], x0, y0, x1, y1)
    radius = layout.params.cap_r[caps[parts]][None, :, None]
    if len(times) > 1:
        d = np.where(usable[:, :, None], d, np.inf)
    ti, pj, si = np.unravel_index(int(np.argmin(d - radius)), d.shape)
    p = axis[ti, pj, si].copy()
    step = np.array([qx[ti, pj, si] - p[0], qy[ti, pj, si] - p[1]])
    gap = float(np.hypot(*step))
    if gap > 1e-9:
        p[:2] += step / gap * min(float(radius[0, pj, 0]), gap)
    return Aim(robot, float(ts[times[ti]]), (float(p[0]), float(p[1]), float(p[2])))


def aim_text(aim: Aim | None) -> str:
    """``Plan.aim``'s text for ``aim`` ('' for none)."""
    if aim is None:
        return ""
    t, (x, y, z) = aim.time, aim.point
    return f"{t:.4f},{x:.4f},{y:.4f},{z:.4f}" + (f",{aim.robot}" if aim.robot else "")


def out_of_reach(sim) -> str:
    """Why no episode can touch the robot at all ('' when one might): every start point is further from all the
    robot sweeps (its swept floor footprint, ``hazard_zone``) than the worker can walk in one episode plus what a
    body touches from where it stands. That reach is taken as stature + arm length from the hip, more than any
    posture of either worker model gets (lying flat, arms stretched beyond the head), so the claim is safe."""
    spec = sim.cell.spec
    h = spec.human
    starts = [s.xy for s in h.starts] or [h.start.xy]
    zone = hazard_zone(sim.layout)
    gap = min(float(np.min(point_segment(x, y, zone.a[:, 0], zone.a[:, 1], zone.b[:, 0], zone.b[:, 1])[0] - zone.r))
              for x, y in starts)
    ep = spec.simulation
    t = ep.dt * ep.steps_per_action * ep.actions_per_episode
    arm = float(sim.params.body[L.B_ARM_LEN])
    reach = h.anthropometry.height + arm
    if gap <= h.walking_speed * t + reach + 1e-9:
        return ""
    where = "every start point is" if len(starts) > 1 else "the start is"
    return (f"the simulated worker cannot get there in one episode: {where} {gap:.2f} m from all the robot sweeps; "
            f"in {t:g} s at {h.walking_speed:g} m/s, with a reach of {reach:.2f} m (stature + arm), a body touches "
            f"nothing beyond {h.walking_speed * t + reach:.2f} m (a longer episode: simulation.actions_per_episode)")


def witness_searches(sim, rows: tuple[CheckRow, ...], budget: int, seed: int, progress=None, aimed: bool = True
                     ) -> tuple[RowWitness, ...]:
    """Search a simulated witness for every failing row of ``rows`` (``check_rows``) on the cell simulator
    ``sim`` (module docstring): ``plan``, ``budget`` episodes from ``seed``; to the first hazard, and when that
    one does not take the row's way in, the whole budget, whose hazards are then tried in order; a row still
    without a witness then takes the first hazard of the other rows' searches that takes its way.
    ``progress(row name)`` before each row's searches; ``aimed=False`` searches every row unaimed (to measure
    what the aim brings: benchmarks/check_witness.py)."""
    runs: dict[tuple[str, str], SearchResult] = {}
    plays: dict[tuple[str, ...], tuple] = {}

    def run(aim: str, until: str) -> SearchResult:
        if (aim, until) not in runs:
            runs[aim, until] = search(sim, SEARCHER, budget, seed, until=until, aim=aim)
        return runs[aim, until]

    def takes(row: CheckRow, actions: tuple[str, ...]) -> bool:
        if actions not in plays:
            trace = sim.run(list(actions))
            plays[actions] = (trace.records(), trace.unsafe_row)
        records, at = plays[actions]
        return at is not None and takes_way(row, sim.layout, records, at)

    out = []
    far = out_of_reach(sim) if any(not r.ok and r.way and not r.limit for r in rows) else ""
    for r in (r for r in rows if not r.ok):
        if r.limit or not r.way or far:
            out.append(RowWitness(r.name, r.limit or (far if r.way else ""), None, None, None))
            continue
        if progress is not None:
            progress(r.name)
        aim = aim_of(sim, r.point) if aimed and r.point is not None and math.isfinite(r.point.t) else None
        text = aim_text(aim)
        res = run(text, "first")
        if res.hazard is None or takes(r, tuple(res.hazard.actions)):
            out.append(RowWitness(r.name, "", aim, res, None if res.hazard is None else
                                  EpisodeRef(episode=res.hazard.episode, actions=res.hazard.actions), len(res.hazards)))
            continue
        res = run(text, "budget")
        hit = next((h for h in res.hazards if takes(r, tuple(h.actions))), None)
        out.append(RowWitness(r.name, "", aim, res, hit, len(res.hazards)))
    # a hazard is a hazard whichever row's search found it: a row its own search left without a witness takes the
    # first one of the other searches (in the order they ran) that takes its way
    failing = [r for r in rows if not r.ok]
    for i, (r, w) in enumerate(zip(failing, out, strict=True)):
        if w.result is None or w.witness is not None:
            continue
        for res in runs.values():
            hit = next((h for h in res.hazards if takes(r, tuple(h.actions))), None)
            if hit is not None:
                out[i] = RowWitness(r.name, "", w.aim, res, hit, len(res.hazards))
                break
    return tuple(out)
