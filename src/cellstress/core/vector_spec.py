"""Named slots of a flat vector (a state, a metric row, a parameter vector) or the values of a small enumeration:
one table of names in order, with a line of meaning each.

Compiled code indexes such vectors with plain module-level integers (numba reads globals as compile-time
constants), so a module that describes a vector assigns those integers from its spec, by name. The order and
the meaning are then written down once, and ``indices`` refuses an assignment that leaves a slot out or names
one twice, so a slot added to the spec cannot be forgotten where the integers are made.
"""

from __future__ import annotations

from dataclasses import dataclass


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
