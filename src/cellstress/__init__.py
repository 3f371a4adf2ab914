"""cellstress: find hidden human-robot hazards in robot cells by Adaptive Stress Testing."""

from __future__ import annotations

__version__ = "0.1.0"

from cellstress.cell.load import BUILTIN_CELLS, Cell, load_cell  # noqa: E402
from cellstress.sim.simulator import Simulator  # noqa: E402

__all__ = ["BUILTIN_CELLS", "Cell", "Simulator", "__version__", "load_cell"]
