"""The fitted collision capsules enclose the robot's collision meshes, and are not absurdly fat."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.capsule_fit import fit_capsule
from cellstress.robot.capsules import fitted_capsules
from cellstress.robot.geometry import robot_geometry
from cellstress.robot.model import example_robot_data_share
from cellstress.sim import kernels as K

ENCLOSE_TOL = 1e-9  # m; round-off only: the fit is meant to enclose exactly


def seg_dist(points, a, b):
    """Distance of each point to segment ab (plain numpy, independent of cellstress.robot.capsules)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    den = d @ d
    t = np.zeros(len(points)) if den == 0 else np.clip((points - a) @ d / den, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * d), axis=1)


def capsule_volume(a, b, r):
    return np.pi * r * r * np.linalg.norm(np.subtract(b, a)) + 4.0 / 3.0 * np.pi * r**3


@pytest.fixture(scope="module")
def robot(baseline_sim):
    return baseline_sim.layout.robot


@pytest.fixture(scope="module")
def meshes(robot):
    """Each link's collision-mesh vertices in its joint's frame."""
    return {g.link: np.concatenate([s.hull_points() for s in g.shapes]) for g in robot_geometry(robot.urdf).links
            if any(s.kind == "mesh" for s in g.shapes)}


@pytest.fixture(scope="module")
def capsules(robot):
    return {c.name: c for c in fitted_capsules(robot)}


def test_every_mesh_has_a_capsule(meshes, capsules, robot):
    assert set(meshes) == set(capsules)
    # the UR10's seven collision meshes, each with hundreds of vertices
    assert len(meshes) == 7
    assert all(len(v) >= 100 for v in meshes.values())
    for name, cap in capsules.items():
        assert cap.joint == robot.link_joint[name]


def test_capsules_enclose_every_vertex_tightly(meshes, capsules):
    for name, verts in meshes.items():
        cap = capsules[name]
        d = seg_dist(verts, cap.p0, cap.p1)
        assert d.max() <= cap.radius + ENCLOSE_TOL, name
        # not padded either: some vertex lies on the capsule's surface
        assert d.max() == pytest.approx(cap.radius, abs=1e-9), name


def test_capsules_are_not_absurdly_fat(meshes, capsules):
    """Two bounds. (1) Never worse than the trivial enclosure, the sphere through the corners of the
    vertices' bounding box. (2) At most BOX_FACTOR times the bounding box volume: a capsule around a cube
    needs at least pi sqrt(3) / 2 = 2.7 times its volume and around a flat disc (the UR10's base plate,
    0.15 x 0.17 x 0.04 m) about 4.5 times; a capsule built on a wrong axis or from a far-off centre is many
    times fatter. Links that are not flat (smallest side >= half the middle one) must do better than 3x."""
    for name, verts in meshes.items():
        cap = capsules[name]
        ext = np.sort(verts.max(axis=0) - verts.min(axis=0))
        box = float(np.prod(ext))
        vol = capsule_volume(cap.p0, cap.p1, cap.radius)
        trivial = 4.0 / 3.0 * np.pi * (0.5 * np.linalg.norm(ext)) ** 3
        assert vol <= trivial, name
        flat = ext[0] < 0.5 * ext[1]
        assert vol <= (5.0 if flat else 3.0) * box, (name, vol / box)


def test_capsules_enclose_the_posed_meshes(baseline_sim, meshes):
    """Through the simulator's own chain (kernel FK + capsule placement) against pinocchio's placement of
    every collision geometry, at random joint angles: ties the capsule frames to the mesh frames."""
    P = baseline_sim.params
    layout = baseline_sim.layout
    robot = layout.robot
    model = pin.buildModelFromUrdf(str(robot.urdf))
    share = example_robot_data_share()
    geom = pin.buildGeomFromUrdf(model, str(robot.urdf), pin.GeometryType.COLLISION,
                                 package_dirs=[str(robot.urdf.parent), str(share), str(share.parent)])
    data, gdata = model.createData(), pin.GeometryData(geom)
    local = [(g, model.frames[o.parentFrame].name, np.asarray(o.geometry.vertices(), float))
             for g, o in enumerate(geom.geometryObjects) if hasattr(o.geometry, "vertices")]
    assert sum(len(v) for _, _, v in local) == sum(len(v) for v in meshes.values())
    index = {c.name: i for i, c in enumerate(layout.capsules)}
    W = K.make_work(P)
    rng = np.random.default_rng(31)
    for q in rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, (25, model.nq)):
        K.forward_kinematics(P, q, W.rot, W.pos)
        K.robot_capsules(P, W.rot, W.pos, W.ra, W.rb)
        pin.updateGeometryPlacements(model, data, geom, gdata, q)
        for g, link, verts in local:
            M = P.base @ gdata.oMg[g].homogeneous
            world = verts @ M[:3, :3].T + M[:3, 3]
            c = index[link]
            assert seg_dist(world, W.ra[c], W.rb[c]).max() <= P.cap_r[c] + 1e-9, link


# ---- fit_capsule on shapes with a known answer -------------------------------------------------------------
def random_frame(rng):
    m, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return m


def capsule_surface(r, length, n_phi=72, n_z=41, n_lat=19):
    """A symmetric lattice on the surface of the capsule from (0,0,0) to (0,0,length) with radius r."""
    phi = np.linspace(0.0, 2 * np.pi, n_phi, endpoint=False)
    z = np.linspace(0.0, length, n_z)
    cyl = np.stack([np.repeat(r * np.cos(phi)[None], n_z, 0), np.repeat(r * np.sin(phi)[None], n_z, 0),
                    np.repeat(z[:, None], n_phi, 1)], axis=-1).reshape(-1, 3)
    lat = np.linspace(0.0, 0.5 * np.pi, n_lat)  # equator .. pole
    ring = np.stack([np.outer(np.cos(lat), np.cos(phi)), np.outer(np.cos(lat), np.sin(phi)),
                     np.outer(np.sin(lat), np.ones_like(phi))], axis=-1).reshape(-1, 3)
    top = r * ring + [0.0, 0.0, length]
    bottom = r * ring * [1.0, 1.0, -1.0]
    return np.concatenate([cyl, top, bottom])


@pytest.mark.parametrize("seed", range(8))
def test_fit_capsule_recovers_a_capsule_exactly(seed):
    """A symmetric sampling of an elongated capsule's surface (length^2 / 12 > r^2 / 2, so the principal axis
    is the capsule's axis), moved to a random pose: the fit is that capsule, to round-off."""
    rng = np.random.default_rng(seed)
    r, length = rng.uniform(0.03, 0.12), rng.uniform(0.4, 1.0)
    R, c = random_frame(rng), rng.uniform(-1, 1, 3)
    pts = capsule_surface(r, length) @ R.T + c
    a, b, rf = fit_capsule(pts)
    assert seg_dist(pts, a, b).max() <= rf + ENCLOSE_TOL
    a0, b0 = c, c + length * R[:, 2]
    assert rf == pytest.approx(r, rel=1e-9)
    if np.dot(b - a, b0 - a0) < 0:
        a, b = b, a
    np.testing.assert_allclose(a, a0, atol=1e-9)
    np.testing.assert_allclose(b, b0, atol=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_fit_capsule_on_random_surface_samples(seed):
    """Random (not symmetric) surface samples: the principal axis and centroid carry sampling noise (axis
    off by up to ~0.5 deg at 6000 points), which can only fatten the enclosing capsule: by at most 5.7 % in
    radius and 12 % in volume over 200 seeds; the bounds leave a margin."""
    rng = np.random.default_rng(100 + seed)
    r, length = rng.uniform(0.03, 0.12), rng.uniform(0.4, 1.0)
    R, c = random_frame(rng), rng.uniform(-1, 1, 3)
    n = 3000
    phi, z = rng.uniform(0, 2 * np.pi, n), rng.uniform(0, length, n)
    cyl = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    caps = r * u + np.where(u[:, 2:] >= 0, [0.0, 0.0, length], 0.0)  # upper half on top, lower below
    pts = np.concatenate([cyl, caps]) @ R.T + c
    a, b, rf = fit_capsule(pts)
    assert seg_dist(pts, a, b).max() <= rf + ENCLOSE_TOL
    assert r <= rf <= 1.08 * r
    assert capsule_volume(a, b, rf) <= 1.2 * capsule_volume(c, c + length * R[:, 2], r)


def test_fit_capsule_degenerate_clouds():
    rng = np.random.default_rng(2)
    # a ball of points: a sphere capsule
    p = rng.normal(size=(2000, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    a, b, r = fit_capsule(0.1 * p + [1, 2, 3])
    assert seg_dist(0.1 * p + [1, 2, 3], a, b).max() <= r + ENCLOSE_TOL
    assert r < 0.105 and np.linalg.norm(b - a) < 0.02
    # points on a line: a zero-radius capsule spanning them
    t = rng.uniform(-1, 1, 50)
    line = np.outer(t, [1.0, 2.0, 2.0]) / 3.0
    a, b, r = fit_capsule(line)
    assert r <= 1e-12
    assert np.linalg.norm(b - a) == pytest.approx(t.max() - t.min(), rel=1e-12)
    # one repeated point
    a, b, r = fit_capsule(np.tile([0.5, -0.5, 1.0], (10, 1)))
    assert r <= 1e-12 and np.allclose(a, [0.5, -0.5, 1.0]) and np.allclose(b, a)
