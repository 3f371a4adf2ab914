"""Drawing primitives shared by every picture: figures without pyplot, capsules as stadiums, projected volumes,
and the cell's plan (floor, fences, table, devices, the robot's swept area, the start pose).

Figures are ``matplotlib.figure.Figure`` objects on an Agg canvas: no pyplot, no global state, no GUI, so
reports can be made in parallel processes and on machines without a display.
"""

from __future__ import annotations

import functools
import io
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon, Rectangle

from cellstress.core.io import atomic_write
from cellstress.sim.build import PEDESTAL, Layout

# One colour per kind of thing, used by every picture (the legend explains them once).
FLOOR = "#f7f7f7"
FENCE = "#2b2b2b"
TABLE = "#dcc9a0"
TABLE_EDGE = "#8a7446"
OBSTACLE = "#c9c3b8"
OBSTACLE_EDGE = "#6f6a60"
SWEPT = "#f3c0bb"
ROBOT = "#5a5a5a"
ROBOT_HIT = "#d62728"
BODY = "#1f77b4"
REACH = "#ff9f1c"
PATH = "#1f77b4"
START = "#2ca02c"
DETECT = "#e6ac00"
# The contact marker's colour is used by nothing else, so a test can find it in the pixels.
CONTACT = "#ff00ff"

# PNG text chunks name the matplotlib version: left out, so the same inputs give the same bytes.
PNG_METADATA = {"Software": None}


@dataclass(frozen=True)
class FigureSize:
    """Figure size in inches and resolution; the image is width*dpi x height*dpi pixels."""

    width: float
    height: float
    dpi: int

    @property
    def pixels(self) -> tuple[int, int]:
        return round(self.width * self.dpi), round(self.height * self.dpi)


def plain_text(func):
    """Make ``func``'s pictures with matplotlib's mathtext off: names come from files other people wrote, and a
    ``$`` in one would be read as mathematics (and a lone one fails the whole picture). Nothing of ours uses it."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with matplotlib.rc_context({"text.parse_math": False}):
            return func(*args, **kwargs)

    return wrapper


def new_figure(size: FigureSize) -> Figure:
    fig = Figure(figsize=(size.width, size.height), dpi=size.dpi)
    FigureCanvasAgg(fig)
    return fig


def save_png(fig: Figure, path: str | Path) -> Path:
    """Save without ``bbox_inches='tight'``, so pixel size and data-to-pixel transform are exactly the figure's."""
    path = Path(path)
    buf = io.BytesIO()
    fig.savefig(buf, dpi=fig.dpi, format="png", metadata=PNG_METADATA)
    atomic_write(path, buf.getvalue())  # a link planted at the path is replaced, never followed
    return path


# ---- shapes -----------------------------------------------------------------------------------------------
def stadiums(a: np.ndarray, b: np.ndarray, r: np.ndarray, n: int = 10) -> np.ndarray:
    """Outlines (m, 2n, 2) of the 2-D segments a-b (each (m, 2)) inflated by r: capsules seen from the side.
    Vectorised: the robot's swept area alone is a few thousand of them."""
    a, b = np.atleast_2d(np.asarray(a, float)), np.atleast_2d(np.asarray(b, float))
    r = np.broadcast_to(np.asarray(r, float), (len(a),))
    d = b - a
    ang = np.where(np.hypot(d[:, 0], d[:, 1]) > 1e-9, np.arctan2(d[:, 1], d[:, 0]), 0.0)
    arc = np.linspace(-np.pi / 2, np.pi / 2, n)
    th_b = ang[:, None] + arc[None, :]
    th_a = th_b + np.pi
    end_b = b[:, None, :] + r[:, None, None] * np.stack([np.cos(th_b), np.sin(th_b)], axis=2)
    end_a = a[:, None, :] + r[:, None, None] * np.stack([np.cos(th_a), np.sin(th_a)], axis=2)
    return np.concatenate([end_b, end_a], axis=1)


def stadium(a: np.ndarray, b: np.ndarray, r: float, n: int = 10) -> np.ndarray:
    """Outline (2n, 2) of one segment a-b inflated by r."""
    return stadiums(np.asarray(a, float)[None], np.asarray(b, float)[None], np.asarray([r], float), n)[0]


def capsule_patches(a2: np.ndarray, b2: np.ndarray, radii: np.ndarray, **style) -> PolyCollection:
    """Projected capsules (axes a2, b2 of shape (n, 2)) as one collection of stadiums."""
    return PolyCollection(stadiums(a2, b2, radii), closed=True, **style)


def occupancy(points2d: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Points rasterised on a grid of ``cell`` metres: (x centres, y centres, 0/1 grid) with an empty border
    so that contours close; None for no points."""
    if len(points2d) == 0:
        return None
    lo = np.floor(points2d.min(axis=0) / cell) - 2
    ij = np.floor(points2d / cell - lo).astype(np.int64)
    shape = ij.max(axis=0) + 3
    grid = np.zeros((shape[1], shape[0]))
    grid[ij[:, 1], ij[:, 0]] = 1.0
    xs = (lo[0] + np.arange(shape[0]) + 0.5) * cell
    ys = (lo[1] + np.arange(shape[1]) + 0.5) * cell
    return xs, ys, grid


def draw_volume(ax, points2d: np.ndarray, cell: float, color: str, alpha: float = 0.3, lw: float = 1.0,
                zorder: float = 3, fill: bool = True, ls: str = "-") -> list:
    """The projection of a point set (e.g. the reach volume's nodes) as a filled region with an outline."""
    occ = occupancy(points2d, cell)
    if occ is None:
        return []
    xs, ys, grid = occ
    artists = []
    if fill:
        artists.append(ax.contourf(xs, ys, grid, levels=[0.5, 1.5], colors=[color], alpha=alpha, zorder=zorder))
    artists.append(ax.contour(xs, ys, grid, levels=[0.5], colors=[color], linewidths=lw, linestyles=ls,
                              zorder=zorder + 0.1))
    return artists


# ---- the cell's plan --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PlanStyle:
    """What the cell plan shows."""

    swept_area: bool = True
    robot_now: bool = True  # the robot at t = 0 (or at the step given to draw_plan)
    start: bool = True
    start_size: float = 0.25  # m, the start marker's length


def swept_footprint(layout: Layout):
    """The floor area the robot sweeps over one cycle: the ISO 13855 check's hazard zone (same sampling)."""
    from cellstress.analysis.hazard_zone import hazard_zone

    return hazard_zone(layout)


def draw_plan(ax, layout: Layout, style: PlanStyle = PlanStyle(), robot_tau: float | np.ndarray | None = None,
              zone=None, robot_when: str = "at contact") -> list:
    """Draw the cell to scale in metres; returns legend handles (one per kind of thing shown). The robot is
    drawn at path time ``robot_tau`` (labelled ``robot_when``), or at t = 0 without one."""
    from cellstress.sim import layout as L
    from cellstress.sim import scene

    spec = layout.cell.spec
    fl = spec.floor
    handles: list = []
    ax.add_patch(Rectangle((fl.xmin, fl.ymin), fl.xmax - fl.xmin, fl.ymax - fl.ymin, facecolor=FLOOR,
                           edgecolor="#bbbbbb", lw=1.0, zorder=0))
    handles.append(Patch(facecolor=FLOOR, edgecolor="#bbbbbb", label="floor (walkable)"))
    handles += draw_obstacles(ax, layout)
    if style.swept_area:
        zone = zone if zone is not None else swept_footprint(layout)
        ax.add_collection(capsule_patches(zone.a, zone.b, zone.r, facecolor=SWEPT, edgecolor="none", zorder=2))
        # the obstacles' edges stay visible through the (opaque) swept area
        for o in layout.obstacles:
            ax.add_patch(Polygon(o.footprint(), closed=True, fill=False, edgecolor=obstacle_colors(o)[1], lw=0.8,
                                 ls=":", zorder=2.1))
        handles.append(Patch(facecolor=SWEPT, label="area the robot sweeps (one cycle)"))
    for d in spec.devices:  # each device kind draws itself (core.protocols.Device.draw)
        handles.append(d.draw(ax))
    for f in spec.fences:
        xy = np.asarray(f.points, float)
        ax.plot(xy[:, 0], xy[:, 1], color=FENCE, lw=3.5, solid_capstyle="projecting", zorder=5)
    if spec.fences:
        handles.append(Line2D([], [], color=FENCE, lw=3.5, label=f"fence ({spec.fences[0].top:g} m)"))
    for rs in spec.robots:
        base = rs.base.xyz
        ax.plot([base[0]], [base[1]], marker="P", ms=9, color=ROBOT, mec="white", zorder=7, ls="none")
        if len(spec.robots) > 1:
            ax.annotate(rs.name, (base[0], base[1]), xytext=(6, 6), textcoords="offset points", fontsize=8,
                        color=ROBOT, zorder=7)
    handles.append(Line2D([], [], marker="P", ms=9, color=ROBOT, mec="white", ls="none",
                          label="robot base" if len(spec.robots) == 1 else "robot bases"))
    if style.robot_now:
        tau = float(layout.params.scal[L.C_PHASE0]) if robot_tau is None else robot_tau  # the pose at t = 0
        a, b = scene.robot_capsules(layout, tau)
        ax.add_collection(capsule_patches(a[:, :2], b[:, :2], layout.params.cap_r, facecolor=ROBOT, alpha=0.55,
                                          edgecolor="white", lw=0.5, zorder=6))
        when = "at t = 0" if robot_tau is None else robot_when
        handles.append(Patch(facecolor=ROBOT, alpha=0.55, label=f"robot links {when} (top view)"))
    if style.start:
        s = spec.human.start
        draw_pose_arrow(ax, s.xy[0], s.xy[1], np.deg2rad(s.heading_deg), START, size=style.start_size, zorder=8)
        handles.append(Line2D([], [], marker=">", ms=9, color=START, ls="none", label="worker start and heading"))
        for named in spec.human.starts:  # a search picks one of these per episode
            x, y = named.xy
            draw_pose_arrow(ax, x, y, np.deg2rad(named.heading_deg), START, size=style.start_size, zorder=8,
                            alpha=0.6)
            ax.annotate(named.name, (x, y), xytext=(0, -11), textcoords="offset points", fontsize=7,
                        ha="center", color="#1a6b1a", zorder=8)
        if spec.human.starts:
            handles.append(Line2D([], [], marker=">", ms=9, color=START, alpha=0.6, ls="none",
                                  label="named start points"))
    ax.set_aspect("equal")
    ax.set_xlim(fl.xmin - 0.1, fl.xmax + 0.1)
    ax.set_ylim(fl.ymin - 0.1, fl.ymax + 0.1)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, color="#dddddd", lw=0.5, zorder=-1)
    ax.set_axisbelow(True)
    return handles


def _is_table(o) -> bool:
    return o.name == "table" or o.name.startswith("table-")


def obstacle_colors(o) -> tuple[str, str]:
    return (TABLE, TABLE_EDGE) if _is_table(o) else (OBSTACLE, OBSTACLE_EDGE)


def draw_obstacles(ax, layout: Layout) -> list:
    """The table's polygons and the obstacles (named, with their height), filled; returns legend handles."""
    handles: list = []
    tables = [o for o in layout.obstacles if _is_table(o)]
    for o in layout.obstacles:
        face, edge = obstacle_colors(o)
        ax.add_patch(Polygon(o.footprint(), closed=True, facecolor=face, edgecolor=edge, lw=1.0, zorder=1))
        if not _is_table(o) and not _is_pedestal(layout, o):  # (the robot base marker shows the pedestal)
            cx, cy = np.mean(np.asarray(o.footprint(), float), axis=0)
            ax.annotate(f"{o.name}\n{o.height:g} m", (cx, cy), ha="center", va="center", fontsize=6,
                        color=edge, zorder=1.5, annotation_clip=True)
    if tables:
        handles.append(Patch(facecolor=TABLE, edgecolor=TABLE_EDGE, label=f"table ({tables[0].height:g} m)"))
    if any(not _is_table(o) and not _is_pedestal(layout, o) for o in layout.obstacles):
        handles.append(Patch(facecolor=OBSTACLE, edgecolor=OBSTACLE_EDGE, label="obstacle (name, height)"))
    return handles


def draw_pose_arrow(ax, x: float, y: float, heading: float, color: str, size: float = 0.25, zorder: float = 8,
                    alpha: float = 1.0):
    """A filled triangle pointing along the heading: where a worker stands and faces."""
    c, s = np.cos(heading), np.sin(heading)
    tip = (x + size * c, y + size * s)
    left = (x - 0.35 * size * c - 0.4 * size * s, y - 0.35 * size * s + 0.4 * size * c)
    right = (x - 0.35 * size * c + 0.4 * size * s, y - 0.35 * size * s - 0.4 * size * c)
    patch = Polygon([tip, left, right], closed=True, facecolor=color, edgecolor="black", lw=0.6, zorder=zorder,
                    alpha=alpha)
    ax.add_patch(patch)
    return patch


def _is_pedestal(layout: Layout, o) -> bool:
    """A robot's own pedestal (``sim.build.pedestal``: after the cell's obstacles, one per robot)."""
    return o.name == PEDESTAL or o in layout.obstacles[len(layout.cell.spec.solid_obstacles()):]
