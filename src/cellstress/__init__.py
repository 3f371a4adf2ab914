"""cellstress: find hidden human-robot hazards in robot cells by Adaptive Stress Testing.

The Python API is ``cellstress.api`` (``load_cell``, ``parse_cell``, ``check``, ``search``, ``simulate``,
``verify``, ``write_report``), also reachable here; ``Simulator`` is the cell simulator. They are imported on
first use: the simulator pulls in numba, and the command line should start fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from cellstress.core.version import __version__

__all__ = ["BUILTIN_CELLS", "Cell", "Simulator", "__version__", "check", "load_cell", "parse_cell", "search",
           "simulate", "verify", "write_report"]
_API = ("check", "load_cell", "parse_cell", "search", "simulate", "verify", "write_report")

if TYPE_CHECKING:
    from cellstress.api import check, load_cell, parse_cell, search, simulate, verify, write_report
    from cellstress.cell.load import BUILTIN_CELLS, Cell
    from cellstress.sim.simulator import Simulator


def __getattr__(name: str):
    if name in _API:
        from cellstress import api

        return getattr(api, name)
    if name in ("BUILTIN_CELLS", "Cell"):
        from cellstress.cell import load

        return getattr(load, name)
    if name == "Simulator":
        from cellstress.sim.simulator import Simulator

        return Simulator
    raise AttributeError(f"module 'cellstress' has no attribute {name!r}")
