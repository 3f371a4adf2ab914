"""The closest point pair of a metric row as a ``core.records.Contact``: for criteria that judge contacts.

Everything a criterion may need about a contact that the compiled loop does not compute: the ISO/TS 15066
body region of the human point (``human.regions``), the contact normal (``scene.contact_normal``), the robot's
joint state at that step (from the kernel's own trajectory) and, from pinocchio, the robot point's velocity
towards the human and the robot's reflected mass along the normal (``robot.dynamics``). Contacts are rare, so
this runs in Python, outside the hot loop.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.core.records import Contact
from cellstress.human.body import BODY_PARTS
from cellstress.human.regions import body_region
from cellstress.robot.dynamics import point_dynamics, reflected_mass
from cellstress.robot.model import load_pinocchio
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.build import Layout


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

    def contact(self, row: np.ndarray) -> Contact:
        """The closest points of a metric row, with the region, normal, v_rel and reflected mass there."""
        lay, P = self.layout, self.layout.params
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
            v_rel, m_r = 0.0, math.inf
        else:
            pb = self.R_base.T @ (rp - self.t_base)  # pinocchio works in the robot base frame
            nb = self.R_base.T @ n
            Jp, M = point_dynamics(self.model, self.data, lay.robot.pinocchio_q(q), j + 1, pb)
            if self.reduce is None:
                m_r = reflected_mass(Jp, M, nb)
            else:
                e = self.reduce
                m_r = reflected_mass(Jp @ e, e.T @ M @ e, nb)
            v_rel = max(0.0, float(nb @ (Jp @ qd)))
        return Contact(float(row[L.M_D]), float(row[L.M_V]), lay.capsules[link].name, BODY_PARTS[part], region,
                       (float(rp[0]), float(rp[1]), float(rp[2])), (float(hp[0]), float(hp[1]), float(hp[2])),
                       (float(n[0]), float(n[1]), float(n[2])), v_rel, m_r)
