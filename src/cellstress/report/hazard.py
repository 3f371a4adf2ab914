"""The still pictures of a hazard report: the cell's top view with the worker's path and the contact, the
contact seen from above and from the side, and the search's risk per episode.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from cellstress.analysis.iso13855 import StaticCheck
from cellstress.core import plane
from cellstress.report import draw as D
from cellstress.report.episode import EpisodeView
from cellstress.report.fit import fit_plan
from cellstress.sim.build import Layout

POSTURE_MARK = {"upright": "U", "bend-forward": "F", "bend-left": "L", "bend-right": "R",
                "bend-forward-left": "FL", "bend-forward-right": "FR"}
SIDE_VIEW_DEPTH = 1.2  # m: the side view shows the obstacles and fence panels this near the worker's hip
REACH_STRIDE_STILL = 1  # still pictures use every node of the reach field (2 cm)


@dataclass(frozen=True)
class StillOptions:
    """Sizes of the still pictures (pixels = inches x dpi)."""

    topview: D.FigureSize = D.FigureSize(11.0, 8.5, 100)
    contact: D.FigureSize = D.FigureSize(12.0, 6.0, 100)
    risk: D.FigureSize = D.FigureSize(8.0, 4.5, 100)
    layout: D.FigureSize = D.FigureSize(11.0, 8.5, 100)


PLAN_AXES = (0.06, 0.07, 0.56, 0.86)  # where a plan starts; fit.fit_plan then sizes the figure to it


def layout_figure(layout: Layout, size: D.FigureSize = StillOptions().layout, title: str | None = None,
                  static: StaticCheck | None = None):
    """The cell alone (``cellstress show``): returns (figure, axes). With ``static`` (the cell's ISO 13855 check)
    each device's distance is drawn as a dimension line from where a worker enters its detection zone to the
    hazard zone, labelled with the distance the standard requires and the one the layout gives."""
    fig = D.new_figure(size)
    ax = fig.add_axes(PLAN_AXES)
    handles = D.draw_plan(ax, layout)
    spec = layout.cell.spec
    if static is not None:
        handles += _draw_distances(ax, static)
    ax.set_title(title or f"{spec.name}: cell layout (top view, metres)", fontsize=11, loc="left")
    fit_plan(fig, ax, handles, size.height)
    return fig, ax


def _draw_distances(ax, static: StaticCheck) -> list:
    """ISO 13855 dimension lines: green where the layout gives the required distance S, red where it does not;
    the closest undetected reach (ISO 13857) likewise."""
    lines = [(d.where, f"{d.device}{' -> ' + d.robot if d.robot else ''}: S {d.required:.2f} m needed, "
              f"{d.actual:.2f} m here", d.ok) for d in static.devices if d.where is not None]
    for a in (static.approach, *static.robot_approaches):  # (several robots: the reach to each one's zone)
        if a.where is not None and math.isfinite(a.distance):
            whose = f" to {a.robot}" if a.robot else ""
            lines.append((a.where, f"reach around{whose}: {a.distance:.2f} m, {a.arm_allowance:.2f} m needed", a.ok))
    placed: list[tuple[float, float]] = []
    for where, text, ok in lines:
        color = OK_COLOR if ok else FAIL_COLOR
        (x0, y0), (x1, y1) = where.point, where.hazard_point
        ax.annotate("", (x1, y1), xytext=(x0, y0), arrowprops=dict(arrowstyle="<|-|>", color=color, lw=1.4),
                    zorder=15)
        # two dimension lines may end at the same place (a scanner's open edge and the reach around it): their
        # labels go one under the other
        lx, ly = (x0 + x1) / 2 + 0.08, (y0 + y1) / 2
        while any(abs(ly - py) < 0.2 and abs(lx - px) < 2.0 for px, py in placed):
            ly -= 0.2
        placed.append((lx, ly))
        ax.annotate(text, (lx, ly), fontsize=7, color=color, zorder=16, va="center",
                    bbox=dict(boxstyle="round,pad=0.15", facecolor="white", edgecolor="none", alpha=0.8))
    if not lines:
        return []
    return [Line2D([], [], color=OK_COLOR, lw=1.4, label="ISO 13855 / 13857 distance met"),
            Line2D([], [], color=FAIL_COLOR, lw=1.4, label="distance not met (check fails)")]


OK_COLOR, FAIL_COLOR = "#2ca02c", "#d62728"

# where an action's label may go, in units of the pose mark, tried in this order (right, then left, above, below)
LABEL_SPOTS = ((0.35, 0.1), (0.35, -0.9), (-1.5, 0.1), (-1.5, -0.9), (0.35, 1.1), (-1.5, 1.1), (0.35, -1.9),
               (-1.5, -1.9), (0.35, 2.1), (-1.5, 2.1), (1.6, 0.1), (-2.7, 0.1))


def _free_spot(x: float, y: float, placed: list[tuple[float, float]], mark: float) -> tuple[float, float]:
    """The first of ``LABEL_SPOTS`` around (x, y) whose label box (about 1.2 x 0.85 marks, the size of a
    two-character label at the mark sizes we draw) overlaps no label placed before; it is then placed. Labels of
    actions that end close together (turning in place, a blocked walk) would otherwise print over each other."""
    w, h = 1.2 * mark, 0.85 * mark
    for dx, dy in LABEL_SPOTS:
        lx, ly = x + dx * mark, y + dy * mark
        if all(abs(lx - px) >= w or abs(ly - py) >= h for px, py in placed):
            break
    placed.append((lx, ly))
    return lx, ly


def _draw_episode(ax, view: EpisodeView, pose, reach: list[np.ndarray], handles: list | None,
                  mark_size: float) -> None:
    """The episode over a drawn plan: path, a heading and posture mark per action, body and reach volumes at the
    key step, the first detection and the contact marker. Appends legend handles when ``handles`` is a list."""
    add = handles.append if handles is not None else (lambda _h: None)
    recs = view.records
    key = view.key_row
    hit = recs[key]
    xy = np.array([[r.x, r.y] for r in recs])
    ax.plot(xy[:, 0], xy[:, 1], color=D.PATH, lw=1.6, zorder=9)
    ax.plot(xy[:, 0], xy[:, 1], ".", color=D.PATH, ms=3, zorder=9)
    add(Line2D([], [], color=D.PATH, lw=1.6, marker=".", ms=3, label=f"worker's path ({view.dt:g} s steps)"))
    placed: list[tuple[float, float]] = []
    for k, act in enumerate(view.actions):
        r = recs[view.action_rows(k)[-1]]
        D.draw_pose_arrow(ax, r.x, r.y, np.deg2rad(r.heading_deg), "white", size=mark_size, zorder=13)
        x, y = _free_spot(r.x, r.y, placed, mark_size)
        ax.annotate(f"{k + 1}{POSTURE_MARK.get(act.partition('+')[2], '?')}", (r.x, r.y), xytext=(x, y),
                    textcoords="data", fontsize=7, color="#0b3c6b", zorder=14, va="bottom", ha="left")
    add(Line2D([], [], marker=">", color="white", mec="black", ls="none", ms=7,
               label="after action k: heading, posture\n(U upright, F forward, L / R left / right)"))
    ax.add_collection(D.capsule_patches(pose.a[:, :2], pose.b[:, :2], pose.r, facecolor=D.BODY, alpha=0.7,
                                        edgecolor="white", lw=0.4, zorder=12))
    add(Patch(facecolor=D.BODY, alpha=0.7, label="worker's body at " + ("contact" if view.unsafe
                                                                          else "the closest call")))
    for side in (0, 1):
        main = hit.body_part == ("left-reach", "right-reach")[side]
        D.draw_volume(ax, reach[side][:, :2], view.layout.reach.spacing, D.REACH, alpha=0.25 if main else 0.0,
                      lw=1.2 if main else 0.8, zorder=11, fill=main, ls="-" if main else "--")
    add(Patch(facecolor=D.REACH, alpha=0.35, edgecolor=D.REACH, label="arm reach volume (projected)"))
    det = view.detection_row
    if det is not None:
        r = recs[det]
        ax.plot([r.x], [r.y], marker="D", ms=8, color=D.DETECT, mec="black", zorder=13, ls="none")
        add(Line2D([], [], marker="D", ms=8, color=D.DETECT, mec="black", ls="none",
                   label=f"first detected (t = {r.t:.2f} s, {', '.join(r.devices)})"))
    cx, cy, _ = hit.robot_point
    label = "contact point" if view.unsafe else "closest point (no contact)"
    ax.plot([cx], [cy], marker="*", ms=18, color=D.CONTACT, mec="black", mew=0.8, zorder=20, ls="none")
    add(Line2D([], [], marker="*", ms=14, color=D.CONTACT, mec="black", ls="none",
               label=f"{label} (t = {hit.t:.2f} s)"))


INSET_AXES = (0.66, 0.07, 0.32, 0.42)  # a first place; fit.fit_plan puts it under the legend


def topview_figure(view: EpisodeView, size: D.FigureSize = StillOptions().topview, title: str | None = None,
                   zone=None):
    """The cell to scale with the worker's path, a heading and posture mark per action, the robot, body and
    reach volume at the key step, the point of detection and the contact point, and an enlarged view of where
    it happens below the legend. Returns (figure, main axes)."""
    fig = D.new_figure(size)
    ax = fig.add_axes(PLAN_AXES)
    key = view.key_row
    zone = zone if zone is not None else D.swept_footprint(view.layout)
    pose = view.pose(key)
    reach = [view.reach(key, side, REACH_STRIDE_STILL, pose) for side in (0, 1)]
    handles = D.draw_plan(ax, view.layout, robot_tau=view.taus[key], zone=zone,
                          robot_when="at contact" if view.unsafe else "at the closest call")
    _draw_episode(ax, view, pose, reach, handles, mark_size=0.16)
    spec = view.layout.cell.spec
    what = "hazard" if view.unsafe else "no hazard; riskiest episode"
    ax.set_title(title or f"{spec.name}: {what} (episode {view.episode}), top view", fontsize=11, loc="left")
    # the enlarged view: the path, the touching reach volume and the contact, with a margin
    inset = fig.add_axes(INSET_AXES)
    D.draw_plan(inset, view.layout, D.PlanStyle(start_size=0.12), robot_tau=view.taus[key], zone=zone)
    _draw_episode(inset, view, pose, reach, None, mark_size=0.08)
    recs = view.records
    hit = recs[key]
    pts = [np.array([[r.x, r.y] for r in recs]), np.asarray(hit.robot_point[:2])[None]]
    lo = np.min(np.concatenate(pts), axis=0) - 0.45
    hi = np.max(np.concatenate(pts), axis=0) + 0.45
    half = 0.5 * max(hi - lo)  # square, so the equal aspect fills the box
    mid = 0.5 * (lo + hi)
    inset.set_xlim(mid[0] - half, mid[0] + half)
    inset.set_ylim(mid[1] - half, mid[1] + half)
    inset.set_title("enlarged", fontsize=9, loc="left")
    inset.tick_params(labelsize=7)
    inset.set_xlabel("")
    inset.set_ylabel("")
    fit_plan(fig, ax, handles, size.height, inset=inset)
    return fig, ax


def _point_segment_2d(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    d = b - a
    t = float(np.clip(np.dot(p - a, d) / max(float(np.dot(d, d)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * d)))


def _side_axis(view: EpisodeView) -> int:
    """The world axis (0 = x, 1 = y) along which the worker and the contact are furthest apart: the side
    view looks across it, so both are seen side by side rather than one behind the other."""
    hit = view.records[view.key_row]
    d = np.abs(np.subtract(hit.robot_point[:2], (hit.x, hit.y)))
    return int(d[1] > d[0])


def contact_figure(view: EpisodeView, size: D.FigureSize = StillOptions().contact):
    """Top and side view at the key step: robot links (the closest one in red), body capsules, both arms'
    reach volumes (the touching arm filled), and the closest points joined by a line. Returns the figure."""
    fig = D.new_figure(size)
    key = view.key_row
    hit = view.records[key]
    pose = view.pose(key)
    ra, rb = view.robot(key)
    radii = view.capsule_radii
    names = [c.name for c in view.layout.capsules]
    hit_link = names.index(hit.robot_link) if hit.robot_link in names else -1
    reach = [view.reach(key, side, REACH_STRIDE_STILL, pose) for side in (0, 1)]
    touching = {"left-reach": 0, "right-reach": 1}.get(hit.body_part)
    rp, hp = np.asarray(hit.robot_point), np.asarray(hit.human_point)
    u = _side_axis(view)
    axis_name = "xy"[u]
    h = view.layout.reach.spacing

    # the region shown: the worker, the reach volume of the touching arm, the closest robot link, the contact
    pts = [pose.a, pose.b, rp[None], hp[None], ra[hit_link][None], rb[hit_link][None]]
    if touching is not None:
        pts.append(reach[touching])
    allp = np.concatenate(pts)
    lo, hi = allp.min(axis=0) - 0.25, allp.max(axis=0) + 0.25

    ax_top = fig.add_axes((0.06, 0.17, 0.42, 0.73))
    ax_side = fig.add_axes((0.55, 0.17, 0.42, 0.73))
    D.draw_plan(ax_top, view.layout, D.PlanStyle(swept_area=False, robot_now=False, start=False))
    spec = view.layout.cell.spec
    for ax, (i, j) in ((ax_top, (0, 1)), (ax_side, (u, 2))):
        for side in (0, 1):
            main = side == touching
            D.draw_volume(ax, reach[side][:, [i, j]], h, D.REACH, alpha=0.3 if main else 0.0, lw=1.2 if main else 0.8,
                          zorder=3, fill=main, ls="-" if main else "--")
        colors = [D.ROBOT_HIT if c == hit_link else D.ROBOT for c in range(len(radii))]
        ax.add_collection(D.capsule_patches(ra[:, [i, j]], rb[:, [i, j]], radii, facecolor=colors, alpha=0.85,
                                            edgecolor="white", lw=0.5, zorder=6))
        ax.add_collection(D.capsule_patches(pose.a[:, [i, j]], pose.b[:, [i, j]], pose.r, facecolor=D.BODY,
                                            alpha=0.75, edgecolor="white", lw=0.5, zorder=7))
        if touching is not None:
            s = pose.shoulders[touching]
            ax.plot([s[i], hp[i]], [s[j], hp[j]], color=D.REACH, lw=1.2, ls="--", zorder=8)
        ax.plot([rp[i], hp[i]], [rp[j], hp[j]], color="black", lw=2.0, zorder=9)
        ax.plot([rp[i]], [rp[j]], marker="o", ms=6, color=D.ROBOT_HIT, mec="black", zorder=10, ls="none")
        ax.plot([hp[i]], [hp[j]], marker="o", ms=4, color=D.BODY, mec="black", zorder=10, ls="none")
        ax.set_aspect("equal")
    ax_top.set_xlim(lo[0], hi[0])
    ax_top.set_ylim(lo[1], hi[1])
    # side view: floor, the obstacles and the fence panels near the worker, projected
    hip = pose.a[2, :2]
    for o in view.layout.obstacles:
        foot = np.asarray(o.footprint(), float)
        if plane.polygon_distance(float(hip[0]), float(hip[1]), foot) > SIDE_VIEW_DEPTH:
            continue
        face, edge = D.obstacle_colors(o)
        ax_side.add_patch(Rectangle((foot[:, u].min(), 0.0), np.ptp(foot[:, u]), o.height, facecolor=face,
                                    edgecolor=edge, alpha=0.6, zorder=1))
    # fence panels near the worker: one seen edge-on is a solid line; one running along the view is drawn as a
    # faint outline only (it stands in front of or behind the scene, not between its parts)
    for f in spec.fences:
        for a, b in zip(f.points, f.points[1:], strict=False):
            if _point_segment_2d(hip, np.asarray(a, float), np.asarray(b, float)) > SIDE_VIEW_DEPTH:
                continue
            u0, u1 = sorted((a[u], b[u]))
            if u1 - u0 < 0.02:
                ax_side.plot([u0, u0], [f.bottom, f.top], color=D.FENCE, lw=3.0, alpha=0.6, zorder=2)
            else:
                ax_side.add_patch(Rectangle((u0, f.bottom), u1 - u0, f.top - f.bottom, facecolor="none",
                                            edgecolor=D.FENCE, alpha=0.3, ls=":", lw=1.0, zorder=2))
    ax_side.axhline(0.0, color="#777777", lw=1.0, zorder=1)
    ax_side.set_xlim(lo[u], hi[u])
    ax_side.set_ylim(0.0, max(hi[2], 2.1))
    ax_side.set_xlabel(f"{axis_name} [m]")
    ax_side.set_ylabel("z [m]")
    ax_side.grid(True, color="#dddddd", lw=0.5)
    ax_side.set_axisbelow(True)
    other = "yx"[u]
    word = "contact" if view.unsafe else "closest call"
    ax_top.set_title(f"top view at the {word}, t = {hit.t:.2f} s", fontsize=10, loc="left")
    ax_side.set_title(f"side view ({axis_name}-z plane, looking along {other})", fontsize=10, loc="left")
    handles = [Patch(facecolor=D.ROBOT_HIT, label=f"robot link {hit.robot_link}"),
               Patch(facecolor=D.ROBOT, label="other robot links"),
               Patch(facecolor=D.BODY, alpha=0.75, label="worker's body capsules"),
               Patch(facecolor=D.REACH, alpha=0.3, edgecolor=D.REACH, label="reach volume (touching arm)"),
               Line2D([], [], color=D.REACH, ls="--", label="other arm's reach / shoulder to contact"),
               Line2D([], [], color=D.FENCE, lw=3.0, alpha=0.6, label="fence (side view: edge-on)"),
               Line2D([], [], color="black", lw=2, marker="o", ms=4,
                      label=f"closest points, d_HR = {hit.d_HR:.3f} m")]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(f"{spec.name}: {hit.robot_link} / {hit.body_part} at t = {hit.t:.2f} s, "
                 f"v_R = {hit.v_R:.2f} m/s, {hit.stop_phase}", fontsize=11, x=0.06, ha="left", y=0.98)
    return fig


RISK_NOTE = ("The risk is the search's guide, not the verdict: the criterion decides what is unsafe. With the "
             "paper's c_S it is exp(v_R) / (d_HR² + 1), so a fast robot near the worker scores high with or without "
             "a hazard, and a hazardous contact with a slow robot can score below a near miss.")


def risk_figure(risks: list[float], hazard_episode: int | None, size: D.FigureSize = StillOptions().risk,
                title: str = "", hazard_episodes: tuple[int, ...] = ()):
    """Each episode's maximum risk (the searcher's reward signal) and the best so far, against the episode
    number, with every hazardous episode marked: the figure must not suggest that the highest risk is the
    hazard (``RISK_NOTE`` is printed under it)."""
    fig = D.new_figure(size)
    ax = fig.add_axes((0.1, 0.24, 0.86, 0.64))
    r = np.array([np.nan if v is None else v for v in risks], dtype=float)
    n = np.arange(1, len(r) + 1)
    ax.plot(n, r, ".", color="#7f7f7f", ms=4, label="episode's max risk (no hazard)")
    if len(r):
        ax.step(n, np.fmax.accumulate(np.nan_to_num(r, nan=0.0)), where="post", color="#1f77b4", lw=1.5,
                label="highest risk so far (guides the search)")
    marked = [e for e in sorted(set(hazard_episodes) | ({hazard_episode} if hazard_episode else set()))
              if 1 <= e <= len(r)]
    if marked:
        ax.plot(marked, r[np.array(marked) - 1], "o", ms=6, color=D.CONTACT, mec="black", mew=0.5, ls="none",
                label=f"hazardous episode ({len(marked)})")
    if hazard_episode is not None:
        ax.axvline(hazard_episode, color="black", ls="--", lw=1.0, label=f"first hazard (episode {hazard_episode})")
    ax.set_xlabel("episode")
    ax.set_ylabel("risk (search signal)")
    ax.set_xlim(0.5, max(len(r), 1) + 0.5)
    ax.grid(True, color="#dddddd", lw=0.5)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(title or "risk per episode", fontsize=10, loc="left")
    fig.text(0.02, 0.02, "\n".join(textwrap.wrap(RISK_NOTE, 125)), fontsize=7.5, color="#444444", va="bottom")
    return fig
