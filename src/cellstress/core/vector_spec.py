"""Named slots of a flat vector (a state, a metric row, a parameter vector) or the values of a small enumeration:
one table of names in order, with a line of meaning each.

Compiled code indexes such vectors with plain module-level integers (numba reads globals as compile-time
constants), so a module that describes a vector assigns those integers from its spec, by name. The order and
the meaning are then written down once, and ``indices`` refuses an assignment that leaves a slot out or names
one twice, so a slot added to the spec cannot be forgotten where the integers are made.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class VectorSpec:
    """``slots``: (name, meaning) in vector order; a slot's index is its position."""

    title: str
    slots: tuple[tuple[str, str], ...]

    def __post_init__(self) -> None:
        names = self.names
        if len(set(names)) != len(names):
            raise ValueError(f"{self.title}: a slot name occurs twice")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.slots)

    @property
    def size(self) -> int:
        return len(self.slots)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"{self.title} has no slot {name!r}") from None

    def meaning(self, name: str) -> str:
        return self.slots[self.index(name)][1]

    def indices(self, *names: str) -> tuple[int, ...]:
        """The index of each of ``names``, which must name every slot once (in any order)."""
        if sorted(names) != sorted(self.names):
            missing = sorted(set(self.names) - set(names))
            extra = sorted(set(names) - set(self.names))
            raise ValueError(f"{self.title}: name every slot once (missing {missing}, unknown {extra})")
        return tuple(self.index(n) for n in names)

    def table(self) -> str:
        """The spec as a Markdown table (index, name, meaning)."""
        lines = [f"{self.title}:", "", "| index | name | meaning |", "|---:|---|---|"]
        lines += [f"| {i} | {n} | {m} |" for i, (n, m) in enumerate(self.slots)]
        return "\n".join(lines)


MERGE_KINDS = ("exact", "free")


@dataclass(frozen=True)
class Merge:
    """How a state slot takes part when ``verify`` merges states whose futures are the same (``verifier.tree``).

    ``exact``: equal bit for bit (the simulator is deterministic, so states equal in every slot that is read
    have the same future, with no approximation). ``free``: nothing that decides the future reads it; ``reason``
    says why (a property test sets such slots to anything and plays on). ``free_while`` (with kind ``exact``):
    the slot is free while the slot of that name holds ``free_value`` (``reason`` says why), exact otherwise.

    There is no "equal within a tolerance": two positions a micrometre apart can fall on either side of a
    fence's or an obstacle's edge and walk on a stride apart (``tests/verifier/test_verify_merge.py`` has such a
    pair), so rounding would let one state's future stand for a different one.
    """

    kind: Literal["exact", "free"]
    reason: str = ""
    free_while: str | None = None
    free_value: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in MERGE_KINDS:
            raise ValueError(f"merge kind must be one of {MERGE_KINDS}, not {self.kind!r}")
        if (self.kind == "free" or self.free_while is not None) and not self.reason:
            raise ValueError("a free slot says why it cannot change the future")
        if self.free_while is not None and (self.kind != "exact" or self.free_value is None):
            raise ValueError("free_while goes with kind 'exact' and a free_value")

    def describe(self) -> str:
        if self.kind == "free":
            return f"free: {self.reason}"
        return "exact" + (f"; free while {self.free_while} = {self.free_value:g}: {self.reason}"
                          if self.free_while else "")


EXACT = Merge("exact")


@dataclass(frozen=True)
class StateSpec(VectorSpec):
    """A ``VectorSpec`` whose every slot also declares how it merges (``Merge``), in the same place as its name
    and meaning: a slot added later without one is refused here, so the verifier's merge key, which is derived
    from these declarations, cannot forget it."""

    merges: tuple[Merge, ...] = ()

    @classmethod
    def of(cls, title: str, entries) -> StateSpec:
        """From (name, meaning, Merge) triples; a triple without its Merge is refused."""
        entries = tuple(entries)
        for e in entries:
            if len(e) != 3 or not isinstance(e[2], Merge):
                raise ValueError(f"{title}: slot {e[0]!r} does not declare how it merges (name, meaning, Merge)")
        return cls(title, tuple((n, m) for n, m, _ in entries), tuple(g for _, _, g in entries))

    def __post_init__(self) -> None:
        super().__post_init__()
        if len(self.merges) != len(self.slots) or not all(isinstance(g, Merge) for g in self.merges):
            raise ValueError(f"{self.title}: every slot declares how it merges")
        for name, g in zip(self.names, self.merges, strict=True):
            if g.free_while is not None and g.free_while not in self.names:
                raise ValueError(f"{self.title}: slot {name!r} is free while {g.free_while!r}, which is no slot")

    def merge(self, name: str) -> Merge:
        return self.merges[self.index(name)]

    def table(self) -> str:
        lines = [f"{self.title}:", "", "| index | name | meaning | merge |", "|---:|---|---|---|"]
        rows = zip(self.slots, self.merges, strict=True)
        lines += [f"| {i} | {n} | {m} | {g.describe()} |" for i, ((n, m), g) in enumerate(rows)]
        return "\n".join(lines)
