"""``cellstress diff``'s outputs: the terminal tables, the JSON document and the JUnit suite of a ``CellDiff``.

Names and values come from the two cell files, so the tables hold them as plain ``rich.text.Text`` (never read
as markup) with control characters shown as escapes (``core.text.for_terminal``); the JUnit writer escapes for
XML itself.
"""

from __future__ import annotations

from cellstress.analysis.cell_diff import CellDiff, ClassKey
from cellstress.core.io import canonical_json
from cellstress.core.text import for_terminal
from cellstress.report.junit import FAILED, PASSED, SKIPPED, Case, Suite, class_words
from cellstress.report.junit import class_name as class_id

NOT_A_PROOF = "a search that finds nothing is not a proof"


def _verdict(ok: bool | None, value: str) -> str:
    return "-" if ok is None else f"{'ok' if ok else 'FAIL'} {value}".strip()


def verdict_line(d: CellDiff) -> str:
    reasons = []
    if d.failing_rows:
        reasons.append(f"NEW fails check rows {', '.join(r.name for r in d.failing_rows)}")
    if d.new_classes:
        reasons.append(f"{len(d.new_classes)} hazard class{'es' if len(d.new_classes) != 1 else ''} found on NEW "
                       f"and not on OLD: {'; '.join(class_id(k) for k in d.new_classes)}")
    if reasons:
        return "FAIL: " + "; ".join(reasons)
    return "PASS: NEW fails no check row and has no hazard class OLD did not have"


def print_diff(d: CellDiff, console) -> None:
    """The tables on a rich console."""
    from rich.table import Table
    from rich.text import Text

    def t(s: object) -> Text:
        return Text(for_terminal(str(s)))

    console.print(t(f"diff      OLD {d.old} -> NEW {d.new}"))
    fields = Table(title="what changed (the loaded cell models)", title_justify="left")
    for col in ("part", "field", "OLD", "NEW"):
        fields.add_column(col, overflow="fold")
    for f in d.fields:
        fields.add_row(t(f.section), t(f.path), t(f.old or "-"), t(f.new or "-"))
    if d.fields:
        console.print(fields)
    else:
        console.print(t("fields    no field changed"))
    rows = Table(title="check rows that changed", title_justify="left")
    for col in ("row", "change", "OLD", "NEW"):
        rows.add_column(col, overflow="fold")
    for r in d.rows:
        rows.add_row(t(r.name), t(r.change), t(_verdict(r.old_ok, r.old_value)), t(_verdict(r.new_ok, r.new_value)))
    if d.rows:
        console.print(rows)
    else:
        console.print(t("check     no row changed verdict or value"))
    classes = Table(title=f"hazard classes ({d.searcher}, seed {d.seed}, budget {d.budget} on each; {NOT_A_PROOF})",
                    title_justify="left")
    for col in ("status", "class"):
        classes.add_column(col, overflow="fold")
    for status, keys in (("NEW", d.new_classes), ("gone", d.gone_classes),
                         ("on both", tuple(k for k in d.new_search.classes if k not in d.new_classes))):
        for k in keys:
            classes.add_row(t(status), t(class_words(k)))
    if d.old_search.classes or d.new_search.classes:
        console.print(classes)
    console.print(t(f"searched  {d.old_search.episodes} episodes on OLD ({len(d.old_search.classes)} classes), "
                    f"{d.new_search.episodes} on NEW ({len(d.new_search.classes)} classes)"))
    console.print(t(verdict_line(d)))


def diff_json(d: CellDiff) -> str:
    """The diff as our canonical JSON (sorted keys; the same cells and search give the same bytes)."""
    def key(k: ClassKey) -> dict:
        return {"device": k.device, "robot_link": k.robot_link, "body_region": k.body_region,
                "approach_cell": list(k.approach_cell), "robot_move": k.robot_move}

    return canonical_json({
        "old": d.old, "new": d.new, "passes": d.passes,
        "search": {"searcher": d.searcher, "seed": d.seed, "budget": d.budget,
                   "old_episodes": d.old_search.episodes, "new_episodes": d.new_search.episodes},
        "fields": [{"part": f.section, "path": f.path, "old": f.old, "new": f.new} for f in d.fields],
        "check_rows": [{"name": r.name, "change": r.change, "old_ok": r.old_ok, "new_ok": r.new_ok,
                        "old_value": r.old_value, "new_value": r.new_value} for r in d.rows],
        "failing_rows": [r.name for r in d.failing_rows],
        "new_classes": [key(k) for k in d.new_classes],
        "gone_classes": [key(k) for k in d.gone_classes],
        "classes_on_both": [key(k) for k in d.new_search.classes if k not in d.new_classes],
    })


def diff_suite(d: CellDiff) -> Suite:
    """One case per check row of NEW (a failing row a failure; a changed row says from what), one per hazard class
    (new: a failure; found on OLD too: skipped, a known hazard the change did not add; gone: passed), and one
    for the changed fields. Failures exactly when the gate fails."""
    changed = {r.name: r for r in d.rows}
    cases = []
    for r in d.new_rows:
        c = changed.get(r.name)
        was = "" if c is None else f" (OLD: {_verdict(c.old_ok, c.old_value)})"
        cases.append(Case(r.name, f"diff.check.{r.kind}", PASSED if r.ok else FAILED,
                          "" if r.ok else f"{r.name}: {r.value}{was}", r.detail, f"{r.value}{was}" if r.ok else ""))
    for k in d.new_classes:
        cases.append(Case(class_id(k), "diff.hazard-class", FAILED, f"new hazard class: {class_words(k)}",
                          f"found on {d.new} and not on {d.old} ({d.searcher}, seed {d.seed}, budget {d.budget})"))
    for k in d.new_search.classes:
        if k not in d.new_classes:
            cases.append(Case(class_id(k), "diff.hazard-class", SKIPPED,
                              f"found on OLD too, not added by the change: {class_words(k)}"))
    for k in d.gone_classes:
        cases.append(Case(class_id(k), "diff.hazard-class", PASSED,
                          output=f"gone: found on OLD, not on NEW ({NOT_A_PROOF}): {class_words(k)}"))
    fields = "\n".join(f"{f.section}: {f.path}: {f.old or '-'} -> {f.new or '-'}" for f in d.fields)
    cases.append(Case("changed fields", "diff.fields", PASSED, output=fields or "no field changed"))
    return Suite(f"cellstress diff {d.old} {d.new}", tuple(cases))
