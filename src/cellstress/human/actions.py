"""The paper's 30 human actions: 5 walking motions x 6 upper-body postures.

An action is written ``WALK+BODY`` (e.g. ``walk+bend-forward``). Its index is ``walk_index * 6 + body_index``,
so that actions sharing a walking motion are contiguous.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.errors import ActionError
from cellstress.core.vector_spec import VectorSpec

# The action table the compiled simulator moves the worker by (SimParams.act), one row per action. Over one
# action the heading turns by TURN, and the trunk, stance and arms go linearly from where they were to their
# targets; a target not set is where it was. The paper's worker reads the first four columns only.
ACT_COLUMNS = VectorSpec("worker action table (SimParams.act)", (
    ("WALK", "walking speed as a fraction of the worker's walking speed; 0: the feet stay"),
    ("TURN", "heading change over the action [rad], counter-clockwise positive"),
    ("FWD", "target trunk forward flexion [rad] (if SET_TRUNK)"),
    ("LAT", "target trunk lateral flexion [rad], to the left positive (if SET_TRUNK)"),
    ("DIR", "walking direction relative to the heading [rad]: 0 forward, pi back, pi/2 to the left"),
    ("SET_TRUNK", "1: FWD and LAT are targets; 0: the trunk holds its flexion"),
    ("SET_STANCE", "1: DROP is a target; 0: the stance holds (articulated worker)"),
    ("DROP", "target hip height above standing [m] (crouch, kneel: negative; tiptoe: positive)"),
    ("SET_ARMS", "1: both arms go to the joint targets Q0..Q4 (the left arm mirrored); 0: the arms hold"),
    ("HANG", "1: the arms hang plumb: shoulder flexion follows the trunk's forward flexion, the rest Q1..Q4"),
    ("Q0", "target shoulder flexion [rad] (human.reach's joint order)"),
    ("Q1", "target shoulder abduction [rad]"),
    ("Q2", "target upper-arm rotation [rad]"),
    ("Q3", "target elbow flexion [rad]"),
    ("Q4", "target wrist flexion [rad]"),
))
(A_WALK, A_TURN, A_FWD, A_LAT, A_DIR, A_SET_TRUNK, A_SET_STANCE, A_DROP, A_SET_ARMS, A_HANG, A_Q0) = \
    ACT_COLUMNS.indices("WALK", "TURN", "FWD", "LAT", "DIR", "SET_TRUNK", "SET_STANCE", "DROP", "SET_ARMS",
                        "HANG", "Q0", "Q1", "Q2", "Q3", "Q4")[:11]
N_ACT_COLUMNS = ACT_COLUMNS.size

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


def index_in(names: tuple[str, ...], action: int | str, grammar: str) -> int:
    """The index of an action given by name or index among ``names``; ActionError (naming ``grammar``, how
    names are formed) for anything else."""
    if isinstance(action, (int, np.integer)) and not isinstance(action, bool):
        if 0 <= int(action) < len(names):
            return int(action)
        raise ActionError(f"action index {action} is out of range 0..{len(names) - 1}")
    if isinstance(action, str):
        key = action.strip().lower()
        if key in names:
            return names.index(key)
        raise ActionError(f"unknown action {action!r}; {grammar}")
    raise ActionError(f"an action is a name or an index, not {type(action).__name__}")


_GRAMMAR = f"actions are WALK+BODY with WALK in {', '.join(WALKS)} and BODY in {', '.join(BODIES)}"


def action_index(action: int | str) -> int:
    """The index of one of the paper's actions given by name or index; raises ActionError for anything else."""
    if isinstance(action, str) and action.strip().lower() in _INDEX:
        return _INDEX[action.strip().lower()]
    return index_in(ACTION_NAMES, action, _GRAMMAR)


MAX_SEQUENCE = 1000  # actions in one played sequence (200 s): its trace is held in memory and printed


def parse_actions(text: str, index=action_index) -> list[int]:
    """Parse a comma-separated action list such as ``walk+upright,walk+bend-forward`` (``index``: a worker
    model's ``action_index``; the paper's by default)."""
    parts = [p for p in (s.strip() for s in text.split(",")) if p]
    if not parts:
        raise ActionError("the action list is empty")
    if len(parts) > MAX_SEQUENCE:
        raise ActionError(f"{len(parts):,} actions; at most {MAX_SEQUENCE:,} in one sequence")
    return [index(p) for p in parts]


def action_table(max_forward_deg: float, max_lateral_deg: float) -> np.ndarray:
    """The paper's actions as rows of ACT_COLUMNS: walking (at full speed) or turning, and a trunk posture."""
    table = np.zeros((N_ACTIONS, N_ACT_COLUMNS))
    for i, name in enumerate(ACTION_NAMES):
        walk, body = name.split("+")
        fwd, lat = _POSTURE[body]
        table[i, A_WALK] = 1.0 if walk == "walk" else 0.0
        table[i, A_TURN] = np.deg2rad(_TURN_DEG[walk])
        table[i, A_FWD] = np.deg2rad(max_forward_deg) * fwd
        table[i, A_LAT] = np.deg2rad(max_lateral_deg) * lat
        table[i, A_SET_TRUNK] = 1.0
    return table


_TURN_WORDS = {"walk": ("walks forward", "walks"), "turn-left-45": ("turns 45° left", "turns 45° left"),
               "turn-left-90": ("turns 90° left", "turns 90° left"),
               "turn-right-45": ("turns 45° right", "turns 45° right"),
               "turn-right-90": ("turns 90° right", "turns 90° right")}
_BODY_WORDS = {"upright": ("stands upright", "upright"), "bend-forward": ("bends forward", "bending forward"),
               "bend-left": ("bends to the left", "bending left"),
               "bend-right": ("bends to the right", "bending right"),
               "bend-forward-left": ("bends forward and to the left", "bending forward-left"),
               "bend-forward-right": ("bends forward and to the right", "bending forward-right")}


class PaperWorker:
    """The paper's worker (Huck et al. 2020): 30 actions, hanging arms, and the reach volumes of its arms."""

    articulated = False
    action_names = ACTION_NAMES

    def action_index(self, action: int | str) -> int:
        return action_index(action)

    def action_table(self, max_forward_deg: float, max_lateral_deg: float, stature: float) -> np.ndarray:
        return action_table(max_forward_deg, max_lateral_deg)

    def action_words(self, action: str, short: bool = False) -> str:
        """'walk+bend-forward' -> 'walks forward and bends forward' (short: 'walks bending forward')."""
        walk, _, body = action.partition("+")
        w, b = _TURN_WORDS.get(walk, (walk, walk)), _BODY_WORDS.get(body, (body, body))
        return f"{w[1]} {b[1]}" if short else f"{w[0]} and {b[0]}"
