"""Fitting one capsule (a segment and a radius) around points and balls, always enclosing them.

``fit_capsule`` is the original fit: the principal axis of the points through their centroid, the segment
shortened by the radius at each end, the radius the largest distance of a point from it. Every mesh-only link
is fitted with it, so the built-in robots keep their capsules bit for bit.

``fit_tight`` is for links with primitive shapes, whose few corner points make the principal axis a poor guide
(a cylinder's 128 rim points outweigh a box's 8 corners) and whose flat ends make the shortened segment fat (a
cylinder of radius r gets sqrt(2) r): it tries several axes (the principal ones and each primitive's own) and,
on each, the line through the centre of the smallest circle around the points seen along the axis and the
segment ends that give the least capsule volume for each of 48 radii; the smallest capsule wins. Whatever the
choice, the final radius is recomputed as the largest distance of any point (or ball) from the chosen
segment, so the capsule encloses them by construction.
"""

from __future__ import annotations

import numpy as np

RADII = 48  # radii tried per axis


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


def fit_capsule_to(points: np.ndarray, balls: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """An enclosing capsule of ``points`` (n x 3) and ``balls`` (k x 4: centre, radius). Without balls it is
    ``fit_capsule``'s; balls add their axis points to the principal-axis fit and their exact farthest distance
    (centre's distance plus radius) to the radius."""
    if balls.shape[0] == 0:
        return fit_capsule(points)
    c, r = balls[:, :3], balls[:, 3]
    axes = np.concatenate([np.eye(3), -np.eye(3)])
    ball_pts = (c[:, None, :] + r[:, None, None] * axes[None]).reshape(-1, 3)
    a, b, rad = fit_capsule(np.concatenate([points, ball_pts]))
    rad = max(rad, float((point_segment_distances(c, a, b) + r).max()))
    return a, b, rad


def _circumcircle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, float]:
    ab, ac = b - a, c - a
    d = 2.0 * (ab[0] * ac[1] - ab[1] * ac[0])
    if abs(d) < 1e-18:  # collinear: the circle on the farthest pair
        pairs = [(a, b), (a, c), (b, c)]
        p, q = max(pairs, key=lambda pq: float(np.sum((pq[0] - pq[1]) ** 2)))
        return 0.5 * (p + q), 0.5 * float(np.linalg.norm(p - q))
    ux = (ac[1] * (ab @ ab) - ab[1] * (ac @ ac)) / d
    uy = (ab[0] * (ac @ ac) - ac[0] * (ab @ ab)) / d
    centre = a + np.array([ux, uy])
    return centre, float(np.hypot(ux, uy))


def enclosing_circle(points: np.ndarray) -> tuple[np.ndarray, float]:
    """The smallest circle around plane points (n x 2), by Welzl's incremental method in a fixed shuffled
    order (deterministic)."""
    pts = points[np.random.default_rng(0).permutation(len(points))]
    tol = 1e-12

    def out(p, c, r):
        return float(np.linalg.norm(p - c)) > r + tol

    c, r = pts[0].copy(), 0.0
    for i in range(1, len(pts)):
        if not out(pts[i], c, r):
            continue
        c, r = pts[i].copy(), 0.0
        for j in range(i):
            if not out(pts[j], c, r):
                continue
            c, r = 0.5 * (pts[i] + pts[j]), 0.5 * float(np.linalg.norm(pts[i] - pts[j]))
            for k in range(j):
                if out(pts[k], c, r):
                    c, r = _circumcircle(pts[i], pts[j], pts[k])
    return c, r


def _basis(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    helper = np.eye(3)[int(np.argmin(np.abs(u)))]
    e1 = np.cross(u, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(u, e1)


def _on_axis(points: np.ndarray, balls: np.ndarray, u: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, float]:
    """The least-volume capsule along direction ``u``: (volume, a, b, radius)."""
    e1, e2 = _basis(u)
    c, e = balls[:, :3], balls[:, 3]
    # the line's position: the centre of the smallest circle around the points and the balls' extreme points
    rim = (c[:, None, :] + e[:, None, None] * np.stack([e1, -e1, e2, -e2])[None]).reshape(-1, 3)
    seen = np.concatenate([points, rim])
    centre2, _ = enclosing_circle(np.column_stack([seen @ e1, seen @ e2]))
    origin = centre2[0] * e1 + centre2[1] * e2
    items = np.concatenate([points, c])
    extra = np.concatenate([np.zeros(len(points)), e])
    t = (items - origin) @ u
    rho = np.linalg.norm((items - origin) - np.outer(t, u), axis=1)
    r_min = float((rho + extra).max())
    span = float((t + extra).max() - (t - extra).min())
    best = (np.inf, origin, origin, 0.0)
    for radius in r_min + np.linspace(0.0, 0.5 * span, RADII):
        reach = np.sqrt(np.maximum((radius - extra) ** 2 - rho**2, 0.0))
        hi, lo = float((t - reach).max()), float((t + reach).min())
        if hi < lo:  # a sphere does: its centre anywhere in [hi, lo]
            lo = hi = 0.5 * (lo + hi)
        length = hi - lo
        volume = np.pi * radius**2 * length + 4.0 / 3.0 * np.pi * radius**3
        if volume < best[0]:
            best = (volume, origin + lo * u, origin + hi * u, float(radius))
    return best


def fit_tight(points: np.ndarray, balls: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The least-volume enclosing capsule over the principal axes of ``points`` and balls, ``directions`` (k x 3,
    e.g. each primitive's axes), and ``fit_capsule_to``'s own; see the module docstring."""
    c, e = balls[:, :3], balls[:, 3]
    cloud = np.concatenate([points, c]) if len(points) else c
    axes = [np.eye(3)] if len(cloud) < 2 else [np.linalg.svd(cloud - cloud.mean(axis=0), full_matrices=False)[2]]
    candidates: list[np.ndarray] = []
    for u in np.concatenate([*axes, np.asarray(directions, dtype=float).reshape(-1, 3)]):
        n = float(np.linalg.norm(u))
        if n > 0.0 and all(abs(float(u @ v)) < 0.9999 * n for v in candidates):
            candidates.append(u / n)
    a, b, r = fit_capsule_to(points, balls)
    best = (np.pi * r**2 * float(np.linalg.norm(b - a)) + 4.0 / 3.0 * np.pi * r**3, a, b, r)
    for u in candidates:
        got = _on_axis(points, balls, u)
        if got[0] < best[0]:
            best = got
    _, a, b, _ = best
    # the radius that encloses everything from this segment, recomputed: enclosing holds whatever the search did
    r = max([float(point_segment_distances(points, a, b).max())] if len(points) else [0.0])
    if len(c):
        r = max(r, float((point_segment_distances(c, a, b) + e).max()))
    return a, b, r
