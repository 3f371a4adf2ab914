"""The report of a verification: the hazard map (``verify.png``: arrival phases x start points) and the text
summary ``cellstress verify`` prints."""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from pathlib import Path

import numpy as np
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.ticker import FuncFormatter, NullFormatter

from cellstress.report import draw as D
from cellstress.report import html as H
from cellstress.report.episode import replay
from cellstress.report.scene3d import view_of_episodes
from cellstress.report.scope import static_lines
from cellstress.report.view3d import STYLE as VIEW3D_STYLE
from cellstress.report.view3d import view_fragment
from cellstress.searchers.severity import words as severity_words
from cellstress.verifier.records import PROVED_SAFE, UNDECIDED, UNSAFE, VerifyResult

PNG_NAME = "verify.png"
HTML_NAME = "verify.html"
MAP_SIZE = D.FigureSize(9.0, 3.6, 100)
SAFE_COLOUR = "#d9f0d3"
UNDECIDED_COLOUR = "#bdbdbd"
MAX_LISTED = 12  # hazardous sub-trees listed one by one in the summary
MAX_WITNESS_VIEWS = 24  # witnesses offered in verify.html's 3D view (each about 0.1-0.3 MB); all are in files


@D.plain_text
def hazard_map(res: VerifyResult, path: str | Path, size: D.FigureSize = MAP_SIZE) -> Path:
    """One row per start point, one column per arrival phase: the exact probability that a uniformly random
    worker reaches the unsafe set (log colour scale), proved-safe sub-trees green, undecided ones grey."""
    starts = list(dict.fromkeys(s.start for s in res.subtrees))
    phases = sorted({s.phase for s in res.subtrees})
    grid = np.full((len(starts), len(phases)), np.nan)
    status = np.zeros(grid.shape, dtype=int)  # 0 safe, 1 unsafe, 2 undecided
    for s in res.subtrees:
        i, j = starts.index(s.start), phases.index(s.phase)
        grid[i, j] = s.probability if s.hazardous else np.nan
        status[i, j] = 1 if s.verdict == UNSAFE else 2 if s.verdict == UNDECIDED else 0
    fig = D.new_figure(size)
    ax = fig.add_axes((0.14, 0.28, 0.74, 0.56))
    extent = (-0.5, len(phases) - 0.5, len(starts) - 0.5, -0.5)
    ax.imshow(np.where(status == 2, 1.0, 0.0), cmap=ListedColormap([SAFE_COLOUR, UNDECIDED_COLOUR]), vmin=0, vmax=1,
              aspect="auto", extent=extent, interpolation="nearest")
    if np.isfinite(grid).any():
        lo = float(np.nanmin(grid))
        img = ax.imshow(grid, cmap="Reds", norm=LogNorm(vmin=min(lo, 0.99e-1), vmax=1.0), aspect="auto",
                        extent=extent, interpolation="nearest")
        bar = fig.colorbar(img, cax=fig.add_axes((0.9, 0.28, 0.02, 0.56)))
        bar.set_label("P(hazard), uniform worker", fontsize=8)
        # plain tick labels: mathtext is off in every picture (names from files), and log ticks would use it
        bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.0e}"))
        bar.ax.yaxis.set_minor_formatter(NullFormatter())
        bar.ax.tick_params(labelsize=7)
    ax.set_yticks(range(len(starts)), starts, fontsize=8)
    step = max(1, len(phases) // 12)
    ax.set_xticks(range(0, len(phases), step), [f"{phases[k]:g}" for k in range(0, len(phases), step)], fontsize=8)
    ax.set_xlabel("arrival phase: the robot's time in its cycle when the worker arrives [s]", fontsize=8)
    ax.set_title(f"{res.cell.name}: {res.verdict}, {res.options.horizon} actions per episode "
                 f"(green: proved safe; grey: undecided)", fontsize=10, loc="left")
    fig.text(0.02, 0.03, f"{res.hazardous:,} of {res.sequences:,} sequences hazardous"
             + (f"; {res.undecided:,} undecided" if res.undecided else ""), fontsize=8, color="#444444")
    return D.save_png(fig, path)


@dataclass(frozen=True)
class Run:
    """Sub-trees of one start point at consecutive arrival phases (in the verification's order) that share a
    condition: how many, and the sum of what ``count`` counts in them."""

    start: str
    first: float
    last: float
    subtrees: int
    count: int
    window: float
    margin: float

    def where(self) -> str:
        if self.subtrees == 1:
            return f"{self.start} at phase {self.first:g} s"
        return f"{self.start} at phases {self.first:g}..{self.last:g} s ({self.subtrees} sub-trees)"


def runs(subtrees, count) -> list[Run]:
    """The ranges of consecutive sub-trees with ``count(sub-tree)`` > 0, per start point."""
    out: list[Run] = []
    prev_in = False
    for s in subtrees:
        n = count(s)
        if n and prev_in and out[-1].start == s.start:
            r = out[-1]
            out[-1] = Run(r.start, r.first, s.phase, r.subtrees + 1, r.count + n, max(r.window, s.window),
                          max(r.margin, s.margin))
        elif n:
            out.append(Run(s.start, s.phase, s.phase, 1, n, s.window, s.margin))
        prev_in = bool(n)
    return out


def summary_lines(res: VerifyResult, criterion_text: str, out: str | None = None) -> list[str]:
    """What ``cellstress verify`` prints: the scope, the proof's size, what each bound cut, the verdict, the
    hazardous sub-trees and each hazard class with its witness."""
    o = res.options
    n_starts = len({s.start for s in res.subtrees})
    n_phases = len({s.phase for s in res.subtrees})
    lines = [
        f"cell      {res.cell.name}  horizon {o.horizon} actions  phases {o.phases_text} ({len(res.subtrees)} "
        f"sub-tree{'s' if len(res.subtrees) != 1 else ''}: {n_starts} start point{'s' if n_starts != 1 else ''}, "
        f"{n_phases} arrival phase{'s' if n_phases != 1 else ''})",
        f"criterion {criterion_text}",
        f"decided   {res.sequences - res.undecided:,} of {res.sequences:,} action sequences; {res.states:,} distinct "
        f"states visited",
    ]
    for p in res.pruned:
        lines.append(f"pruned    {p.bound}: {p.states:,} states, {p.sequences:,} sequences proved safe")
    sc = res.scope
    where = f"from start point{'s' if len(sc.starts) > 1 else ''} {', '.join(sc.starts)}, at {sc.arrival}"
    if res.verdict == PROVED_SAFE:
        lines.append(f"PROVED-SAFE: no sequence of {o.horizon} actions reaches the unsafe set {where}")
    elif res.verdict == UNDECIDED:
        why = []
        if res.undecided:
            why.append(f"{res.undecided:,} sequences were not decided (time limit)")
        if res.alarms:
            why.append(f"{res.alarms:,} sequences touch the robot grown by its arrival margin but are hazardous at "
                       "none of the arrival moments replayed across their window (alarms, listed below)")
        lines.append(f"UNDECIDED: {'; '.join(why)}; no hazard among the rest; this is not a proof")
    elif res.hazardous:
        lines.append(f"UNSAFE: {res.hazardous:,} of {res.sequences:,} sequences hazardous at the grid moments "
                     f"(p = {res.hazardous / res.sequences:.3e} for a uniformly random worker)")
    else:
        confirmed = sum(s.confirmed for s in res.subtrees)
        lines.append(f"UNSAFE: none hazardous at the grid moments, but {confirmed:,} sequences are at arrival "
                     "moments between them (replayed; their witnesses below)")
    if res.verdict != UNSAFE:
        lines += static_lines(res.static_failures, "this proof")
    if sc.horizon < sc.cell_horizon:
        lines.append(f"note      {sc.horizon} actions per episode, fewer than the cell's own {sc.cell_horizon}: "
                     "contacts after them are not decided")
    for a in sc.approximations:
        size = f" ({a.size:.3g} {a.unit})" if a.size else ""
        lines.append(f"model     {a.name}{size}: {a.what}")
    hazardous = [s for s in res.subtrees if s.hazardous]
    for s in hazardous[:MAX_LISTED]:
        lines.append(f"  {s.start} at phase {s.phase:g} s: {s.hazardous:,} of {s.sequences:,} hazardous "
                     f"(p = {s.probability:.3e})")
    if len(hazardous) > MAX_LISTED:
        worst = max(hazardous, key=lambda s: s.hazardous)
        lines.append(f"  ... {len(hazardous) - MAX_LISTED} more hazardous sub-trees (verify.json, verify.html); the "
                     f"most: {worst.start} at phase {worst.phase:g} s (p = {worst.probability:.3e})")
    between = [s for s in res.subtrees if s.confirmed and not s.hazardous]
    for s in between[:MAX_LISTED]:
        lines.append(f"  {s.start} within {s.window:g} s of phase {s.phase:g} s: {s.confirmed:,} sequences hazardous "
                     "at an arrival moment between grid points (replayed)")
    undecided = runs(res.subtrees, lambda s: s.undecided)
    for r in undecided[:MAX_LISTED]:
        lines.append(f"  undecided: {r.where()}: {r.count:,} sequences")
    alarmed = runs(res.subtrees, lambda s: s.alarms)
    for r in alarmed[:MAX_LISTED]:
        lines.append(f"  alarm: {r.where()}, each within {r.window:g} s: {r.count:,} sequences touch the robot grown "
                     f"by up to {r.margin * 1000:.0f} mm, none hazardous when replayed")
    if len(undecided) > MAX_LISTED or len(alarmed) > MAX_LISTED:
        more_u, more_a = max(len(undecided) - MAX_LISTED, 0), max(len(alarmed) - MAX_LISTED, 0)
        lines.append(f"  ... {more_u} more undecided and {more_a} more alarmed ranges: every sub-tree is in "
                     "verify.json")
    for i, w in enumerate(res.classes, start=1):
        k = w.klass
        failed = "no device saw the worker" if k.device == "none" else f"{k.device} stopped the robot too late"
        where = f"{out}/{w.file}" if out else w.file
        x0, y0, x1, y1 = k.approach_cell
        sev = "" if w.severity is None else f"; {severity_words(w.severity)}"
        lines.append(f"class {i:<3} {failed}; {k.robot_link} / {k.body_region}, worker at x {x0:g}..{x1:g}, "
                     f"y {y0:g}..{y1:g}{sev}; {w.sequences:,} sequences; first at "
                     f"{w.start}, phase {w.phase:g} s: {', '.join(w.actions)}")
        lines.append(f"          cellstress replay {where}")
    return lines


def witness_view(res: VerifyResult, sim) -> str:
    """The 3D view of the first ``MAX_WITNESS_VIEWS`` witnesses, replayed in ``sim`` (one to pick at a time);
    empty without a witness."""
    if not res.classes:
        return ""
    views = []
    for i, w in enumerate(res.classes[:MAX_WITNESS_VIEWS], start=1):
        view = replay(sim, list(w.actions), episode=1)
        views.append((view, f"class {i}: {w.klass.robot_link} / {w.klass.body_region} ({w.klass.device})"))
    return view_fragment(view_of_episodes(views[0][0].layout, views), episode_labels=True)


def verify_page(res: VerifyResult, png: str | Path, path: str | Path, criterion_text: str, view3d: str = "") -> Path:
    """``verify.html``: the verdict, the proof's size, the hazard map, the hazardous sub-trees and each hazard
    class with its witness (self-contained, like every report page); ``view3d`` (``witness_view``) shows each
    witness in 3D."""
    lines = summary_lines(res, criterion_text)
    verdict = next(ln for ln in lines if ln.startswith(res.verdict))
    body = [f"<h1>{escape(res.cell.name)}: {escape(res.verdict)}</h1>",
            f'<div class="verdict {"safe" if res.verdict == PROVED_SAFE else "hazard"}">{escape(verdict)}</div>',
            H.table(None, [[ln.split(" ", 1)[0], ln.split(" ", 1)[1].strip()] for ln in lines[:3 + len(res.pruned)]]),
            f"<p>{escape(res.scope.statement)}</p>",
            *([H.table(["check row that fails", "value", "what the simulated worker cannot do"],
                       [[f.name, f.value, f.limit or "(it can; no sequence of this scope did)"]
                        for f in res.static_failures])] if res.static_failures else []),
            H.table(["approximation", "size", "what"],
                    [[a.name, f"{a.size:.3g} {a.unit}" if a.size else "", a.what]
                     for a in res.scope.approximations]),
            H.figure(png, "Hazard map: arrival phases x start points", "hazard map"),
            "<h2>Sub-trees</h2>",
            H.table(["start", "phase [s]", "verdict", "hazardous", "of", "P(hazard)", "between grid moments",
                     "alarms", "undecided", "states"],
                    [[s.start, f"{s.phase:g}", s.verdict, f"{s.hazardous:,}", f"{s.sequences:,}",
                      f"{s.probability:.3e}", f"{s.confirmed:,}", f"{s.alarms:,}", f"{s.undecided:,}",
                      f"{sum(s.states):,}"] for s in res.subtrees if s.verdict != PROVED_SAFE]
                    or [["(every sub-tree proved safe)", "", "", "", "", "", "", "", "", ""]],
                    numeric={1, 3, 4, 5, 6, 7, 8, 9})]
    if res.classes:  # worst first (searchers.severity)
        body += ["<h2>Hazard classes and their witnesses</h2>",
                 H.table(["class", "device", "robot link / body region", "severity", "sequences", "witness",
                          "file"],
                         [[i, w.klass.device, f"{w.klass.robot_link} / {w.klass.body_region}",
                           severity_words(w.severity), f"{w.sequences:,}", ", ".join(w.actions), w.file]
                          for i, w in enumerate(res.classes, start=1)],
                         numeric={0, 4})]
    if view3d:
        shown = min(len(res.classes), MAX_WITNESS_VIEWS)
        body += ["<h2>Witnesses in 3D</h2>",
                 f"<p>Each witness replayed (pick one; {shown} of {len(res.classes)} classes shown): the robot's "
                 "capsules, the worker's body and reach volumes, the fences, solids and detection fields. The "
                 "slider's last step is the contact.</p>", view3d]
    return H.write_page(path, H.page(f"verify {res.cell.name}", body,
                                     f"cellstress {res.version}; replay a witness with: cellstress replay FILE",
                                     extra_style=VIEW3D_STYLE if view3d else ""))
