"""A contact with what surrounds it: the fixed surface behind the body region (is it clamped?), how far the robot
still travels towards it before standing still, and how fast the worker's body region moved towards the robot.

The simulator (``sim.contacts``, ``sim.clamping``) measures these from the cell's own geometry and the worker's
pose change; a criterion that judges contacts (``criteria.iso15066``) decides from them whether the contact is
quasi-static (clamping) or transient, and with which force. Kept apart from ``core.records`` (which the compiled
kernels import, and whose bytes key their cache).
"""

from __future__ import annotations

from dataclasses import dataclass

from cellstress.core.records import Contact, Point3


@dataclass(frozen=True)
class Backing:
    """The nearest fixed surface behind a contact: along ``direction`` (unit, the way the robot pushes the body
    region), from the body's contact point.

    ``surface`` names it (``floor``, an obstacle's or the table's name, ``fence panel N``, ``door panel N``,
    ``pallet panel N``); ``distance`` [m] is from the contact point to the surface (0 when the point is inside a
    solid); ``thickness`` [m] is the body region's thickness there (its capsule's diameter); ``v_push`` [m/s] is
    the robot point's speed along ``direction`` (>= 0); ``m_push`` [kg] the robot's reflected mass along it
    (without payload; inf where its joints cannot move the point that way); ``travel`` [m] how far the robot
    point still advances along ``direction`` until the robot stands still (>= 0; see docs/criteria.md)."""

    surface: str
    distance: float
    thickness: float
    direction: Point3
    v_push: float
    m_push: float
    travel: float

    @property
    def gap(self) -> float:
        """Free space [m] between the body region's far side and the surface (negative: the capsule overlaps it)."""
        return self.distance - self.thickness


@dataclass(frozen=True)
class ContactInCell(Contact):
    """A ``core.records.Contact`` with its surroundings: ``v_human`` [m/s], the body region's speed towards the robot
    along the contact normal over the step before (>= 0: motion away from the robot counts 0; the simulator's raw
    estimate, uncapped), and ``backing``, the nearest fixed surface behind the body region within the simulator's
    search range (None: none)."""

    v_human: float = 0.0
    backing: Backing | None = None
