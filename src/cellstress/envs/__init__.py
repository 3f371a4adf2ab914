"""Gymnasium, both ways.

* **Our cells as Gymnasium envs** (``cell_env``): ``import cellstress.envs`` registers ``cellstress/Cell-v0``,
  so ``gymnasium.make("cellstress/Cell-v0", cell="s3-fence-gap")`` is a cell with the paper's worker
  (``Discrete(30)``), the criterion's reward, and ``terminated`` on the unsafe set. Without importing anything
  first, ``gymnasium.make("cellstress.envs:cellstress/Cell-v0", cell=...)`` does the same: Gymnasium imports the
  module named before the colon. (Gymnasium 1.0 removed the ``gymnasium.envs`` entry-point plug-ins that made
  ``make`` import a package by itself; this ``module:id`` form is the way its release notes give instead.)
  The env draws the worker's arrival moment at each reset where the cell says ``arrival: cycle``.
  ``CellVectorEnv`` steps many copies at once, all at the cell's own arrival moment.
* **Any Gymnasium env stress-tested by our searchers** (``gym_simulator``): ``GymSimulator`` makes a
  deterministic env with a discrete action space and a safety measure in its ``info`` into a
  ``core.protocols.Simulator`` (registered as the ``gym`` simulator), by the Adaptive Stress Testing pattern:
  a state is the action sequence played from a fixed seed, and it is replayed when needed.
"""

from __future__ import annotations

import gymnasium

from cellstress.envs.cell_env import CellEnv, CellVectorEnv
from cellstress.envs.gym_simulator import GymSimulator, GymState

ENV_ID = "cellstress/Cell-v0"
MAKE_ID = "cellstress.envs:" + ENV_ID  # for gymnasium.make without importing cellstress first

__all__ = ["ENV_ID", "MAKE_ID", "CellEnv", "CellVectorEnv", "GymSimulator", "GymState"]

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="cellstress.envs.cell_env:CellEnv",
                       vector_entry_point="cellstress.envs.cell_env:CellVectorEnv")
