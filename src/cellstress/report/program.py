"""The robot's program alone, before any search (``cellstress show CELL --program``, and ``program.png`` in a
report): every robot's capsules over one cycle, from above and from the side, each move in its own colour, the
waypoints' poses outlined and numbered at the tool, the tool's path, and the program check's lines beneath
(``analysis.program_check``): what the simulator will move, and what is wrong with it.

The capsules are posed by the simulator's kernels at the program check's own path times (``capsule_axes``), so
the picture shows what the check and the search see. The same cell gives the same bytes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from cellstress.analysis.program_check import ProgramCheck, check_programs, tool_frame
from cellstress.analysis.program_sweep import capsule_axes, robot_params
from cellstress.core.text import for_terminal
from cellstress.report import draw as D
from cellstress.sim import kernels as K
from cellstress.sim.build import Layout

FAIL = "#ff0000"  # pure red: no move colour is near it (tab10 without its red)
POSES_PER_MOVE = 9  # capsule poses drawn per move, its two ends included
LINEAR_POSES = 60  # capsule poses drawn over the cycle of a trajectory file
TOOL_DT = 0.02  # s of path time between points of the tool's path
MAX_TEXT = 14  # lines of the program check printed under the views


@dataclass(frozen=True)
class ProgramPicture:
    size: D.FigureSize = D.FigureSize(13.0, 8.0, 100)


def _move_colors(n: int) -> list:
    cmap = matplotlib.colormaps["tab10"]
    palette = [cmap(i) for i in range(10) if i != 3]  # (3 is tab10's red, which would read as a failure)
    return [palette[i % len(palette)] for i in range(n)]


def _tool_points(layout: Layout, r: int, taus: np.ndarray) -> np.ndarray:
    """The tool frame's origin in the cell at path times ``taus``, by the kernels' kinematics of robot r."""
    part = layout.robots[r]
    joint, placement = part.model.link_frame(tool_frame(part))
    P = robot_params(layout, r)
    W = K.make_work(P)
    out = np.empty((len(taus), 3))
    for k, tau in enumerate(taus):
        K.joint_trajectory(P, float(tau), 1.0, W.q, W.qd)
        K.forward_kinematics(P, W.q, W.rot, W.pos)
        out[k] = W.pos[joint] + W.rot[joint] @ placement[:3, 3] if joint >= 0 else \
            P.base[:3, :3] @ placement[:3, 3] + P.base[:3, 3]
    return out


@dataclass(frozen=True)
class _Motion:
    """What is drawn of one robot: capsule axes (moves, poses, capsules, 3), the tool path and waypoints."""

    a: np.ndarray
    b: np.ndarray
    radii: np.ndarray
    tool: np.ndarray  # (k, 3)
    tool_move: np.ndarray  # (k,) the move of each tool point
    waypoints: np.ndarray  # (n, 3) the tool at each waypoint (none for a trajectory file)


def _spans(traj) -> list[tuple[float, float]]:
    """(start, duration) of each stretch drawn in one colour: each move of a waypoint program; a trajectory
    file's rows, hundreds of short moves, as one stretch over the whole cycle."""
    if traj.linear:
        return [(0.0, traj.cycle)]
    return [(float(b), float(d)) for b, d in zip(traj.starts + traj.dwells, traj.move_times, strict=True)]


def _motion(layout: Layout, r: int) -> _Motion:
    part = layout.robots[r]
    traj = part.trajectory
    spans = _spans(traj)
    per = LINEAR_POSES if traj.linear else POSES_PER_MOVE
    u = np.linspace(0.0, 1.0, per)
    taus = np.concatenate([b + u * d for b, d in spans])
    a, b = capsule_axes(layout, r, taus)
    shape = (len(spans), per, len(part.capsules), 3)
    tool_t, tool_m = [], []
    for i, (begin, dur) in enumerate(spans):
        n = max(2, math.ceil(dur / TOOL_DT) + 1)
        tool_t.append(begin + np.linspace(0.0, 1.0, n) * dur)
        tool_m.append(np.full(n, i))
    radii = layout.params.cap_r[part.first_capsule:part.first_capsule + len(part.capsules)]
    marks = np.zeros((0, 3)) if traj.linear else _tool_points(layout, r, traj.starts + traj.dwells)
    return _Motion(a.reshape(shape), b.reshape(shape), radii, _tool_points(layout, r, np.concatenate(tool_t)),
                   np.concatenate(tool_m), marks)


def _extent(motions: list[_Motion]) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) corners of everything the robots sweep, with their radii."""
    lo = np.min([np.minimum(m.a, m.b).reshape(-1, 3).min(axis=0) - m.radii.max() for m in motions], axis=0)
    hi = np.max([np.maximum(m.a, m.b).reshape(-1, 3).max(axis=0) + m.radii.max() for m in motions], axis=0)
    return lo, hi


def _draw_robot(ax, m: _Motion, i: int, j: int, colors: list, fails) -> None:
    """Robot capsules projected on axes (i, j): each move's poses translucent in its colour, the waypoints'
    poses outlined, the tool's path, the waypoints numbered; failing links at their time in red."""
    n_moves = m.a.shape[0]
    for k in range(n_moves):
        a, b = m.a[k, 1:-1].reshape(-1, 3), m.b[k, 1:-1].reshape(-1, 3)
        r = np.tile(m.radii, m.a.shape[1] - 2)
        ax.add_collection(D.capsule_patches(a[:, [i, j]], b[:, [i, j]], r, facecolor=colors[k], alpha=0.08,
                                            edgecolor="none", zorder=3))
        ax.add_collection(D.capsule_patches(m.a[k, 0][:, [i, j]], m.b[k, 0][:, [i, j]], m.radii, facecolor="none",
                                            edgecolor=D.ROBOT, lw=0.9, zorder=4))
        pts = m.tool[m.tool_move == k]
        ax.plot(pts[:, i], pts[:, j], color=colors[k], lw=1.8, zorder=5)
    for w, p in enumerate(m.waypoints):
        ax.plot([p[i]], [p[j]], marker="o", ms=5, color="white", mec="black", zorder=6, ls="none")
        ax.annotate(str(w + 1), (p[i], p[j]), xytext=(4, 4), textcoords="offset points", fontsize=8, zorder=6,
                    color="black")
    for a, b, r in fails:
        ax.add_collection(D.capsule_patches(a[None, [i, j]], b[None, [i, j]], np.array([r]), facecolor=FAIL,
                                            alpha=0.7, edgecolor="black", lw=0.6, zorder=7))


def _fail_capsules(layout: Layout, r: int, check: ProgramCheck) -> list[tuple[np.ndarray, np.ndarray, float]]:
    part = layout.robots[r]
    names = [c.name for c in part.capsules]
    out = []
    for x in check.passes:
        a, b = capsule_axes(layout, r, np.array([x.t]))
        c = names.index(x.link)
        out.append((a[0, c], b[0, c], float(layout.params.cap_r[part.first_capsule + c])))
    return out


def _side_view_solids(ax, layout: Layout, u: int) -> None:
    for o in layout.obstacles:
        foot = np.asarray(o.footprint(), float)
        face, edge = D.obstacle_colors(o)
        ax.add_patch(Rectangle((foot[:, u].min(), 0.0), float(np.ptp(foot[:, u])), o.height, facecolor=face,
                               edgecolor=edge, alpha=0.35, lw=0.8, zorder=1))
    for f in layout.cell.spec.fences:
        for a, b in zip(f.points, f.points[1:], strict=False):
            u0, u1 = sorted((a[u], b[u]))
            if u1 - u0 < 0.02:
                ax.plot([u0, u0], [f.bottom, f.top], color=D.FENCE, lw=2.5, alpha=0.5, zorder=2)
            else:
                ax.add_patch(Rectangle((u0, f.bottom), u1 - u0, f.top - f.bottom, facecolor="none", edgecolor=D.FENCE,
                                       alpha=0.3, ls=":", lw=1.0, zorder=2))
    ax.axhline(0.0, color="#777777", lw=1.0, zorder=1)


@D.plain_text
def program_figure(layout: Layout, checks: tuple[ProgramCheck, ...] | None = None,
                   options: ProgramPicture = ProgramPicture()):
    """The figure: top view left, side view right (looking across the axis the robots sweep further along),
    the program check's lines under them. Returns the figure."""
    checks = checks if checks is not None else check_programs(layout)
    fig = D.new_figure(options.size)
    top = fig.add_axes((0.07, 0.36, 0.41, 0.58))
    side = fig.add_axes((0.54, 0.36, 0.43, 0.58))
    D.draw_plan(top, layout, D.PlanStyle(swept_area=False, robot_now=False, start=False))
    motions = [_motion(layout, r) for r in range(len(layout.robots))]
    lo, hi = _extent(motions)
    u = int(hi[1] - lo[1] > hi[0] - lo[0])  # the side view looks across the longer plan axis
    _side_view_solids(side, layout, u)
    n_moves = max(m.a.shape[0] for m in motions)
    colors = _move_colors(n_moves)
    for r, (m, c) in enumerate(zip(motions, checks, strict=True)):
        fails = _fail_capsules(layout, r, c)
        _draw_robot(top, m, 0, 1, colors, fails)
        _draw_robot(side, m, u, 2, colors, fails)
    margin = 0.5
    fl = layout.cell.spec.floor
    top.set_xlim(max(lo[0] - margin, fl.xmin - 0.1), min(hi[0] + margin, fl.xmax + 0.1))
    top.set_ylim(max(lo[1] - margin, fl.ymin - 0.1), min(hi[1] + margin, fl.ymax + 0.1))
    side.set_xlim(*(top.get_xlim() if u == 0 else top.get_ylim()))
    side.set_ylim(-0.05, max(hi[2] + 0.2, 2.1))
    side.set_aspect("equal")
    side.set_xlabel(f"{'xy'[u]} [m]")
    side.set_ylabel("z [m]")
    side.grid(True, color="#dddddd", lw=0.5)
    side.set_axisbelow(True)
    spec = layout.cell.spec
    cycles = ", ".join(f"{c.robot + ' ' if c.robot else ''}{c.cycle:.2f} s" for c in checks)
    top.set_title("top view", fontsize=10, loc="left")
    side.set_title(f"side view ({'xy'[u]}-z plane, looking along {'yx'[u]})", fontsize=10, loc="left")
    fig.suptitle(f"{spec.name}: the robot's program over one cycle ({cycles}), without the worker", fontsize=11,
                 x=0.05, ha="left", y=0.985)
    linear = all(part.trajectory.linear for part in layout.robots)
    handles = [Patch(facecolor=colors[0], alpha=0.5, label="the trajectory file's cycle")] if linear else \
        [Patch(facecolor=colors[k], alpha=0.5, label=f"move {k + 1}") for k in range(min(n_moves, 9))]
    handles.append(Line2D([], [], color=D.ROBOT, lw=0.9, label="pose at the cycle's start (outline)" if linear
                          else "pose at a waypoint (outline)"))
    if not linear:
        handles.append(Line2D([], [], marker="o", color="white", mec="black", ls="none", label="tool at waypoint k"))
    if any(c.passes for c in checks):
        handles.append(Patch(facecolor=FAIL, alpha=0.7, label="link passing through a solid (FAIL)"))
    fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.05, 0.29), ncol=6, fontsize=8, frameon=False)
    lines = [line for c in checks for line in c.lines()]
    if len(lines) > MAX_TEXT:
        lines = [*lines[:MAX_TEXT - 1], f"... ({len(lines) - MAX_TEXT + 1} more lines: cellstress check)"]
    for k, line in enumerate(lines):
        fig.text(0.05, 0.205 - k * 0.0145, for_terminal(line), fontsize=7.5, family="monospace", va="top",
                 color=FAIL if "FAIL" in line else "#222222")
    return fig


def show_program(cell, out: str | Path, options: ProgramPicture = ProgramPicture()) -> Path:
    """Draw a cell's robot program (``cellstress show --program``) into a PNG file."""
    from cellstress.cell.load import load_cell
    from cellstress.sim.build import build_layout

    c = cell if not isinstance(cell, (str, Path)) else load_cell(cell)
    return D.save_png(program_figure(build_layout(c), options=options), out)
