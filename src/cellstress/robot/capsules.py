"""Collision capsules of the robot links: fitted to the collision meshes, or declared in the cell file.

A fitted capsule encloses every vertex of its link's collision mesh: its axis is the mesh's principal axis,
its radius the largest distance of a vertex from that axis segment. Enclosing (not approximating) keeps the
distance d_HR conservative: the simulated robot is never thinner than the real one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.robot.model import RobotModel, collision_vertices


@dataclass(frozen=True)
class Capsule:
    name: str
    joint: int  # joint frame the capsule is fixed to (-1: robot base)
    p0: tuple[float, float, float]
    p1: tuple[float, float, float]
    radius: float


def point_segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    denom = float(ab @ ab)
    if denom == 0.0:
        return np.linalg.norm(points - a, axis=1)
    t = np.clip((points - a) @ ab / denom, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def fit_capsule(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """An enclosing capsule along the principal axis of ``points`` (n x 3)."""
    center = points.mean(axis=0)
    centered = points - center
    _, _, vt = np.linalg.svd(centered, full_matrices=False)
    axis = vt[0]
    t = centered @ axis
    radial = np.linalg.norm(centered - np.outer(t, axis), axis=1)
    r = float(radial.max())
    lo, hi = float(t.min()) + r, float(t.max()) - r
    if hi < lo:  # short, fat part: a sphere
        lo = hi = 0.5 * (float(t.min()) + float(t.max()))
    a, b = center + lo * axis, center + hi * axis
    r = float(point_segment_distances(points, a, b).max())
    return a, b, r


def fitted_capsules(robot: RobotModel) -> list[Capsule]:
    caps = []
    for link, verts in sorted(collision_vertices(robot.urdf).items(), key=lambda kv: robot.link_joint[kv[0]]):
        a, b, r = fit_capsule(verts)
        caps.append(Capsule(link, robot.link_joint[link], tuple(a), tuple(b), r))
    return caps


def declared_capsule(robot: RobotModel, name: str, link: str, p0, p1, radius: float) -> Capsule:
    """A capsule given in a link's frame, re-expressed in the frame of the joint that carries the link."""
    joint, placement = robot.link_frame(link)
    a = placement[:3, :3] @ np.asarray(p0, float) + placement[:3, 3]
    b = placement[:3, :3] @ np.asarray(p1, float) + placement[:3, 3]
    return Capsule(name, joint, tuple(a), tuple(b), float(radius))


MIN_BASE_RADIUS = 0.05  # m: a base without a collision mesh still stands somewhere


def base_footprint(robot: RobotModel) -> tuple[np.ndarray, float]:
    """The robot's base seen from above, in the base frame: (convex hull (n x 2) of the collision meshes of the
    links that do not move, height of their top). A base without such meshes is a small square."""
    fixed = [v for link, v in collision_vertices(robot.urdf).items() if robot.link_joint.get(link, 0) < 0]
    if not fixed:
        r = MIN_BASE_RADIUS
        return np.asarray([(-r, -r), (r, -r), (r, r), (-r, r)]), r
    pts = np.concatenate(fixed)
    return convex_hull_2d(pts[:, :2]), float(pts[:, 2].max())


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of plan points (Andrew's monotone chain)."""
    pts = sorted(set(map(tuple, np.round(np.asarray(points, float), 9))))
    if len(pts) < 3:
        raise ValueError("a hull needs three distinct points")

    def half(seq):
        out: list = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(reversed(pts))
    return np.asarray(lower[:-1] + upper[:-1])
