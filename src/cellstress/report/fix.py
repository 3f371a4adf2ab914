"""``cellstress fix``'s outputs: the terminal table, fix.json (canonical JSON) and fix.html (escaped text).

Names and change descriptions come from the cell file (device names), so the terminal holds them as plain
``rich.text.Text`` with control characters shown as escapes (``core.text.for_terminal``) and the page escapes
every cell of its tables (``report.html.table``).
"""

from __future__ import annotations

from cellstress.analysis.fix import FixResult, Proposal, Retest
from cellstress.core.io import canonical_json
from cellstress.core.text import for_terminal
from cellstress.report.html import page, table

COLUMNS = ("file", "change", "cycle +s", "floor +m2", "parts +", "verdict after", "how proved")
COST_ORDER = "cycle time added, then floor area added, then parts added, then the order tried"


def _verdict(p: Proposal) -> str:
    if p.failing_after:
        return "check fails: " + ", ".join(p.failing_after)
    if p.retest is None:
        return "-"
    if p.retest.hazards:
        return f"check passes; {p.retest.hazards} hazard classes"
    return "check passes; " + ("proved safe" if p.retest.proved else "no hazard found")


def _how(t: Retest | None) -> str:
    return "-" if t is None else t.words


def _rows(r: FixResult) -> list[list[str]]:
    order = [*r.kept, *(p for p in r.candidates if not p.kept)]
    files = {p.number: f"proposal-{i + 1}.yaml" for i, p in enumerate(r.kept)}
    return [[files.get(p.number, f"candidate-{p.number}.yaml"), ("KEPT " if p.kept else "dropped ") + p.change,
             f"{p.cycle_added:+.2f}",
             f"{p.floor_added:+.2f}", str(p.parts_added), _verdict(p), _how(p.retest)] for p in order]


SPEED_COLUMNS = ("robot", "move", "speed scale", "largest safe scale")


def _speed_rows(r: FixResult) -> list[list[str]]:
    return [[str(m.robot + 1), str(m.move + 1), f"{m.original:g}",
             f"{m.safe:.4g}" if m.safe > 0 else "none (a hazard at 1/8)"] for m in r.speeds]


def speed_title(r: FixResult) -> str:
    return (f"largest safe speed per move under {r.criterion} (scales 1/8..1 from the slowest up, each judged by "
            f"search plan, {r.budget} episodes, seed {r.seed}; the other moves at the program's largest safe scale; "
            "a search that finds nothing is not a proof)")


def summary(r: FixResult) -> str:
    if r.needs_nothing:
        return f"NOTHING TO FIX: {r.cell} fails no check row and its re-test found nothing ({_how(r.retest_before)})"
    before = (f"check fails {', '.join(r.failing_before)}" if r.failing_before
              else f"check passes, re-test: {_how(r.retest_before)}")
    if r.kept:
        best = r.kept[0]
        return (f"{len(r.kept)} of {len(r.candidates)} proposals work ({before}); cheapest: proposal-1.yaml "
                f"(candidate {best.number}): {best.change}")
    return f"NO PROPOSAL WORKS: {len(r.candidates)} candidates tried ({before})"


def print_fix(r: FixResult, console) -> None:
    from rich.table import Table
    from rich.text import Text

    def t(s: object) -> Text:
        return Text(for_terminal(str(s)))

    grid = Table(title=f"fix {for_terminal(r.cell)}: candidates, cheapest kept first ({COST_ORDER})",
                 title_justify="left")
    for col in COLUMNS:
        grid.add_column(col, overflow="fold")
    for row in _rows(r):
        grid.add_row(*(t(v) for v in row))
    if r.candidates:
        console.print(grid)
    if r.speeds:
        speeds = Table(title=for_terminal(speed_title(r)), title_justify="left")
        for col in SPEED_COLUMNS:
            speeds.add_column(col)
        for row in _speed_rows(r):
            speeds.add_row(*(t(v) for v in row))
        console.print(speeds)
    console.print(t(summary(r)))


def _retest_doc(t: Retest | None) -> dict | None:
    return None if t is None else {"method": t.method, "hazard_classes": t.hazards, "proved": t.proved,
                                   "words": t.words}


def fix_json(r: FixResult) -> str:
    """The result as our canonical JSON (sorted keys): the same cell and options give the same bytes."""
    kept = {p.number: i + 1 for i, p in enumerate(r.kept)}
    return canonical_json({
        "cell": r.cell, "exit_code": r.exit_code, "needs_nothing": r.needs_nothing,
        "failing_before": list(r.failing_before), "retest_before": _retest_doc(r.retest_before),
        "options": {"budget": r.budget, "seed": r.seed, "time_limit": r.time_limit},
        "cost_order": COST_ORDER, "criterion": r.criterion,
        "move_speeds": [{"robot": m.robot + 1, "move": m.move + 1, "speed_scale": m.original, "safe_scale": m.safe}
                        for m in r.speeds],
        "candidates": [{"candidate": p.number, "proposal": kept.get(p.number), "kind": p.kind, "change": p.change,
                        "answers": list(p.answers), "cycle_added_s": p.cycle_added, "floor_added_m2": p.floor_added,
                        "parts_added": p.parts_added, "failing_after": list(p.failing_after),
                        "retest": _retest_doc(p.retest), "kept": p.kept} for p in r.candidates],
    })


def fix_page(r: FixResult) -> str:
    """fix.html: the summary and the table (every text escaped by ``report.html``)."""
    from html import escape

    body = [f"<h1>cellstress fix: {escape(r.cell)}</h1>",
            f'<div class="verdict {"safe" if r.exit_code == 0 else "hazard"}">{escape(summary(r))}</div>',
            f"<p>Ranked by cost: {escape(COST_ORDER)}. Re-test: verify where it decides within "
            f"{r.time_limit:g} s, else the search (plan, {r.budget} episodes, seed {r.seed}); a search that finds "
            "nothing is not a proof.</p>"]
    if r.candidates:
        body.append(table(list(COLUMNS), _rows(r), numeric={2, 3, 4}))
    if r.speeds:
        body += [f"<h2>{escape(speed_title(r))}</h2>", table(list(SPEED_COLUMNS), _speed_rows(r), numeric={0, 1, 2})]
    return page(f"cellstress fix {r.cell}", body, "cellstress fix: every kept proposal is proposal-N.yaml, "
                "numbered in the order of cost")


def fix_suite(r: FixResult):
    """JUnit: one case per candidate (kept: passed; dropped: skipped, with why) and one for the verdict, failed
    exactly when the exit code is 1 (no proposal works)."""
    from cellstress.report.junit import FAILED, PASSED, SKIPPED, Case, Suite

    cases = [Case(f"candidate {p.number}: {p.kind}", "fix.candidate", PASSED if p.kept else SKIPPED,
                  "" if p.kept else _verdict(p), output=f"{p.change}\n{_how(p.retest)}") for p in r.candidates]
    cases.append(Case("fix", "fix.verdict", PASSED if r.exit_code == 0 else FAILED,
                      "" if r.exit_code == 0 else summary(r), output=summary(r) if r.exit_code == 0 else ""))
    return Suite(f"cellstress fix {r.cell}", tuple(cases))
