"""Robot dynamics at a point, from pinocchio: the point Jacobian, the joint-space inertia, the reflected mass.

The ISO/TS 15066 force estimate (``criteria.iso15066``) needs the robot's effective mass at a contact point along
the contact normal; this is the one place that asks pinocchio for it.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin


def reflected_mass(J_point: np.ndarray, M: np.ndarray, n: np.ndarray) -> float:
    """(n . J M^-1 J^T n)^-1: the robot's inertia felt at a point along the unit direction n (inf if the joints
    cannot move the point along n)."""
    u = J_point.T @ n
    w = float(u @ np.linalg.solve(M, u))
    return math.inf if w <= 1e-12 else 1.0 / w


def point_dynamics(model, data, q, joint_id: int, point) -> tuple[np.ndarray, np.ndarray]:
    """(3 x nv linear Jacobian of a point fixed to pinocchio joint ``joint_id``, given in the model's world frame;
    nv x nv joint-space inertia matrix M(q)) from pinocchio."""
    pin.computeJointJacobians(model, data, q)
    Jj = np.asarray(pin.getJointJacobian(model, data, joint_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
    Jj = Jj.reshape(6, model.nv)  # (eigenpy hands a 6 x 1 matrix back as a vector)
    r = np.asarray(point, dtype=float) - data.oMi[joint_id].translation
    skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    M = np.asarray(pin.crba(model, data, q)).reshape(model.nv, model.nv)  # upper triangle filled
    return Jj[:3] - skew @ Jj[3:], np.triu(M) + np.triu(M, 1).T
