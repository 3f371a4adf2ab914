"""Table III's S2 row with the robot's phase at the worker's arrival drawn once per run (issue 21's hypothesis).

    python benchmarks/s2_run_phase.py [--cell s2-elbow-intrusion] [--edit KEY=YAML ...] [--phases cycle]
           [--seeds 0:40] [--searchers random,mcts,mcts-commit] [--workers 2] [--out runs.jsonl]
           [--write-cell FILE] [--per-run]

Each run (seed s) draws its phase from ``numpy.random.default_rng(s)``: one draw, ``rng.integers(len(grid))``, an
index into the grid of phases ``--phases`` gives; all searchers of seed s meet the same phase (paired runs). The
searcher does not know it: its cell file is the given one with ``robot.task.phase`` set to the draw (and
``human.arrival: fixed`` as before), so to the searcher every run is an ordinary fixed cell. ``--phases``:

- ``cycle``: every 50 ms time step of one robot cycle (``sim.layout.trajectory.cycle``), 0 <= phase < cycle;
- ``window:A:B``: every time step in [A, B] (s);
- ``list:a,b,c``: these phases, equally likely; ``fixed:X``: phase X in every run (the ordinary cell).

``--edit KEY=VALUE`` changes the cell before the phase is set (a physical variant): KEY is a dotted path into the
YAML (list items by index, e.g. ``fences.0.points``), VALUE is parsed as YAML (``robot.base.xyz=[0,-0.15,0.85]``).
The cell keeps its ``name``, so a variant of S2 is compared with S2's paper rows. ``--write-cell FILE`` writes the
edited cell (its own phase) for ``cellstress check FILE``.

Runs go through the campaign's backend (``benchmarks/mcts_constants.py``'s ``specs_for``-style RunSpecs; its
``rows_text`` prints the rows: found/N, mean with its 95 % t interval, the mean of the hits, and whether the
paper's rate and mean are inside our Wilson and t intervals). Then, per searcher, the hits' phases, and with
``--per-run`` one line per seed (phase, episodes per searcher; ``-`` = not found) so that any run can be
replayed: ``cellstress search`` on the cell with that phase and seed. ``--out`` writes the records (with
``phase``) as JSON lines.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mcts_constants import BUDGET, rows_text, seed_range  # noqa: E402

from cellstress.campaign import Backend, resolve  # noqa: E402
from cellstress.campaign.plan import RunSpec  # noqa: E402
from cellstress.cell.load import BUILTIN_CELLS, builtin_text, load_cell  # noqa: E402
from cellstress.sim.simulator import Simulator  # noqa: E402
from cellstress.sim.starts import phase_grid  # noqa: E402


def cell_data(ref: str) -> dict:
    text = builtin_text(ref) if ref in BUILTIN_CELLS else Path(ref).read_text()
    return yaml.safe_load(text)


def apply_edit(data: dict, edit: str) -> None:
    key, _, value = edit.partition("=")
    if not _:
        raise SystemExit(f"--edit {edit!r}: expected KEY=VALUE")
    parts = key.split(".")
    node = data
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node[p]
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = yaml.safe_load(value)
    else:
        node[last] = yaml.safe_load(value)


def phase_choices(spec: str, data: dict, folder: Path) -> tuple[float, ...]:
    kind, _, rest = spec.partition(":")
    if kind == "fixed":
        return (float(rest),)
    if kind == "list":
        return tuple(float(x) for x in rest.split(",") if x.strip())
    path = folder / "cycle-probe.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    sim = Simulator(load_cell(str(path)))
    if kind == "cycle":
        cycle = float(sim.layout.trajectory.cycle)
        return tuple(p for p in phase_grid(sim.dt, 0.0, cycle) if p < cycle)
    if kind == "window":
        a, b = (float(x) for x in rest.split(":"))
        return phase_grid(sim.dt, a, b)
    raise SystemExit(f"--phases {spec!r}: cycle, window:A:B, list:a,b or fixed:X")


def draw_phase(seed: int, grid: tuple[float, ...]) -> float:
    return grid[int(np.random.default_rng(seed).integers(len(grid)))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cell", default="s2-elbow-intrusion", help="built-in name or file")
    ap.add_argument("--edit", action="append", default=[], help="KEY=YAML, e.g. robot.base.xyz=[0,-0.15,0.85]")
    ap.add_argument("--phases", default="cycle", help="cycle | window:A:B | list:a,b | fixed:X")
    ap.add_argument("--seeds", default="0:40", help="a:b, seeds a..b-1")
    ap.add_argument("--searchers", default="random,mcts,mcts-commit")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", help="write the records (with their phase) here, as JSON lines")
    ap.add_argument("--write-cell", help="write the edited cell (its own phase) here, then go on")
    ap.add_argument("--per-run", action="store_true", help="one line per seed: phase and episodes per searcher")
    args = ap.parse_args()

    data = cell_data(args.cell)
    for e in args.edit:
        apply_edit(data, e)
    if args.write_cell:
        Path(args.write_cell).write_text(yaml.safe_dump(data, sort_keys=False))
    seeds = seed_range(args.seeds)
    searchers = tuple(s for s in args.searchers.split(",") if s)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="s2_run_phase_") as tmp:
        folder = Path(tmp)
        grid = phase_choices(args.phases, data, folder)
        phases = {seed: draw_phase(seed, grid) for seed in seeds}
        refs = {}  # phase -> (CellRef, SearcherRefs)
        for ph in sorted(set(phases.values())):
            d = json.loads(json.dumps(data))
            d["robot"]["task"]["phase"] = ph
            path = folder / f"{data['name']}-p{ph:.3f}.yaml"
            path.write_text(yaml.safe_dump(d, sort_keys=False))
            plan = resolve((str(path),), searchers, 1, BUDGET, {})
            refs[ph] = (plan.cells[0], plan.searchers)
        specs = [RunSpec(refs[phases[seed]][0], sref, seed, BUDGET)
                 for i, _ in enumerate(searchers) for seed in seeds
                 for sref in [refs[phases[seed]][1][i]]]
        records = []
        for rec in Backend(workers=args.workers).run(specs):
            rec["phase"] = phases[rec["seed"]]
            records.append(rec)
    elapsed = time.perf_counter() - t0

    edits = " ".join(args.edit) or "(none)"
    digest = hashlib.sha256(yaml.safe_dump(data, sort_keys=True).encode()).hexdigest()[:12]
    print(f"cell {args.cell}, edits {edits} (edited cell sha {digest}); phases {args.phases}: {len(grid)} "
          f"choices {grid[0]:g}..{grid[-1]:g} s; seeds {seeds.start}-{seeds.stop - 1}; budget {BUDGET}")
    lines, inside = rows_text(records)
    print("\n".join(lines))
    print(f"paper numbers inside: {inside}/{2 * len(lines)}")
    by = {(r["searcher"], r["seed"]): r for r in records}
    for s in searchers:
        hits = sorted((by[s, seed]["phase"], by[s, seed]["episodes"]) for seed in seeds if by[s, seed]["found"])
        print(f"  {s:<11} hits at phases (phase:episodes): "
              + " ".join(f"{p:g}:{e}" for p, e in hits))
    if args.per_run:
        print("  seed phase " + " ".join(f"{s:>11}" for s in searchers))
        for seed in seeds:
            cols = [str(by[s, seed]["episodes"]) if by[s, seed]["found"] else "-" for s in searchers]
            print(f"  {seed:>4} {phases[seed]:5.2f} " + " ".join(f"{c:>11}" for c in cols))
    if args.out:
        with open(args.out, "w") as f:
            for r in sorted(records, key=lambda r: (searchers.index(r["searcher"]), r["seed"])):
                f.write(json.dumps(r) + "\n")
    print(f"({elapsed:.0f} s, {args.workers} workers)")


if __name__ == "__main__":
    main()
