"""From a validated Cell to the arrays the compiled simulator runs on."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from cellstress.cell.load import Cell
from cellstress.cell.program import held_joints, robot_program
from cellstress.cell.robot_stop import robot_stop
from cellstress.cell.schema import ObstacleSpec, RobotSpec
from cellstress.core import registry
from cellstress.core.errors import CellError
from cellstress.core.protocols import Channels, TimedPanels, WorkerKind
from cellstress.core.records import MAX_DOORS, Channel, DoorLeaf, ScanPlane, VerticalField
from cellstress.devices.base import stops_of
from cellstress.human.actions import PaperWorker
from cellstress.human.body import BodyDimensions
from cellstress.human.reach import ReachField, reach_field
from cellstress.robot.capsules import Capsule, base_footprint, declared_capsule, fitted_capsules
from cellstress.robot.joints import JointMap
from cellstress.robot.model import PRISMATIC, RobotModel, base_matrix, load_robot, resolve_urdf
from cellstress.robot.stopping import RobotStop, hold_radii
from cellstress.robot.trajectory import Trajectory
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.speeds import capsule_speeds

SCANNER, CURTAIN, DOOR = L.DEV_SCANNER, L.DEV_CURTAIN, L.DEV_DOOR  # detection primitive kinds in the kernel


@dataclass(frozen=True)
class DeviceArrays:
    """One row per channel (a device's detection primitive and its effect; one per device unless a device has
    a warning field)."""

    kind: np.ndarray  # (nd,) int64
    response: np.ndarray  # (nd,) s
    rect: np.ndarray  # (nd, 6): vertical field x0 y0 x1 y1 bottom top; scan plane [4] = its height
    poly: np.ndarray  # (nd, 2) int64: start and count of each scan plane's polygon in verts
    verts: np.ndarray  # (V, 2)
    names: tuple[str, ...]
    speed: np.ndarray  # (nd,) 0: the channel stops the robot; SEPARATION: it scales the speed; else the reduced
    # speed's fraction
    clear: np.ndarray  # (nd,) s without detection before its stop or reduction is released; inf: manual
    muted: np.ndarray  # (nd, 2) clock window [on, off] in which the channel sees nothing; (inf, inf): never
    separation: np.ndarray  # (n_sep, 6) each SEPARATION channel's rule: v_h, v_max, T_r, T_s, allowance, its row


def pack_polygons(polys) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate polygons into one vertex array plus (start, count) rows."""
    verts, index = [], []
    for p in polys:
        index.append((len(verts), len(p)))
        verts.extend(p)
    return np.asarray(verts, dtype=float).reshape(-1, 2), np.asarray(index, dtype=np.int64).reshape(-1, 2)


def device_arrays(devices) -> DeviceArrays:
    """The kernel's arrays of the cell's devices, from each device's detection primitive."""
    kinds, resp, rects, polys, names, speed, clear, muted, sep = [], [], [], [], [], [], [], [], []
    for d in devices:
        chans = d.channels() if isinstance(d, Channels) else \
            tuple(Channel(p, d.name, 0.0, d.response_time, np.inf) for p in d.primitives())
        n_sep = sum(c.separation is not None for c in chans)
        if n_sep > 1 or (n_sep == 1 and len(chans) > 1) or \
                (n_sep == 0 and sum(c.speed == 0.0 for c in chans) != 1):
            raise NotImplementedError(f"device {d.name!r}: the kernel takes one stopping primitive per device, or "
                                      "one speed-and-separation channel")
        for c in chans:
            _channel(d, c.primitive, kinds, rects, polys)
            resp.append(c.response_time)
            names.append(c.name)
            rule = c.separation
            speed.append(c.speed if rule is None else L.SEPARATION)
            if rule is not None:
                sep.append((rule.human_speed, rule.max_speed, rule.reaction_time, rule.stopping_time, rule.allowance,
                            len(names) - 1))
            clear.append(c.clear_time)
            muted.append((np.inf, np.inf) if c.muted is None else c.muted)
    verts, index = pack_polygons(polys)
    return DeviceArrays(np.asarray(kinds, dtype=np.int64), np.asarray(resp, dtype=float),
                        np.asarray(rects, dtype=float).reshape(-1, 6), index, verts, tuple(names),
                        np.asarray(speed, dtype=float), np.asarray(clear, dtype=float),
                        np.asarray(muted, dtype=float).reshape(-1, 2), np.asarray(sep, dtype=float).reshape(-1, 6))


def _check_separation(cell: Cell, dev: DeviceArrays, delay_of_robot0: float = 0.0) -> None:
    """The kernel keeps one separation channel's commands, at most SEP_QUEUE - 1 time steps in flight (the
    response time and the robot's controller delay)."""
    spec, rows = cell.spec, dev.separation
    if rows.shape[0] == 0:
        return
    i = next(i for i, d in enumerate(spec.devices) if d.name == dev.names[int(rows[-1, 5])])
    if rows.shape[0] > 1:
        raise CellError(cell.source, f"devices[{i}]", "a cell takes one speed-separation device (not implemented "
                                                      "for several)")
    limit = (L.SEP_QUEUE - 1) * spec.simulation.dt
    delay = delay_of_robot0
    if dev.response[int(rows[0, 5])] + delay > limit + 1e-12:
        extra = f" less the robot's controller delay {delay:g} s" if delay > 0.0 else ""
        raise CellError(cell.source, f"devices[{i}].response_time", f"must be at most {limit:g} s{extra} "
                                                                    f"({L.SEP_QUEUE - 1} time steps of "
                                                                    f"{spec.simulation.dt:g} s)")


def _channel(d, prim, kinds, rects, polys) -> None:
    if isinstance(prim, ScanPlane):
        kinds.append(SCANNER)
        rects.append((0.0, 0.0, 0.0, 0.0, prim.height, prim.height))
        polys.append(prim.polygon)
    elif isinstance(prim, DoorLeaf):
        kinds.append(DOOR)
        rects.append((*prim.start, *prim.end, prim.bottom, prim.top))
        polys.append(())
    elif isinstance(prim, VerticalField):
        kinds.append(CURTAIN)
        rects.append((*prim.start, *prim.end, prim.bottom, prim.top))
        polys.append(())
    else:
        raise TypeError(f"device {d.name!r}: unknown detection primitive {type(prim).__name__}")


@dataclass(frozen=True)
class Layout:
    """Everything the simulator knows about a cell, with the names that go into reports."""

    cell: Cell
    robot: RobotModel
    capsules: tuple[Capsule, ...]
    trajectory: Trajectory
    body: BodyDimensions
    reach: ReachField
    device_names: tuple[str, ...]
    params: K.SimParams
    joints: JointMap  # the joints the program drives; the others are held or mimic ones
    obstacles: tuple[ObstacleSpec, ...] = ()  # the table's polygons, the cell's obstacles, the robots' pedestals
    robots: tuple[RobotPart, ...] = ()  # every robot, robot 0 (robot, capsules' first, trajectory, joints) first
    worker: WorkerKind = PaperWorker()  # the worker model (registry group ``workers``): its actions by name

    @property
    def static_fences(self) -> bool:
        """True when the cell has no guard door and no pallet: every fence panel blocks for the whole episode.
        A door's leaf blocks until it opens (its state slots say when), a pallet while it passes. The verifier's
        bounds ignore fences altogether (they only shorten the worker's reach and walk), so they hold either
        way; whatever assumes fixed panels asks this."""
        return self.params.door_dev.shape[0] == 0 and self.params.panel_fence.shape[0] == 0

    @property
    def stops_latch(self) -> bool:
        """True when every stop holds for the rest of the episode and no device changes a robot's speed
        otherwise (every device restarts manually, none has a warning field or monitors the separation): once a
        robot's latched stop has taken full effect it is at rest for good (each robot of a cell of several by its
        own stop). False with an automatic restart, a warning field or speed and separation monitoring."""
        return bool(np.all(self.params.dev_clear == np.inf) and np.all(self.params.dev_speed == 0.0))

    @property
    def stops_hold(self) -> bool:
        """True when no device that stops a robot restarts it by itself: a latched stop holds for the rest of the
        episode, whatever warning fields or a separation monitor do to the speed before it (their releases and
        commands keep a latched stop's target speed at 0: ``kernels.step.release``, ``kernels.scaling``)."""
        stops = self.params.dev_speed == 0.0
        return bool(np.all(self.params.dev_clear[stops] == np.inf))


PEDESTAL = "robot-pedestal"


def pedestal(rs: RobotSpec, robot: RobotModel, several: bool = False) -> ObstacleSpec | None:
    """The robot's base as an obstacle: its footprint from the floor to the top of its fixed links (named
    ``robot-pedestal``, or ``NAME-pedestal`` in a cell of several robots)."""
    if rs.pedestal == "none":
        return None
    hull, top = base_footprint(robot)
    m = base_matrix(rs.base.xyz, rs.base.yaw_deg)
    world = hull @ m[:2, :2].T + m[:2, 3]
    height = float(m[2, 3]) + top
    if height <= 0.0:
        return None
    name = f"{rs.name}-pedestal" if several else PEDESTAL
    return ObstacleSpec.model_construct(name=name, polygon=tuple(map(tuple, world.tolist())), box=None,
                                        height=height)


def obstacle_arrays(obstacles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices, (start, count) rows, bounding box and height rows) of the obstacles' footprints."""
    feet = [np.asarray(o.footprint(), dtype=float) for o in obstacles]
    verts, index = pack_polygons(feet)
    box = np.asarray([(f[:, 0].min(), f[:, 0].max(), f[:, 1].min(), f[:, 1].max(), o.height)
                      for f, o in zip(feet, obstacles, strict=True)], dtype=float).reshape(-1, 5)
    return verts, index, box



@dataclass(frozen=True)
class RobotPart:
    """One robot of a cell as the simulator holds it: ``Layout.robots``, robot 0 first."""

    name: str
    spec: RobotSpec
    model: RobotModel
    capsules: tuple[Capsule, ...]  # named "NAME:link" in a cell of several robots
    trajectory: Trajectory
    joints: JointMap
    first_capsule: int  # its capsules' first index in Layout.capsules (and the kernel's capsule arrays)
    stop: RobotStop  # how it stops (category, delay, braking; robot.stopping)


def _robot_part(cell: Cell, rs: RobotSpec, first: int, prefix: str, where: str = "robot") -> RobotPart:
    robot = load_robot(resolve_urdf(rs.urdf, cell.files_dir))
    if rs.capsules == "auto":
        caps = list(fitted_capsules(robot))
    else:
        caps = [declared_capsule(robot, c.link, c.link, c.p0, c.p1, c.radius) for c in rs.capsules]
    for i, c in enumerate(rs.extra_capsules):
        caps.append(declared_capsule(robot, f"{c.link}#extra{i}", c.link, c.p0, c.p1, c.radius))
    if prefix:
        caps = [dataclasses.replace(c, name=prefix + c.name) for c in caps]
    traj = robot_program(cell.source, robot, rs, cell.files_dir)
    stop = robot_stop(cell.source, where, rs, robot, traj, cell.files_dir)
    if stop.hold:  # category 0: each capsule grown to hold the arm wherever its joints' brakes stop it
        grow = hold_radii(robot, np.asarray([c.joint for c in caps], dtype=np.int64),
                          np.asarray([c.p0 for c in caps], dtype=float).reshape(-1, 3),
                          np.asarray([c.p1 for c in caps], dtype=float).reshape(-1, 3), np.asarray(stop.travel))
        caps = [dataclasses.replace(c, radius=c.radius + float(g)) for c, g in zip(caps, grow, strict=True)]
    return RobotPart(rs.name, rs, robot, tuple(caps), traj, held_joints(cell.source, robot, rs), first, stop)


def _ancestors(robot: RobotModel) -> np.ndarray:
    nj = robot.n_joints
    anc = np.zeros((nj, nj))
    for i in range(nj):
        j = int(robot.parents[i])
        while j >= 0:
            anc[i, j] = 1.0
            j = int(robot.parents[j])
    return anc


def build_layout(cell: Cell) -> Layout:
    spec = cell.spec
    parts: list[RobotPart] = []
    several = len(spec.robots) > 1
    for i, rs in enumerate(spec.robots):
        first = sum(len(p.capsules) for p in parts)
        parts.append(_robot_part(cell, rs, first, f"{rs.name}:" if several else "",
                                 f"robots[{i}]" if "robots" in spec.model_fields_set else "robot"))
    part0 = parts[0]
    robot, traj, task = part0.model, part0.trajectory, spec.robot.task
    caps = [c for p in parts for c in p.capsules]
    anth = spec.human.anthropometry
    worker = registry.load("workers", spec.human.model)()
    body = BodyDimensions(anth.height, anth.upper_arm, anth.forearm, anth.hand, spec.human.walking_speed,
                          articulated=worker.articulated)
    reach = reach_field(anth.upper_arm, anth.forearm, anth.hand)

    fences = [(a[0], a[1], b[0], b[1], f.bottom, f.top)
              for f in spec.fences for a, b in zip(f.points, f.points[1:], strict=False)]
    peds = tuple(p for p in (pedestal(rs, part.model, several) for rs, part in zip(spec.robots, parts, strict=True))
                 if p is not None)
    obstacles = spec.solid_obstacles() + peds
    obs_verts, obs_poly, obs_box = obstacle_arrays(obstacles)

    dev = device_arrays(spec.devices)
    _check_separation(cell, dev, part0.stop.delay)
    doors = [d for d in range(len(dev.kind)) if dev.kind[d] == DOOR]
    if len(doors) > MAX_DOORS:  # (the cell schema refuses such a cell first)
        raise ValueError(f"{len(doors)} guard doors; the simulator takes at most {MAX_DOORS}")
    door_leaves = [p for d in spec.devices for p in d.primitives() if isinstance(p, DoorLeaf)]
    # a door's leaf is a fence panel after the fences' own while it is closed (kernels.doors)
    door_fence = [len(fences) + i for i in range(len(doors))]
    fences += [tuple(dev.rect[d]) for d in doors]
    # timed panels (a muted curtain's pallet) after them: they block only within their clock windows
    timed = [p for d in spec.devices if isinstance(d, TimedPanels) for p in d.timed_panels()]
    panel_fence = [len(fences) + i for i in range(len(timed))]
    fences += [(*p.start, *p.end, p.bottom, p.top) for p in timed]

    scal = np.zeros(L.N_SCAL)
    scal[L.C_DT] = spec.simulation.dt
    _stop_scalars(scal, part0.stop)
    scal[L.C_PHASE0] = task.phase
    scal[L.C_CYCLE] = traj.cycle
    scal[L.C_LINEAR] = 1.0 if traj.linear else 0.0
    # a criterion without a kernel fast path: the kernel latches no contact (it may be safe), the Simulator judges
    fast = spec.criterion.kernel_test()
    scal[L.C_DTOL] = spec.criterion.distance_tolerance if fast is None else fast.distance_tolerance
    scal[L.C_VTOL] = np.inf if fast is None else fast.speed_tolerance
    scal[L.C_REACH_ORIGIN] = reach.origin
    scal[L.C_REACH_H] = reach.spacing
    scal[L.C_SWEEP] = 1.0  # contact in continuous time between the steps (kernels.sweep)
    act = np.ascontiguousarray(worker.action_table(spec.human.max_forward_flexion_deg,
                                                   spec.human.max_lateral_flexion_deg, anth.height))
    scal[L.C_RHO] = K.worker_radius(body.params(), float(act[:, L.A_DROP].max(initial=0.0)), reach.spacing)

    params = K.SimParams(
        scal=scal,
        spa=int(spec.simulation.steps_per_action),
        act=act,
        body=body.params(),
        base=base_matrix(spec.robot.base.xyz, spec.robot.base.yaw_deg),
        parents=robot.parents.astype(np.int64),
        placements=np.ascontiguousarray(robot.placements),
        axes=np.ascontiguousarray(robot.axes),
        jtype=_joint_kinds(robot),
        anc=_ancestors(robot),
        wp=np.ascontiguousarray(traj.waypoints),
        seg_start=traj.starts.astype(float),
        seg_move=traj.move_times.astype(float),
        seg_dwell=traj.dwells.astype(float),
        cap_joint=np.asarray([c.joint for c in part0.capsules], dtype=np.int64),
        cap_a=np.asarray([c.p0 for c in part0.capsules], dtype=float).reshape(-1, 3),
        cap_b=np.asarray([c.p1 for c in part0.capsules], dtype=float).reshape(-1, 3),
        cap_r=np.asarray([c.radius for c in caps], dtype=float),
        reach=np.ascontiguousarray(reach.values),
        fences=np.asarray(fences, dtype=float).reshape(-1, 6),
        obs_verts=obs_verts,
        obs_poly=obs_poly,
        obs_box=obs_box,
        floor=np.asarray([spec.floor.xmin, spec.floor.xmax, spec.floor.ymin, spec.floor.ymax], dtype=float),
        dev_kind=dev.kind,
        dev_resp=dev.response,
        dev_rect=dev.rect,
        dev_poly=dev.poly,
        dev_verts=dev.verts,
        dev_speed=dev.speed,
        dev_clear=dev.clear,
        door_dev=np.asarray(doors, dtype=np.int64),
        door_fence=np.asarray(door_fence, dtype=np.int64),
        door_open=np.asarray([p.opening_time for p in door_leaves], dtype=float),
        door_lock=np.asarray([1.0 if p.guard_locking else 0.0 for p in door_leaves], dtype=float),
        dev_muted=dev.muted,
        panel_fence=np.asarray(panel_fence, dtype=np.int64),
        panel_win=np.asarray([(p.t_in, p.t_out) for p in timed], dtype=float).reshape(-1, 2),
        pre_ra=np.zeros((0, len(caps), 3)),
        pre_rb=np.zeros((0, len(caps), 3)),
        pre_v=np.zeros(0),
        pre_tau=np.zeros(0),
        cap_robot=np.asarray([r for r, p in enumerate(parts) for _ in p.capsules], dtype=np.int64),
        dev_robots=_device_robots(spec),
        **_other_robot_arrays(spec, parts, scal),
        pre_xv=np.zeros((0, len(parts) - 1)),
        pre_xtau=np.zeros((0, len(parts) - 1)),
        dev_sep=dev.separation,
        cap_speed=np.concatenate([capsule_speeds(p) for p in parts]),
    )
    params = _with_robot_table(params, spec)
    return Layout(cell, robot, tuple(caps), traj, body, reach, dev.names, params, part0.joints, obstacles,
                  tuple(parts), worker)


def _stop_scalars(scal: np.ndarray, stop: RobotStop) -> None:
    """A robot's stop in its scalars: the delay before braking, the braking time, category 0's hold."""
    scal[L.C_STOP_TIME] = stop.braking
    scal[L.C_STOP_DELAY] = stop.delay
    scal[L.C_STOP_HOLD] = 1.0 if stop.hold else 0.0


def _joint_kinds(robot: RobotModel) -> np.ndarray:
    return np.asarray([L.JOINT_PRISMATIC if k == PRISMATIC else L.JOINT_REVOLUTE for k in robot.kinds], dtype=np.int64)


def _device_robots(spec) -> np.ndarray:
    """Per kernel channel (a device's channels in order), the bit mask of the robots its stop stops."""
    names = [r.name for r in spec.robots]
    masks = []
    for d in spec.devices:
        stops = names if stops_of(d) is None else stops_of(d)
        mask = sum(1 << names.index(n) for n in stops)
        n_chan = len(d.channels()) if isinstance(d, Channels) else len(tuple(d.primitives()))
        masks.extend([mask] * n_chan)
    return np.asarray(masks, dtype=np.int64)


def _other_robot_arrays(spec, parts: list[RobotPart], scal: np.ndarray) -> dict[str, np.ndarray]:
    """The x_ fields of SimParams: robots 1.., each padded to the largest joint, waypoint and capsule counts."""
    others = parts[1:]
    nx = len(others)
    njx = max((p.model.n_joints for p in others), default=0)
    nwx = max((len(p.trajectory.starts) + 1 for p in others), default=0)  # +1: the wrap-around row
    ncx = max((len(p.capsules) for p in others), default=0)
    out = {
        "x_scal": np.zeros((nx, L.N_SCAL)), "x_base": np.zeros((nx, 4, 4)),
        "x_parents": np.full((nx, njx), -1, dtype=np.int64), "x_placements": np.tile(np.eye(4), (nx, njx, 1, 1)),
        "x_axes": np.tile(np.array([0.0, 0.0, 1.0]), (nx, njx, 1)),
        "x_jtype": np.full((nx, njx), L.JOINT_REVOLUTE, dtype=np.int64), "x_anc": np.zeros((nx, njx, njx)),
        "x_wp": np.zeros((nx, nwx, njx)), "x_seg_start": np.full((nx, nwx), np.inf),
        "x_seg_move": np.ones((nx, nwx)), "x_seg_dwell": np.zeros((nx, nwx)),
        "x_cap_joint": np.full((nx, ncx), -1, dtype=np.int64), "x_cap_a": np.zeros((nx, ncx, 3)),
        "x_cap_b": np.zeros((nx, ncx, 3)), "x_cap0": np.zeros(nx, dtype=np.int64),
        "x_ncap": np.zeros(nx, dtype=np.int64),
    }
    for r, (rs, p) in enumerate(zip(spec.robots[1:], others, strict=True)):
        m, tr, nj, nw, nc = p.model, p.trajectory, p.model.n_joints, len(p.trajectory.starts), len(p.capsules)
        out["x_scal"][r] = scal
        _stop_scalars(out["x_scal"][r], p.stop)
        out["x_scal"][r, L.C_PHASE0] = rs.task.phase
        out["x_scal"][r, L.C_CYCLE] = tr.cycle
        out["x_scal"][r, L.C_LINEAR] = 1.0 if tr.linear else 0.0
        out["x_base"][r] = base_matrix(rs.base.xyz, rs.base.yaw_deg)
        out["x_parents"][r, :nj] = m.parents
        out["x_placements"][r, :nj] = m.placements
        out["x_axes"][r, :nj] = m.axes
        out["x_jtype"][r, :nj] = _joint_kinds(m)
        out["x_anc"][r, :nj, :nj] = _ancestors(m)
        # the last segment moves to the row after it: the first waypoint again (the padding never starts)
        out["x_wp"][r, :nw, :nj] = tr.waypoints
        out["x_wp"][r, nw:, :nj] = tr.waypoints[0]
        out["x_seg_start"][r, :nw] = tr.starts
        out["x_seg_move"][r, :nw] = tr.move_times
        out["x_seg_dwell"][r, :nw] = tr.dwells
        out["x_cap_joint"][r, :nc] = [c.joint for c in p.capsules]
        out["x_cap_a"][r, :nc] = [c.p0 for c in p.capsules]
        out["x_cap_b"][r, :nc] = [c.p1 for c in p.capsules]
        out["x_cap0"][r], out["x_ncap"][r] = p.first_capsule, nc
    return out


def _with_robot_table(params: K.SimParams, spec) -> K.SimParams:
    """``params`` with the robot before any stop, for every step of an episode (and one spare action)."""
    n_pre = 1 + spec.simulation.steps_per_action * (spec.simulation.actions_per_episode + 1)
    nc, nx = params.cap_r.shape[0], params.x_scal.shape[0]
    pre_ra, pre_rb = np.zeros((n_pre, nc, 3)), np.zeros((n_pre, nc, 3))
    pre_v, pre_tau = np.zeros(n_pre), np.zeros(n_pre)
    pre_xv, pre_xtau = np.zeros((n_pre, nx)), np.zeros((n_pre, nx))
    K.robot_table(params, n_pre, pre_ra, pre_rb, pre_v, pre_tau, pre_xv, pre_xtau)
    return params._replace(pre_ra=pre_ra, pre_rb=pre_rb, pre_v=pre_v, pre_tau=pre_tau, pre_xv=pre_xv,
                           pre_xtau=pre_xtau)


def with_phase(layout: Layout, phase: float) -> Layout:
    """The same cell with the robot's cycle at ``phase`` s when an episode starts (a start point's own
    ``phase``): only the phase scalar and the robot table of the steps before any stop change."""
    if float(phase) == float(layout.params.scal[L.C_PHASE0]):
        return layout
    scal = layout.params.scal.copy()
    scal[L.C_PHASE0] = float(phase)
    # the other robots' clocks move with robot 0's: the worker arrives at another moment of the whole cell
    x_scal = layout.params.x_scal.copy()
    x_scal[:, L.C_PHASE0] += float(phase) - float(layout.params.scal[L.C_PHASE0])
    nc, nx = layout.params.cap_r.shape[0], layout.params.x_scal.shape[0]
    bare = layout.params._replace(scal=scal, x_scal=x_scal, pre_ra=np.zeros((0, nc, 3)), pre_rb=np.zeros((0, nc, 3)),
                                  pre_v=np.zeros(0), pre_tau=np.zeros(0), pre_xv=np.zeros((0, nx)),
                                  pre_xtau=np.zeros((0, nx)))  # as build_layout computes it
    params = _with_robot_table(bare, layout.cell.spec)
    return dataclasses.replace(layout, params=params)
