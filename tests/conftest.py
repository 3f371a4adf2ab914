"""Shared fixtures. The tests/ tree mirrors src/cellstress/ without __init__.py files, so every test module
needs a unique base name (pytest's default "prepend" import mode)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def baseline_sim():
    """The built-in reference cell (UR10 on a table), built once per test session."""
    from cellstress.sim.simulator import Simulator

    return Simulator("baseline")
