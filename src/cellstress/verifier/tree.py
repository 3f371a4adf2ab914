"""One start point at one arrival phase, decided: every sequence of the worker's actions, layer by layer, with
identical simulator states merged and sub-trees cut only where a sound bound proves them safe.

**Layers.** Layer n holds the distinct states after n actions that are not unsafe and not proved safe. Every
state carries how many action prefixes reach it (its multiplicity, an exact integer) and one of them, the
lexicographically smallest (its witness prefix): the states of a layer are kept in that order, so the children
of state i by action a, numbered i * 30 + a, come in the order of their prefixes too, and the first child
that falls on a merged state is the one whose prefix is the smallest.

**Merging.** Two states merge when their futures are the same. What that takes is declared slot by slot in the
state layout itself (``layout.STATE``: each slot's ``core.vector_spec.Merge``), and the key is derived from
those declarations (``KEY_COLUMNS``), so a slot added later cannot be left out: every slot that anything
reads is compared bit for bit (the worker's pose, the latched stops, releases, anchors, speed reductions,
doors, speed commands in flight, other robots' stops), a slot that only an automatic release reads is ignored
while no release can happen, and the slots nothing reads but the reports are left out. The simulator is
deterministic, so merged states have identical futures: the merging approximates nothing. (An earlier key
rounded positions to 1 um; a micrometre can decide whether a stride clears a fence's edge, so it could let
one future stand for another.) ``TRIG_DEV`` is kept because it names the device of a hazard's class
(``searchers.distinct``): merging it away could hide a class. ``tests/verifier/test_verify_merge.py`` sets
the free slots to anything and plays on. The merged state is the witness prefix's own state, bit for bit, so
every witness is a sequence the simulator really plays.

**Counting.** A child that is unsafe ends its episode: all 30^r completions of its prefix are hazardous
(r actions left), times its parent's multiplicity. A child proved safe by a bound (``verifier.bounds``) counts its
completions as safe. A leaf that is neither is safe. Every count is a Python int; hazardous + safe = 30^N
exactly when the tree is decided, and what a time limit leaves is reported as undecided.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cellstress.sim import layout as L
from cellstress.sim.kernels.expand import expand_pairs
from cellstress.verifier.bounds import DISTANCE, Bounds

CHILDREN = 8192 * 30  # children per compiled expansion (bounds memory; the time limit and progress are checked between)
MAX_ACTIONS = 127  # actions per decision the witness prefixes (int8) can hold (the paper's 30, the articulated 119)


@dataclass(frozen=True)
class Hit:
    """An unsafe child: its action prefix, its state and the metric row of its unsafe step; ``sequences``: the
    hazardous sequences it stands for (its parent's multiplicity times 30^(actions left))."""

    actions: tuple[int, ...]
    state: np.ndarray
    row: np.ndarray
    sequences: int


@dataclass
class TreeOutcome:
    """What deciding one tree found: exact counts, states per layer, what each bound cut, the unsafe children."""

    horizon: int
    total: int
    hazardous: int = 0
    safe: int = 0
    states: list[int] = field(default_factory=list)
    expanded: int = 0
    pruned_states: dict[str, int] = field(default_factory=dict)
    pruned_sequences: dict[str, int] = field(default_factory=dict)
    hits: list[Hit] = field(default_factory=list)
    timed_out: bool = False
    layers: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)  # (sorted keys, states), if kept
    seconds: list[float] = field(default_factory=list)  # wall time of each action's layer (benchmarks only: the
    # verdict and verify.json never read it, so the same inputs still give the same bytes)

    @property
    def undecided(self) -> int:
        return self.total - self.hazardous - self.safe

    @property
    def decided(self) -> bool:
        return self.undecided == 0


def _key_columns() -> tuple[tuple[tuple[int, int, float], ...], int]:
    """The merge key's columns, derived from the state layout's declarations (``layout.STATE.merges``): (slot,
    slot it is free while or -1, value there) for every slot not declared free."""
    cols = []
    for i, g in enumerate(L.STATE.merges):
        if g.kind == "free":
            continue
        cond = -1 if g.free_while is None else L.STATE.index(g.free_while)
        cols.append((i, cond, np.nan if g.free_value is None else g.free_value))
    return tuple(cols), len(cols)


KEY_COLUMNS, N_KEY = _key_columns()
KEY_SLOTS = np.array([c[0] for c in KEY_COLUMNS], dtype=np.int64)
_CONDITIONAL = tuple((j, cond, value) for j, (_, cond, value) in enumerate(KEY_COLUMNS) if cond >= 0)


def merge_keys(states: np.ndarray) -> np.ndarray:
    """One fixed-size byte key per state (rows of ``states``): equal keys, equal futures (see the module and
    ``layout.STATE``). Every slot that is read is compared bit for bit."""
    states = np.asarray(states, dtype=float).reshape(-1, L.NS)
    key = np.ascontiguousarray(states[:, KEY_SLOTS]).view(np.int64)
    for j, cond, value in _CONDITIONAL:
        key[states[:, cond] == value, j] = 0  # free there: every value merges
    return np.ascontiguousarray(key).view(np.dtype((np.void, key.dtype.itemsize * N_KEY))).ravel()


class _Judge:
    """For a criterion without a kernel test: children whose action came within the contact distance are
    stepped again by ``Simulator.step``, which hands each contact to the criterion and ends the episode where it
    says so (contacts are rare, so this costs little)."""

    def __init__(self, sim):
        self.sim = sim
        self.active = sim.contacts is not None
        self.dtol = sim.criterion.distance_tolerance

    def __call__(self, parents, children, last, d_min, parent, action):
        if not self.active:
            return
        for c in np.flatnonzero(d_min <= self.dtol):
            nxt, rows = self.sim.step(parents[parent[c]], int(action[c]))
            children[c] = nxt
            last[c] = rows[-1]


def decide(sim, horizon: int, bounds: Bounds, *, deadline: float | None = None,
           progress: Callable[[int], None] | None = None, keep: bool = False) -> TreeOutcome:
    """Decide every sequence of ``horizon`` actions from ``sim``'s start (see the module). ``deadline``: a
    ``time.monotonic()`` after which the tree is left undecided; ``progress(sequences)`` is told how many more
    sequences each step decided; ``keep``: keep every layer's merged states, for ``lookup``."""
    n_act = sim.n_actions
    chunk = max(1, CHILDREN // n_act)  # parents per expansion
    out = TreeOutcome(horizon, n_act ** horizon)
    judge = _Judge(sim)
    s0 = sim.reset()
    out.states.append(1)
    if s0[L.S_UNSAFE] != 0.0:  # unsafe where it starts: every sequence is hazardous
        out.hazardous = out.total
        out.hits.append(Hit((), s0, sim.initial_metrics(), out.total))
        _tell(progress, out.total)
        return out
    # multiplicities are at most 30^N: int64 while that fits, Python ints beyond
    exact = np.int64 if out.total < 2 ** 62 else object
    states, mult, prefixes = s0[None, :].copy(), np.ones(1, dtype=exact), np.zeros((1, 0), dtype=np.int8)
    for depth in range(1, horizon + 1):
        t_layer = time.perf_counter()
        weight = n_act ** (horizon - depth)
        kept_states, kept_mult, kept_parent, kept_action = [], [], [], []
        for i0 in range(0, len(states), chunk):
            if deadline is not None and time.monotonic() > deadline:
                out.timed_out = True
                return out
            parents = states[i0:i0 + chunk]
            pmult = mult[i0:i0 + chunk]
            before = out.hazardous + out.safe
            clear = bounds.last_safe(parents) if depth == horizon else None
            if clear is None:  # every child, numbered parent * n_act + action
                n_child = len(parents) * n_act
                parent = np.repeat(np.arange(len(parents)), n_act)
                action = np.tile(np.arange(n_act), len(parents))
            else:  # the last layer: the children the bound does not clear (still in prefix order)
                _count_cut(out, pmult, clear)
                parent, action = np.nonzero(~clear)
                n_child = len(parent)
            children = np.empty((n_child, L.NS))
            last = np.empty((n_child, L.NM))
            d_min = np.empty(n_child)
            expand_pairs(sim.params, parents, parent, action, children, last, d_min)
            judge(parents, children, last, d_min, parent, action)
            out.expanded += n_child
            cmult = pmult[parent]
            unsafe = children[:, L.S_UNSAFE] != 0.0
            for c in np.flatnonzero(unsafe):
                seqs = int(cmult[c]) * weight
                out.hazardous += seqs
                acts = (*prefixes[i0 + parent[c]].tolist(), int(action[c]))
                out.hits.append(Hit(tuple(acts), children[c].copy(), last[c].copy(), seqs))
            alive = ~unsafe
            if depth == horizon:
                out.safe += int(cmult[alive].sum())
            else:
                for name, cut in bounds.prune(children, last, alive, horizon - depth):
                    n_cut = int(np.count_nonzero(cut))
                    if n_cut:
                        seqs = int(cmult[cut].sum()) * weight
                        out.safe += seqs
                        out.pruned_states[name] = out.pruned_states.get(name, 0) + n_cut
                        out.pruned_sequences[name] = out.pruned_sequences.get(name, 0) + seqs
                        alive &= ~cut
                idx = np.flatnonzero(alive)
                kept_states.append(children[idx])
                kept_mult.append(cmult[idx])
                kept_parent.append(i0 + parent[idx])
                kept_action.append(action[idx].astype(np.int8))
            _tell(progress, out.hazardous + out.safe - before)
        if depth == horizon:
            out.seconds.append(time.perf_counter() - t_layer)
            break
        states, mult, prefixes = _merge(np.concatenate(kept_states), np.concatenate(kept_mult),
                                        np.concatenate(kept_parent), np.concatenate(kept_action), prefixes)
        out.states.append(len(states))
        out.seconds.append(time.perf_counter() - t_layer)
        if keep:
            keys = merge_keys(states)
            order = np.argsort(keys)
            out.layers.append((keys[order], states[order]))
        if not len(states):
            break
    return out


def _count_cut(out: TreeOutcome, pmult: np.ndarray, clear: np.ndarray) -> None:
    """Count the last layer's children the distance bound cleared before play (``Bounds.last_safe``) as safe."""
    per_parent = clear.sum(axis=1)
    n_cut = int(per_parent.sum())
    if n_cut:
        seqs = sum(int(m) * int(k) for m, k in zip(pmult, per_parent, strict=True) if k)
        out.safe += seqs
        out.pruned_states[DISTANCE] = out.pruned_states.get(DISTANCE, 0) + n_cut
        out.pruned_sequences[DISTANCE] = out.pruned_sequences.get(DISTANCE, 0) + seqs


def lookup(sim, out: TreeOutcome, bounds: Bounds, actions) -> str:
    """How a kept tree (``decide(..., keep=True)``) counted the sequence ``actions``: ``hazardous``, ``safe`` or
    ``pruned:BOUND``. It follows the sequence through the merged states, as the counting did: the state after
    each action is the merged state its key falls on."""
    state = sim.reset()
    if state[L.S_UNSAFE] != 0.0:
        return "hazardous"
    for depth, a in enumerate(actions, start=1):
        if depth == out.horizon:
            clear = bounds.last_safe(state[None, :])
            if clear is not None and clear[0, sim.action_index(a)]:
                return f"pruned:{DISTANCE}"
        child, rows = sim.step(state, a)
        if child[L.S_UNSAFE] != 0.0:
            return "hazardous"
        if depth == out.horizon:
            return "safe"
        alive = np.ones(1, dtype=bool)
        for name, cut in bounds.prune(child[None, :], rows[-1:], alive, out.horizon - depth):
            if cut[0]:
                return f"pruned:{name}"
        keys, states = out.layers[depth - 1]
        i = int(np.searchsorted(keys, merge_keys(child[None, :])[0]))
        if i >= len(keys) or keys[i] != merge_keys(child[None, :])[0]:
            raise KeyError(f"the state after {list(actions[:depth])} is in no merged state of layer {depth}")
        state = states[i]
    return "safe"


def _merge(children, cmult, parent, action, prefixes):
    """The distinct states among ``children`` (in prefix order), their summed multiplicities and witness
    prefixes."""
    if not len(children):
        return children, cmult, np.zeros((0, prefixes.shape[1] + 1), dtype=np.int8)
    keys = merge_keys(children)
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # distinct states in the order of their first (smallest) prefix
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    mult = np.zeros(len(first), dtype=cmult.dtype)
    np.add.at(mult, rank[inverse.ravel()], cmult)
    reps = first[order]
    new_prefixes = np.concatenate([prefixes[parent[reps]], action[reps, None]], axis=1)
    return children[reps], mult, new_prefixes


def _tell(progress, n: int) -> None:
    if progress is not None and n:
        progress(n)
