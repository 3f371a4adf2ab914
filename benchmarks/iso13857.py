"""The articulated worker against ISO 13857 (issue 20): how far beyond a protective structure the simulated
worker gets, against the standard's safety distances.

    python benchmarks/iso13857.py [--quick] [--bodies p95-male,p50-male] [--flexion 55,90] [--width 8]
                                  [--per-heading 2] [--depth 8] [--spa 4] [--columns 1000,1400]
                                  [--openings-only | --no-openings] [--kernel-steps-only] [--show A,B]
                                  [--low-risk]

Reach over (Table 2, high risk): for each structure height b of the table's columns, a cell with one straight
fence panel (bottom 0, top b) across the floor and the worker (``human: {model: articulated, body: ...}``)
standing 1.32 m in front of it, facing it. For every hazard height a of the table's rows, c_sim is the largest
horizontal distance beyond the fence's face at which a body capsule's surface crosses the plane z = a, over
every 50 ms pose of every action sequence the search plays (computed exactly: ``section_reach``). Reach through
(Table 4): a tall panel with a square hole or a horizontal slot of width e centred at the standing shoulder
height; c_sim is the deepest point of the body beyond the face.

The search is a deterministic beam search over the worker's 112 actions (no random numbers: stable sorts, ties
to the lower index): every child of the beam is played from the start by ``Simulator.worker_paths`` (blocking
by the fence included), its poses turned into capsules by ``Simulator.worker_capsules``; for each objective (a
hazard height, and a-agnostic set-ups) the ``--width`` children with the best guide score at their last pose,
and the best ``--per-heading`` of each niche (45-degree heading; through an opening also the arm's pose), join
the next beam (identical poses once). A sequence is dropped when a limb goes below the floor or a body point
crosses the fence's plane between two time steps where the plane is closed (``Objective.swept_ok``: a check
of its own, independent of the kernel's, which tests the motion between poses too: kernels.sensing.path_blocked).
Agreement, per cell: |c_sim - c_iso| <= 100 mm (one step of
the table's c grid), with c_sim = 0 where no part of the body gets beyond the face at that height; rows the
standard calls out of reach (c = 0) thus agree when the worker gets at most 100 mm beyond the face.
docs/results.md and docs/worker.md discuss the numbers.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from cellstress.cell.load import parse_cell  # noqa: E402
from cellstress.core.iso13857 import TABLE_1, TABLE_2, TABLE_4, opening_distance  # noqa: E402
from cellstress.human.anthropometry import BODY_SIZES, TIPTOE_RISE  # noqa: E402
from cellstress.human.reach_bound import attainable, body_bound  # noqa: E402
from cellstress.sim.simulator import Simulator  # noqa: E402

STEP_MM = 100.0  # one step of Table 2's c grid: the agreement tolerance
START_GAP = 1.12  # m between the start and the closest the feet get (0.2 m) to the fence: 14 walking and 20
# side or back steps of 50 ms exactly, so that walking up to the fence ends right at it
ACTION_S = 0.2  # s per action (the paper's 4 x 50 ms); --spa splits it into finer time steps
OPENING_TOP = 2.5  # m: the panel with the opening is too high to reach over (the p95 man's tiptoe reach ~2.46 m)
FLOOR_TOL = 1e-9
LAMBDA = 1.0  # guide: metres of reach one metre of height miss costs

CELL = """name: {name}
robot:
  urdf: ur10
  base: {{xyz: [0.0, -4.0, 0.0], yaw_deg: 0.0}}
  stopping_time: 0.15
  task:
    waypoints_deg:
      - [124.8, -44.8, 78.4, -123.6, -90.0, 0.0]
      - [37.1, -44.8, 78.4, -123.6, -90.0, 0.0]
    dwell: 0.2
    speed_scale: 0.5
fences:
{fences}
floor: {{xmin: -3.0, xmax: 3.0, ymin: -5.5, ymax: 3.0}}
human:
  model: articulated
  body: {body}
  arrival: fixed
  start: {{xy: [{x0}, {y0}], heading_deg: -90.0}}
  max_forward_flexion_deg: {flexion}
simulation: {{dt: {dt}, steps_per_action: {spa}, actions_per_episode: 8}}
"""


def fence_line(x0: float, x1: float, bottom: float, top: float) -> str:
    return f"  - {{points: [[{x0!r}, 0.0], [{x1!r}, 0.0]], bottom: {bottom!r}, top: {top!r}}}"


def make_sim(name: str, fences: list[str], body: str, flexion: float, spa: int, x0: float = 0.0) -> Simulator:
    """A cell with the given fence panels along y = 0 (the hazard side is y < 0), the worker START_GAP + 0.2 m in
    front of them facing them, the UR10 4 m behind (out of reach: only the worker matters here)."""
    text = CELL.format(name=name, fences="\n".join(fences), body=body, x0=round(x0, 6),
                       y0=round(0.2 + START_GAP + 1e-6, 6), flexion=flexion, dt=ACTION_S / spa, spa=spa)
    return Simulator(parse_cell(text, name, None))


def reach_over_sim(b_m: float, body: str, flexion: float, spa: int) -> Simulator:
    """One long panel (x -6..6 m, longer than the 6 m floor, so nothing reaches around its ends) of top b."""
    return make_sim(f"iso-reach-over-{int(round(b_m * 1000))}", [fence_line(-6.0, 6.0, 0.0, b_m)], body, flexion,
                    spa)


def shoulder_height(body: str) -> float:
    """The standing shoulder joint's height (human.body: hip 0.530 H + shoulder rise 0.288 H)."""
    return 0.818 * BODY_SIZES[body].stature


def shoulder_half(body: str) -> float:
    """Sideways offset of the shoulder joint from the body's axis (human.body.BodyDimensions.params)."""
    return 0.259 * BODY_SIZES[body].stature / 2 - 0.05


def opening_sim(e_m: float, shape: str, body: str, flexion: float, spa: int, x0: float) -> Simulator:
    """A panel OPENING_TOP high with a square hole (side e, centred at x = 0) or a horizontal slot (width e, the
    floor's whole width) whose centre is at the standing shoulder height."""
    zc = shoulder_height(body)
    lo, hi = zc - e_m / 2, zc + e_m / 2
    if shape == "slot":
        fences = [fence_line(-6.0, 6.0, 0.0, lo), fence_line(-6.0, 6.0, hi, OPENING_TOP)]
    else:
        h = e_m / 2
        fences = [fence_line(-6.0, -h, 0.0, OPENING_TOP), fence_line(h, 6.0, 0.0, OPENING_TOP),
                  fence_line(-h, h, 0.0, lo), fence_line(-h, h, hi, OPENING_TOP)]
    return make_sim(f"iso-opening-{shape}-{int(round(e_m * 1000))}", fences, body, flexion, spa, x0)


# ---- pure geometry (tests/benchmarks/test_iso13857_bench.py) ------------------------------------------------
def section_reach(a: np.ndarray, b: np.ndarray, r: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """For capsules (axis a-b (..., 3), radius r (...)) and heights (K,): the largest -y of the capsule's surface
    in the plane z = height, (..., K); -inf where the capsule does not reach that height.

    A capsule is the union of balls of radius r on its axis s(t) = a + t (b - a); its section at z = h is the
    union of discs of radius sqrt(r^2 - (s_z(t) - h)^2) around (s_x, s_y)(t), so the answer is the maximum over
    t of -s_y(t) + sqrt(r^2 - u(t)^2), u = s_z - h, over the t where |u| <= r. That function is concave in t: its
    stationary point u* = -r d_y sgn(d_z) / |(d_y, d_z)|, clipped to the feasible interval, is the maximum."""
    a, b, r = np.asarray(a, float), np.asarray(b, float), np.asarray(r, float)
    h = np.asarray(heights, float)
    az, ay = a[..., 2, None], a[..., 1, None]
    dz, dy = (b[..., 2] - a[..., 2])[..., None], (b[..., 1] - a[..., 1])[..., None]
    rr = r[..., None]
    flat = np.abs(dz) < 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        sdz = np.where(flat, 1.0, dz)
        t1, t2 = (h - rr - az) / sdz, (h + rr - az) / sdz
        lo, hi = np.clip(np.minimum(t1, t2), 0.0, 1.0), np.clip(np.maximum(t1, t2), 0.0, 1.0)
        feasible = (np.maximum(t1, t2) >= 0.0) & (np.minimum(t1, t2) <= 1.0)
        ustar = -rr * dy * np.sign(sdz) / np.hypot(dy, sdz)
        t = np.clip((h + ustar - az) / sdz, lo, hi)
    u = az + t * dz - h
    val = -(ay + t * dy) + np.sqrt(np.maximum(rr * rr - u * u, 0.0))
    u0 = az - h  # a level capsule: every t at the same height, the far end counts
    flat_val = -np.minimum(ay, ay + dy) + np.sqrt(np.maximum(rr * rr - u0 * u0, 0.0))
    out = np.where(flat, flat_val, val)
    ok = np.where(flat, np.abs(u0) <= rr, feasible)
    return np.where(ok, out, -np.inf)


def guide_reach(a: np.ndarray, b: np.ndarray, r: np.ndarray, heights: np.ndarray, samples: int = 5) -> np.ndarray:
    """A smooth stand-in for ``section_reach`` that the beam ranks by: the largest -s_y + g over sampled axis
    points, g = sqrt(r^2 - u^2) within the radius of the height and -LAMBDA (|u| - r) beyond it. (..., K)."""
    t = np.linspace(0.0, 1.0, samples)
    s = a[..., None, :] + t[:, None] * (b - a)[..., None, :]  # (..., samples, 3)
    u = np.abs(s[..., 2, None] - heights)  # (..., samples, K)
    rr = r[..., None, None]
    g = np.where(u <= rr, np.sqrt(np.maximum(rr * rr - u * u, 0.0)), -LAMBDA * (u - rr))
    return (-s[..., 1, None] + g).max(axis=-2)


def depth_reach(a: np.ndarray, b: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The deepest point of each capsule beyond the plane y = 0 (its largest -y), at any height."""
    return -np.minimum(a[..., 1], b[..., 1]) + r


def agreement(c_iso_mm: float, c_sim_mm: float) -> str:
    """'agree' when |c_sim - c_iso| <= one step (100 mm), 'short' when the worker gets less far than the
    standard's distance minus a step (the standard keeps a margin), 'beyond' when it gets further than the
    distance plus a step (the standard's distance would not protect this worker). c_sim = 0: nothing beyond."""
    if c_sim_mm > c_iso_mm + STEP_MM:
        return "beyond"
    if c_sim_mm < c_iso_mm - STEP_MM:
        return "short"
    return "agree"


# ---- search -----------------------------------------------------------------------------------------------
def crossings_free(y0, z0, x0, y1, z1, x1, r, free) -> np.ndarray:
    """Between two consecutive poses, does every body point that crosses the fence's plane y = 0 cross it where
    the plane is open (``free(x, z, r)``: above the top, or inside an opening, with the capsule's radius to
    spare)? Points move in straight lines between the poses (fine for 50 ms steps). Arrays broadcast; True where
    no point goes through a panel."""
    crosses = np.asarray(y0 > 0.0) != np.asarray(y1 > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(crosses, y0 / (y0 - y1), 0.0)
    xc, zc = x0 + f * (x1 - x0), z0 + f * (z1 - z0)
    return np.logical_or(~crosses, free(xc, zc, r))


class Objective:
    """What a search maximises: ``exact(a, b, r)`` (n, steps, caps, ...) -> (n, K) over the steps and capsules,
    ``guide`` the same at one pose -> (n, K); ``free(x, z, r)``: where the fence's plane lets a capsule of
    radius r through (above the top ``top``; inside the square hole or the slot of width ``e`` centred at
    ``centre``)."""

    def __init__(self, heights_m: np.ndarray | None = None, centre: tuple[float, float] | None = None,
                 slot: bool = False, top: float = OPENING_TOP, e: float = 0.0):
        self.heights = heights_m
        self.centre, self.slot, self.top, self.e = centre, slot, top, e

    def free(self, x, z, r) -> np.ndarray:
        ok = np.asarray(z >= self.top + r)
        if self.centre is not None:
            inside = np.abs(z - self.centre[1]) <= self.e / 2 - r
            if not self.slot:
                inside &= np.abs(x - self.centre[0]) <= self.e / 2 - r
            ok |= inside
        return ok

    def niche(self, poses: np.ndarray) -> np.ndarray:
        """A kind of pose the beam keeps a few of whatever their score: the heading in 45-degree steps; through an
        opening also the right arm's flexion and abduction in 45-degree steps (which arm goes through matters)."""
        key = np.round(poses[:, 2] / (np.pi / 4)).astype(np.int64) % 8
        if self.heights is None:
            q = np.round(poses[:, 11:13] / (np.pi / 4)).astype(np.int64)
            key = key * 100 + q[:, 0] * 10 + q[:, 1]
        return key

    def swept_ok(self, a, b, r) -> np.ndarray:
        """(n,): no point of the trunk, head or arms (capsule ends and middles) passes through a panel between
        consecutive poses of (n, steps + 1, caps, ...) (the kernel checks the poses only, every 50 ms)."""
        pts = np.stack([a[:, :, 2:], (a[:, :, 2:] + b[:, :, 2:]) / 2, b[:, :, 2:]], axis=3)  # (n, s, c, 3, xyz)
        p0, p1 = pts[:, :-1], pts[:, 1:]
        rr = r[:, 1:, 2:, None]
        ok = crossings_free(p0[..., 1], p0[..., 2], p0[..., 0], p1[..., 1], p1[..., 2], p1[..., 0], rr, self.free)
        return ok.reshape(len(a), -1).all(axis=1)

    @property
    def k(self) -> int:
        return 1 if self.heights is None else len(self.heights)

    def exact(self, a, b, r) -> np.ndarray:
        depth = depth_reach(a, b, r)
        if self.heights is None:
            return depth.max(axis=(1, 2))[:, None]
        # only capsules that get beyond the face at all can count (c_sim is clamped at 0): the rest skipped
        v = np.full((*depth.shape, self.k), -np.inf)
        hit = depth > 0.0
        v[hit] = section_reach(a[hit], b[hit], r[hit], self.heights)
        return v.max(axis=(1, 2))

    def guide(self, a, b, r) -> np.ndarray:
        """(n, K + extra): one column per objective, then a-agnostic set-ups the beam also keeps: the deepest
        point of the body beyond the face, of the trunk and head, and the highest fingertip (a reach over a
        low fence and down behind it, or up and over a high one, passes through poses that are poor for
        the target height itself)."""
        if self.heights is not None:
            caps = slice(2, None)  # trunk, head, arms (the legs stay 0.2 m back)
            per_height = np.maximum(guide_reach(a[:, caps], b[:, caps], r[:, caps], self.heights, 3).max(axis=1),
                                    section_reach(a, b, r, self.heights).max(axis=1))
            setups = np.stack([depth_reach(a, b, r).max(axis=1), depth_reach(a[:, 2:4], b[:, 2:4], r[:, 2:4]).max(1),
                               b[:, 8:10, 2].max(axis=1)], axis=1)
            return np.concatenate([per_height, setups], axis=1)
        # through an opening: each hand's depth, less by how much the arm's line (shoulder to fingertip) misses
        # the opening where it meets the fence's plane (the rest of the body coming close scores nothing)
        sh, tip = a[:, 4:6], b[:, 8:10]  # shoulders (upper arms' starts), hands' capsule ends
        d = tip - sh
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = np.where(d[..., 1] < 0.0, sh[..., 1] / -d[..., 1], np.inf)
            cx, cz = sh[..., 0] + t0 * d[..., 0], sh[..., 2] + t0 * d[..., 2]
        miss = np.abs(cz - self.centre[1]) if self.slot else np.hypot(cx - self.centre[0], cz - self.centre[1])
        miss = np.where(np.isfinite(miss), miss, 10.0)  # pointing away from the fence
        return (-tip[..., 1] - miss).max(axis=1)[:, None]


def floor_ok(a: np.ndarray, b: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(n, steps): no capsule but the legs (which end on the floor) goes below the floor."""
    low = np.minimum(a[..., 2:, 2], b[..., 2:, 2]) - r[..., 2:]
    return (low >= -FLOOR_TOL).all(axis=-1)


def beam_search(sim: Simulator, obj: Objective, width: int, depth: int, swept: bool = True,
                per_heading: int = 0):
    """Best exact value per objective over every pose of every sequence the beam plays, and the sequence that
    first reached it: (best (K,), sequences [tuple of action names or None], episodes played). A sequence that
    puts a limb below the floor, or (``swept``) moves a body point through a panel between two poses, is
    dropped with all that would follow it."""
    spa, n_act = sim.steps_per_action, sim.n_actions
    best = np.full(obj.k, -np.inf)
    best_seq: list[tuple[int, ...] | None] = [None] * obj.k
    beam = np.zeros((1, 0), dtype=np.int64)
    played = 0
    for _ in range(depth):
        kids = np.concatenate([np.repeat(beam, n_act, axis=0),
                               np.tile(np.arange(n_act), len(beam))[:, None]], axis=1)
        # the action's poses and the one before it (none before the first: the worker starts 1.3 m away)
        poses = sim.worker_paths(kids)[:, -spa - 1:, :]
        played += len(kids)
        a, b, r = sim.worker_capsules(poses.reshape(-1, poses.shape[-1]))
        shape = (len(kids), poses.shape[1], *a.shape[1:])
        a, b, r = a.reshape(shape), b.reshape(shape), r.reshape(shape[:3])
        ok = obj.swept_ok(a, b, r) if swept else np.ones(len(kids), dtype=bool)
        poses, a, b, r = poses[:, -spa:], a[:, -spa:], b[:, -spa:], r[:, -spa:]
        ok &= floor_ok(a, b, r).all(axis=1)
        ex = np.where(ok[:, None], obj.exact(a, b, r), -np.inf)
        for k in range(obj.k):
            i = int(np.argmax(ex[:, k]))
            if ex[i, k] > best[k]:
                best[k], best_seq[k] = ex[i, k], tuple(int(v) for v in kids[i])
        g = obj.guide(a[:, -1], b[:, -1], r[:, -1])
        # one child per distinct last pose (the first), and only sequences that stayed off the floor
        # (along a straight fence the worker's x does not matter: poses that differ only in x are one)
        key = poses[:, -1, 1:] if obj.heights is not None else poses[:, -1, :]
        _, first = np.unique(np.round(key, 6), axis=0, return_index=True)
        cand = np.sort(first[ok[first]])
        # per objective, the best `width`, and the best `per_heading` of each niche (obj.niche): a reach turned
        # sideways (the shoulder to the fence) starts by turning away from the best frontal poses
        niche = obj.niche(poses[cand, -1])
        niches = np.unique(niche)
        keep = set()
        for k in range(g.shape[1]):
            order = np.argsort(-g[cand, k], kind="stable")
            keep.update(int(i) for i in cand[order[:width]])
            if per_heading:
                for h in niches:
                    keep.update(int(i) for i in cand[order[niche[order] == h][:per_heading]])
        beam = kids[sorted(keep)]
    names = sim.action_names
    return best, [None if s is None else tuple(names[i] for i in s) for s in best_seq], played


def replay_value(sim: Simulator, obj: Objective, seq: tuple[str, ...], k: int) -> float:
    """The witness played again alone: its exact value for objective k (the same number, or the search lied)."""
    acts = np.array([[sim.action_index(s) for s in seq]])
    poses = sim.worker_paths(acts)
    a, b, r = sim.worker_capsules(poses[0])
    return float(obj.exact(a[None], b[None], r[None])[0, k])


# ---- the tables -------------------------------------------------------------------------------------------
def run_reach_over(body: str, flexion: float, args, columns, rows) -> dict:
    heights = np.array(rows) / 1000.0
    out, t0, played = {}, time.perf_counter(), 0
    for b_mm in columns:
        sim = reach_over_sim(b_mm / 1000.0, body, flexion, args.spa)
        obj = Objective(heights, top=b_mm / 1000.0)
        best, seqs, n = beam_search(sim, obj, args.width, args.depth, not args.kernel_steps_only,
                                       args.per_heading)
        played += n
        for k, a_mm in enumerate(rows):
            c = max(0.0, float(best[k])) * 1000.0 if np.isfinite(best[k]) else 0.0
            out[a_mm, b_mm] = (c, seqs[k])
            if args.show and (a_mm, b_mm) == args.show and seqs[k] is not None:
                again = replay_value(sim, obj, seqs[k], k) * 1000.0
                print(f"witness a={a_mm:g} b={b_mm:g}: c_sim {c:.0f} mm (replayed alone: {again:.0f} mm): "
                      f"{' '.join(seqs[k])}")
    secs = time.perf_counter() - t0
    print_reach_over(out, body, flexion, columns, rows, secs, played, args)
    return out


def print_reach_over(out, body, flexion, columns, rows, secs, played, args) -> None:
    table = args.table
    print(f"\n### {table.table} ({table.risk} risk), {body}, trunk flexion up to {flexion:g} deg: "
          f"c_iso / c_sim [mm]\n")
    print("| a \\ b | " + " | ".join(f"{b:g}" for b in columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    counts = {"agree": 0, "short": 0, "beyond": 0}
    mark = {"agree": "", "short": " -", "beyond": " **+**"}
    for a in sorted(rows, reverse=True):
        cells = []
        for b in columns:
            c_iso, c_sim = table.c(a, b), out[a, b][0]
            verdict = agreement(c_iso, c_sim)
            counts[verdict] += 1
            cells.append(f"{c_iso:g} / {c_sim:.0f}{mark[verdict]}")
        print(f"| {a:g} | " + " | ".join(cells) + " |")
    n = sum(counts.values())
    print(f"\n{body}, {flexion:g} deg: agree {counts['agree']}/{n}, short (worker reaches less than c - 100 mm) "
          f"{counts['short']}, beyond (worker reaches further than c + 100 mm) {counts['beyond']}; "
          f"beam width {args.width} per height, depth {args.depth} actions, {args.spa} steps per action, "
          f"{played} sequences played, {secs:.1f} s")
    # the cells a body of this size can reach at all (benchmarks/iso13857_bound.py, its generous defaults)
    bound = body_bound(body, 180.0, TIPTOE_RISE)
    within = {"agree": 0, "short": 0, "beyond": 0}
    for a in rows:
        for b in columns:
            if attainable(bound, table.c(a, b), a, b):
                within[agreement(table.c(a, b), out[a, b][0])] += 1
    print(f"{body}: of the {sum(within.values())} cells the body can reach at all (iso13857_bound.py): agree "
          f"{within['agree']}, short {within['short']}, beyond {within['beyond']}")


FITS = ((0.025, "hand"), (0.04, "forearm"), (0.05, "upper arm"))  # capsule radii, human/body.py


def fits(e_m: float) -> str:
    """The largest limb capsule whose diameter an opening of width e lets through ("none": only a fingertip's
    worth of the hand's rounded end pokes in, r - sqrt(r^2 - e^2/4))."""
    names = [name for r, name in FITS if 2 * r < e_m]
    return names[-1] if names else "none"


def run_openings(body: str, flexion: float, args) -> None:
    t0, played = time.perf_counter(), 0
    zc = shoulder_height(body)
    print(f"\n### Table 4 (openings), {body}, trunk flexion up to {flexion:g} deg, opening centred at "
          f"{zc:.3f} m\n")
    print("| e [mm] | row | body part (table) | limb that fits | slot s_r / c_sim | square s_r / c_sim |")
    print("|---|---|---|---|---|---|")
    # Each row at its upper bound, and two more openings of the last row (60 and 90 mm: the hand, the forearm
    # through). The worker starts with its body's axis across the opening's centre: turned sideways, a shoulder
    # is then in front of it (the deepest reach; facing it, the other arm stops at the panel).
    rows = [(r.e_max_mm, r) for r in TABLE_4]
    rows[-1:-1] = [(60.0, TABLE_4[-1]), (90.0, TABLE_4[-1])]
    for e_mm, row in rows:
        e = e_mm / 1000.0
        cells = []
        for shape in ("slot", "square"):
            sim = opening_sim(e, shape, body, flexion, args.spa, 0.0)
            obj = Objective(None, centre=(0.0, zc), slot=shape == "slot", e=e)
            # nothing but a fingertip's worth fits below the hand's diameter: a small search suffices there
            big = fits(e) != "none"
            v, _, n = beam_search(sim, obj, args.width * (2 if big else 1), args.depth, not args.kernel_steps_only,
                                  1 if big else 0)
            played += n
            c = max(0.0, float(v[0])) * 1000.0
            sr = opening_distance(e_mm, shape)
            verdict = agreement(sr, c)
            cells.append(f"{sr:g} / {c:.0f}{' -' if verdict == 'short' else ''}"
                         f"{' **+**' if verdict == 'beyond' else ''}")
        print(f"| {e_mm:g} | {row.e_above_mm:g} < e <= {row.e_max_mm:g} | {row.body_part} | {fits(e)} | "
              + " | ".join(cells) + " |", flush=True)
    print(f"\n(beam width {args.width * 2} and 1 per niche where a limb fits, {args.width} otherwise; depth "
          f"{args.depth}; {played} sequences played, {time.perf_counter() - t0:.1f} s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="columns 1000, 1400, 2000, 2500, p95-male, 55 deg only")
    ap.add_argument("--bodies", default="p95-male")
    ap.add_argument("--flexion", default="55", help="largest trunk flexion(s) [deg], comma-separated")
    ap.add_argument("--width", type=int, default=8, help="beam children kept per objective (hazard height)")
    ap.add_argument("--per-heading", type=int, default=2,
                    help="beam children kept per objective and 45-degree heading besides --width")
    ap.add_argument("--depth", type=int, default=8, help="actions per sequence")
    ap.add_argument("--spa", type=int, default=4, help="time steps per 0.2 s action")
    ap.add_argument("--columns", default="", help="b values [mm] to run (default: all of Table 2)")
    ap.add_argument("--kernel-steps-only", action="store_true",
                    help="accept what the kernel accepts (poses checked every time step, not the motion between)")
    ap.add_argument("--openings-only", action="store_true")
    ap.add_argument("--no-openings", action="store_true")
    ap.add_argument("--low-risk", action="store_true", help="reach over: Table 1 (low risk) instead of Table 2")
    ap.add_argument("--show", default="", help="A,B: print the witness action sequence of one cell")
    args = ap.parse_args()
    args.show = tuple(float(v) for v in args.show.split(",")) if args.show else None
    args.table = TABLE_1 if args.low_risk else TABLE_2
    columns = [float(v) for v in args.columns.split(",")] if args.columns else list(args.table.b_mm)
    bodies, flexions = args.bodies.split(","), [float(v) for v in args.flexion.split(",")]
    if args.quick:
        columns, bodies, flexions = [1000.0, 1400.0, 2000.0, 2500.0], ["p95-male"], [55.0]
    t0 = time.perf_counter()
    for body in bodies:
        for flexion in flexions:
            if not args.openings_only:
                run_reach_over(body, flexion, args, columns, list(args.table.a_mm))
            if not args.no_openings and (not args.quick or body == bodies[0]):
                run_openings(body, flexion, args)
    print(f"\ntotal {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
