"""Collision capsules of the robot links: fitted to each link's shapes, or declared in the cell file.

A fitted capsule encloses its link's shapes (``robot.geometry``: collision shapes, else visual ones); how its axis
and ends are chosen is ``robot.capsule_fit``'s (the original principal-axis fit for a link of meshes, a
least-volume search for a link with primitives), and its radius is always the largest distance of the shapes from the
chosen segment. Enclosing (not approximating) keeps the distance d_HR conservative: the simulated robot is never
thinner than the real one. Why enclosing the points suffices: a capsule (the points within r of a segment) is
convex, since the distance to a segment is a convex function; a convex set that contains some points contains
their convex hull. A mesh lies in the hull of its vertices, a box is the hull of its 8 corners, a cylinder lies in
the prism on the regular 64-gon circumscribing its rims (whose corners are fitted), and a sphere or a capsule
shape is the hull of its end balls, whose farthest point from the segment is exactly the ball centre's distance
plus its radius (the point of the ball straight away from the segment's nearest point). So containing those points
and balls contains the solid shape, and the audit (``analysis.robot_audit``) checks it independently on dense
samples of the true surfaces.

A link whose shapes lie inside one capsule already fitted on the same joint (the UR arms' 1 cm cube on
``ee_link``, inside the wrist's capsule) gets no capsule of its own: the robot is enclosed just the same, and the
built-in robots keep their capsules.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.capsule_fit import fit_capsule_to, fit_tight, point_segment_distances
from cellstress.robot.geometry import LinkGeometry, robot_geometry
from cellstress.robot.model import RobotModel


@dataclass(frozen=True)
class Capsule:
    name: str
    joint: int  # joint frame the capsule is fixed to (-1: robot base)
    p0: tuple[float, float, float]
    p1: tuple[float, float, float]
    radius: float


def _inside(cap: Capsule, g: LinkGeometry) -> bool:
    """Whether every shape of the link lies inside ``cap`` (both in the same joint frame)."""
    a, b = np.asarray(cap.p0), np.asarray(cap.p1)
    pts = [s.hull_points() for s in g.shapes]
    balls = [s.balls() for s in g.shapes]
    far = max([float(point_segment_distances(p, a, b).max()) for p in pts if len(p)]
              + [float((point_segment_distances(q[:, :3], a, b) + q[:, 3]).max()) for q in balls if len(q)])
    return far <= cap.radius


def link_capsule(g: LinkGeometry) -> Capsule:
    """The capsule enclosing one link's shapes, on the link's joint, named after the link: ``fit_capsule``'s
    for a link of meshes only (the built-in robots' capsules), ``fit_tight`` for a link with a primitive."""
    pts = np.concatenate([s.hull_points() for s in g.shapes])
    balls = np.concatenate([s.balls() for s in g.shapes])
    if all(s.kind == "mesh" for s in g.shapes):
        a, b, r = fit_capsule_to(pts, balls)
    else:
        directions = np.concatenate([s.axes() for s in g.shapes])
        a, b, r = fit_tight(pts, balls, directions)
    return Capsule(g.link, g.joint, tuple(a), tuple(b), r)


def fitted_capsules(robot: RobotModel) -> list[Capsule]:
    """One enclosing capsule per link with shapes, ordered by joint (links on one joint in pinocchio's order);
    links fitted from meshes first on each joint, then the primitive-only ones that are not inside one of
    them already. CellstressError when no link has a shape at all."""
    links = [g for g in robot_geometry(robot.urdf).links if g.shapes]
    caps: list[Capsule] = []
    for g in sorted(links, key=lambda g: (g.joint, not any(s.kind == "mesh" for s in g.shapes))):
        if any(s.kind == "mesh" for s in g.shapes) or not any(c.joint == g.joint and _inside(c, g) for c in caps):
            caps.append(link_capsule(g))
    if not caps:
        raise CellstressError(f"{robot.urdf}: no link has a <collision> or <visual> shape; the robot would be "
                              "invisible")
    return sorted(caps, key=lambda c: c.joint)


def declared_capsule(robot: RobotModel, name: str, link: str, p0, p1, radius: float) -> Capsule:
    """A capsule given in a link's frame, re-expressed in the frame of the joint that carries the link."""
    joint, placement = robot.link_frame(link)
    a = placement[:3, :3] @ np.asarray(p0, float) + placement[:3, 3]
    b = placement[:3, :3] @ np.asarray(p1, float) + placement[:3, 3]
    return Capsule(name, joint, tuple(a), tuple(b), float(radius))


MIN_BASE_RADIUS = 0.05  # m: a base without a collision mesh still stands somewhere


def base_footprint(robot: RobotModel) -> tuple[np.ndarray, float]:
    """The robot's base seen from above, in the base frame: (convex hull (n x 2) of the shapes of the links that
    do not move, height of their top). The hull is never larger than the real footprint (round shapes are
    sampled on their rims), as the base is an obstacle the worker walks around. A base without shapes is a
    small square."""
    fixed = [s.footprint_points() for g in robot_geometry(robot.urdf).links if g.joint < 0 for s in g.shapes]
    if not fixed:
        r = MIN_BASE_RADIUS
        return np.asarray([(-r, -r), (r, -r), (r, r), (-r, r)]), r
    pts = np.concatenate(fixed)
    try:
        return convex_hull_2d(pts[:, :2]), float(pts[:, 2].max())
    except ValueError:  # the fixed shapes are flat seen from above (a vertical plate): no area to walk around
        r = MIN_BASE_RADIUS
        return np.asarray([(-r, -r), (r, -r), (r, r), (-r, r)]), float(pts[:, 2].max())


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
