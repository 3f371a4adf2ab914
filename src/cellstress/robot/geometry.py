"""Every link's shape, in the frame of the joint that carries it: the URDF's collision shapes (boxes, cylinders,
spheres, capsules and meshes), or its visual shapes where a link has no collision shape.

A link without any shape is a frame (``tool0``, a flange, a camera frame) when it has no mass or a negligible
one (below ``FRAME_MASS``: URDFs give such frames a placeholder mass of 1e-4 kg or less because simulators need
one); it has no extent. A link with a mass but no shape is a real part nobody described: if it moves, the
robot is refused (``unseen_links``), since a capsule-less moving part would be invisible to every check.

Shapes are placed as pinocchio places them (the link frame's placement in its joint, times the element's
``<origin>``, with urdfdom's roll-pitch-yaw quaternion), so a mesh's vertices land bit for bit where pinocchio's
geometry model puts them (a test checks this on every short-name robot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.meshes import Mesh, read_mesh
from cellstress.robot.model import RobotModel, load_robot
from cellstress.robot.urdf_file import ShapeSpec, quoted, read_urdf, resolve_mesh

FRAME_MASS = 1e-3  # kg: below this a link without a shape is a frame
MAX_ROBOT_TRIANGLES = 1_000_000  # all the meshes a robot uses, together
ROUND_SIDES = 64  # a cylinder is enclosed by the prism on the regular 64-gon circumscribing its rims


@dataclass(frozen=True)
class Shape:
    """One shape of a link: ``pose`` (4x4) places its own frame in the joint frame; ``size`` as ShapeSpec's
    (box: edge lengths; cylinder, capsule: radius, length along its z axis; sphere: radius; mesh: the scale)."""

    link: str
    joint: int
    source: str  # "collision" or "visual"
    kind: str  # box, cylinder, sphere, capsule, mesh
    size: tuple[float, ...]
    pose: np.ndarray
    mesh: Mesh | None = None

    def local_hull_points(self) -> np.ndarray:
        """Points in the shape's own frame whose convex hull contains the shape (none for a sphere or capsule:
        see ``balls``). Box: its corners; cylinder: the corners of the circumscribed 64-sided prism; mesh: its
        vertices (a capsule is convex, so containing the vertices contains every triangle)."""
        if self.kind == "mesh":
            assert self.mesh is not None
            return self.mesh.vertices
        if self.kind == "box":
            h = 0.5 * np.asarray(self.size)
            signs = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
            return signs * h
        if self.kind == "cylinder":
            r, length = self.size
            phi = 2.0 * np.pi * np.arange(ROUND_SIDES) / ROUND_SIDES
            rc = r / np.cos(np.pi / ROUND_SIDES)
            ring = np.stack([rc * np.cos(phi), rc * np.sin(phi)], axis=1)
            return np.concatenate([np.column_stack([ring, np.full(ROUND_SIDES, z)]) for z in (-0.5 * length,
                                                                                             0.5 * length)])
        return np.zeros((0, 3))

    def hull_points(self) -> np.ndarray:
        """``local_hull_points`` in the joint frame."""
        pts = self.local_hull_points()
        return pts @ self.pose[:3, :3].T + self.pose[:3, 3]

    def balls(self) -> np.ndarray:
        """(k, 4) balls (centre in the joint frame, radius) whose convex hull is the shape: a sphere's one, a
        capsule's two end balls; none for the other kinds."""
        if self.kind == "sphere":
            return np.array([[*self.pose[:3, 3], self.size[0]]])
        if self.kind == "capsule":
            r, length = self.size
            ends = np.array([[0.0, 0.0, -0.5 * length], [0.0, 0.0, 0.5 * length]]) @ self.pose[:3, :3].T
            ends += self.pose[:3, 3]
            return np.column_stack([ends, [r, r]])
        return np.zeros((0, 4))

    def axes(self) -> np.ndarray:
        """The shape's own directions in the joint frame (k x 3): a cylinder's or capsule's axis, a box's three
        edges; none for a sphere or mesh."""
        rot = self.pose[:3, :3]
        if self.kind in ("cylinder", "capsule"):
            return rot[:, 2:3].T.copy()
        if self.kind == "box":
            return rot.T.copy()
        return np.zeros((0, 3))

    def footprint_points(self) -> np.ndarray:
        """Points (joint frame) on the shape whose plan hull lies inside the shape's plan footprint, and whose
        highest is the shape's top: for the robot's base as an obstacle, which must not be larger than the
        real one (a larger obstacle would keep the worker away). Round shapes are sampled on their rims."""
        if self.kind in ("mesh", "box"):
            return self.hull_points()
        phi = 2.0 * np.pi * np.arange(ROUND_SIDES) / ROUND_SIDES
        ring = np.stack([np.cos(phi), np.sin(phi), np.zeros(ROUND_SIDES)], axis=1)
        if self.kind == "cylinder":
            r, length = self.size
            local = np.concatenate([r * ring + [0.0, 0.0, z] for z in (-0.5 * length, 0.5 * length)])
            return local @ self.pose[:3, :3].T + self.pose[:3, 3]
        out = []
        for *c, r in self.balls():
            out += [np.asarray(c) + r * ring, (np.asarray(c) + [0.0, 0.0, r])[None]]  # the horizontal great circle, top
        return np.concatenate(out)


@dataclass(frozen=True)
class LinkGeometry:
    """A link's shapes and what they are: ``source`` collision, visual (no collision shape), or none."""

    link: str
    joint: int  # -1: fixed to the robot's base
    mass: float | None
    source: str
    shapes: tuple[Shape, ...]

    @property
    def is_frame(self) -> bool:
        """No shape and no (or a negligible) mass: a coordinate frame, without extent."""
        return not self.shapes and (self.mass is None or self.mass < FRAME_MASS)


@dataclass(frozen=True)
class RobotGeometry:
    urdf: Path
    links: tuple[LinkGeometry, ...]  # in pinocchio's link order

    def moving(self) -> tuple[LinkGeometry, ...]:
        return tuple(g for g in self.links if g.joint >= 0)

    def mesh_files(self) -> tuple[Path, ...]:
        """The mesh files read for the shapes (each once, in order): a subset of ``model.mesh_paths``, which
        also lists visual meshes of links that have collision shapes, never read."""
        out: dict[Path, None] = {}
        for g in self.links:
            for s in g.shapes:
                if s.mesh is not None:
                    out.setdefault(s.mesh.path, None)
        return tuple(out)

    def unseen_links(self) -> tuple[LinkGeometry, ...]:
        """Moving links with a mass but no shape: parts of the robot nobody described."""
        return tuple(g for g in self.moving() if not g.shapes and not g.is_frame)


def _quaternion_matrix(rpy) -> np.ndarray:
    """The rotation of an ``<origin rpy>`` as urdfdom computes it (its quaternion), through pinocchio's
    quaternion-to-matrix conversion: the same bits as pinocchio's geometry placements."""
    import pinocchio as pin

    phi, the, psi = (0.5 * float(v) for v in rpy)
    x = math.sin(phi) * math.cos(the) * math.cos(psi) - math.cos(phi) * math.sin(the) * math.sin(psi)
    y = math.cos(phi) * math.sin(the) * math.cos(psi) + math.sin(phi) * math.cos(the) * math.sin(psi)
    z = math.cos(phi) * math.cos(the) * math.sin(psi) - math.sin(phi) * math.sin(the) * math.cos(psi)
    w = math.cos(phi) * math.cos(the) * math.cos(psi) + math.sin(phi) * math.sin(the) * math.sin(psi)
    s = math.sqrt(x * x + y * y + z * z + w * w)
    return np.asarray(pin.Quaternion(w / s, x / s, y / s, z / s).matrix())


def shape_pose(link_in_joint: np.ndarray, spec: ShapeSpec) -> np.ndarray:
    """The shape's frame in its joint's frame (4x4), composed as pinocchio composes it."""
    import pinocchio as pin

    body = pin.SE3(np.ascontiguousarray(link_in_joint[:3, :3]), np.ascontiguousarray(link_in_joint[:3, 3]))
    origin = pin.SE3(_quaternion_matrix(spec.rpy), np.asarray(spec.xyz, dtype=float))
    return np.asarray((body * origin).homogeneous)


def _shape(robot: RobotModel, spec: ShapeSpec, urdf: Path) -> Shape:
    joint, placement = robot.link_frame(spec.link)
    mesh = None
    if spec.kind == "mesh":
        try:
            mesh = read_mesh(resolve_mesh(spec.filename, urdf), spec.size)
        except CellstressError as exc:
            raise CellstressError(f"{urdf}: link {quoted(spec.link)} <{spec.source}> {spec.index}: {exc}") from None
    return Shape(spec.link, joint, spec.source, spec.kind, spec.size, shape_pose(placement, spec), mesh)


@lru_cache(maxsize=8)
def robot_geometry(urdf: Path) -> RobotGeometry:
    """Every link's shapes (collision, else visual) in its joint's frame; the meshes read and checked."""
    robot = load_robot(urdf)
    doc = read_urdf(urdf)
    links = []
    triangles = 0
    for link in robot.link_joint:  # pinocchio's order, which is the order its geometry model had
        if link not in doc.masses:
            continue  # a frame pinocchio made, not a URDF link
        specs, source = doc.collision[link], "collision"
        if not specs:
            specs, source = doc.visual[link], ("visual" if doc.visual[link] else "none")
        shapes = tuple(_shape(robot, s, urdf) for s in specs)
        triangles += sum(len(s.mesh.triangles) for s in shapes if s.mesh is not None)
        if triangles > MAX_ROBOT_TRIANGLES:
            raise CellstressError(f"{urdf}: its meshes have more than {MAX_ROBOT_TRIANGLES:,} triangles together; "
                                  "cellstress reads at most that many per robot (simplify the meshes)")
        links.append(LinkGeometry(link, robot.link_joint[link], doc.masses[link], source, shapes))
    return RobotGeometry(urdf, tuple(links))


def unseen_message(geometry: RobotGeometry, robot: RobotModel, g: LinkGeometry) -> str:
    """The error for a moving link with a mass but no shape (``RobotGeometry.unseen_links``)."""
    return (f"{geometry.urdf}: link {quoted(g.link)} moves (with joint {quoted(robot.joint_names[g.joint])}) and has "
            f"a mass of {g.mass:g} kg but no <collision> or <visual> shape, so no check could see it; give it a "
            "shape in the URDF or declare a capsule on it")
