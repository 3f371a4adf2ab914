"""The compiled simulator: one time step of worker, devices and robot, and whole episodes in batches.

Everything here is numba-compiled and works on ``SimParams`` (a named tuple of arrays built once per cell by
``sim.build``) and a state vector laid out as ``sim.layout`` describes. One module per concern, lowest first:
params (the arrays), robot, body, fences, reach, sensing, separation, step, batch, worker; a module imports only
from those before it. numba inlines ``inline="always"`` functions across modules as within one, so the split
costs nothing at run time.

Speed: numba reference-counts arrays, and passing a tuple of arrays (SimParams, Work) into an inlined function
increments and decrements every member, atomically. On the hot path that bookkeeping once took two thirds of
the run time. So the inlined helpers take the arrays they read (and scalars, and index rows element-wise
rather than slicing views); only the entry points take SimParams and Work. The step itself allocates nothing
and is compiled without reference counting at all (``geometry.NO_REFCOUNT``); only run_batch, which
allocates, keeps it.

The names below are what the rest of cellstress calls, so callers need not know which module holds a kernel;
the layout constants are not among them: they are read from ``sim.layout``.
"""

from cellstress.sim.kernels.batch import make_handle, run_batch, run_episode, step_with_handle
from cellstress.sim.kernels.body import human_pose, pose_body, pose_capsules, worker_radius
from cellstress.sim.kernels.fences import collect_near_fences, fence_detour, near_fences
from cellstress.sim.kernels.params import SimParams, Work, make_work
from cellstress.sim.kernels.reach import TRACE_REL_TOL, reach_value
from cellstress.sim.kernels.robot import (
    fastest_joint_speed,
    forward_kinematics,
    joint_trajectory,
    other_robots,
    robot_capsules,
    robot_live,
    robot_table,
)
from cellstress.sim.kernels.sensing import device_sees, trunk_clear
from cellstress.sim.kernels.separation import separation
from cellstress.sim.kernels.step import (
    latch_seen,
    reset_state,
    sense_and_measure,
    step_action,
)
from cellstress.sim.kernels.worker import worker_paths, worker_point_distances

__all__ = [
    "SimParams", "Work", "make_work",
    "robot_live", "joint_trajectory", "forward_kinematics", "fastest_joint_speed", "robot_capsules", "robot_table",
    "other_robots",
    "human_pose", "pose_body", "pose_capsules", "worker_radius",
    "near_fences", "collect_near_fences", "fence_detour",
    "reach_value", "TRACE_REL_TOL",
    "device_sees", "trunk_clear",
    "separation",
    "reset_state", "sense_and_measure", "step_action", "worker_paths", "worker_point_distances", "latch_seen",
    "run_episode", "run_batch", "make_handle", "step_with_handle",
]
