"""Record the bytes of many command outputs, or check that the current code reproduces them exactly.

    python scripts/golden.py record DIR      # before a refactor that must not change behaviour
    python scripts/golden.py check DIR       # after it: exit 1 and list every file that differs

Covers result.json of every searcher on every built-in reference cell (first hazard and whole budget, with
--distinct, with --criterion iso15066), the campaign's runs.jsonl (sorted) and table.md, ``simulate --json``,
and the report files of one search. Complements ``kernel_reference.py``, which checks the simulator's raw
arrays.
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import sys
import tempfile
from pathlib import Path

FLAWED = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
SEARCHERS = ("random", "mcts", "mcts-commit", "evolve", "plan")


def commands() -> list[tuple[str, list[str], list[str]]]:
    """(name, argv after 'cellstress', files to keep from the --out folder)."""
    out: list[tuple[str, list[str], list[str]]] = []
    res = ["result.json"]
    for cell in ("baseline", *FLAWED):
        for s in SEARCHERS:
            for seed in (0, 1):
                budget = "60" if cell == "baseline" else "200"
                out.append((f"search-{cell}-{s}-{seed}",
                            ["search", cell, "--searcher", s, "--budget", budget, "--seed", str(seed),
                             "--no-report"], res))
    for s in ("random", "mcts", "evolve"):
        out.append((f"search-s3-{s}-budget-distinct",
                    ["search", "s3-fence-gap", "--searcher", s, "--budget", "150", "--seed", "3", "--until", "budget",
                     "--distinct", "--no-report"], res))
    for s in ("evolve", "plan"):
        out.append((f"search-allflaws-{s}-distinct",
                    ["search", "all-flaws", "--searcher", s, "--budget", "300", "--seed", "0", "--until", "budget",
                     "--distinct", "--no-report"], res))
    out.append(("search-allflaws-mcts", ["search", "all-flaws", "--searcher", "mcts", "--budget", "100", "--seed", "2",
                                         "--no-report"], res))
    for cell in ("s2-elbow-intrusion", "s3-fence-gap"):
        for s in ("random", "mcts", "evolve", "plan"):
            out.append((f"search-{cell}-{s}-iso15066",
                        ["search", cell, "--searcher", s, "--budget", "60", "--seed", "0", "--criterion", "iso15066",
                         "--no-report"], res))
    out.append(("search-s1-evolve-set", ["search", "s1-scanner-width", "--searcher", "evolve", "--budget", "80",
                                         "--seed", "5", "--set", "pool=3", "--until", "budget", "--no-report"], res))
    out.append(("report-s3-mcts", ["search", "s3-fence-gap", "--searcher", "mcts", "--budget", "200", "--seed", "0"],
                ["result.json", "topview.png", "contact.png", "replay.gif", "risk.png", "report.html"]))
    out.append(("campaign-paper", ["campaign", "--workers", "1"], ["runs.jsonl", "table.md", "table.csv"]))
    out.append(("campaign-ours", ["campaign", "--workers", "2", "--searchers", "evolve,plan", "--seeds", "4"],
                ["runs.jsonl", "table.md"]))
    return out


SIMULATE = [
    ("simulate-s1", ["simulate", "s1-scanner-width", "--actions",
                     "walk+bend-left,walk+bend-left,walk+bend-forward,walk+bend-forward-right", "--json"]),
    ("simulate-s3", ["simulate", "s3-fence-gap", "--actions", "walk+bend-right,turn-left-45+bend-forward-left,"
                     "walk+bend-forward,walk+bend-forward-left", "--json"]),
    ("simulate-s2-iso", ["simulate", "s2-elbow-intrusion", "--criterion", "iso15066", "--actions",
                         "walk+bend-right,walk+bend-left,turn-right-45+upright,walk+bend-forward-left", "--json"]),
]


def produce(dest: Path) -> None:
    import contextlib
    import io

    from cellstress.cli import main

    dest.mkdir(parents=True, exist_ok=True)
    for name, argv, keep in commands():
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "out"
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
                code = main([*argv, "--out", str(out)])
            if code not in (0, 1):
                raise SystemExit(f"{name}: exit {code}")
            for f in keep:
                src = out / f
                data = src.read_bytes()
                if f == "runs.jsonl":
                    data = b"".join(sorted(data.splitlines(keepends=True)))
                (dest / f"{name}--{f}").write_bytes(data)
        print(name, flush=True)
    for name, argv in SIMULATE:
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            main(argv)
        (dest / f"{name}.json").write_text(buf.getvalue())
        print(name, flush=True)


def main_() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("record", "check"))
    ap.add_argument("dir")
    a = ap.parse_args()
    ref = Path(a.dir)
    if a.mode == "record":
        if ref.exists():
            shutil.rmtree(ref)
        produce(ref)
        print(f"recorded {len(list(ref.iterdir()))} files in {ref}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        new = Path(tmp) / "new"
        produce(new)
        bad = []
        names = sorted({p.name for p in ref.iterdir()} | {p.name for p in new.iterdir()})
        for n in names:
            a_, b_ = ref / n, new / n
            ha = hashlib.sha256(a_.read_bytes()).hexdigest() if a_.exists() else "missing"
            hb = hashlib.sha256(b_.read_bytes()).hexdigest() if b_.exists() else "missing"
            if ha != hb:
                bad.append(n)
                print(f"DIFFERS {n}")
        print(f"{len(names) - len(bad)} of {len(names)} files identical")
        return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main_())
