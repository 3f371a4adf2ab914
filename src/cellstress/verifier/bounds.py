"""Sound pruning bounds: a sub-tree is cut only when no completion of it can reach the unsafe set.

Each bound takes a layer's children (states after an action, and the metric row of each one's last step) and
says which of the living ones are safe for every completion of ``r`` more actions. docs/verify.md gives each
soundness argument; ``tests/verify/test_bounds.py`` checks the assumptions they rest on over many random steps.

* ``at-rest``: every robot's latched stop has taken full effect: the robots stand for good, and the criterion's
  kernel test needs one to move.
* ``distance``: the worker cannot come within the criterion's contact distance of anything the robot can occupy
  in the time left (``verifier.reach``); in the last layer, where the action is known, no pose of that action
  can (``verifier.last_action``: ``last_safe``).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from cellstress.sim import layout as L
from cellstress.verifier.last_action import LastAction, applies
from cellstress.verifier.reach import SweptField

AT_REST = "at-rest"
DISTANCE = "distance"
BOUND_NAMES = (AT_REST, DISTANCE)
REST_VTOL = 1e-9  # m/s: see Bounds (at rest behind a warning field or a separation monitor)


class Bounds:
    """The bounds that hold for one simulator (its criterion and robot); ``enabled``: the names to use."""

    def __init__(self, sim, enabled: tuple[str, ...] = BOUND_NAMES, horizon: int = 8):
        scal = sim.params.scal
        self.dt = float(scal[L.C_DT])
        self.stop_time = float(scal[L.C_STOP_TIME])
        self.spa = sim.params.spa
        vtol = float(scal[L.C_VTOL])
        # The kernel test is d_HR <= DTOL and v_R > VTOL; a robot at rest has v_R == 0 exactly (see docs), so it is
        # never unsafe when VTOL >= 0. A criterion that judges contacts itself (VTOL inf: no kernel test) may call
        # a contact with a standing robot unsafe (ISO/TS 15066 clamping), so the bound does not apply to it.
        # ``at-rest`` rests on a latched stop holding for good: a device that restarts the robot by itself breaks
        # that (Layout.stops_hold). Behind a warning field or a separation monitor the robot's time scaling is
        # ramped in closed form (``live_path_time``), which reaches 0 at most one stopping time after the stop in
        # exact arithmetic; in floating point a re-anchored ramp may end a rounding error later, a speed of
        # ~1e-16 of the path's, so there the criterion's speed tolerance must be at least REST_VTOL. In a cell of
        # several robots every robot must stand, each by its own stop. ``distance`` rests only on each robot's
        # path time advancing no faster than the clock, which every device keeps (verifier.reach).
        layout = sim.layout
        vtol_ok = 0.0 <= vtol < np.inf if layout.stops_latch else REST_VTOL <= vtol < np.inf
        self.at_rest = layout.stops_hold and AT_REST in enabled and sim.contacts is None and vtol_ok
        self.x_stop_times = np.asarray(sim.params.x_scal[:, L.C_STOP_TIME], dtype=float)  # robots 1..
        # Every criterion judges contacts only (d_HR at most its distance tolerance, the kernel's DTOL; a criterion
        # without a kernel test is shown only the rows within it, Simulator.first_unsafe): the distance bound holds
        # for all of them.
        self.swept = SweptField(sim, horizon) if DISTANCE in enabled else None
        # the same argument in the last layer, where the action is known (verifier.last_action)
        self.last = LastAction(sim, self.swept) if self.swept is not None and applies(sim) else None

    def prune(self, children: np.ndarray, last: np.ndarray, alive: np.ndarray, left: int
              ) -> Iterator[tuple[str, np.ndarray]]:
        """(bound name, mask of living children it proves safe for all ``left`` more actions), in order."""
        t = children[:, L.S_K] * self.dt
        if self.at_rest:
            # the kernel's own test of a completed stop (path_time): t - t_stop >= T, in the same float arithmetic,
            # for robot 0 and for every other robot with its own stop and stopping time
            rest = t - children[:, L.S_TSTOP] >= self.stop_time
            for r, stop_time in enumerate(self.x_stop_times):
                rest &= t - children[:, L.S_XTSTOP + r] >= stop_time
            yield AT_REST, alive & rest
        if self.swept is not None:
            yield DISTANCE, alive & self.swept.safe(children, left * self.spa)

    def last_safe(self, parents: np.ndarray) -> np.ndarray | None:
        """(parents, actions): the last layer's children the distance bound proves safe before they are played,
        or None where it has no last-action bound (the articulated worker, or the bound not enabled)."""
        return None if self.last is None else self.last.safe(parents)
