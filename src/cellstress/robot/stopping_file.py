"""A robot maker's stopping data as a file: stopping distance and time per joint, stop category, speed, payload
and extension, at the points the maker published (ISO 10218-1:2011, Annex B: the stopping time and distance
metric, measured from the stop signal to standstill; the tables and graphs of a robot's manual).

CSV, one published point per row, after a header naming the columns in this order::

    # lines starting with '#' are comments: say where the numbers come from
    joint,category,speed_pct,payload_kg,extension_pct,distance,unit,time_s
    shoulder_pan_joint,0,100,5,100,0.31,rad,0.244

* ``joint``: the URDF joint's name;
* ``category``: the stop category the row was measured with (IEC 60204-1: 0, 1 or 2);
* ``speed_pct``, ``extension_pct``: the joint's speed and the arm's extension, in percent of their maximum
  (makers publish 33, 66 and 100); ``payload_kg``: the payload [kg];
* ``distance`` in ``unit`` (``deg`` or ``rad`` for a revolute joint, ``m`` or ``mm`` for a prismatic one): how
  far the joint travels from the stop signal to standstill;
* ``time_s`` (or ``time_ms``, the header says which): the time from the stop signal to standstill.

The file is untrusted: its size and row count are bounded before anything is parsed, and every bad value is one
error naming its row (a row is its line, comments counted) and its column. An error never quotes the file's text:
a cell may name any file (``/etc/passwd``), and its first line must not end up in a log.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from cellstress.core.io import InputFileError, read_input_bytes
from cellstress.robot.joint_file import JointFileError

MAX_BYTES = 1024 * 1024
MAX_ROWS = 10_000
COLUMNS = ("joint", "category", "speed_pct", "payload_kg", "extension_pct", "distance", "unit")
TIME_COLUMNS = {"time_s": 1.0, "time_ms": 0.001}
ANGLE_UNITS = {"deg": math.pi / 180.0, "rad": 1.0}
LENGTH_UNITS = {"m": 1.0, "mm": 0.001}
MAX_TIME = 60.0  # s: no robot of ours takes a minute to stop
MAX_PAYLOAD = 10_000.0  # kg


class StoppingFileError(JointFileError):
    """A problem with a stopping data file: ``where`` is '' or 'row R, column C (name)'."""


@dataclass(frozen=True)
class StoppingRow:
    """One published point, in SI units (``distance`` in rad or m, by the unit the row gave)."""

    row: int  # its line in the file
    joint: str
    category: int
    speed_pct: float
    payload_kg: float
    extension_pct: float
    distance: float  # rad (deg, rad) or m (m, mm)
    angular: bool  # the row's unit is an angle
    time: float  # s

    @property
    def point(self) -> tuple[float, float, float]:
        return (self.speed_pct, self.payload_kg, self.extension_pct)


def read_stopping_file(path: Path) -> tuple[StoppingRow, ...]:
    """Every published point of the file, checked; StoppingFileError (one line) for anything wrong."""
    try:
        raw = read_input_bytes(path, MAX_BYTES)
    except InputFileError as exc:
        raise StoppingFileError("", exc.problem) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise StoppingFileError(f"row {line}", "is not UTF-8 text") from None
    text = text.replace("\r\n", "\n").replace("\r", "\n")  # a row ends at any of the three line ends
    lines = text.split("\n")
    if len(lines) - (not lines[-1]) > MAX_ROWS + 1:  # a header and MAX_ROWS rows (comments count as rows)
        raise StoppingFileError("", f"has more than {MAX_ROWS:,} rows")
    first = next((i for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")), None)
    if first is None:
        raise StoppingFileError("", "has no header; it needs 'joint,category,speed_pct,payload_kg,extension_pct,"
                                    "distance,unit,time_s' (or time_ms)")
    try:
        header = [h.strip() for h in next(csv.reader([lines[first]]))]
    except csv.Error as exc:
        raise StoppingFileError(f"row {first + 1}", f"not valid CSV ({exc})") from None
    want = ",".join(COLUMNS)
    if tuple(header[:-1]) != COLUMNS or len(header) != len(COLUMNS) + 1 or header[-1] not in TIME_COLUMNS:
        raise StoppingFileError(f"row {first + 1}", f"the header must be {want},time_s (or time_ms); "
                                                    f"{_header_problem(header)}")
    time_scale = TIME_COLUMNS[header[-1]]
    out: list[StoppingRow] = []
    seen: dict[tuple, int] = {}
    body = [(i + 1, ln) for i, ln in enumerate(lines) if i > first and ln.strip()
            and not ln.lstrip().startswith("#")]
    try:
        for r, ln in body:
            row = next(csv.reader([ln]))
            out.append(_row(row, r, header, time_scale))
            key = (out[-1].joint, out[-1].category, out[-1].point)
            if key in seen:
                raise StoppingFileError(f"row {r}", f"repeats row {seen[key]} (the same joint, category, speed, "
                                                    "payload and extension)")
            seen[key] = r
    except csv.Error as exc:
        raise StoppingFileError(f"row {r}", f"not valid CSV ({exc})") from None
    if not out:
        raise StoppingFileError("", "has no data rows after its header")
    return tuple(out)


def _header_problem(header: list[str]) -> str:
    """What is wrong with the header, by column number: never the file's own words."""
    if len(header) != len(COLUMNS) + 1:
        return f"it has {len(header)} columns, not {len(COLUMNS) + 1}"
    k = next((k for k, h in enumerate(header[:-1]) if h != COLUMNS[k]), len(COLUMNS))
    return f"column {k + 1} should be {COLUMNS[k] if k < len(COLUMNS) else 'time_s or time_ms'}"


def _row(row: list[str], r: int, header: list[str], time_scale: float) -> StoppingRow:
    if len(row) != len(header):
        raise StoppingFileError(f"row {r}", f"has {len(row)} values; expected {len(header)} ({','.join(header)})")

    def where(k: int) -> str:
        return f"row {r}, column {k + 1} ({header[k]})"

    joint = row[0].strip()
    if not joint or len(joint) > 200:
        raise StoppingFileError(where(0), "needs a joint name (at most 200 characters)")
    cat = row[1].strip()
    if cat not in ("0", "1", "2"):
        raise StoppingFileError(where(1), "is not a stop category (0, 1 or 2)")
    speed = _number(row[2], where(2), 0.0, 100.0, low_open=True)
    payload = _number(row[3], where(3), 0.0, MAX_PAYLOAD)
    extension = _number(row[4], where(4), 0.0, 100.0, low_open=True)
    unit = row[6].strip()
    if unit not in ANGLE_UNITS and unit not in LENGTH_UNITS:
        raise StoppingFileError(where(6), "is not a unit: deg or rad (revolute joints), m or mm (prismatic "
                                          "joints)")
    scale = ANGLE_UNITS.get(unit, LENGTH_UNITS.get(unit, 1.0))
    top = 4.0 * math.pi if unit in ANGLE_UNITS else 10.0  # two turns; 10 m
    distance = _number(row[5], where(5), 0.0, top / scale) * scale
    time = _number(row[7], where(7), 0.0, MAX_TIME / time_scale, low_open=True) * time_scale
    return StoppingRow(r, joint, int(cat), speed, payload, extension, distance, unit in ANGLE_UNITS, time)


def _number(text: str, where: str, lo: float, hi: float, low_open: bool = False) -> float:
    try:
        x = float(text)
    except ValueError:
        raise StoppingFileError(where, "is not a number") from None
    if not math.isfinite(x) or x < lo or x > hi or (low_open and x == lo):
        side = f"above {lo:g}" if low_open else f"at least {lo:g}"
        raise StoppingFileError(where, f"is out of range (a finite number {side} and at most {hi:g})")
    return x
