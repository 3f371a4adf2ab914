"""The episode animated: one frame per simulation step (row 0, the start, included), as an animated GIF.

Each frame shows the part of the cell the episode happens in (top view): the robot links and the worker's body
and reach volumes at that step, the closest points joined by a line, and beside it the time, d_HR, v_R, what
each safety device sees and the robot's stop phase. The static cell is rendered once; each frame restores that
image and draws the moving things over it (so they lie above every static thing, whatever its zorder).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from cellstress.core.io import atomic_write
from cellstress.report import draw as D
from cellstress.report.episode import EpisodeView
from cellstress.report.story import stop_request


@dataclass(frozen=True)
class AnimationOptions:
    size: D.FigureSize = D.FigureSize(8.0, 5.0, 80)  # 640 x 400 pixels
    frame_ms: int = 200  # a 50 ms step shown for 200 ms: a quarter of real time, slow enough to follow
    last_frame_ms: int = 2000  # hold the contact
    reach_stride: int = 2  # reach volume on a 4 cm grid: the outline is smooth enough at this size


def _region(view: EpisodeView, zone) -> tuple[float, float, float, float]:
    """Plan region to show: the worker's path, the robot's swept area and the contact, with a margin."""
    xs = [r.x for r in view.records] + [view.records[view.key_row].robot_point[0]]
    ys = [r.y for r in view.records] + [view.records[view.key_row].robot_point[1]]
    x0, x1, y0, y1 = zone.extent()
    arm = view.layout.body.arm_length + 0.3
    lo_x, hi_x = min(min(xs) - arm, x0 - 0.2), max(max(xs) + arm, x1 + 0.2)
    lo_y, hi_y = min(min(ys) - arm, y0 - 0.2), max(max(ys) + arm, y1 + 0.2)
    fl = view.layout.cell.spec.floor
    return max(lo_x, fl.xmin - 0.1), min(hi_x, fl.xmax + 0.1), max(lo_y, fl.ymin - 0.1), min(hi_y, fl.ymax + 0.1)


def frame_count(view: EpisodeView) -> int:
    return len(view.records)


def render_frames(view: EpisodeView, options: AnimationOptions = AnimationOptions(), zone=None) -> list[np.ndarray]:
    """One RGB image per simulation step."""
    zone = zone if zone is not None else D.swept_footprint(view.layout)
    fig = D.new_figure(options.size)
    ax = fig.add_axes((0.07, 0.1, 0.55, 0.85))
    D.draw_plan(ax, view.layout, D.PlanStyle(robot_now=False), zone=zone)
    x0, x1, y0, y1 = _region(view, zone)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.tick_params(labelsize=7)
    ax.xaxis.label.set_size(8)
    ax.yaxis.label.set_size(8)
    panel = fig.add_axes((0.64, 0.1, 0.35, 0.85))
    panel.set_axis_off()
    spec = view.layout.cell.spec
    names = [c.name for c in view.layout.capsules]
    radii = view.capsule_radii
    h = view.layout.reach.spacing * options.reach_stride
    recs = view.records
    path = np.array([[r.x, r.y] for r in recs])
    tripped: dict[str, float] = {}
    frames = []
    # blitting: the static cell is rendered once; each frame restores it and draws only the moving artists
    canvas = fig.canvas
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    n_steps = len(recs) - 1
    for i, r in enumerate(recs):
        artists = []
        pose = view.pose(i)
        ra, rb = view.robot(i)
        link = names.index(r.robot_link) if r.robot_link in names else -1
        colors = [D.ROBOT_HIT if c == link else D.ROBOT for c in range(len(radii))]
        artists.append(ax.add_collection(D.capsule_patches(ra[:, :2], rb[:, :2], radii, facecolor=colors,
                                                           alpha=0.8, edgecolor="white", lw=0.4, zorder=6)))
        for side in (0, 1):
            pts = view.reach(i, side, options.reach_stride, pose)
            main = r.body_part == ("left-reach", "right-reach")[side]
            artists += D.draw_volume(ax, pts[:, :2], h, D.REACH, alpha=0.25, lw=1.0 if main else 0.6, zorder=7,
                                     fill=main, ls="-" if main else "--")
        artists.append(ax.add_collection(D.capsule_patches(pose.a[:, :2], pose.b[:, :2], pose.r, facecolor=D.BODY,
                                                           alpha=0.8, edgecolor="white", lw=0.4, zorder=8)))
        artists += ax.plot(path[: i + 1, 0], path[: i + 1, 1], color=D.PATH, lw=1.2, zorder=9)
        rp, hp = r.robot_point, r.human_point
        artists += ax.plot([rp[0], hp[0]], [rp[1], hp[1]], color="black", lw=1.5, zorder=10)
        if r.unsafe:
            artists += ax.plot([rp[0]], [rp[1]], marker="*", ms=14, color=D.CONTACT, mec="black", zorder=11,
                               ls="none")
        for name in r.devices:
            tripped.setdefault(name, r.t)
        lines = [(f"t = {r.t:.2f} s   step {r.step} / {n_steps}", "black"),
                 (f"action {(i - 1) // view.steps_per_action + 1}: {r.action}" if r.action else "start",
                  "black"),
                 ("", "black"),
                 (f"d_HR = {r.d_HR:.3f} m", "black"),
                 (f"v_R  = {r.v_R:.2f} m/s", "black"),
                 (f"closest: {r.robot_link} / {r.body_part}", "#444444"),
                 ("", "black"),
                 ("devices", "black")]
        for d in spec.devices:
            if d.name in r.devices:
                state, color = "sees the worker", "#b00000"
            elif d.name in tripped:
                state, color = f"tripped at {tripped[d.name]:.2f} s", "#b06000"
            else:
                state, color = "clear", "#2a7a2a"
            lines.append((f"  {d.name}: {state}", color))
        stop = stop_request(view, i)
        phase = r.stop_phase
        phase_text = {"running": "running", "stop-pending": f"stop pending (at {stop[0]:.2f} s)" if stop else
                      "stop pending", "braking": "braking", "stopped": "stopped"}.get(phase, phase)
        lines += [("", "black"), (f"robot: {phase_text}", "#b00000" if phase != "running" else "black")]
        if r.unsafe:
            lines += [("", "black"), ("UNSAFE: contact while moving", D.CONTACT)]
        for k, (text, color) in enumerate(lines):
            artists.append(panel.text(0.0, 1.0 - k * 0.055, text, color=color, fontsize=8.5, va="top",
                                      family="monospace", transform=panel.transAxes))
        canvas.restore_region(background)
        for a in sorted(artists, key=lambda a: a.get_zorder()):  # stable: equal zorders keep their order
            a.axes.draw_artist(a)
        frames.append(np.asarray(canvas.buffer_rgba())[:, :, :3].copy())
        for a in artists:
            a.remove()
    return frames


def write_gif(frames: list[np.ndarray], path: str | Path, options: AnimationOptions = AnimationOptions()) -> Path:
    path = Path(path)
    images = [Image.fromarray(f) for f in frames]
    durations = [options.frame_ms] * (len(images) - 1) + [options.last_frame_ms]
    # frames always differ (the time is printed on each), so Pillow keeps every one (it merges identical ones)
    buf = io.BytesIO()
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:], duration=durations, loop=0,
                   optimize=False, disposal=1)
    atomic_write(path, buf.getvalue())
    return path


def animate(view: EpisodeView, path: str | Path, options: AnimationOptions = AnimationOptions(),
            zone=None) -> Path:
    return write_gif(render_frames(view, options, zone), path, options)
