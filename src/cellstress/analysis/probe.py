"""Brute-force probe behind a cell's light curtain: how close the robot comes to an unseen worker standing still.

Run it with ``python scripts/curtain_probe.py [CELL] [--step 0.05]``.

Standing points on a grid behind the curtain (x -0.6..0.6, y from the curtain line back 0.35 m, every ``--step`` m),
headings every 30 degrees, the six postures at full flexion, and the robot (never stopped) every 50 ms over its
whole cycle. Poses that a device sees, or whose trunk would pass a fence panel, are left out. Prints the smallest
d_HR over the rest and where it happens: positive means no worker standing still behind the curtain can be touched
(docs/cells.md, "The ISO 13855 check", uses it for S2). It uses the simulator's own kernels.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

FLEX = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (1.0, 1.0), (1.0, -1.0))  # (forward, lateral) fractions


@njit(cache=True)
def _unseen_and_clear(P, W):
    for d in range(P.dev_kind.shape[0]):
        if K.device_sees(P.dev_kind, P.dev_rect, P.dev_poly, P.dev_verts, P.body, d, W.ha, W.hb, W.hr):
            return False
    return K.trunk_clear(P.body, P.fences, P.obs_verts, P.obs_poly, P.obs_box, W.ha, W.hb, W.hr)


@njit(cache=True)
def _closest(P, W, ras, rbs, row):
    """min over the robot poses (ras[k], rbs[k]) of d_HR for the worker pose in W; (d, pose index)."""
    n_near = K.collect_near_fences(P.fences, W.sh, W.near, P.body[L.B_ARM_LEN] + 0.05)
    best, arg = np.inf, -1
    for k in range(ras.shape[0]):
        d = K.separation(P.cap_r, P.reach, P.scal[L.C_REACH_ORIGIN], P.scal[L.C_REACH_H], P.body[L.B_ARM_LEN],
                         P.fences, W.near, ras[k], rbs[k], W.sh, W.tr, W.ha, W.hb, W.hr, W.lbs, W.ts, W.best_r,
                         n_near, row, int(P.body[L.B_N_CAPS]))
        if d < best:
            best, arg = d, k
    return best, arg


def probe(cell: str = "s2-elbow-intrusion", step: float = 0.05) -> dict:
    """The smallest d_HR over the unseen standing poses behind the cell's (first) light curtain; see above."""
    sim = Simulator(cell)
    P, lay = sim.params, sim.layout
    W = K.make_work(P)
    dt, cycle, phase0 = float(P.scal[L.C_DT]), float(P.scal[L.C_CYCLE]), float(P.scal[L.C_PHASE0])
    times = np.arange(0.0, cycle, dt) - phase0  # the robot's whole cycle
    ras = np.empty((len(times), *W.ra.shape))
    rbs = np.empty_like(ras)
    for k, t in enumerate(times):
        K.robot_live(P, t, np.inf, W)
        ras[k], rbs[k] = W.ra, W.rb
    curtain = next(i for i, kind in enumerate(P.dev_kind) if kind == L.DEV_CURTAIN)
    y_line = float(min(P.dev_rect[curtain, 1], P.dev_rect[curtain, 3]))
    hum = sim.cell.spec.human
    fwd_max, lat_max = math.radians(hum.max_forward_flexion_deg), math.radians(hum.max_lateral_flexion_deg)
    row = np.zeros(L.NM)
    out = {"cell": cell, "curtain_y": y_line, "poses": 0, "unseen": 0, "robot_poses": len(times), "d": math.inf}
    for x in np.arange(-0.6, 0.6 + 1e-9, step):
        for y in np.arange(y_line - 0.35, y_line + 1e-9, step):
            for heading_deg in range(0, 360, 30):
                for f, lat in FLEX:
                    out["poses"] += 1
                    K.human_pose(P, L.pose_vector(x, y, math.radians(heading_deg), f * fwd_max, lat * lat_max), W)
                    if not _unseen_and_clear(P, W):
                        continue
                    out["unseen"] += 1
                    d, k = _closest(P, W, ras, rbs, row)
                    if d < out["d"]:
                        out.update(d=float(d), x=round(float(x), 3), y=round(float(y), 3), heading_deg=heading_deg,
                                   posture=(f, lat), path_time=round(float(times[k] + phase0), 3),
                                   link=lay.capsules[int(row[L.M_LINK])].name, part=int(row[L.M_PART]))
    return out
