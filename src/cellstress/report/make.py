"""A search result's report: topview.png, contact.png, replay.gif, risk.png, program.png and report.html,
written next to result.json. The same result.json gives the same files (no dates, no versions in the PNGs).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from cellstress.analysis.check_rows import static_failures
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.shortfall import shortfall
from cellstress.core.errors import CellstressError
from cellstress.core.provenance import file_changes
from cellstress.report import draw as D
from cellstress.report import html as H
from cellstress.report.animate import AnimationOptions, animate
from cellstress.report.episode import EpisodeView, episode_of
from cellstress.report.hazard import StillOptions, contact_figure, risk_figure, topview_figure
from cellstress.report.program import program_figure
from cellstress.report.scene3d import view_of_episodes, view_of_program
from cellstress.report.scope import NOT_A_PROOF, judged_by, search_scope, static_lines, strongest_contact
from cellstress.report.story import Account, account
from cellstress.report.view3d import STYLE as VIEW3D_STYLE
from cellstress.report.view3d import view_fragment, view_page
from cellstress.searchers.result import FILE_NAME, SearchResult
from cellstress.searchers.severity import words as severity_words

NAMES = ("topview.png", "contact.png", "replay.gif", "risk.png", "program.png", "report.html")


class ReportError(CellstressError):
    """A result file the report cannot use (missing, not a result, its cell no longer loads)."""


@dataclass(frozen=True)
class ReportOptions:
    stills: StillOptions = field(default_factory=StillOptions)
    animation: AnimationOptions = field(default_factory=AnimationOptions)
    view3d: bool = True  # report.html holds the interactive 3D view (plotly.js inline, about 5 MB)


@dataclass(frozen=True)
class ReportFiles:
    topview: Path
    contact: Path
    replay: Path
    risk: Path
    program: Path
    html: Path
    account: Account
    found: bool
    cell_changed: bool  # the cell file, or a file it reads, differs from the one searched (sha256)

    @property
    def paths(self) -> tuple[Path, ...]:
        return (self.topview, self.contact, self.replay, self.risk, self.program, self.html)


def _load(result: SearchResult | str | Path) -> tuple[SearchResult, Path | None]:
    if isinstance(result, SearchResult):
        return result, None
    p = Path(result)
    res = SearchResult.load(p)  # SearchError (a CellstressError) for a missing or foreign file
    return res, (p if p.is_dir() else p.parent)


def _simulator(res: SearchResult, sim):
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.cell.schema import DEFAULT_CRITERION
    from cellstress.sim.simulator import Simulator

    if sim is not None and sim.cell.sha256 == res.cell.sha256:
        return sim
    try:
        return Simulator(with_criterion(load_cell(res.cell.source), res.cell.criterion or DEFAULT_CRITERION))
    except CellstressError as exc:
        raise ReportError(f"cannot load the result's cell: {exc}") from None


@D.plain_text
def write_report(result: SearchResult | str | Path, out_dir: str | Path | None = None, *, sim=None,
                 options: ReportOptions = ReportOptions()) -> ReportFiles:
    """Write the report of ``result`` (a SearchResult, a result.json or its folder) into ``out_dir`` (default:
    the result's folder). ``sim`` may be the Simulator the search used, to save building it again."""
    res, folder = _load(result)
    out = Path(out_dir) if out_dir is not None else folder
    if out is None:
        raise ReportError("out_dir is needed for a SearchResult object")
    out.mkdir(parents=True, exist_ok=True)
    sim = _simulator(res, sim)
    view = episode_of(res, sim)
    zone = D.swept_footprint(sim.layout)
    st = options.stills
    fig, _ = topview_figure(view, st.topview, zone=zone)
    top = D.save_png(fig, out / NAMES[0])
    contact = D.save_png(contact_figure(view, st.contact), out / NAMES[1])
    gif = animate(view, out / NAMES[2], options.animation, zone=zone)
    h = res.hazard
    title = f"{res.searcher}, seed {res.seed}: max risk per episode ({res.episodes} episodes)"
    risk = D.save_png(risk_figure(res.risk_per_episode, h.episode if h else None, st.risk, title,
                                  tuple(e.episode for e in res.hazards)), out / NAMES[3])
    program = D.save_png(program_figure(sim.layout), out / NAMES[4])
    acc = account(view, res.episodes)
    changed = sim.cell.sha256 != res.cell.sha256 or (  # or a file it reads (a URDF, a mesh; issue 29)
        res.cell.files is not None and bool(file_changes(res.cell.files, sim.cell.files)))
    strongest = None if res.found else strongest_contact(sim, view.actions)
    static = check_cell(sim.cell) if not res.found or res.hazard.why is not None else None
    why = None if not res.found or res.hazard.why is None else shortfall(res.hazard.why, static)
    page = hazard_page(res, view, acc, top, contact, gif, risk, changed, Judgement(
        judged_by(sim.criterion), search_scope(res, sim.cell.spec, sim.layout.trajectory.cycle), strongest, why,
        () if res.found else static_lines(static_failures(static), "this search")),
        program, view3d=_view3d(view) if options.view3d else "")
    html = H.write_page(out / NAMES[5], page)
    return ReportFiles(top, contact, gif, risk, program, html, acc, res.found, changed)


def _view3d(view: EpisodeView) -> str:
    what = "hazard" if view.kind == "hazard" else "riskiest kept episode"
    return view_fragment(view_of_episodes(view.layout, [(view, f"episode {view.episode} ({what})")]))


def _fmt(x, nd: int = 3) -> str:
    return "-" if x is None else f"{x:.{nd}f}"


def action_rows(view: EpisodeView) -> tuple[list[list], list[str]]:
    rows, classes = [], []
    recs = view.records
    for k, act in enumerate(view.actions):
        span = view.action_rows(k)
        rr = [recs[i] for i in span]
        last = rr[-1]
        seen = sorted({d for r in rr for d in r.devices})
        rows.append([k + 1, act, f"{recs[span.start - 1].t:.2f}-{last.t:.2f}",
                     f"({last.x:.2f}, {last.y:.2f})", f"{last.heading_deg:.1f}",
                     f"{last.forward_flexion_deg:.1f}", f"{last.lateral_flexion_deg:.1f}",
                     _fmt(min(r.d_HR for r in rr)), _fmt(max(r.v_R for r in rr), 2),
                     ", ".join(seen) or "-", last.stop_phase])
        classes.append("unsafe" if any(r.unsafe for r in rr) else "")
    return rows, classes


@dataclass(frozen=True)
class Judgement:
    """What the page says was judged: the criterion in words, what the search covered, and (no hazard, a
    criterion that judges contacts) the strongest contact of the episode shown."""

    criterion: str
    scope: str
    strongest: str | None = None
    why: str | None = None  # a hazard: why the safeguards did not prevent it (analysis.shortfall)
    static: tuple[str, ...] = ()  # no hazard: the rows check fails, which the search did not clear (scope.static_lines)


def hazard_page(res: SearchResult, view: EpisodeView, acc: Account, top: Path, contact: Path, gif: Path,
                risk: Path, cell_changed: bool, judgement: Judgement, program: Path | None = None,
                view3d: str = "") -> str:
    cell = res.cell.name
    e = H.escape
    body = [f"<h1>cellstress report: {e(cell)}</h1>"]
    if res.found:
        h = res.hazard
        verdict = (f"<b>Hazard found</b> at episode {h.episode} of {res.budget} ({e(res.searcher)}, seed "
                   f"{res.seed}): {e(str(h.robot_link))} / {e(str(h.body_part))} at t = {h.time_s:.2f} s, "
                   f"v_R = {h.v_R:.2f} m/s.")
        sev = h.severity
        if sev is not None and (sev.creeping or sev.force_ratio is not None):  # (v_R is its speed, shown above)
            verdict += f" Severity: {e(severity_words(sev))}."
        if h.verdict is not None:
            name, numbers = h.verdict
            verdict += f" {e(name)}: {e(str(numbers.get('reason')))}."
        if judgement.why is not None:
            verdict += f"<br>Why: {e(judgement.why)}."
        verdict += f"<br>Judged by {e(judgement.criterion)}."
        body.append(f'<div class="verdict hazard">{verdict}</div>')
    else:
        strongest = ("" if judgement.strongest is None else
                     f" Its strongest contact: {e(judgement.strongest)}.")
        body.append(f'<div class="verdict safe"><b>No hazard found</b> in {res.episodes} episodes '
                    f"({e(res.searcher)}, seed {res.seed}), judged by {e(judgement.criterion)}.<br>"
                    f"Searched: {e(judgement.scope)}.<br>{e(NOT_A_PROOF)}<br>The riskiest episode kept "
                    f"(episode {view.episode}) is shown instead.{strongest}</div>")
        body += [f'<p class="warn">{e(line.removeprefix("static").strip())}</p>' for line in judgement.static]
    if cell_changed:
        body.append('<p class="warn">The cell file, or a file it reads, has changed since the search (sha256 '
                    "differs; cellstress replay names it): the pictures show the episode replayed in the current "
                    "cell.</p>")
    if view.matches_file is False:
        body.append('<p class="warn">The replay does not agree bit-exactly with the trace in result.json.</p>')
    body.append("<h2>What happens</h2>")
    body.append(f"<p><b>{H.escape(acc.headline)}</b></p>")
    body.append("<ol>" + "".join(f"<li>{H.escape(d)}</li>" for d in acc.details) + "</ol>")
    if view3d:
        key = view.key_row
        word = "hazard's" if view.unsafe else "closest call's"
        body.append("<h2>In 3D</h2>")
        body.append(f"<p>The episode replayed step by step ({view.dt:g} s each): the robot's collision capsules, the "
                    "worker's body capsules and reach volumes, the cell's fences, solids and detection fields; a "
                    f"device's field turns bright from the step it sees the worker. Move the slider to step {key} "
                    f"(the {word} step) to see the touching parts and the closest points.</p>")
        body.append(view3d)
    body.append("<h2>Pictures</h2>")
    body.append(H.figure(top, "Top view of the cell to scale: the worker's path with a heading and posture mark "
                         "after each action, the robot and the worker at the key step, the arms' reach volumes, "
                         "where a device first saw the worker, and the contact point (star).", "top view"))
    body.append(H.figure(contact, "The key step from above and from the side: robot links (the closest in red), "
                         "the worker's body capsules, the reach volumes and the closest points joined by a line.",
                         "contact view"))
    body.append(H.figure(gif, f"The episode, one frame per {view.dt:g} s simulation step ({len(view.records)} frames, "
                         "shown at a quarter of real time).", "animated replay"))
    body.append(H.figure(risk, "The search: each episode's maximum risk (the searcher's guide, not the verdict) "
                         "and the highest so far; hazardous episodes in red.", "risk plot"))
    if program is not None:
        body.append(H.figure(program, "The robot's program alone over one cycle, from above and from the side: each "
                             "move in its colour, the poses at the waypoints outlined, the tool's path, and the "
                             "program check (cellstress check) beneath.", "robot program"))
    body.append("<h2>Actions</h2>")
    rows, classes = action_rows(view)
    body.append(H.table(["#", "action", "t [s]", "position at end [m]", "heading [deg]", "forward [deg]",
                         "lateral [deg]", "min d_HR [m]", "max v_R [m/s]", "seen by", "robot at end"],
                        rows, numeric={0, 2, 3, 4, 5, 6, 7, 8}, row_classes=classes))
    body.append("<h2>Parameters</h2>")
    params = ", ".join(f"{k} = {v}" for k, v in sorted(res.params.items()) if v != "")  # (empty text: not given)
    spec = view.layout.cell.spec
    body.append(H.table(None, [
        ["cell", f"{cell} ({res.cell.source})"],
        ["cell sha256", res.cell.sha256],
        ["searcher", f"{res.searcher} ({params})"],
        ["criterion", judgement.criterion],
        ["seed", res.seed], ["budget", f"{res.budget} episodes (until {res.until})"],
        ["episodes used", res.episodes], ["hazardous episodes", len(res.hazards)],
        ["episode shown", f"{view.episode} ({'first hazard' if view.kind == 'hazard' else 'riskiest kept'})"],
        ["simulation", f"dt {spec.simulation.dt:g} s, {spec.simulation.steps_per_action} steps per action, "
                       f"{spec.simulation.actions_per_episode} actions per episode"],
        ["robot stopping time", view.layout.robots[0].stop.describe() if len(spec.robots) == 1 else
         ", ".join(f"{p.name} {p.stop.describe()}" for p in view.layout.robots)],
        ["devices", "; ".join(f"{d.name} ({d.type}, response {d.response_time:g} s)" for d in spec.devices) or "-"],
        ["replay", "agrees bit-exactly with result.json" if view.matches_file else
         ("no trace in result.json (riskiest episode replayed)" if view.matches_file is None else "DIFFERS")],
        ["cellstress", res.version],
    ]))
    body.append("<h2>Trace</h2>")
    trace_rows = [[r.step, f"{r.t:.2f}", r.action or "-", f"{r.x:.3f}", f"{r.y:.3f}",
                   f"{r.heading_deg:.1f}", f"{r.forward_flexion_deg:.1f}", f"{r.lateral_flexion_deg:.1f}",
                   _fmt(r.d_HR), _fmt(r.v_R), r.stop_phase, ", ".join(r.devices) or "-",
                   f"{r.robot_link} / {r.body_part}"] for r in view.records]
    body.append("<details><summary>every simulation step</summary>")
    body.append(H.table(["step", "t [s]", "action", "x [m]", "y [m]", "heading", "forward", "lateral", "d_HR [m]",
                         "v_R [m/s]", "robot", "devices", "closest"], trace_rows, numeric={0, 1, 3, 4, 5, 6, 7, 8, 9},
                        row_classes=["unsafe" if r.unsafe else "" for r in view.records]))
    body.append("</details>")
    return H.page(f"cellstress report: {cell}", body, f"Made by cellstress {res.version} from {FILE_NAME} "
                  f"(searcher {res.searcher}, seed {res.seed}). Replay: cellstress replay {FILE_NAME}",
                  extra_style=VIEW3D_STYLE if view3d else "")


@D.plain_text
def show_cell(cell, out: str | Path, size: D.FigureSize | None = None) -> Path:
    """Draw a cell's layout (``cellstress show``) into a PNG file, with the static check's distances."""
    from cellstress.cell.load import load_cell
    from cellstress.report.hazard import layout_figure
    from cellstress.sim.build import build_layout

    c = cell if not isinstance(cell, (str, Path)) else load_cell(cell)
    layout = build_layout(c)
    fig, _ = layout_figure(layout, size or StillOptions().layout, static=check_cell(c, layout))
    return D.save_png(fig, out)


def show_cell_3d(cell, out: str | Path) -> Path:
    """``cellstress show --3d``: the cell in 3D with its robots' program animated over one cycle (no worker) and
    the start points, as one self-contained HTML page."""
    from cellstress.cell.load import load_cell
    from cellstress.core.version import __version__
    from cellstress.sim.build import build_layout

    c = cell if not isinstance(cell, (str, Path)) else load_cell(cell)
    layout = build_layout(c)
    cycle = layout.trajectory.cycle
    intro = [f"<p>The cell <b>{H.escape(c.spec.name)}</b> to scale: fences with their bottom and top, solids, "
             "detection fields and the start points (green arrows), with the robot's program over one cycle "
             f"({cycle:g} s, from the cell's phase; the slider moves through it). No worker: this is the layout "
             "a search starts from.</p>"]
    return view_page(out, f"{c.spec.name}: the cell in 3D", intro, view_of_program(layout),
                     f"Made by cellstress {__version__} from {c.source}.")
