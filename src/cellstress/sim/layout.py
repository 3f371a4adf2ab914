"""The cell simulator's flat vectors, described once: the state, the metric row, the scalar parameters, the
stop phases, the device kinds and the body parts the kernels know, and (from ``human.body``) the body
parameters.

Each is a ``VectorSpec`` (names in order, a line of meaning each); the integer constants the compiled kernels
index with (``S_X``, ``M_D``, ``C_DT``, ...) are taken from it by name, as plain module globals because numba
reads globals as compile-time constants. Code outside the kernels reads these names here, never from the
kernels, so where a slot lives is decided in this file alone.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.records import MAX_DOORS
from cellstress.core.vector_spec import EXACT, Merge, StateSpec, VectorSpec
from cellstress.human.actions import (  # noqa: F401  (re-exported: the action table's columns)
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
    ACT_COLUMNS,
    N_ACT_COLUMNS,
)
from cellstress.human.body import (  # noqa: F401  (re-exported: the kernels and their callers read them here)
    B_ARM_LEN,
    B_BODY_RADIUS,
    B_FOREARM,
    B_HAND,
    B_HEAD_RISE,
    B_HIP_Z,
    B_LEG_HALF,
    B_MODEL,
    B_N_CAPS,
    B_R_ARM,
    B_R_FORE,
    B_R_HAND,
    B_R_HEAD,
    B_R_LEG,
    B_R_TRUNK,
    B_R_UPPER,
    B_SHOULDER_HALF,
    B_SHOULDER_RISE,
    B_TRUNK_TOP,
    B_UPPER_ARM,
    B_WALK_SPEED,
    BODY_PARAMS,
    BODY_PARTS,
    CAPSULE_PART,
    MAX_CAPSULES,
    N_BODY_PARAMS,
    N_CAPSULES,
    NO_WALK_BELOW,
)

SEP_QUEUE = 16  # speed commands in flight at most: a separation channel's response time is below 16 time steps
_SEP_SLOTS = tuple(f"SEP_Q{i}" for i in range(1, SEP_QUEUE))  # (the kernels index them as S_SEP_Q0 + i)
_ARM_SLOTS = tuple(f"ARM{k}_Q{j}" for k in range(2) for j in range(5))
_DOOR_SLOTS = tuple(f"DOOR{i}_{what}" for what in ("REQ", "OPEN") for i in range(MAX_DOORS))

# How each state slot merges in verify (core.vector_spec.Merge): bit for bit, or not at all where nothing that
# decides the future reads it (each such slot says why).
_RECORD = "a record for the reports, written by the kernels and read by nothing that moves the worker or the " \
          "robot, senses, or judges a step"

STATE = StateSpec.of("state vector (a snapshot is a copy of it)", (
    ("K", "time step k (a float): the state's time is k * dt", EXACT),
    ("X", "worker's position on the floor, x [m]", EXACT),
    ("Y", "worker's position on the floor, y [m]", EXACT),
    ("HEADING", "worker's heading [rad], counter-clockwise from +x", EXACT),
    ("FWD", "trunk forward flexion [rad]", EXACT),
    ("LAT", "trunk lateral flexion [rad]", EXACT),
    ("TSTOP", "time the robot's latched stop takes effect [s]; inf: none latched", EXACT),
    ("TRIG_DEV", "device whose detection set TSTOP; -1: none (exact: it names a hazard's class)", EXACT),
    ("TRIG_T", "time of the first detection [s]; -1: none",
     Merge("free", reason="written when the first stop latches, read only to keep that first time; " + _RECORD)),
    ("UNSAFE", "1 once a step was unsafe: the episode has ended and the state no longer moves", EXACT),
    ("ACTIONS", "actions played so far", EXACT),
    # safeguards (issue 18): restart and speed reduction; appended, so the slots above never move
    ("LIVE", "1 once a stop was released or a speed reduction latched: the robot is computed live from the "
             "anchor below (0: path time = phase + t until TSTOP, the pre-stop table)", EXACT),
    ("A_T", "anchor: time of the last release [s] (0 at reset)", EXACT),
    ("A_TAU", "anchor: path time at A_T, less the cell's phase [s]", EXACT),
    ("A_SIG", "anchor: time scaling dtau/dt at A_T", EXACT),
    ("A_TGT", "anchor: time scaling the path ramps to after A_T (at 1 / stopping time per second)", EXACT),
    ("TSLOW", "time the latched speed reduction takes effect [s]; inf: none latched", EXACT),
    ("SLOW", "the latched reduction's time scaling (a warning field's reduced_speed)", EXACT),
    ("STOP_SEEN", "last time a stopping device saw the worker [s]; -1: never",
     Merge("exact", reason="read only by the automatic release (t - STOP_SEEN >= STOP_CLEAR), which never "
                           "happens while STOP_CLEAR is inf; the next stop that latches writes it anew",
           free_while="STOP_CLEAR", free_value=float("inf"))),
    ("STOP_CLEAR", "clear time [s] the latched stop waits for: the longest automatic restart time of the devices "
                   "that saw the worker since it latched; inf: one of them restarts manually, or none latched",
     EXACT),
    ("SLOW_SEEN", "last time a warning field saw the worker [s]; -1: never",
     Merge("exact", reason="read only by the release of the speed reduction, which never happens while "
                           "SLOW_CLEAR is inf; the next warning writes it anew",
           free_while="SLOW_CLEAR", free_value=float("inf"))),
    ("SLOW_CLEAR", "the same for the latched speed reduction", EXACT),
    ("RESTARTS", "stops released so far", Merge("free", reason="a counter for the reports; " + _RECORD)),
    # interlocked guard doors (issue 18): two slots per door, MAX_DOORS doors, in the order of SimParams.door_dev
    *((f"DOOR{i}_REQ", f"guard door {i}: time the worker first pushed it [s] (its interlock's stop request); "
                       "inf: not yet", EXACT) for i in range(MAX_DOORS)),
    *((f"DOOR{i}_OPEN", f"guard door {i}: time it started to open [s] (with guard locking: once the robot was "
                        "at rest); passable from this time plus its opening time; inf: closed", EXACT)
      for i in range(MAX_DOORS)),
    # several robots: robot 0's stop is TSTOP above; robots 1..3 latch their own (appended: nothing above moves)
    ("XTSTOP1", "time robot 1's latched stop takes effect [s]; inf: none latched (or no such robot)", EXACT),
    ("XTSTOP2", "the same for robot 2", EXACT),
    ("XTSTOP3", "the same for robot 3", EXACT),
    # speed and separation monitoring (issue 18): the speed commands; appended, so the slots above never move
    ("SEP_ON", "the speed fraction the separation monitor's command in effect allows (1 at reset)", EXACT),
    *((f"SEP_Q{i}", f"the fraction commanded at a step k with k mod {SEP_QUEUE} = {i} (in flight until k dt + the "
                    "response time); -1: none", EXACT) for i in range(SEP_QUEUE)),
    ("SEP_LOW", "the lowest fraction commanded so far (1: none below full speed)",
     Merge("free", reason="read only to keep the lowest; " + _RECORD)),
    ("SEP_LOW_T", "time of the measurement that commanded SEP_LOW [s]; -1: none", Merge("free", reason=_RECORD)),
    ("SEP_LOW_S", "the separation measured then [m]; -1: none", Merge("free", reason=_RECORD)),
    # the articulated worker (issue 20; appended): its stance and arm joints (0 for the paper's worker)
    ("DROP", "the hip's height above its standing height [m]: negative crouching or kneeling, positive on tiptoe",
     EXACT),
    *((f"ARM{k}_Q{j}", f"{side} arm's joint {j} [rad] (human.reach's order: shoulder flexion, abduction, upper-arm "
                       "rotation, elbow flexion, wrist flexion), relative to the trunk", EXACT)
      for k, side in enumerate(("left", "right")) for j in range(5)),
    # the swept contact test (issue 34; appended)
    ("D_SEP", "d_HR at the state's time as separation computed it, before clipping at 0 [m] (the swept contact "
              "test starts the next step from it: kernels.sweep)", EXACT),
))
(S_K, S_X, S_Y, S_HEADING, S_FWD, S_LAT, S_TSTOP, S_TRIG_DEV, S_TRIG_T, S_UNSAFE, S_ACTIONS, S_LIVE, S_A_T, S_A_TAU,
 S_A_SIG, S_A_TGT, S_TSLOW, S_SLOW, S_STOP_SEEN, S_STOP_CLEAR, S_SLOW_SEEN, S_SLOW_CLEAR, S_RESTARTS,
 S_DOOR0_REQ, S_DOOR1_REQ, S_DOOR2_REQ, S_DOOR3_REQ, S_DOOR0_OPEN, S_DOOR1_OPEN, S_DOOR2_OPEN,
 S_DOOR3_OPEN, S_XTSTOP1, S_XTSTOP2, S_XTSTOP3, S_SEP_ON, S_SEP_Q0, S_SEP_Q1, S_SEP_Q2, S_SEP_Q3, S_SEP_Q4,
 S_SEP_Q5, S_SEP_Q6, S_SEP_Q7, S_SEP_Q8, S_SEP_Q9, S_SEP_Q10, S_SEP_Q11, S_SEP_Q12, S_SEP_Q13, S_SEP_Q14, S_SEP_Q15,
 S_SEP_LOW, S_SEP_LOW_T, S_SEP_LOW_S, S_DROP, S_ARM0_Q0, S_ARM0_Q1, S_ARM0_Q2, S_ARM0_Q3, S_ARM0_Q4, S_ARM1_Q0,
 S_ARM1_Q1, S_ARM1_Q2, S_ARM1_Q3, S_ARM1_Q4, S_D_SEP) = STATE.indices(
    "K", "X", "Y", "HEADING", "FWD", "LAT", "TSTOP", "TRIG_DEV", "TRIG_T", "UNSAFE", "ACTIONS", "LIVE", "A_T", "A_TAU",
    "A_SIG", "A_TGT", "TSLOW", "SLOW", "STOP_SEEN", "STOP_CLEAR", "SLOW_SEEN", "SLOW_CLEAR", "RESTARTS",
    *_DOOR_SLOTS, "XTSTOP1", "XTSTOP2", "XTSTOP3", "SEP_ON", "SEP_Q0", *_SEP_SLOTS, "SEP_LOW",
    "SEP_LOW_T", "SEP_LOW_S", "DROP", *_ARM_SLOTS, "D_SEP")
S_ARM = S_ARM0_Q0  # arm k's joint j: S_ARM + 5 k + j
S_DOOR_REQ, S_DOOR_OPEN = S_DOOR0_REQ, S_DOOR0_OPEN  # door i's slots: these + i (the kernels index by door)
NS = STATE.size
S_XTSTOP = S_XTSTOP1  # robot r >= 1's stop is S_XTSTOP + r - 1 (the kernels loop over them)
MAX_ROBOTS = 4  # robot r >= 1 keeps its stop in S_XTSTOP + r - 1 and its path in the row's XTAU and XPHASE slots

ROW = VectorSpec("metric row (one per time step; row 0 of an episode is its start)", (
    ("T", "time [s]"),
    ("X", "worker's position, x [m]"),
    ("Y", "worker's position, y [m]"),
    ("HEADING", "worker's heading [rad]"),
    ("FWD", "trunk forward flexion [rad]"),
    ("LAT", "trunk lateral flexion [rad]"),
    ("D", "d_HR: least distance between robot and worker (body capsules or reach volumes), 0 in contact [m]"),
    ("V", "v_R: the fastest robot joint origin's speed [m/s]"),
    ("SEEN", "bit d set: device d sees the worker"),
    ("PHASE", "robot's stop phase (PHASE)"),
    ("LINK", "robot capsule nearest the worker; -1: none"),
    ("PART", "worker's part nearest the robot, an index into BODY_PARTS; -1: none"),
    ("RX", "nearest point on the robot, x [m] (RX, RY, RZ are consecutive)"),
    ("RY", "nearest point on the robot, y [m]"),
    ("RZ", "nearest point on the robot, z [m]"),
    ("HX", "nearest point on the worker, x [m] (HX, HY, HZ are consecutive)"),
    ("HY", "nearest point on the worker, y [m]"),
    ("HZ", "nearest point on the worker, z [m]"),
    ("UNSAFE", "1 where the criterion's kernel test holds (d_HR <= DTOL while v_R > VTOL)"),
    ("TAU", "robot's path time [s]"),
    ("ACTION", "action played; -1 in an episode's first row"),
    ("STEP", "time step k"),
    # several robots (appended): V above is the speed of the robot that owns LINK; TAU and PHASE are robot 0's
    ("ROBOT", "robot owning the capsule LINK (0 in a one-robot cell); -1: none"),
    ("XTAU1", "robot 1's path time [s]; -1: no such robot"),
    ("XTAU2", "robot 2's path time [s]"),
    ("XTAU3", "robot 3's path time [s]"),
    ("XPHASE1", "robot 1's stop phase (PHASE); -1: no such robot"),
    ("XPHASE2", "robot 2's stop phase"),
    ("XPHASE3", "robot 3's stop phase"),
    # the articulated worker (appended): the pose beyond X..LAT, as the state's DROP and ARMk_Qj
    ("DROP", "the hip's height above standing [m] (state DROP)"),
    *((f"ARM{k}_Q{j}", f"arm {k}'s joint {j} [rad] (state ARM{k}_Q{j})") for k in range(2) for j in range(5)),
    # the swept contact test (issue 34; appended)
    ("TC", "time of the contact the row reports [s]: T for the step's own sample, earlier for one the swept test "
           "found between the previous step and this one; -1: no contact"),
    ("SWEPT", "how the row's contact was found: 0 at the step's sample (or none), 1 at an in-between sample of the "
              "swept test, 2 the swept test could not rule one out within its finest sub-step (a conservative "
              "unsafe step: D and the points are then the nearer end's)"),
))
(M_T, M_X, M_Y, M_HEADING, M_FWD, M_LAT, M_D, M_V, M_SEEN, M_PHASE, M_LINK, M_PART, M_RX, M_RY, M_RZ, M_HX, M_HY, M_HZ,
 M_UNSAFE, M_TAU, M_ACTION, M_STEP, M_ROBOT, M_XTAU1, M_XTAU2, M_XTAU3, M_XPHASE1, M_XPHASE2, M_XPHASE3, M_DROP,
 M_ARM0_Q0, M_ARM0_Q1, M_ARM0_Q2, M_ARM0_Q3, M_ARM0_Q4, M_ARM1_Q0, M_ARM1_Q1, M_ARM1_Q2, M_ARM1_Q3,
 M_ARM1_Q4, M_TC, M_SWEPT) = ROW.indices(
    "T", "X", "Y", "HEADING", "FWD", "LAT", "D", "V", "SEEN", "PHASE", "LINK", "PART", "RX", "RY", "RZ", "HX", "HY",
    "HZ", "UNSAFE", "TAU", "ACTION", "STEP", "ROBOT", "XTAU1", "XTAU2", "XTAU3", "XPHASE1", "XPHASE2", "XPHASE3",
    "DROP", *_ARM_SLOTS, "TC", "SWEPT")
M_ARM = M_ARM0_Q0
NM = ROW.size
# A worker's pose as a vector (Simulator.worker_paths, worker_distances, scene.body_pose): x, y, heading, forward
# and lateral flexion, then DROP and the ten arm joints; where a state and a row keep it.
N_POSE = 16
POSE_STATE = (S_X, S_Y, S_HEADING, S_FWD, S_LAT, *range(S_DROP, S_DROP + 11))
POSE_ROW = (M_X, M_Y, M_HEADING, M_FWD, M_LAT, *range(M_DROP, M_DROP + 11))
POSE_EXT = 5  # where DROP is in a pose vector (the kernels read DROP and the joints from there on)


def row_pose(row) -> np.ndarray:
    """The worker's pose vector (POSE_ROW) of a metric row."""
    return np.asarray(row, dtype=float)[list(POSE_ROW)]


def pose_vector(x: float, y: float, heading: float, forward: float = 0.0, lateral: float = 0.0,
                limbs=None) -> np.ndarray:
    """A pose vector from its parts (``limbs``: the articulated worker's drop and ten arm joints; absent: 0)."""
    pose = np.zeros(N_POSE)
    pose[:5] = x, y, heading, forward, lateral
    if limbs is not None:
        pose[POSE_EXT:] = limbs
    return pose
M_XTAU, M_XPHASE = M_XTAU1, M_XPHASE1  # robot r >= 1's path time and stop phase: + r - 1

PHASE = VectorSpec("robot stop phase (values of the row's PHASE; records.STOP_PHASES names them in files)", (
    ("RUNNING", "no stop latched"),
    ("PENDING", "a stop is latched and takes effect later (the device's response time)"),
    ("BRAKING", "slowing linearly to a standstill within the stopping time"),
    ("STOPPED", "standing"),
    ("REDUCED", "no stop latched; a warning field's speed reduction is latched (pending or in effect)"),
))
PHASE_RUNNING, PHASE_PENDING, PHASE_BRAKING, PHASE_STOPPED, PHASE_REDUCED = PHASE.indices(
    "RUNNING", "PENDING", "BRAKING", "STOPPED", "REDUCED")

SCALARS = VectorSpec("scalar parameters (SimParams.scal)", (
    ("DT", "time step [s]"),
    ("STOP_TIME", "robot's braking time: from full speed, once it begins to brake (STOP_DELAY after its stop's "
                  "signal), to standstill [s]"),
    ("PHASE0", "robot's path time when an episode starts [s]"),
    ("CYCLE", "robot's cycle time [s]"),
    ("LINEAR", "1: the robot's moves are at constant speed (a trajectory file); 0: minimum-jerk"),
    ("DTOL", "contact distance of the criterion's kernel test [m]"),
    ("VTOL", "robot speed above which a contact is unsafe [m/s]; inf: the kernel judges no contact"),
    ("REACH_ORIGIN", "reach field: coordinate of its first grid node on every axis [m]"),
    ("REACH_H", "reach field: grid spacing [m]"),
    ("ANY_MOTION", "1: the kernel test's speed condition is that the robot owning the nearest capsule is not at a "
                   "standstill (stop phase other than STOPPED), whatever v_R (verify's arrival-window model: the "
                   "robot's speed at arrival moments between grid points is not known there); 0: v_R above VTOL"),
    # how the robot stops (issue 28; appended, so the slots above never move)
    ("STOP_DELAY", "time from a stop's signal (detection plus the device's response) until the robot begins to brake "
                   "[s]: the controller's delay; the latched stop (TSTOP) takes effect after it. 0 for category 0"),
    ("STOP_HOLD", "1: a category 0 stop: from the moment it takes effect the robot is posed where it was, its "
                  "capsules grown for the joints' independent braking (sim.build) and its speed falling to 0 "
                  "within STOP_TIME; 0: it brakes along its path"),
    ("SWEEP", "1: contact is tested in continuous time between the steps (kernels.sweep); 0: at the steps alone "
              "(for the cross-check against finely sampled motion)"),
    ("RHO", "a radius about the worker's hip pivot (x, y, hip height plus the stance's drop) that holds every "
            "point of the worker in every pose, reach volumes included (kernels.body.worker_radius) [m]"),
))
(C_DT, C_STOP_TIME, C_PHASE0, C_CYCLE, C_LINEAR, C_DTOL, C_VTOL, C_REACH_ORIGIN, C_REACH_H,
 C_ANY_MOTION, C_STOP_DELAY, C_STOP_HOLD, C_SWEEP, C_RHO) = SCALARS.indices(
    "DT", "STOP_TIME", "PHASE0", "CYCLE", "LINEAR", "DTOL", "VTOL", "REACH_ORIGIN", "REACH_H", "ANY_MOTION",
    "STOP_DELAY", "STOP_HOLD", "SWEEP", "RHO")
N_SCAL = SCALARS.size

DEVICE_KINDS = VectorSpec("detection primitive kinds (SimParams.dev_kind)", (
    ("SCANNER", "horizontal scan plane over a polygon (dev_poly, dev_verts; its height in dev_rect[4])"),
    ("CURTAIN", "vertical rectangle (dev_rect: x0 y0 x1 y1 bottom top)"),
    ("DOOR", "an interlocked guard door's switch (dev_rect: the leaf's x0 y0 x1 y1 bottom top): it signals from "
             "the time the worker pushes the door (its DOORi_REQ slot, i = the door's index in SimParams.door_dev)"),
))
DEV_SCANNER, DEV_CURTAIN, DEV_DOOR = DEVICE_KINDS.indices("SCANNER", "CURTAIN", "DOOR")
# SimParams.dev_speed of a channel that sets the speed from the measured separation (its rule in dev_sep),
# instead of latching a stop (0) or a reduction (a fraction in (0, 1))
SEPARATION = -1.0

JOINT_KINDS = VectorSpec("robot joint kinds (SimParams.jtype)", (
    ("REVOLUTE", "turns by q [rad] about its axis"),
    ("PRISMATIC", "slides by q [m] along its axis"),
))
JOINT_REVOLUTE, JOINT_PRISMATIC = JOINT_KINDS.indices("REVOLUTE", "PRISMATIC")

# The worker's parts in the row's PART: the paper worker's six capsules, its two reach volumes, then the
# articulated worker's forearms and hands (capsule c is part CAPSULE_PART[c]). Work holds MAX_CAPSULES.
N_BODY_CAPSULES = N_CAPSULES
PART_LEFT_REACH, PART_RIGHT_REACH = BODY_PARTS.index("left-reach"), BODY_PARTS.index("right-reach")
