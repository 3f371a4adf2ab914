"""Why S2's hazard resists guided search: its structure, counted by playing sequences (issue 4, part 6).

    python benchmarks/s2_structure.py [--cell s2-deceptive] [--episodes 100000] [--seed 5]

1. **Every 4-action sequence** (30^4 = 810,000) is played from the cell's start with ``run_batch``, padded to
   8 actions with ``turn-left-45+upright`` (the simulator is causal, so the padding cannot change anything up
   to the end of the 4th action). Those unsafe within their 4 actions are counted by walk/turn pattern (W: a
   walking action, t: a turn), and for the most common pattern by the action at each position. Printed: the
   hazard rate of each pattern among all sequences of that pattern, and of the smallest per-position "box"
   (the product of the actions that occur at each position among that pattern's hazards).
2. **The safety devices' share.** The same ``--episodes`` uniformly random 8-action episodes are played in the
   cell and in a copy of it without safety devices (the cell file with ``devices: []``). Printed: how many
   touch the moving robot in each, and the share of the device-free contacts that are hazards with devices.

A searcher that knew where and when the robot can be touched would still have to pick, from the device-free
contacts, the few whose timing beats the devices; a searcher that learns from played episodes must first
learn both. docs/results.md ("Why S2 resists") gives the numbers.
"""

from __future__ import annotations

import argparse
import collections
import itertools
import tempfile
from pathlib import Path

import numpy as np
import yaml

from cellstress.cell.load import builtin_text, safe_load_yaml
from cellstress.human.actions import ACTION_NAMES, WALKS
from cellstress.sim.simulator import Simulator

PAD = ACTION_NAMES.index("turn-left-45+upright")
N_BODIES = len(ACTION_NAMES) // len(WALKS)


def pattern(seq) -> str:
    return "".join("W" if a // N_BODIES == 0 else "t" for a in seq)


def four_action_hazards(sim: Simulator) -> np.ndarray:
    """All 4-action sequences that reach the unsafe set within their 4 actions."""
    n = sim.n_actions
    seqs = np.array(list(itertools.product(range(n), repeat=4)), dtype=np.int64)
    padded = np.concatenate([seqs, np.full((len(seqs), sim.actions_per_episode - 4), PAD, dtype=np.int64)], axis=1)
    b = sim.run_batch(padded)
    within = (b.unsafe_step >= 0) & (b.unsafe_step <= 4 * sim.steps_per_action)
    return seqs[within]


def report_patterns(haz: np.ndarray, n_actions: int) -> None:
    total = n_actions ** 4
    print(f"4-action sequences unsafe within 4 actions: {len(haz)} of {total:,} ({100 * len(haz) / total:.3f} %)")
    counts = collections.Counter(pattern(s) for s in haz)
    n_walk = n_actions // len(WALKS)
    print("| pattern | hazards | sequences of the pattern | rate |")
    print("|---|---:|---:|---:|")
    for pat, k in counts.most_common():
        size = 1
        for c in pat:
            size *= n_walk if c == "W" else n_actions - n_walk
        print(f"| {pat} | {k} | {size:,} | {100 * k / size:.2f} % |")
    main = counts.most_common(1)[0][0] if counts else None
    if main is None:
        return
    sub = haz[np.array([pattern(s) == main for s in haz])]
    box = 1
    print(f"\n{main}: the actions at each position among its {len(sub)} hazards")
    for k in range(4):
        c = collections.Counter(ACTION_NAMES[a] for a in sub[:, k])
        box *= len(c)
        print(f"  position {k + 1}: " + ", ".join(f"{name} {m}" for name, m in c.most_common()))
    print(f"smallest per-position box holding them: {box} sequences, {len(sub)} hazards ({100 * len(sub) / box:.1f} %)")


def without_devices(cell: str, tmp: Path) -> Path:
    spec = safe_load_yaml(builtin_text(cell))
    spec["name"] = f"{cell}-no-devices"
    spec["devices"] = []
    path = tmp / f"{spec['name']}.yaml"
    path.write_text(yaml.safe_dump(spec, sort_keys=False), encoding="utf-8")
    return path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cell", default="s2-deceptive")
    ap.add_argument("--episodes", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=5)
    args = ap.parse_args()
    sim = Simulator(args.cell)
    report_patterns(four_action_hazards(sim), sim.n_actions)

    with tempfile.TemporaryDirectory() as tmp:
        bare = Simulator(without_devices(args.cell, Path(tmp)))
    actions = np.random.default_rng(args.seed).integers(0, sim.n_actions, size=(args.episodes, sim.actions_per_episode))
    real, free = sim.run_batch(actions).unsafe_step >= 0, bare.run_batch(actions).unsafe_step >= 0
    print(f"\n{args.episodes:,} random episodes (seed {args.seed}): {int(free.sum())} touch the moving robot without "
          f"devices, {int(real.sum())} with them ({int((real & free).sum())} of those also without); "
          f"share of device-free contacts that are hazards: {(real & free).sum() / max(int(free.sum()), 1):.3f}")


if __name__ == "__main__":
    main()
