"""Reading cell files: built-in names or paths, safe YAML, one clear error per problem."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import yaml
from pydantic import ValidationError

from cellstress.cell.schema import CellSpec
from cellstress.errors import CellError

BUILTIN_CELLS: tuple[str, ...] = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


@dataclass(frozen=True)
class Cell:
    """A validated cell: its spec, where it came from and a hash of its text (for result files)."""

    spec: CellSpec
    source: str  # the built-in name or the path as given
    directory: Path | None  # folder for relative paths in the file (None for built-ins)
    sha256: str

    @property
    def name(self) -> str:
        return self.spec.name


def _builtin_text(name: str) -> str:
    return resources.files("cellstress.cell").joinpath("builtin").joinpath(f"{name}.yaml").read_text(encoding="utf-8")


def _field_path(loc: tuple) -> str:
    parts: list[str] = []
    for item in loc:
        if isinstance(item, int):
            parts.append(f"[{item}]")
        elif item in ("laser-scanner", "light-curtain", "function-after", "function-before"):
            continue  # pydantic's tag for the union branch, not a field
        else:
            parts.append(("." if parts else "") + str(item))
    return "".join(parts)


def parse_cell(text: str, source: str, directory: Path | None) -> Cell:
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "YAML"
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise CellError(source, where, f"YAML syntax error: {problem}") from None
    if data is None:
        raise CellError(source, "", "the file is empty")
    if not isinstance(data, dict):
        raise CellError(source, "", f"a cell file holds a mapping of fields, not a {type(data).__name__}")
    try:
        spec = CellSpec.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown field"
        elif err["type"] == "missing":
            msg = "required field is missing"
        msg = msg.removeprefix("Value error, ")
        more = f" (and {exc.error_count() - 1} more problem(s))" if exc.error_count() > 1 else ""
        raise CellError(source, _field_path(err["loc"]), msg + more) from None
    cell = Cell(spec, source, directory, hashlib.sha256(text.encode()).hexdigest())
    check_geometry(cell)
    return cell


def load_cell(name_or_path: str | Path) -> Cell:
    """A built-in cell by name (see ``BUILTIN_CELLS``) or a cell file by path."""
    ref = str(name_or_path)
    if ref in BUILTIN_CELLS:
        return parse_cell(_builtin_text(ref), ref, None)
    path = Path(ref).expanduser()
    if not path.exists():
        known = ", ".join(BUILTIN_CELLS)
        raise CellError(ref, "", f"no such file, and not a built-in cell ({known})")
    if path.is_dir():
        raise CellError(ref, "", "is a directory, not a cell file")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise CellError(ref, "", "is not a UTF-8 text file") from None
    except OSError as exc:
        raise CellError(ref, "", f"cannot be read: {exc.strerror}") from None
    return parse_cell(text, ref, path.resolve().parent)


def check_geometry(cell: Cell) -> None:
    """Checks that need more than one field: the URDF, the waypoints against it, the start pose."""
    from cellstress.errors import CellstressError
    from cellstress.robot.model import load_robot, resolve_urdf
    from cellstress.sim.geometry import point_segment_2d, polygon_distance

    spec, src = cell.spec, cell.source
    urdf = resolve_urdf(spec.robot.urdf, cell.directory)
    if not urdf.is_file():
        raise CellError(src, "robot.urdf", f"URDF file not found: {urdf}")
    try:
        robot = load_robot(urdf)
    except CellstressError as exc:
        raise CellError(src, "robot.urdf", str(exc)) from None
    except Exception as exc:  # pinocchio raises plain RuntimeError/ValueError for unreadable URDFs
        raise CellError(src, "robot.urdf", f"pinocchio cannot read it: {str(exc).splitlines()[0]}") from None
    nj = robot.n_joints
    for i, w in enumerate(spec.robot.task.waypoints_deg):
        if len(w) != nj:
            raise CellError(src, f"robot.task.waypoints_deg[{i}]",
                            f"has {len(w)} joint values but the robot has {nj} joints")
    caps = spec.robot.capsules if spec.robot.capsules != "auto" else ()
    for i, c in enumerate(tuple(caps) + spec.robot.extra_capsules):
        if c.link not in robot.link_joint:
            field = f"robot.capsules[{i}].link" if i < len(caps) else f"robot.extra_capsules[{i - len(caps)}].link"
            raise CellError(src, field, f"the robot has no link {c.link!r}")
    import numpy as np

    x, y = spec.human.start.xy
    r = 0.20
    fl = spec.floor
    if not (fl.xmin + r <= x <= fl.xmax - r and fl.ymin + r <= y <= fl.ymax - r):
        raise CellError(src, "human.start.xy", f"({x}, {y}) is not on the floor (with the body's 0.2 m radius)")
    for i, poly in enumerate(spec.table.polygons):
        verts = np.asarray(poly, dtype=float)
        if polygon_distance(x, y, verts, 0, len(verts)) < r:
            raise CellError(src, "human.start.xy", f"({x}, {y}) is inside or touching table polygon {i}")
    for i, fence in enumerate(spec.fences):
        for a, b in zip(fence.points, fence.points[1:], strict=False):
            if fence.bottom < 0.5 and point_segment_2d(x, y, a[0], a[1], b[0], b[1]) < r:
                raise CellError(src, "human.start.xy", f"({x}, {y}) is inside or touching fence {i}")
