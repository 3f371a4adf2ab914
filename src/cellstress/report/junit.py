"""JUnit XML, the test report format CI servers read (GitLab's and GitHub's test reports, Jenkins' junit step):
``check``, ``search``, ``verify`` and ``diff`` write one with ``--junit FILE``.

The structure is the one of the schema CI servers commonly validate against (Jenkins' and Ant's
``junit-10.xsd``): ``testsuites`` > ``testsuite`` (``name tests failures errors skipped time``) > ``testcase``
(``name classname time``) > at most one of ``failure``/``error``/``skipped`` (``message`` attribute, text), then
``system-out``. Every name and message comes from a cell or result file someone else wrote, so all text passes
through ``core.text.for_xml``.

**Same inputs, same bytes.** Every ``time`` attribute is 0: cellstress keeps wall-clock time out of its files
(``result.json`` has no time field), and a measured time would make two runs of one gate differ. Nothing else
varies between runs: no timestamp, no host name.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cellstress.core.io import atomic_write_text
from cellstress.core.text import for_xml

PASSED, FAILED, ERROR, SKIPPED = "passed", "failure", "error", "skipped"


@dataclass(frozen=True)
class Case:
    """One test case: ``outcome`` one of PASSED, FAILED, ERROR, SKIPPED; ``message`` its one-line reason."""

    name: str
    classname: str
    outcome: str = PASSED
    message: str = ""
    text: str = ""  # the failure's (or error's) longer account
    output: str = ""  # system-out: what the check printed for this case


@dataclass(frozen=True)
class Suite:
    name: str
    cases: tuple[Case, ...]

    def count(self, outcome: str) -> int:
        return sum(c.outcome == outcome for c in self.cases)


def _attrs(**values: object) -> str:
    return "".join(f' {k}="{for_xml(str(v), attribute=True)}"' for k, v in values.items())


def _case(c: Case) -> list[str]:
    head = f"    <testcase{_attrs(name=c.name, classname=c.classname, time=0)}"
    body = []
    if c.outcome in (FAILED, ERROR):
        body.append(f"      <{c.outcome}{_attrs(message=c.message)}>{for_xml(c.text)}</{c.outcome}>")
    elif c.outcome == SKIPPED:
        body.append(f"      <skipped{_attrs(message=c.message)}/>")
    elif c.outcome != PASSED:
        raise ValueError(f"unknown outcome {c.outcome!r}")
    if c.output:
        body.append(f"      <system-out>{for_xml(c.output)}</system-out>")
    if not body:
        return [head + "/>"]
    return [head + ">", *body, "    </testcase>"]


def junit_xml(suites: tuple[Suite, ...] | list[Suite]) -> str:
    """The JUnit XML document of ``suites`` (UTF-8, deterministic)."""
    totals = {k: sum(s.count(k) for s in suites) for k in (FAILED, ERROR, SKIPPED)}
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f"<testsuites{_attrs(tests=sum(len(s.cases) for s in suites), failures=totals[FAILED])}"
             f"{_attrs(errors=totals[ERROR], skipped=totals[SKIPPED], time=0)}>"]
    for s in suites:
        lines.append(f"  <testsuite{_attrs(name=s.name, tests=len(s.cases), failures=s.count(FAILED))}"
                     f"{_attrs(errors=s.count(ERROR), skipped=s.count(SKIPPED), time=0)}>")
        for c in s.cases:
            lines += _case(c)
        lines.append("  </testsuite>")
    lines.append("</testsuites>")
    return "\n".join(lines) + "\n"


def write_junit(path: str | Path, suites: tuple[Suite, ...] | list[Suite]) -> Path:
    """Write the JUnit file atomically (its folder made if missing); returns its path."""
    p = Path(path)
    if str(p.parent):
        p.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(p, junit_xml(suites))
    return p


# ---- what each command reports -----------------------------------------------------------------------------
def check_suite(cell: str, rows, witnesses: dict[str, str] | None = None) -> Suite:
    """``check``: one case per row (``analysis.check_rows``), a failed row a failure; ``witnesses`` (``check
    --witness``): a row's simulated witness line, added to its text."""
    said = witnesses or {}
    return Suite(f"cellstress check {cell}",
                 tuple(Case(r.name, f"check.{r.kind}", PASSED if r.ok else FAILED,
                            "" if r.ok else f"{r.name}: {r.value}",
                            r.detail + (f"\nsimulated: {said[r.name]}" if r.name in said else ""),
                            "" if not r.ok else r.value)
                       for r in rows))


def class_words(k) -> str:
    """A hazard class (a result file's ``HazardClass`` or ``analysis.cell_diff.ClassKey``) in words: the safeguard
    that failed, robot link / body region, where the worker stood."""
    x0, y0, x1, y1 = k.approach_cell
    failed = "no device saw the worker" if k.device == "none" else f"{k.device} stopped the robot too late"
    move = "" if k.robot_move is None else f", robot's move {k.robot_move}"
    return f"{failed}; {k.robot_link} / {k.body_region}, worker at x {x0:g}..{x1:g}, y {y0:g}..{y1:g}{move}"


def class_name(k) -> str:
    """A hazard class's case name: its key (``searchers.distinct.hazard_class``) as text."""
    x0, y0, _, _ = k.approach_cell
    move = "" if k.robot_move is None else f" move {k.robot_move}"
    return f"{k.device} / {k.robot_link} / {k.body_region} @ ({x0:g}, {y0:g}){move}"


def search_suite(result) -> Suite:
    """``search``: one failing case per hazard class found (``--distinct``), or per first hazard without it; one
    passing case when none was found (which is not a proof: the message says so)."""
    name = f"cellstress search {result.cell.name} ({result.searcher}, seed {result.seed}, budget {result.budget})"
    if result.distinct:
        return Suite(name, tuple(Case(class_name(d.klass), "search.hazard-class", FAILED,
                                      f"episode {d.episode}: {class_words(d.klass)}",
                                      f"actions: {', '.join(d.actions)}") for d in result.distinct))
    h = result.hazard
    if h is not None:
        return Suite(name, (Case(f"hazard: {h.robot_link} / {h.body_part}", "search.hazard", FAILED,
                                 f"episode {h.episode}: {h.robot_link} / {h.body_part} at t={h.time_s:g} s",
                                 f"actions: {', '.join(h.actions)}"),))
    return Suite(name, (Case("no hazard found", "search.hazard", PASSED,
                             output=f"{result.episodes} episodes searched; a search is not a proof"),))


def verify_suite(res) -> Suite:
    """``verify``: the verdict (PROVED-SAFE passes, UNSAFE fails, UNDECIDED is an error: not a proof) and one
    failing case per hazard class with its witness."""
    from_verdict = {"PROVED-SAFE": PASSED, "UNSAFE": FAILED, "UNDECIDED": ERROR}[res.verdict]
    why = {PASSED: "", FAILED: f"{res.hazardous:,} of {res.sequences:,} action sequences hazardous",
           ERROR: f"{res.undecided:,} sequences undecided, {res.alarms:,} alarms: not a proof"}[from_verdict]
    cases = [Case(f"verdict: {res.verdict}", "verify.verdict", from_verdict, why, res.scope.statement,
                  res.scope.statement if from_verdict == PASSED else "")]
    for w in res.classes:
        cases.append(Case(class_name(w.klass), "verify.witness", FAILED,
                          f"{w.sequences:,} sequences: {class_words(w.klass)}",
                          f"first at {w.start}, phase {w.phase:g} s: {', '.join(w.actions)}; witness {w.file}"))
    return Suite(f"cellstress verify {res.cell.name} (horizon {res.options.horizon}, phases {res.options.phases_text})",
                 tuple(cases))
