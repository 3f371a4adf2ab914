"""Plane geometry of the static check (numpy, and numba where it loops): distances from points to segments and
polygons, the parts of an edge no cover lies along, and the shortest arm path among line obstacles (fence panels
and curtains as walls, their ends as the corners a path bends round)."""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.jit import njit

JOIN_EXT = 1e-4  # m, panels meeting at a vertex are lengthened by this so no line slips through the joint
NODE_OFF = 1e-3  # m, detour nodes sit this far off a fence end or outer corner
COVER_TOL = 1e-6  # m, a field edge lying within this of a fence or table edge is covered by it


def point_segment(px, py, ax, ay, bx, by):
    """Distance and closest point from points p to segments ab (all broadcast)."""
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(den > 1e-300, ((px - ax) * dx + (py - ay) * dy) / np.where(den > 1e-300, den, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    qx, qy = ax + t * dx, ay + t * dy
    return np.hypot(px - qx, py - qy), qx, qy


def points_in_polygon(px, py, poly) -> np.ndarray:
    inside = np.zeros(np.shape(px), dtype=bool)
    n = len(poly)
    for i in range(n):
        (xi, yi), (xj, yj) = poly[i], poly[i - 1]
        cond = (yi > py) != (yj > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = xi + (py - yi) * (xj - xi) / (yj - yi)
        inside ^= cond & (px < xc)
    return inside


def distance_to_polyline(px, py, pts, closed: bool) -> np.ndarray:
    best = np.full(np.shape(px), np.inf)
    n = len(pts)
    for i in range(n if closed else n - 1):
        (ax, ay), (bx, by) = pts[i], pts[(i + 1) % n]
        best = np.minimum(best, point_segment(px, py, ax, ay, bx, by)[0])
    return best


@njit(cache=True, error_model="numpy", inline="always")
def orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True, error_model="numpy")
def blocked(ax, ay, bx, by, walls):
    """Does the straight line a-b properly cross any wall (x0, y0, x1, y1)?"""
    for k in range(walls.shape[0]):
        w0, w1, w2, w3 = walls[k, 0], walls[k, 1], walls[k, 2], walls[k, 3]
        o1 = orient(w0, w1, w2, w3, ax, ay)
        o2 = orient(w0, w1, w2, w3, bx, by)
        if o1 * o2 >= 0.0:
            continue
        o3 = orient(ax, ay, bx, by, w0, w1)
        o4 = orient(ax, ay, bx, by, w2, w3)
        if o3 * o4 < 0.0:
            return True
    return False


@njit(cache=True, error_model="numpy")
def direct(px, py, za, zb, zr, walls, bound):
    """Shortest straight, unobstructed distance from p to a stadium's nearest point, if below ``bound``;
    (distance, index), or (bound, -1)."""
    best = bound
    besti = -1
    for i in range(zr.shape[0]):
        ax, ay, bx, by = za[i, 0], za[i, 1], zb[i, 0], zb[i, 1]
        dx, dy = bx - ax, by - ay
        den = dx * dx + dy * dy
        t = 0.0 if den <= 1e-300 else ((px - ax) * dx + (py - ay) * dy) / den
        t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        qx, qy = ax + t * dx, ay + t * dy
        d = np.sqrt((px - qx) ** 2 + (py - qy) ** 2)
        g = d - zr[i]
        if g >= best:
            continue
        if g <= 0.0:
            return 0.0, i
        # the stadium's boundary point nearest p (the line to it is all that must be clear)
        f = g / d
        if not blocked(px, py, px + (qx - px) * f, py + (qy - py) * f, walls):
            best = g
            besti = i
    return best, besti


@njit(cache=True, error_model="numpy")
def node_values(nodes, za, zb, zr, walls):
    """Shortest path length from every detour node to the zone (Bellman-Ford on the visibility graph)."""
    n = nodes.shape[0]
    g = np.full(n, np.inf)
    gi = np.full(n, -1, dtype=np.int64)
    for k in range(n):
        g[k], gi[k] = direct(nodes[k, 0], nodes[k, 1], za, zb, zr, walls, np.inf)
    vis = np.zeros((n, n), dtype=np.bool_)
    for k in range(n):
        for j in range(k + 1, n):
            if not blocked(nodes[k, 0], nodes[k, 1], nodes[j, 0], nodes[j, 1], walls):
                vis[k, j] = True
                vis[j, k] = True
    for _ in range(n):
        changed = False
        for k in range(n):
            for j in range(n):
                if vis[k, j]:
                    c = np.sqrt((nodes[k, 0] - nodes[j, 0]) ** 2 + (nodes[k, 1] - nodes[j, 1]) ** 2) + g[j]
                    if c < g[k] - 1e-12:
                        g[k] = c
                        gi[k] = gi[j]
                        changed = True
        if not changed:
            break
    return g, gi


@njit(cache=True, error_model="numpy")
def arm_path(px, py, za, zb, zr, walls, nodes, g, gi, bound):
    """Shortest path from p to the zone around the walls (straight, or via detour nodes) if below ``bound``:
    (length, zone index), or (bound, -1)."""
    best, bi = bound, -1
    for k in range(nodes.shape[0]):  # the detours first: a cheap bound that spares most straight-line tests
        c = np.sqrt((px - nodes[k, 0]) ** 2 + (py - nodes[k, 1]) ** 2) + g[k]
        if c < best and not blocked(px, py, nodes[k, 0], nodes[k, 1], walls):
            best = c
            bi = gi[k]
    d, i = direct(px, py, za, zb, zr, walls, best)
    if i >= 0:
        best, bi = d, i
    return best, bi


@njit(cache=True, error_model="numpy")
def rasterise_zone(za, zb, zr, x0, y0, h, ny, nx, grow):
    """Cells whose centre lies within ``grow`` of the zone."""
    occ = np.zeros((ny, nx), dtype=np.bool_)
    for i in range(zr.shape[0]):
        ax, ay, bx, by = za[i, 0], za[i, 1], zb[i, 0], zb[i, 1]
        reach = zr[i] + grow
        ix0 = max(int(np.floor((min(ax, bx) - reach - x0) / h - 0.5)), 0)
        ix1 = min(int(np.ceil((max(ax, bx) + reach - x0) / h - 0.5)), nx - 1)
        iy0 = max(int(np.floor((min(ay, by) - reach - y0) / h - 0.5)), 0)
        iy1 = min(int(np.ceil((max(ay, by) + reach - y0) / h - 0.5)), ny - 1)
        dx, dy = bx - ax, by - ay
        den = dx * dx + dy * dy
        for iy in range(iy0, iy1 + 1):
            py = y0 + (iy + 0.5) * h
            for ix in range(ix0, ix1 + 1):
                if occ[iy, ix]:
                    continue
                px = x0 + (ix + 0.5) * h
                t = 0.0 if den <= 1e-300 else ((px - ax) * dx + (py - ay) * dy) / den
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
                if (px - ax - t * dx) ** 2 + (py - ay - t * dy) ** 2 <= reach * reach:
                    occ[iy, ix] = True
    return occ


@njit(cache=True, error_model="numpy")
def closest_reach(U, x0, y0, h, E, offs, lean_walls, za, zb, zr, arm_walls, nodes, g, gi):
    """Over all shoulder positions p (grid cell centres) within the lean of an undetected standing cell c
    (with c-p clear of lean_walls): the shortest arm path from p to the zone.

    Cells are visited in order of E, a lower bound of their distance to the zone (hence of the path), so the
    search stops as soon as no remaining cell can do better. Returns (distance, zone index, p cell, c cell).
    """
    ny, nx = U.shape
    order = np.argsort(E)
    best = np.inf
    bi, bp, bc = -1, -1, -1
    for m in range(order.shape[0]):
        idx = order[m]
        if E[idx] >= best:
            break
        iy, ix = idx // nx, idx % nx
        px, py = x0 + (ix + 0.5) * h, y0 + (iy + 0.5) * h
        found = -1
        for o in range(offs.shape[0]):
            cy, cx = iy + offs[o, 0], ix + offs[o, 1]
            if cy < 0 or cy >= ny or cx < 0 or cx >= nx or not U[cy, cx]:
                continue
            if not blocked(x0 + (cx + 0.5) * h, y0 + (cy + 0.5) * h, px, py, lean_walls):
                found = cy * nx + cx
                break
        if found < 0:
            continue
        d, i = arm_path(px, py, za, zb, zr, arm_walls, nodes, g, gi, best)
        if i >= 0 and d < best:
            best, bi, bp, bc = d, i, idx, found
    return best, bi, bp, bc


def open_intervals(p0, p1, covers) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Parts of segment p0-p1 not lying along any of the cover segments."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    u = p1 - p0
    length = float(np.hypot(*u))
    u /= length
    n = np.array([-u[1], u[0]])
    spans = []
    for a, b in covers:
        a, b = np.asarray(a, float), np.asarray(b, float)
        if abs((a - p0) @ n) > COVER_TOL or abs((b - p0) @ n) > COVER_TOL:
            continue
        s0, s1 = sorted(((a - p0) @ u, (b - p0) @ u))
        s0, s1 = max(s0, 0.0), min(s1, length)
        if s1 > s0:  # collinear covers beyond the edge's ends do not count
            spans.append((s0, s1))
    spans.sort()
    out, pos = [], 0.0
    for s0, s1 in spans:
        if s0 > pos + COVER_TOL:
            out.append((pos, s0))
        pos = max(pos, s1)
    if pos < length - COVER_TOL:
        out.append((pos, length))
    return [(tuple(round(float(v), 9) for v in p0 + s0 * u), tuple(round(float(v), 9) for v in p0 + s1 * u))
            for s0, s1 in out if s1 - s0 > 1e-9]


def junctions(segments) -> dict[tuple[int, int], tuple[np.ndarray, list[float]]]:
    """Every wall end with the directions of all walls leaving it: walls that end there, and both directions
    of a wall that passes through it (a T-junction)."""
    def key(p):
        return (round(float(p[0]) * 1e6), round(float(p[1]) * 1e6))

    segs = [(np.asarray(a, float), np.asarray(b, float)) for a, b in segments]
    out: dict[tuple[int, int], tuple[np.ndarray, list[float]]] = {}
    for a, b in segs:
        for p, q in ((a, b), (b, a)):
            out.setdefault(key(p), (p, []))[1].append(math.atan2(q[1] - p[1], q[0] - p[0]))
    for p, angles in out.values():
        for a, b in segs:
            u = b - a
            t = float((p - a) @ u / (u @ u))
            if 1e-9 < t < 1 - 1e-9 and np.hypot(*(a + t * u - p)) < 1e-9:
                angles += [math.atan2(u[1], u[0]), math.atan2(-u[1], -u[0])]
    return out


def extended_walls(segments) -> np.ndarray:
    """Walls as an (n, 4) array, each end that meets another wall lengthened by JOIN_EXT, so that no straight
    line slips through the joint."""
    joints = junctions(segments)
    out = []
    for a, b in segments:
        a, b = np.asarray(a, float), np.asarray(b, float)
        u = (b - a) / np.hypot(*(b - a))
        if len(joints[(round(a[0] * 1e6), round(a[1] * 1e6))][1]) > 1:
            a = a - JOIN_EXT * u
        if len(joints[(round(b[0] * 1e6), round(b[1] * 1e6))][1]) > 1:
            b = b + JOIN_EXT * u
        out.append((*a, *b))
    return np.asarray(out, dtype=float).reshape(-1, 4)


def detour_nodes(segments) -> np.ndarray:
    """Points just off every free wall end and outer corner: where shortest paths around walls bend."""
    nodes = []
    for p, angles in junctions(segments).values():
        angles = sorted(angles)
        for i, a0 in enumerate(angles):
            a1 = angles[(i + 1) % len(angles)] + (2 * math.pi if i + 1 == len(angles) else 0.0)
            if a1 - a0 > math.pi + 1e-9:  # a reflex gap between walls: paths bend around this corner
                mid = 0.5 * (a0 + a1)
                nodes.append((p[0] + NODE_OFF * math.cos(mid), p[1] + NODE_OFF * math.sin(mid)))
    return np.asarray(nodes, dtype=float).reshape(-1, 2)
