"""The guard door device kind: its ISO 13855 distance by hand (opening time credited), the ISO 14119 access time,
its primitive, its record's checks and its drawing (locked and unlocked told apart)."""

from __future__ import annotations

import pytest
from matplotlib.figure import Figure
from pydantic import ValidationError

from cellstress.core.records import DoorLeaf
from cellstress.devices.guard_door import GuardDoor


def door(**kw) -> GuardDoor:
    return GuardDoor.model_validate({"type": "guard-door", "name": "d", "start": (0, 0), "end": (1, 0), **kw})


def test_door_distance_by_hand():
    # ISO 13855, interlocking guard without guard locking: S = 1600 (0.05 + 1.0 - 0.6) + 850 = 1570 mm
    d = door(response_time=0.05, opening_time=0.6).required_distance(1.0)
    assert (d.K, d.C) == (1600.0, 850.0)
    assert d.T == pytest.approx(0.45) and d.S == pytest.approx(1570.0)
    # a door that takes longer to open than the robot to stop needs only the reach allowance
    assert door(opening_time=2.0).required_distance(1.0).S == pytest.approx(850.0)
    # with guard locking nothing is required
    assert door(guard_locking=True).required_distance(1.0).S == 0.0


def test_access_time_against_rest():
    d = door(response_time=0.05, opening_time=0.6)
    # 0.6 + (1.367 - 0.85) / 1.6 = 0.92 s < 1.05 s to rest
    assert "0.92 s" in d.access_note(1.367, 1.0) and "guard locking required" in d.access_note(1.367, 1.0)
    assert "no guard locking needed" in d.access_note(2.0, 1.0)
    assert "holds the door" in door(guard_locking=True).access_note(1.367, 1.0)


def test_door_primitive_and_stop_channel():
    d = door(top=2.2, opening_time=0.5, guard_locking=True)
    assert d.primitives() == (DoorLeaf((0.0, 0.0), (1.0, 0.0), 0.0, 2.2, 0.5, True),)
    (ch,) = d.channels()
    assert ch.speed == 0.0 and ch.clear_time == float("inf") and ch.response_time == 0.05


def test_door_record_checks():
    with pytest.raises(ValidationError, match="same point"):
        door(end=(0, 0))
    with pytest.raises(ValidationError, match="above bottom"):
        door(bottom=1.0, top=0.5)
    with pytest.raises(ValidationError, match="manual"):
        door(restart={"automatic": 1.0})
    with pytest.raises(ValidationError, match="greater than 0"):
        door(opening_time=0.0)


def test_drawing_tells_locked_from_unlocked():
    handles = []
    for locking in (False, True):
        ax = Figure().add_subplot()
        handles.append(door(guard_locking=locking).draw(ax))
    assert "no guard locking" in handles[0].get_label() and "no guard" not in handles[1].get_label()
    assert handles[0].get_linestyle() != handles[1].get_linestyle()
