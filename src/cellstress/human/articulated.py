"""The articulated worker (``human: {model: articulated}``): jointed arms, more postures, sideways and backward
steps.

An action is ``MOVE+CHANGE``: what the feet do over the action (walk, step back, side-step, stand, turn) and
one change of the body (a trunk posture, a stance, or an arm target). The rest of the body holds: a worker who
crouches keeps their arms where they were, one who reaches keeps their stance. So a reach over a panel is
several actions: step up to it, rise on tiptoe, raise the arms, reach over.

Each arm is the 5-DOF arm of ``human.reach`` (shoulder flexion, abduction, upper-arm rotation, elbow flexion,
wrist flexion, within the AAOS ranges cited there), posed on the shoulders of the trunk; both arms go to the
same joint targets (the left one mirrored), and an arm that would pass through a fence panel or into an
obstacle holds where it was (``kernels.step.move_worker``), while the other goes on. Where the values come from
is in docs/worker.md.
"""

from __future__ import annotations

import numpy as np

from cellstress.human.actions import (
    A_DIR,
    A_DROP,
    A_FWD,
    A_HANG,
    A_LAT,
    A_Q0,
    A_SET_ARMS,
    A_SET_STANCE,
    A_SET_TRUNK,
    A_TURN,
    A_WALK,
    N_ACT_COLUMNS,
    index_in,
)
from cellstress.human.anthropometry import GAITS, POSTURES
from cellstress.human.body import PRONE_HIP_Z
from cellstress.human.reach import JOINT_RANGES_DEG

# Feet: (speed as a fraction of walking speed, direction relative to the heading [deg], turn [deg]).
# Stepping back and sideways is slower than walking forward (human.anthropometry.GAITS, docs/worker.md).
BACKWARD_SPEED = GAITS["step-back"].speed_fraction
SIDEWAYS_SPEED = GAITS["side-step"].speed_fraction
MOVES: dict[str, tuple[float, float, float]] = {
    "walk": (1.0, 0.0, 0.0),
    "step-back": (BACKWARD_SPEED, 180.0, 0.0),
    "side-left": (SIDEWAYS_SPEED, 90.0, 0.0),
    "side-right": (SIDEWAYS_SPEED, -90.0, 0.0),
    "stand": (0.0, 0.0, 0.0),
    "turn-left-45": (0.0, 0.0, 45.0),
    "turn-right-45": (0.0, 0.0, -45.0),
}

# Trunk postures: (forward, lateral) fractions of the largest flexions (HumanSpec), as the paper's.
TRUNK: dict[str, tuple[float, float]] = {
    "upright": (0.0, 0.0),
    "bend-forward": (1.0, 0.0),
    "bend-left": (0.0, 1.0),
    "bend-right": (0.0, -1.0),
}

# Stances (human.anthropometry.POSTURES): the hip's height above its standing height. "crawl" lies prone, the hip
# at human.body.PRONE_HIP_Z: the worker crawls at CRAWL_SPEED and passes under panels higher than PRONE_HEIGHT.
STANCES = ("stand-up", "crouch", "kneel", "tiptoe", "crawl")


def stance_drop(stance: str, stature: float) -> float:
    """The hip's height in ``stance`` above its standing height [m] for a body of ``stature`` [m]."""
    stand = POSTURES["stand"].hip_height(stature)
    if stance == "crawl":
        return PRONE_HIP_Z - stand
    posture = POSTURES["stand" if stance == "stand-up" else stance]
    return posture.hip_height(stature) - stand

# Arm targets [deg] in human.reach's joint order (flexion, abduction, rotation, elbow, wrist); "hang" lets the
# arms hang plumb whatever the trunk does.
ARMS: dict[str, tuple[float, float, float, float, float]] = {
    "hang": (0.0, 0.0, 0.0, 0.0, 0.0),
    "reach-low": (45.0, 0.0, 0.0, 0.0, 0.0),
    "reach-forward": (90.0, 0.0, 0.0, 0.0, 0.0),
    "reach-high": (135.0, 0.0, 0.0, 0.0, 0.0),
    "reach-up": (180.0, 0.0, 0.0, 0.0, 0.0),
    "reach-over": (120.0, 0.0, 0.0, 0.0, -70.0),  # forward and up, the hand bent down over an edge
    "reach-side": (0.0, 90.0, 0.0, 0.0, 0.0),
    "reach-across": (90.0, -30.0, 0.0, 0.0, 0.0),
}

CHANGES: tuple[str, ...] = (*TRUNK, *STANCES, *ARMS)
# The 112 actions the worker had before it could crawl keep their indices; the seven MOVE+crawl follow.
ACTION_NAMES: tuple[str, ...] = (*(f"{m}+{c}" for m in MOVES for c in CHANGES if c != "crawl"),
                                 *(f"{m}+crawl" for m in MOVES))
_GRAMMAR = f"the articulated worker's actions are MOVE+CHANGE with MOVE in {', '.join(MOVES)} and CHANGE in " \
           f"{', '.join(CHANGES)}"

_MOVE_WORDS = {"walk": ("walks forward", "walks"), "step-back": ("steps back", "steps back"),
               "side-left": ("side-steps to the left", "side-steps left"),
               "side-right": ("side-steps to the right", "side-steps right"), "stand": ("stands", "stands"),
               "turn-left-45": ("turns 45° left", "turns 45° left"),
               "turn-right-45": ("turns 45° right", "turns 45° right")}
_CHANGE_WORDS = {"upright": ("straightens up", "straightening up"),
                 "bend-forward": ("bends forward", "bending forward"),
                 "bend-left": ("bends to the left", "bending left"),
                 "bend-right": ("bends to the right", "bending right"),
                 "stand-up": ("rises from a crouch", "rising"), "crouch": ("crouches", "crouching"),
                 "kneel": ("kneels", "kneeling"), "tiptoe": ("rises on tiptoe", "on tiptoe"),
                 "crawl": ("lies down to crawl", "crawling"),
                 "hang": ("lets the arms hang", "arms down"), "reach-low": ("reaches forward and down", "reaching low"),
                 "reach-forward": ("reaches forward", "reaching forward"),
                 "reach-high": ("reaches forward and up", "reaching high"), "reach-up": ("reaches up", "reaching up"),
                 "reach-over": ("reaches over, the hands bent down", "reaching over"),
                 "reach-side": ("reaches out to the sides", "reaching sideways"),
                 "reach-across": ("reaches across the body", "reaching across")}


def _check_ranges() -> None:
    """Every arm target lies within the joint ranges of human.reach (an import-time guard for edits)."""
    for name, q in ARMS.items():
        for (lo, hi), v in zip(JOINT_RANGES_DEG, q, strict=True):
            if not lo <= v <= hi:
                raise ValueError(f"arm target {name} is outside the joint ranges")


_check_ranges()


class ArticulatedWorker:
    """Jointed arms that collide with fences, the table and obstacles; crouching, kneeling, tiptoe; stepping back
    and sideways (module docstring)."""

    articulated = True
    action_names = ACTION_NAMES

    def action_index(self, action: int | str) -> int:
        return index_in(ACTION_NAMES, action, _GRAMMAR)

    def action_table(self, max_forward_deg: float, max_lateral_deg: float, stature: float) -> np.ndarray:
        table = np.zeros((len(ACTION_NAMES), N_ACT_COLUMNS))
        for i, name in enumerate(ACTION_NAMES):
            move, change = name.split("+")
            speed, direction, turn = MOVES[move]
            row = table[i]
            row[A_WALK], row[A_DIR], row[A_TURN] = speed, np.deg2rad(direction), np.deg2rad(turn)
            if change in TRUNK:
                fwd, lat = TRUNK[change]
                row[A_SET_TRUNK] = 1.0
                row[A_FWD], row[A_LAT] = np.deg2rad(max_forward_deg) * fwd, np.deg2rad(max_lateral_deg) * lat
            elif change in STANCES:
                row[A_SET_STANCE], row[A_DROP] = 1.0, stance_drop(change, stature)
            else:
                row[A_SET_ARMS] = 1.0
                row[A_HANG] = 1.0 if change == "hang" else 0.0
                row[A_Q0:A_Q0 + 5] = np.deg2rad(ARMS[change])
        return table

    def action_words(self, action: str, short: bool = False) -> str:
        move, _, change = action.partition("+")
        m, c = _MOVE_WORDS.get(move, (move, move)), _CHANGE_WORDS.get(change, (change, change))
        return f"{m[1]} {c[1]}" if short else f"{m[0]} and {c[0]}"
