"""What every safety device record has: a name, a response time, how the stop it requests is released, and
the record conventions of cell files."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Discriminator, Field, Tag

from cellstress.core.fields import Name, PositiveTime, Record
from cellstress.core.records import Channel, IsoDistance


class AutomaticRestart(Record):
    """The stop is released by itself once the device has not seen the worker for ``automatic`` seconds."""

    automatic: PositiveTime
    """Clear time [s]: how long the device must not see the worker before the robot restarts."""


def _restart_kind(v) -> str:
    return "manual" if isinstance(v, str) else "automatic"


# a tagged union, so that a wrong value gets the one message of the form it tried (a word or a mapping)
Restart = Annotated[Annotated[Literal["manual"], Tag("manual")] | Annotated[AutomaticRestart, Tag("automatic")],
                    Discriminator(_restart_kind)]


class DeviceRecord(Record):
    """The fields every device kind shares. A device kind is a subclass with a ``type: Literal[...]`` tag (its
    name in cell files and in the ``cellstress.devices`` registry) and the ``core.protocols.Device`` methods."""

    name: Name
    """The device's name, shown in outputs; unique in the cell."""
    response_time: PositiveTime
    """Time [s] from detection to the stop signal."""
    restart: Restart = "manual"
    """How its stop is released: ``manual`` (a reset outside the cell: the robot stays stopped for the rest of
    the episode) or ``{automatic: CLEAR_TIME}`` (the robot restarts once this device has not seen the worker for
    CLEAR_TIME seconds and no other device holds a stop)."""

    stops: tuple[Annotated[str, Field(min_length=1, max_length=32)], ...] | None = Field(None, min_length=1,
                                                                                       max_length=4)
    """The robots its detection stops, by name (``robots[].name``); absent: every robot of the cell."""

    @property
    def clear_time(self) -> float:
        """The automatic restart's clear time [s]; inf for a manual restart (the stop is never released)."""
        return float("inf") if self.restart == "manual" else float(self.restart.automatic)

    def channels(self) -> tuple[Channel, ...]:
        """What the kernel senses for this device: each detection primitive with its effect. By default every
        primitive stops the robot; a kind with a warning field adds one that reduces its speed."""
        return tuple(Channel(p, self.name, 0.0, self.response_time, self.clear_time) for p in self.primitives())

    def warning_distance(self, stopping_time: float) -> IsoDistance | None:
        """ISO 13855 distance of the device's warning field (a channel that reduces the speed), if it has one."""
        return None

    def static_check(self, distance: float, stopping_time: float) -> tuple[float, str]:
        """This kind's own part of the static check (``analysis.iso13855``): the separation it guarantees given
        the ``distance`` its detection zone keeps from the hazard zone, and a note for the check's row. By
        default the zone's distance itself, without a note; a guard door credits its opening time, a speed and
        separation monitor its configured protective separation."""
        return distance, ""

    # How the robot stops, in two parts (docs/robot.md, Stopping): after the stop signal reaches it, it keeps its
    # speed for ``delay`` seconds (its controller's delay), then brakes to a standstill over ``braking``. ISO
    # 13855's S = K T + C counts only the time, T = response + delay + braking, so by default a kind sees the sum
    # (its ``stopping_time``); a kind whose distance depends on how the robot moves meanwhile (a warning field's
    # reduced speed, speed and separation monitoring) overrides these.
    def stop_distance(self, delay: float, braking: float) -> IsoDistance:
        """ISO 13855 distance for a robot that keeps its speed ``delay`` s after the signal, then brakes over
        ``braking`` s."""
        return self.required_distance(delay + braking)

    def warning_stop_distance(self, delay: float, braking: float) -> IsoDistance | None:
        """``warning_distance`` for such a robot."""
        return self.warning_distance(delay + braking)

    def stop_check(self, distance: float, delay: float, braking: float) -> tuple[float, str]:
        """``static_check`` for such a robot."""
        return self.static_check(distance, delay + braking)


def stops_of(device) -> tuple[str, ...] | None:
    """The robot names a device's stop is limited to (``DeviceRecord.stops``); None: every robot (also for a
    device kind that is not a ``DeviceRecord``)."""
    return device.stops if isinstance(device, DeviceRecord) else None


def stops_robot(device, robot: str) -> bool:
    """Whether ``device``'s stop stops the robot named ``robot``."""
    stops = stops_of(device)
    return stops is None or robot in stops
