"""cellstress: find hidden human-robot hazards in robot cells by Adaptive Stress Testing."""

from __future__ import annotations

from typing import TYPE_CHECKING

__version__ = "0.3.0"

__all__ = ["BUILTIN_CELLS", "Cell", "Simulator", "__version__", "load_cell", "search"]

if TYPE_CHECKING:
    from cellstress.cell.load import BUILTIN_CELLS, Cell, load_cell
    from cellstress.search import search
    from cellstress.sim.simulator import Simulator


def __getattr__(name: str):
    # Imported on first use: the simulator pulls in numba, and the command line should start fast.
    if name in ("BUILTIN_CELLS", "Cell", "load_cell"):
        from cellstress.cell import load

        return getattr(load, name)
    if name == "Simulator":
        from cellstress.sim.simulator import Simulator

        return Simulator
    if name == "search":
        # the subpackage cellstress.search is callable: cellstress.search(cell, searcher=..., budget=..., seed=...)
        import importlib

        return importlib.import_module("cellstress.search")
    raise AttributeError(f"module 'cellstress' has no attribute {name!r}")
