"""Random walls for the fence kernels' tests: one straight wall as one run or as collinear runs, a shoulder on one
side and points on the other, and every panel near as the kernel collects them."""

from __future__ import annotations

import numpy as np

from cellstress.sim.kernels.fences import collect_near_fences
from cellstress.sim.kernels.params import near_size


def random_wall(rng, pieces: int) -> tuple[np.ndarray, np.ndarray]:
    """A random straight wall as one panel and as ``pieces`` collinear panels meeting end to end."""
    a = rng.uniform(-2.0, 2.0, 2)
    ang = rng.uniform(0.0, 2 * np.pi)
    length = rng.uniform(0.5, 3.0)
    u = np.array([np.cos(ang), np.sin(ang)])
    bottom, top = rng.choice([0.0, 0.0, 0.3]), rng.uniform(1.0, 2.4)
    cuts = np.sort(rng.uniform(0.1, 0.9, pieces - 1))
    ts = np.concatenate(([0.0], cuts, [1.0]))
    pts = [a + t * length * u for t in ts]
    whole = np.array([[*pts[0], *pts[-1], bottom, top]])
    split = np.array([[*p, *q, bottom, top] for p, q in zip(pts, pts[1:], strict=False)])
    return whole, split


def every_panel_near(fences):
    """Every panel near, as the kernel collects them (with which one continues which)."""
    near = np.zeros(near_size(len(fences)), dtype=np.int64)
    return near, collect_near_fences(fences, np.zeros((2, 3)), near, np.inf)


def sides(rng, whole):
    """A shoulder on one side of the wall's line and a point on the other, near it."""
    x0, y0, x1, y1 = whole[0, :4]
    u = np.array([x1 - x0, y1 - y0])
    n = np.array([-u[1], u[0]]) / np.linalg.norm(u)
    along = np.array([x0, y0]) + rng.uniform(-0.2, 1.2) * u
    s = np.array([*(along + rng.uniform(0.05, 0.6) * n), rng.uniform(0.8, 1.7)])
    q = np.array([*(along + rng.uniform(-0.3, 0.3) * u - rng.uniform(0.05, 0.8) * n), rng.uniform(0.3, 1.8)])
    return s, q
