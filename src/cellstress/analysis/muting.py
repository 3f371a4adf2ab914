"""The muting check: a light curtain muted for a conveyor opening must end its muting as soon as the pallet has
cleared the opening (IEC 62046:2018, muting: the muting ends when the material has passed; the opening is then
protected again), or whoever follows the pallet passes unseen."""

from __future__ import annotations

from dataclasses import dataclass

from cellstress.devices.light_curtain import LightCurtain


@dataclass(frozen=True)
class MutingCheck:
    """One muted curtain: when the pallet has passed and when the muting ends [s of the cell's clock]."""

    device: str
    pallet_in: float
    pallet_out: float
    until: float

    @property
    def ok(self) -> bool:
        return self.until <= self.pallet_out + 1e-9

    def line(self) -> str:
        head = (f"{self.device}: muted {self.pallet_in:g}..{self.until:g} s of the cycle, the pallet fills the "
                f"opening {self.pallet_in:g}..{self.pallet_out:g} s")
        if self.ok:
            return head + ": the muting ends as the pallet clears (IEC 62046): ok"
        return (head + f": muted {self.until - self.pallet_out:.2f} s after the pallet cleared, nobody following it "
                "is seen: FAIL")


def muting_checks(spec) -> tuple[MutingCheck, ...]:
    """A check for every light curtain of the cell with muting."""
    return tuple(MutingCheck(d.name, float(d.muting.pallet[0]), float(d.muting.pallet[1]), float(d.muting.until))
                 for d in spec.devices if isinstance(d, LightCurtain) and d.muting is not None)
