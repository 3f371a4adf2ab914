"""The robot audit of ``cellstress check``: does every part of the robot lie inside the capsules the simulator
uses?

For each link with a shape, the true surfaces of its shapes (the URDF's boxes, cylinders, spheres and capsules
themselves, not the points the fit used; a mesh's triangles, not only its vertices) are sampled densely, about
every ``SPACING``, and each sample's distance outside the union of the capsules on the link's joint (those
that move with it: fitted, declared and extra ones) is measured; the audit reports the largest. Fitted
capsules enclose their shapes by construction (``robot.capsules``), so this is 0 up to round-off; it is an
independent check of that construction (the sampling and the distances are written here again), and it shows
what declared capsules leave out. Samples bound the error from below only: a part of a surface between samples
could stick out by less than the sample spacing times the surface's curvature; for the flat faces of meshes
and boxes a point outside a convex capsule would make a whole neighbourhood of samples outside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.robot.geometry import LinkGeometry, RobotGeometry, Shape
from cellstress.robot.joints import JointMap, chains

SPACING = 0.01  # m between surface samples
MAX_SAMPLES = 100_000  # per shape: a finer mesh is sampled more coarsely per triangle (at least its corners)
OUTSIDE_TOL = 1e-9  # m: round-off; anything above is reported as outside


@dataclass(frozen=True)
class LinkAudit:
    link: str
    joint: int  # -1: fixed to the base
    source: str  # "collision" or "visual" (the link has no collision shape)
    shapes: str  # e.g. "2 cylinders, 1 box"
    capsules: tuple[str, ...]  # the capsules on its joint
    outside: float  # m: the largest distance of a surface sample outside those capsules
    samples: int


@dataclass(frozen=True)
class RobotAudit:
    links: tuple[LinkAudit, ...]
    frames: tuple[str, ...]  # links without shape and without (or with a negligible) mass
    unshaped_fixed: tuple[str, ...]  # links with a mass but no shape that do not move (the base's parts)
    branches: tuple[tuple[str, ...], ...] = ()  # the driven joints per branch, when the robot is a tree

    @property
    def worst(self) -> float:
        return max((a.outside for a in self.links), default=0.0)

    def lines(self, joint_names: tuple[str, ...]) -> list[str]:
        n_vis = sum(a.source == "visual" for a in self.links)
        head = (f"{len(self.links)} links with shapes ({n_vis} from their visual shapes: no collision shape)"
                if n_vis else f"{len(self.links)} links with shapes")
        out = [f"{head}; the largest distance of any sampled point of their surfaces outside the capsules on their "
               f"joint: {_mm(self.worst)}"]
        for a in self.links:
            where = "fixed" if a.joint < 0 else joint_names[a.joint]
            caps = ", ".join(a.capsules) if a.capsules else "NO CAPSULE"
            kind = a.shapes + (" (visual)" if a.source == "visual" else "")
            out.append(f"{a.link:<18} {where:<20} {kind:<26} in {caps}: outside by {_mm(a.outside)}")
        if self.frames:
            out.append(f"frames (no shape, no mass): {', '.join(self.frames)}")
        if len(self.branches) > 1:
            out.append(f"a tree: the program drives {len(self.branches)} branches together, in step: "
                       + " | ".join(", ".join(b) for b in self.branches))
        if self.unshaped_fixed:
            out.append(f"fixed links with a mass but no shape (not part of the base's footprint): "
                       f"{', '.join(self.unshaped_fixed)}")
        return out


def _mm(x: float) -> str:
    return f"{x * 1000.0:.3f} mm" if np.isfinite(x) else "all of it (no capsule)"


def _plural(kind: str, n: int) -> str:
    word = {"box": "boxes", "mesh": "meshes"}.get(kind, kind + "s") if n != 1 else kind
    return f"{n} {word}"


def _lattice(n: int) -> np.ndarray:
    """Barycentric weights (k x 3) of the points i/n, j/n, (n-i-j)/n of a triangle."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    i, j = i[keep], j[keep]
    return np.column_stack([i, j, n - i - j]).astype(float) / n


def _mesh_samples(shape: Shape) -> np.ndarray:
    assert shape.mesh is not None
    tri = shape.mesh.vertices[shape.mesh.triangles]  # (m, 3, 3)
    edge = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)
    levels = np.clip(np.ceil(edge / SPACING), 1, 16).astype(int)
    while True:
        count = int(np.sum((levels + 1) * (levels + 2) // 2))
        if count <= MAX_SAMPLES or levels.max() == 1:
            break
        levels = np.maximum(levels // 2, 1)
    out = []
    for n in np.unique(levels):
        w = _lattice(int(n))
        out.append(np.einsum("kc,mcd->mkd", w, tri[levels == n]).reshape(-1, 3))
    return np.concatenate(out)


def _grid(n: int) -> np.ndarray:
    return np.linspace(-0.5, 0.5, n)


def _box_samples(size) -> np.ndarray:
    out = []
    for axis in range(3):
        u, v = [k for k in range(3) if k != axis]
        nu, nv = (max(10, int(np.ceil(size[k] / SPACING)) + 1) for k in (u, v))
        gu, gv = np.meshgrid(_grid(nu) * size[u], _grid(nv) * size[v], indexing="ij")
        for side in (-0.5, 0.5):
            p = np.zeros((gu.size, 3))
            p[:, u], p[:, v], p[:, axis] = gu.ravel(), gv.ravel(), side * size[axis]
            out.append(p)
    return np.concatenate(out)


def _round_samples(radius: float, length: float, hemispheres: bool) -> np.ndarray:
    """A cylinder's side, rims and end discs (or a capsule's side and end hemispheres) on the true circle."""
    n_phi = max(360, int(np.ceil(2 * np.pi * radius / SPACING)))
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    ring = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n_phi)])
    zs = np.linspace(-0.5 * length, 0.5 * length, max(2, int(np.ceil(length / SPACING)) + 1))
    out = [radius * ring + [0.0, 0.0, z] for z in zs]
    n_r = max(5, int(np.ceil(radius / SPACING)) + 1)
    for k, side in ((1, 1.0), (-1, -1.0)):
        z_end = side * 0.5 * length
        if hemispheres:
            for lat in np.linspace(0.0, 0.5 * np.pi, n_r):
                out.append(radius * np.cos(lat) * ring + [0.0, 0.0, z_end + k * radius * np.sin(lat)])
        else:
            out += [rr * ring + [0.0, 0.0, z_end] for rr in np.linspace(0.0, radius, n_r)]
    return np.concatenate(out)


def _sphere_samples(radius: float) -> np.ndarray:
    n = max(2000, int(np.ceil(4 * np.pi * radius**2 / SPACING**2)))
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k
    rxy = np.sqrt(1.0 - z * z)
    return radius * np.column_stack([rxy * np.cos(phi), rxy * np.sin(phi), z])


def surface_samples(shape: Shape) -> np.ndarray:
    """Points on the shape's true surface (and a cylinder's end discs), in the shape's own frame."""
    if shape.kind == "mesh":
        return _mesh_samples(shape)  # in the mesh's own frame, like the primitives' below
    if shape.kind == "box":
        local = _box_samples(shape.size)
    elif shape.kind == "cylinder":
        local = _round_samples(shape.size[0], shape.size[1], hemispheres=False)
    elif shape.kind == "capsule":
        local = _round_samples(shape.size[0], shape.size[1], hemispheres=True)
    else:
        local = _sphere_samples(shape.size[0])
    return local


def _placed(shape: Shape, local: np.ndarray) -> np.ndarray:
    return local @ shape.pose[:3, :3].T + shape.pose[:3, 3]


def _outside(points: np.ndarray, capsules) -> np.ndarray:
    """Each point's distance outside the union of the capsules (negative inside), written out afresh."""
    best = np.full(len(points), np.inf)
    for c in capsules:
        a, b = np.asarray(c.p0, float), np.asarray(c.p1, float)
        d = b - a
        dd = float(d @ d)
        t = np.zeros(len(points)) if dd == 0.0 else np.clip((points - a) @ d / dd, 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - a - t[:, None] * d, axis=1) - c.radius)
    return best


def audit_link(g: LinkGeometry, capsules) -> LinkAudit:
    """One link's audit against the robot's capsules (those on its joint count)."""
    mine = [c for c in capsules if c.joint == g.joint]
    worst, n = 0.0, 0
    for s in g.shapes:
        pts = _placed(s, surface_samples(s))
        n += len(pts)
        far = float(_outside(pts, mine).max()) if mine else np.inf
        worst = max(worst, far if far > OUTSIDE_TOL else 0.0)
    kinds: dict[str, int] = {}
    for s in g.shapes:
        kinds[s.kind] = kinds.get(s.kind, 0) + 1
    shapes = ", ".join(_plural(k, v) for k, v in kinds.items())
    return LinkAudit(g.link, g.joint, g.source, shapes, tuple(c.name for c in mine), worst, n)


def audit_robot(geometry: RobotGeometry, capsules, jmap: JointMap | None = None) -> RobotAudit:
    """The audit of every link with a shape, against ``capsules`` (a robot's ``Capsule`` list); with the
    program's joint map, the branches it drives."""
    links = tuple(audit_link(g, capsules) for g in geometry.links if g.shapes)
    frames = tuple(g.link for g in geometry.links if g.is_frame)
    unshaped = tuple(g.link for g in geometry.links if not g.shapes and not g.is_frame and g.joint < 0)
    branches = () if jmap is None else tuple(tuple(jmap.robot.joint_names[j] for j in c) for c in chains(jmap))
    return RobotAudit(links, frames, unshaped, branches)
