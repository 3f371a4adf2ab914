"""Building blocks of the file schemas (pydantic): the frozen record base and the value types with their units.

Lengths are metres, angles degrees, times seconds. Cell records (``cell.schema``) and the records of device
and criterion plug-ins are built from these, so every file field is checked the same way.

Cell files come from other people, so every number has a physically sensible range (no allocation or loop
may grow with a number a user wrote without a cap) and every list a length cap. Files are validated strictly
(``cell.load``): ``true`` is not a number, ``"1.5"`` is not a number.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

MAX_EXTENT = 100.0  # m: every coordinate of a cell lies within this of the origin (a cell, not a factory)
MAX_HEIGHT = 10.0  # m: fences, tables, devices
MAX_VERTICES = 256  # per polygon or fence polyline
MAX_TIME = 10.0  # s: response and stopping times

Finite = Annotated[float, Field(allow_inf_nan=False)]
Coordinate = Annotated[float, Field(ge=-MAX_EXTENT, le=MAX_EXTENT, allow_inf_nan=False)]
Point2 = tuple[Coordinate, Coordinate]
Point3 = tuple[Coordinate, Coordinate, Coordinate]
Angle = Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)]
PositiveTime = Annotated[float, Field(gt=0.0, le=MAX_TIME, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, le=MAX_EXTENT, allow_inf_nan=False)]
Length = Annotated[float, Field(gt=0.0, le=MAX_EXTENT, allow_inf_nan=False)]
Height = Annotated[float, Field(gt=0.0, le=MAX_HEIGHT, allow_inf_nan=False)]
Elevation = Annotated[float, Field(ge=0.0, le=MAX_HEIGHT, allow_inf_nan=False)]
# a name shown in text, tables and pictures: printable, one line (no control characters, no bidirectional
# overrides that would reorder what a terminal shows), not too long
PRINTABLE = r"^[^\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]+$"
Name = Annotated[str, Field(min_length=1, max_length=100, pattern=PRINTABLE)]


class Record(BaseModel):
    """A frozen file record: unknown fields are an error (a misspelt field must not be silently ignored)."""

    # a string right under a field is its description: docs/cell-format.md and `cellstress schema` show it
    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)


def _segments_cross(a: Point2, b: Point2, c: Point2, d: Point2) -> bool:
    """True when segments ab and cd properly intersect (touching at shared endpoints is not a crossing)."""

    def orient(p: Point2, q: Point2, r: Point2) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    return (o1 * o2 < 0) and (o3 * o4 < 0)


def check_simple_polygon(points: tuple[Point2, ...]) -> tuple[Point2, ...]:
    if len(points) < 3:
        raise ValueError(f"a polygon needs at least 3 points, got {len(points)}")
    n = len(points)
    # crossings first: a symmetric bow-tie has zero signed area, and "intersects itself" is the real problem
    for i in range(n):
        for j in range(i + 1, n):
            if j in (i, (i + 1) % n) or i == (j + 1) % n:
                continue
            if _segments_cross(points[i], points[(i + 1) % n], points[j], points[(j + 1) % n]):
                raise ValueError(f"the polygon intersects itself (edge {i} from point {i} crosses edge {j} "
                                 f"from point {j})")
    area2 = sum(points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]
                for i in range(n))
    if abs(area2) < 1e-12:
        raise ValueError("the polygon has zero area")
    return points


# A simple polygon; validated per polygon so that errors name the polygon's index (table.polygons[1]).
Polygon = Annotated[tuple[Point2, ...], Field(max_length=MAX_VERTICES), AfterValidator(check_simple_polygon)]
