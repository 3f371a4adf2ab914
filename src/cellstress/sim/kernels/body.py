"""The worker's body capsules, shoulders and trunk frame for a position, heading and trunk flexion."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.layout import (
    B_ARM_LEN,
    B_HEAD_RISE,
    B_HIP_Z,
    B_LEG_HALF,
    B_R_ARM,
    B_R_HEAD,
    B_R_LEG,
    B_R_TRUNK,
    B_SHOULDER_HALF,
    B_SHOULDER_RISE,
    B_TRUNK_TOP,
)


@njit(cache=True, error_model="numpy")
def human_pose(P, x, y, heading, fwd, lat, W):
    """Body capsules (W.ha, W.hb, W.hr), shoulders (W.sh) and trunk frame (W.tr, columns x, y, z)."""
    pose_body(P.body, x, y, heading, fwd, lat, W.ha, W.hb, W.hr, W.sh, W.tr)


@njit(cache=True, error_model="numpy", inline="always")
def pose_body(b, x, y, heading, fwd, lat, ha, hb, hr, sh, tr):
    """human_pose on the arrays themselves (the hot path: see the module docstring)."""
    ch, shh = np.cos(heading), np.sin(heading)
    cf, sf = np.cos(fwd), np.sin(fwd)
    cl, sl = np.cos(lat), np.sin(lat)
    # trunk axes in body coordinates (forward, left, up), then in the world
    xb0, xb1, xb2 = cf, 0.0, -sf
    zb0, zb1, zb2 = sf * cl, sl, cf * cl
    yb0, yb1, yb2 = zb1 * xb2 - zb2 * xb1, zb2 * xb0 - zb0 * xb2, zb0 * xb1 - zb1 * xb0
    tr[0, 0], tr[1, 0], tr[2, 0] = xb0 * ch - xb1 * shh, xb0 * shh + xb1 * ch, xb2
    tr[0, 1], tr[1, 1], tr[2, 1] = yb0 * ch - yb1 * shh, yb0 * shh + yb1 * ch, yb2
    tr[0, 2], tr[1, 2], tr[2, 2] = zb0 * ch - zb1 * shh, zb0 * shh + zb1 * ch, zb2
    hz = b[B_HIP_Z]
    lx, ly = -shh, ch  # body left in the world
    # legs
    for k in range(2):
        sgn = 1.0 if k == 0 else -1.0
        ha[k, 0], ha[k, 1], ha[k, 2] = x + sgn * b[B_LEG_HALF] * lx, y + sgn * b[B_LEG_HALF] * ly, hz
        hb[k, 0], hb[k, 1], hb[k, 2] = ha[k, 0], ha[k, 1], b[B_R_LEG]
        hr[k] = b[B_R_LEG]
    # trunk and head
    ha[2, 0], ha[2, 1], ha[2, 2] = x, y, hz
    for r in range(3):
        hb[2, r] = ha[2, r] + b[B_TRUNK_TOP] * tr[r, 2]
        ha[3, r] = ha[2, r] + b[B_HEAD_RISE] * tr[r, 2]
        hb[3, r] = ha[3, r]
    hr[2] = b[B_R_TRUNK]
    hr[3] = b[B_R_HEAD]
    # shoulders and hanging arms (left = 0, right = 1)
    for k in range(2):
        sgn = 1.0 if k == 0 else -1.0
        for r in range(3):
            sh[k, r] = ha[2, r] + b[B_SHOULDER_RISE] * tr[r, 2] + sgn * b[B_SHOULDER_HALF] * tr[r, 1]
            ha[4 + k, r] = sh[k, r]
            hb[4 + k, r] = sh[k, r]
        low = sh[k, 2] - (b[B_ARM_LEN] - b[B_R_ARM])
        hb[4 + k, 2] = low if low > b[B_R_ARM] else b[B_R_ARM]
        hr[4 + k] = b[B_R_ARM]
