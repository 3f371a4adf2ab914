"""The arrays the kernels run on: ``SimParams`` (one per cell, built by ``sim.build``) and ``Work`` (scratch
space, one set per thread of stepping)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.layout import MAX_CAPSULES, NM, NS

SWEEP_DEPTH = 5  # the swept test halves a step this often on separation's values (1/32 of a step)
SWEEP_CERTIFIED = 5  # then this often more on certified lower bounds (1/1024 of a step)
SWEEP_STACK = SWEEP_DEPTH + SWEEP_CERTIFIED + 2  # intervals waiting at most: one per level, and one being split


class SimParams(NamedTuple):
    scal: np.ndarray  # (N_SCAL,) laid out as sim.layout.SCALARS
    spa: int  # steps per action
    act: np.ndarray  # (n_actions, N_ACT_COLUMNS) laid out as human.actions.ACT_COLUMNS
    body: np.ndarray  # (N_BODY_PARAMS,) laid out as sim.layout.BODY_PARAMS
    base: np.ndarray  # (4, 4) robot base in the world
    parents: np.ndarray  # (nj,) int64
    placements: np.ndarray  # (nj, 4, 4)
    axes: np.ndarray  # (nj, 3)
    jtype: np.ndarray  # (nj,) int64, layout.JOINT_KINDS
    anc: np.ndarray  # (nj, nj) float: 1 where column joint moves row joint's origin
    wp: np.ndarray  # (nw, nj) waypoints, every joint (mimic and held ones included)
    seg_start: np.ndarray  # (nw,) when segment i's dwell begins, strictly increasing from 0
    seg_move: np.ndarray  # (nw,) its move's duration
    seg_dwell: np.ndarray  # (nw,) its dwell at waypoint i before the move
    cap_joint: np.ndarray  # (nc,) int64, -1 = base
    cap_a: np.ndarray  # (nc, 3)
    cap_b: np.ndarray  # (nc, 3)
    cap_r: np.ndarray  # (nc,)
    reach: np.ndarray  # (n, n, n) float32 signed distance
    fences: np.ndarray  # (nf, 6) x0 y0 x1 y1 zlo zhi
    obs_verts: np.ndarray  # (V, 2) obstacle footprints (the table's polygons first)
    obs_poly: np.ndarray  # (O, 2) int64 start, count into obs_verts
    obs_box: np.ndarray  # (O, 5) footprint bounding box xmin xmax ymin ymax, and the obstacle's height
    floor: np.ndarray  # (4,) xmin xmax ymin ymax
    dev_kind: np.ndarray  # (nd,) int64
    dev_resp: np.ndarray  # (nd,)
    dev_rect: np.ndarray  # (nd, 6) curtain rectangle; for scanners [4] holds the scan height
    dev_poly: np.ndarray  # (nd, 2) int64 start, count into dev_verts
    dev_verts: np.ndarray  # (V, 2)
    dev_speed: np.ndarray  # (nd,) 0: detection latches a stop; else a warning field's reduced speed fraction
    dev_clear: np.ndarray  # (nd,) automatic restart's clear time [s]; inf: manual (latched for the episode)
    door_dev: np.ndarray  # (n_doors,) int64: door i's channel (a DEV_DOOR row of dev_*); its state slots: layout
    door_fence: np.ndarray  # (n_doors,) int64: door i's leaf, a row of fences (blocks only while not passable)
    door_open: np.ndarray  # (n_doors,) opening time [s]: passable this long after it starts to open
    door_lock: np.ndarray  # (n_doors,) 1: guard locking (starts to open only once the robot is at rest)
    dev_muted: np.ndarray  # (nd, 2) cell-clock window [on, off] in which channel d sees nothing; (inf, inf): never
    panel_fence: np.ndarray  # (n_panels,) int64: timed panels (a pallet), rows of fences blocking only in a window
    panel_win: np.ndarray  # (n_panels, 2) cell-clock window [in, out] in which timed panel i blocks
    pre_ra: np.ndarray  # (n_pre, nc, 3) robot capsules at step k before any stop (a cache: see robot_at)
    pre_rb: np.ndarray
    pre_v: np.ndarray  # (n_pre,) v_R
    pre_tau: np.ndarray  # (n_pre,) path time
    # Several robots. Robot 0 is the arrays above (a one-robot cell is exactly what it was); robots 1.. are the
    # x_ arrays, one row each, padded to the largest (padding joints are fixed and unmoved, padding capsules
    # never read, padding segments start at inf). Every robot's capsules are in cap_r, W.ra, pre_ra, robot 0's
    # first; cap_a, cap_b and cap_joint hold robot 0's.
    cap_robot: np.ndarray  # (nc,) int64 the robot owning each capsule
    dev_robots: np.ndarray  # (nd,) int64 bit r set: the channel's stop stops robot r
    x_scal: np.ndarray  # (nx, N_SCAL) scal with robot r's stopping time, phase, cycle, linear
    x_base: np.ndarray  # (nx, 4, 4)
    x_parents: np.ndarray  # (nx, njx) int64
    x_placements: np.ndarray  # (nx, njx, 4, 4)
    x_axes: np.ndarray  # (nx, njx, 3)
    x_jtype: np.ndarray  # (nx, njx) int64
    x_anc: np.ndarray  # (nx, njx, njx)
    x_wp: np.ndarray  # (nx, nwx, njx)
    x_seg_start: np.ndarray  # (nx, nwx)
    x_seg_move: np.ndarray
    x_seg_dwell: np.ndarray
    x_cap_joint: np.ndarray  # (nx, ncx) int64
    x_cap_a: np.ndarray  # (nx, ncx, 3)
    x_cap_b: np.ndarray
    x_cap0: np.ndarray  # (nx,) int64 robot r's first capsule in cap_r
    x_ncap: np.ndarray  # (nx,) int64 its number of capsules
    pre_xv: np.ndarray  # (n_pre, nx) v_R of robot r before its stop
    pre_xtau: np.ndarray  # (n_pre, nx) its path time
    # speed and separation monitoring, one row per channel whose dev_speed is layout.SEPARATION (at most one: the
    # cell schema): v_h, v_max, configured T_r and T_s, allowance C + Z_d + Z_r, the channel's row of dev_*
    dev_sep: np.ndarray  # (n_sep, 6)
    # the swept contact test (kernels.sweep): per capsule (every robot's), a bound on the speed of any point of
    # its axis per second of path time (sim.speeds)
    cap_speed: np.ndarray  # (nc,)


class Work(NamedTuple):
    q: np.ndarray
    qd: np.ndarray
    rot: np.ndarray
    pos: np.ndarray
    ra: np.ndarray
    rb: np.ndarray
    ha: np.ndarray
    hb: np.ndarray
    hr: np.ndarray
    sh: np.ndarray
    tr: np.ndarray
    near: np.ndarray
    best_r: np.ndarray
    lbs: np.ndarray
    ts: np.ndarray
    stopped: np.ndarray  # (2,) t_stop, v_R of the standstill pose held in ra/rb, or NaN (see robot_at)
    fences: np.ndarray  # P.fences with every passable door's leaf moved out of the way (kernels.doors)
    xq: np.ndarray  # robots 1..: scratch for one robot at a time (njx,)
    xqd: np.ndarray
    xrot: np.ndarray
    xpos: np.ndarray
    xra: np.ndarray  # (ncx, 3)
    xrb: np.ndarray
    xv: np.ndarray  # (nx,) each robot's v_R at the step
    xtau: np.ndarray  # (nx,) path time
    xphase: np.ndarray  # (nx,) stop phase
    ext0: np.ndarray  # (11,) the articulated worker's drop and arm joints when the action began (move_worker)
    ext1: np.ndarray  # (11,) the same for the pose being tried
    ext2: np.ndarray  # (11,) an in-between pose of the sweep (sensing.path_blocked)
    pa: np.ndarray  # (MAX_CAPSULES, 3) capsule ends at the sweep's previous in-between pose
    pb: np.ndarray
    prev: np.ndarray  # (NS,) the state before the step being taken (the swept contact test starts from it)
    srow: np.ndarray  # (NM,) a metric row for the swept test's in-between samples
    crow: np.ndarray  # (NM,) the contact it found so far
    stack: np.ndarray  # (SWEEP_STACK, 6) its intervals still to test: s_a, s_b, d_a, d_b, depth, certified


@njit(cache=True, error_model="numpy", inline="always")
def near_size(n_fences):
    """The length of a ``near`` array (``Work.near``) for a cell with ``n_fences`` panels: the near panels'
    indices in its first ``n_fences`` slots, then for each panel and end the near panel that continues it there
    (``kernels.fences.continuation``)."""
    return 3 * n_fences + 1


@njit(cache=True, error_model="numpy")
def make_work(P):
    nj = P.placements.shape[0]
    nc = P.cap_r.shape[0]
    nx, njx, ncx = P.x_parents.shape[0], P.x_parents.shape[1], P.x_cap_joint.shape[1]
    return Work(
        np.zeros(nj), np.zeros(nj), np.zeros((nj, 3, 3)), np.zeros((nj, 3)),
        np.zeros((nc, 3)), np.zeros((nc, 3)),
        np.zeros((MAX_CAPSULES, 3)), np.zeros((MAX_CAPSULES, 3)), np.zeros(MAX_CAPSULES),
        np.zeros((2, 3)), np.zeros((3, 3)), np.zeros(near_size(P.fences.shape[0]), dtype=np.int64),
        np.zeros(3),
        np.zeros(2 * nc), np.zeros(2 * nc), np.full(2, np.nan), P.fences.copy(),
        np.zeros(njx), np.zeros(njx), np.zeros((njx, 3, 3)), np.zeros((njx, 3)), np.zeros((ncx, 3)),
        np.zeros((ncx, 3)), np.zeros(nx), np.zeros(nx), np.zeros(nx), np.zeros(11), np.zeros(11), np.zeros(11),
        np.zeros((MAX_CAPSULES, 3)), np.zeros((MAX_CAPSULES, 3)),
        np.zeros(NS), np.zeros(NM), np.zeros(NM), np.zeros((SWEEP_STACK, 6)),
    )
