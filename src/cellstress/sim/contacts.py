"""The closest point pair of a metric row as a ``core.records.Contact``: for criteria that judge contacts.

Everything a criterion may need about a contact that the compiled loop does not compute: the ISO/TS 15066
body region of the human point (``human.regions``), the contact normal (``scene.contact_normal``), the robot's
joint state at that step (from the kernel's own trajectory) and, from pinocchio, the robot point's velocity
towards the human and the robot's reflected mass along the normal (``robot.dynamics``); and what surrounds the
contact (``sim.clamping``): the fixed surface behind the body region, the robot's travel towards it until it
stands, the worker's own speed towards the robot. Contacts are rare, so this runs in Python, outside the hot
loop.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.core.surroundings import Backing, ContactInCell
from cellstress.human.body import BODY_PARTS
from cellstress.human.regions import body_region
from cellstress.robot.dynamics import point_dynamics, reflected_mass
from cellstress.robot.model import load_pinocchio
from cellstress.sim import clamping, scene
from cellstress.sim import layout as L
from cellstress.sim.build import Layout
from cellstress.sim.kernels.params import SWEEP_CERTIFIED, SWEEP_DEPTH


def at_contact(row: np.ndarray, dt: float) -> tuple[np.ndarray, float]:
    """A metric row as of its contact's own moment, and the time since the step before. A contact the swept test
    found between two steps (``M_SWEPT`` 1 or 2) holds the robot and the worker as posed at ``M_TC``, while
    ``M_T`` is the step's time: the robot's time scaling and the worker's speed (the worker moves at a constant
    velocity within a step, ``kernels.sweep``) are taken at ``M_TC``. The time since the step before is kept
    above the finest part the swept test halves a step into."""
    if row[L.M_SWEPT] == 0.0 or not row[L.M_TC] >= 0.0:
        return row, dt
    at = np.array(row, dtype=float)
    at[L.M_T] = row[L.M_TC]
    return at, max(float(row[L.M_TC]) - (float(row[L.M_T]) - dt), dt / 2 ** (SWEEP_DEPTH + SWEEP_CERTIFIED))


def step_end_pose(row: np.ndarray, start: np.ndarray, dt: float) -> np.ndarray:
    """The worker's pose vector at the end of a row's step, from its pose at the step's start: the row's own pose,
    or for a contact found within the step (whose row holds the contact moment's pose, ``at_contact``) the
    straight line from the start through it, continued to the step's end (the worker moves on that line within
    a step, ``kernels.sweep``). So the pose the next step starts from is known from the rows alone."""
    if row[L.M_SWEPT] == 0.0 or not row[L.M_TC] >= 0.0:
        return L.row_pose(row)
    s = (float(row[L.M_TC]) - (float(row[L.M_T]) - dt)) / dt
    if not s > 0.0:
        return L.row_pose(row)
    start = np.asarray(start, dtype=float)
    return start + (L.row_pose(row) - start) / s


class ContactModel:
    """Contacts of one simulator layout (pinocchio model and data made once, like the simulator's work arrays)."""

    def __init__(self, layout: Layout):
        if len(layout.robots) > 1:  # (the dynamics below are robot 0's; a contact may be with another robot)
            raise CellstressError(f"{layout.cell.source}: criterion {layout.cell.spec.criterion.type!r} judges each "
                                  "contact with the robot's dynamics, which is not implemented yet for a cell of "
                                  "several robots; use a criterion with a kernel test (contact-while-moving)")
        self.layout = layout
        self.model = load_pinocchio(layout.robot.urdf)
        self.data = self.model.createData()
        P = layout.params
        self.R_base = np.asarray(P.base[:3, :3])
        self.t_base = np.asarray(P.base[:3, 3])
        # held joints are locked and a mimic joint moves with its master: the inertia the worker feels is that
        # of the driven joints only (None: every joint is driven, nothing to reduce)
        jm = layout.joints
        self.reduce = None if len(jm.driven) == layout.robot.n_joints else jm.jacobian_map()
        self.surfaces = clamping.FixedSurfaces(layout)

    def contact(self, row: np.ndarray, before: np.ndarray | None = None) -> ContactInCell:
        """The closest points of a metric row, with the region, normal, v_rel and reflected mass there, and its
        surroundings. ``before`` is the worker's pose vector (``layout.POSE_ROW``'s order) one time step earlier:
        the worker's speed is estimated from it (None: taken as 0)."""
        lay, P = self.layout, self.layout.params
        row, elapsed = at_contact(row, float(P.scal[L.C_DT]))
        link, part = int(row[L.M_LINK]), int(row[L.M_PART])
        rp = np.array(row[L.M_RX:L.M_RZ + 1], dtype=float)
        hp = np.array(row[L.M_HX:L.M_HZ + 1], dtype=float)
        pose = scene.body_pose(lay, L.row_pose(row))
        q, qd = scene.joint_state(lay, row)
        n = scene.contact_normal(lay, row, pose)
        b = lay.body
        region = body_region(part, hp, pose, b.height, b.upper_arm, b.forearm)
        j = int(P.cap_joint[link])
        if j < 0:  # a capsule on the fixed base
            v_rel, m_r, v_point = 0.0, math.inf, np.zeros(3)
            mass = None
        else:
            pb = self.R_base.T @ (rp - self.t_base)  # pinocchio works in the robot base frame
            Jp, M = point_dynamics(self.model, self.data, lay.robot.pinocchio_q(q), j + 1, pb)
            v_base = Jp @ qd
            v_point = self.R_base @ v_base
            Jm, Mm = (Jp, M) if self.reduce is None else (Jp @ self.reduce, self.reduce.T @ M @ self.reduce)

            def mass(u: np.ndarray) -> float:
                return reflected_mass(Jm, Mm, self.R_base.T @ u)

            m_r = mass(n)
            v_rel = max(0.0, float((self.R_base.T @ n) @ v_base))
        v_human = 0.0
        if before is not None:
            v = clamping.body_point_velocity(part, hp, pose, scene.body_pose(lay, before), elapsed)
            v_human = max(0.0, -float(n @ v))
        backing = None  # apart (d_HR over any criterion's distance tolerance) nothing is clamped yet
        if float(row[L.M_D]) <= clamping.CONTACT_RANGE:
            backing = self._backing(row, part, rp, hp, n, pose, j, v_point, mass)
        return ContactInCell(float(row[L.M_D]), float(row[L.M_V]), lay.capsules[link].name, BODY_PARTS[part],
                             region, _p3(rp), _p3(hp), _p3(n), v_rel, m_r, v_human, backing)

    def _backing(self, row, part, rp, hp, n, pose, j, v_point, mass) -> Backing | None:
        """The nearest fixed surface behind the body region along the push direction: the contact normal for a
        body capsule; for a reach volume (a hand anywhere in it) the robot point's own direction of motion, and
        the robot surface point anywhere in the worker's envelope that pins a hand with the least gap."""
        thick = clamping.body_thickness(self.layout, part, pose)
        d = n
        speed = float(np.linalg.norm(v_point))
        reach = part in (L.PART_LEFT_REACH, L.PART_RIGHT_REACH)
        if reach and speed > 1e-9:
            d = v_point / speed
        hit = self.surfaces.nearest(hp, d)
        pinned = self._pinning_point(row) if reach else None
        if pinned is not None and (hit is None or pinned[0][1] < hit[1]):
            (name, dist), point, d, v_push, jp = pinned
            return Backing(name, dist, thick, _p3(d), v_push, self._mass_along(jp, point, row, d),
                           self._travel(row, jp, point, d, v_push, dist - thick))
        if hit is None:
            return None
        v_push = max(0.0, float(d @ v_point))
        return Backing(hit[0], hit[1], thick, _p3(d), v_push, math.inf if mass is None else mass(d),
                       self._travel(row, j, rp, d, v_push, hit[1] - thick))

    def _travel(self, row, joint: int, point, d, v_push: float, gap: float) -> float:
        """The robot point's travel along ``d`` until standstill, behind a gap of at most TRAVEL_GAP; else 0."""
        if gap > clamping.TRAVEL_GAP:
            return 0.0
        return clamping.travel(self.layout, row, joint, point, d, v_push)

    def _pinning_point(self, row):
        """((surface, distance), point, direction, speed, joint) of the robot surface point inside the worker's
        envelope with the nearest fixed surface ahead of it (the least gap; the first such point on a tie), or
        None (``clamping.robot_surface_points``)."""
        points, dirs, speeds, joints = clamping.robot_surface_points(self.layout, row)
        if not len(points):
            return None
        which, dist = self.surfaces.nearest_many(points, dirs)
        i = int(np.argmin(dist))  # the first on a tie
        if which[i] < 0:
            return None
        return ((self.surfaces.names[int(which[i])], float(dist[i])), points[i], dirs[i], float(speeds[i]),
                int(joints[i]))

    def _mass_along(self, joint: int, point: np.ndarray, row, d: np.ndarray) -> float:
        """The robot's reflected mass [kg] at ``point`` on kernel joint ``joint`` along ``d`` (no payload)."""
        q, _ = scene.joint_state(self.layout, row)
        pb = self.R_base.T @ (point - self.t_base)
        Jp, M = point_dynamics(self.model, self.data, self.layout.robot.pinocchio_q(q), joint + 1, pb)
        if self.reduce is not None:
            Jp, M = Jp @ self.reduce, self.reduce.T @ M @ self.reduce
        return reflected_mass(Jp, M, self.R_base.T @ d)


def _p3(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
