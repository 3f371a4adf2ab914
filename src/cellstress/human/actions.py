"""The paper's 30 human actions: 5 walking motions x 6 upper-body postures.

An action is written ``WALK+BODY`` (e.g. ``walk+bend-forward``). Its index is ``walk_index * 6 + body_index``,
so that actions sharing a walking motion are contiguous.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.errors import ActionError

WALKS: tuple[str, ...] = ("walk", "turn-left-45", "turn-left-90", "turn-right-45", "turn-right-90")
BODIES: tuple[str, ...] = (
    "upright",
    "bend-forward",
    "bend-left",
    "bend-right",
    "bend-forward-left",
    "bend-forward-right",
)
ACTION_NAMES: tuple[str, ...] = tuple(f"{w}+{b}" for w in WALKS for b in BODIES)
N_ACTIONS = len(ACTION_NAMES)
_INDEX = {name: i for i, name in enumerate(ACTION_NAMES)}

# Heading change of each walking motion [deg]; counter-clockwise (left) is positive.
_TURN_DEG = {"walk": 0.0, "turn-left-45": 45.0, "turn-left-90": 90.0, "turn-right-45": -45.0, "turn-right-90": -90.0}
# Target posture of each upper-body motion as (forward, lateral) fractions of the maximum flexion;
# lateral is positive to the left. Combined bends use the full range on both axes.
_POSTURE = {
    "upright": (0.0, 0.0),
    "bend-forward": (1.0, 0.0),
    "bend-left": (0.0, 1.0),
    "bend-right": (0.0, -1.0),
    "bend-forward-left": (1.0, 1.0),
    "bend-forward-right": (1.0, -1.0),
}


def action_index(action: int | str) -> int:
    """The index of an action given by name or index; raises ActionError for anything else."""
    if isinstance(action, (int, np.integer)) and not isinstance(action, bool):
        if 0 <= int(action) < N_ACTIONS:
            return int(action)
        raise ActionError(f"action index {action} is out of range 0..{N_ACTIONS - 1}")
    if isinstance(action, str):
        key = action.strip().lower()
        if key in _INDEX:
            return _INDEX[key]
        raise ActionError(f"unknown action {action!r}; actions are WALK+BODY with WALK in {', '.join(WALKS)} "
                          f"and BODY in {', '.join(BODIES)}")
    raise ActionError(f"an action is a name or an index, not {type(action).__name__}")


MAX_SEQUENCE = 1000  # actions in one played sequence (200 s): its trace is held in memory and printed


def parse_actions(text: str) -> list[int]:
    """Parse a comma-separated action list such as ``walk+upright,walk+bend-forward``."""
    parts = [p for p in (s.strip() for s in text.split(",")) if p]
    if not parts:
        raise ActionError("the action list is empty")
    if len(parts) > MAX_SEQUENCE:
        raise ActionError(f"{len(parts):,} actions; at most {MAX_SEQUENCE:,} in one sequence")
    return [action_index(p) for p in parts]


def action_table(max_forward_deg: float, max_lateral_deg: float) -> np.ndarray:
    """Per action: [walks (0/1), heading change (rad), target forward flexion (rad), target lateral flexion (rad)]."""
    table = np.zeros((N_ACTIONS, 4))
    for i, name in enumerate(ACTION_NAMES):
        walk, body = name.split("+")
        fwd, lat = _POSTURE[body]
        table[i] = (
            1.0 if walk == "walk" else 0.0,
            np.deg2rad(_TURN_DEG[walk]),
            np.deg2rad(max_forward_deg) * fwd,
            np.deg2rad(max_lateral_deg) * lat,
        )
    return table
