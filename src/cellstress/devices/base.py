"""What every safety device record has: a name, a response time, and the record conventions of cell files."""

from __future__ import annotations

from cellstress.core.fields import Name, PositiveTime, Record


class DeviceRecord(Record):
    """The fields every device kind shares. A device kind is a subclass with a ``type: Literal[...]`` tag (its
    name in cell files and in the ``cellstress.devices`` registry) and the ``core.protocols.Device`` methods."""

    name: Name
    """The device's name, shown in outputs; unique in the cell."""
    response_time: PositiveTime
    """Time [s] from detection to the stop signal."""
