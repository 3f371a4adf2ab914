"""Reading cell files: built-in names or paths, safe YAML, one clear error per problem."""

from __future__ import annotations

import difflib
import hashlib
import re
import reprlib
import types
import typing
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import yaml
from pydantic import BaseModel, ValidationError

from cellstress.cell.files import cell_files, refuse_files_outside
from cellstress.cell.program import robot_program
from cellstress.cell.robot_stop import check_hold, robot_stop
from cellstress.cell.schema import CRITERIA, DEVICE_KINDS, CellSpec
from cellstress.core import registry
from cellstress.core.errors import CellError, CellstressError
from cellstress.core.io import MAX_INPUT_BYTES, InputFileError, read_input_bytes
from cellstress.core.plane import point_segment_distance, polygon_distance
from cellstress.core.protocols import Channels
from cellstress.core.provenance import InputFile
from cellstress.core.records import Channel
from cellstress.devices.base import stops_of
from cellstress.human.body import BODY_RADIUS, WALK_BLOCK_HEIGHT
from cellstress.robot.capsules import fitted_capsules
from cellstress.robot.geometry import robot_geometry, unseen_message
from cellstress.robot.model import load_robot, resolve_urdf, unknown_urdf_message

BUILTIN_CELLS: tuple[str, ...] = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap", "all-flaws",
                                  "s2-deceptive", "restart-auto", "restart-manual", "warning-field-short",
                                  "warning-field-ok", "mat-short", "mat-ok", "palletizing", "palletizing-fixed",
                                  "door-unlocked", "door-locked", "muting-long", "muting-ok",
                                  "two-robots", "two-robots-fixed", "ssm-latency", "ssm-ok", "reach-over",
                                  "reach-over-ok", "long-gripper", "long-gripper-ok", "machine-tending",
                                  "machine-tending-delay", "machine-tending-delay-ok", "crawl-under", "crawl-under-ok",
                                  "curtain-reach-over", "curtain-reach-over-ok")


@dataclass(frozen=True)
class Cell:
    """A validated cell: its spec, where it came from and a hash of its text (for result files)."""

    spec: CellSpec
    source: str  # the built-in name or the path as given
    directory: Path | None  # folder for relative paths in the file (None for built-ins)
    sha256: str
    files: tuple[InputFile, ...] = ()  # every file the cell reads, with its size and SHA-256 (cell.files)

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def files_dir(self) -> Path | None:
        """Where the file's relative paths (a URDF, a trajectory file) are looked up: the cell file's folder, or
        the built-in cells' folder for a built-in."""
        if self.directory is not None:
            return self.directory
        return Path(str(resources.files("cellstress.cell").joinpath("builtin"))) if self.source in BUILTIN_CELLS \
            else None


def _builtin_path(name: str):
    return resources.files("cellstress.cell").joinpath("builtin").joinpath(f"{name}.yaml")


def builtin_file(name: str) -> str:
    """Where a built-in cell's file is (to read it as an example, or copy it as a start)."""
    return str(_builtin_path(name))


def builtin_text(name: str) -> str:
    """The YAML text of a built-in cell; CellError when its file is missing from the installation."""
    path = _builtin_path(name)
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CellError(name, "", f"the built-in cell's file is missing from the installation ({path})") \
            from None


MAX_VALUES = 200_000  # values in a cell file once its aliases are expanded (a big cell has about 2,000)
MAX_DEPTH = 40  # nesting of lists and mappings (a cell needs 5)


class _CellLoader(yaml.SafeLoader):
    """PyYAML's safe loader (plain data only, no Python tags) that also rejects repeated keys and reads
    numbers such as ``1e-3`` as YAML 1.2 does (YAML 1.1 would make them text)."""

    def construct_mapping(self, node, deep=False):
        seen: dict = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key!r} (first at line {seen[key].line + 1})",
                        key_node.start_mark)
                seen[key] = key_node.start_mark
            except TypeError:  # an unhashable key: let the base class report it
                pass
        return super().construct_mapping(node, deep=deep)


_CellLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789"))


def safe_load_yaml(text: str):
    """Parse YAML as plain data (never Python objects), rejecting duplicate keys."""
    return yaml.load(text, Loader=_CellLoader)  # noqa: S506 - _CellLoader is a SafeLoader


class _TooBig(Exception):
    pass


def _frozen(data, budget: list[int], depth: int = 0):
    """``data`` with every list made a tuple (the schema's containers), counting values against ``budget``:
    YAML aliases can make a small file expand to billions of values, and deep nesting can exhaust the stack."""
    budget[0] -= 1
    if budget[0] < 0:
        raise _TooBig(f"the file expands to more than {MAX_VALUES:,} values (YAML aliases?)")
    if depth > MAX_DEPTH:
        raise _TooBig(f"lists and mappings are nested more than {MAX_DEPTH} deep")
    if isinstance(data, list):
        return tuple(_frozen(v, budget, depth + 1) for v in data)
    if isinstance(data, dict):
        return {k: _frozen(v, budget, depth + 1) for k, v in data.items()}
    return data


# pydantic puts the tag of a tagged-union branch into an error's location; it is not a field name
_UNION_TAGS = {*DEVICE_KINDS, *CRITERIA, "capsules-auto", "capsules-list", "function-after", "function-before"}
_TYPE_WORDS = {"list": "list", "str": "single text value", "int": "single number", "float": "single number",
               "bool": "single true/false value"}


def _field_path(loc: tuple) -> str:
    parts: list[str] = []
    for item in loc:
        if isinstance(item, int):
            parts.append(f"[{item}]")
        elif item in _UNION_TAGS:
            continue  # pydantic's tag for the union branch, not a field
        else:
            parts.append(("." if parts else "") + str(item))
    return "".join(parts)


def _model_at(loc: tuple) -> type[BaseModel] | None:
    """The schema record at ``loc`` (a pydantic error location), or None when it cannot be followed."""
    tp: object = CellSpec
    for item in loc:
        tp = _unwrap(tp, item)
        if item in _UNION_TAGS:
            continue  # _unwrap picked the branch
        if isinstance(item, int):
            args = typing.get_args(tp)
            if typing.get_origin(tp) is not tuple or not args:
                return None
            if len(args) == 2 and args[1] is Ellipsis:
                tp = args[0]
            else:
                tp = args[item] if item < len(args) else None
        elif isinstance(tp, type) and issubclass(tp, BaseModel) and item in tp.model_fields:
            tp = tp.model_fields[item].annotation
        else:
            return None
    tp = _unwrap(tp, None)
    return tp if isinstance(tp, type) and issubclass(tp, BaseModel) else None


def _unwrap(tp: object, item) -> object:
    """Strip Annotated; pick the union branch a location item points into (by tag, or the only container)."""
    while True:
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            tp = typing.get_args(tp)[0]
        elif origin in (typing.Union, types.UnionType):
            branches = [_unwrap(a, None) for a in typing.get_args(tp)]
            records = [b for b in branches if isinstance(b, type) and issubclass(b, BaseModel)]
            tagged = [b for b in records if "type" in b.model_fields
                      and typing.get_args(b.model_fields["type"].annotation) == (item,)]
            if tagged:
                return tagged[0]
            containers = records + [b for b in branches if typing.get_origin(b) is tuple]
            if len(containers) != 1:
                return None
            tp = containers[0]
        else:
            return tp


def _unknown_field_message(loc: tuple) -> str:
    model = _model_at(loc[:-1])
    if model is None or not isinstance(loc[-1], str):
        return "unknown field"
    allowed = list(model.model_fields)
    close = difflib.get_close_matches(loc[-1], allowed, n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"unknown field; {hint}allowed here: {', '.join(allowed)}"


def _short_repr() -> reprlib.Repr:
    r = reprlib.Repr()  # (Python 3.11's Repr takes no keyword arguments)
    r.maxlevel, r.maxtuple, r.maxlist, r.maxdict, r.maxstring, r.maxother = 2, 4, 4, 4, 30, 30
    return r


def _describe(value: object) -> str:
    """A value as a short text: never the whole of it (it may be huge, or an alias bomb)."""
    if value is None:
        return "nothing (null)"
    text = _short_repr().repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _validation_problem(err: dict) -> tuple[str, str]:
    """(field path, problem) for one pydantic error, worded for a person editing the YAML file."""
    loc, kind, msg = tuple(err["loc"]), err["type"], err["msg"]
    ctx = err.get("ctx") or {}
    value = err.get("input")
    msg = msg.removeprefix("Value error, ")
    if kind == "extra_forbidden":
        return _field_path(loc), _unknown_field_message(loc)
    if kind == "missing" and _is_short_tuple(err):
        # a fixed-size tuple (a point) given too few numbers; _merge_short_tuples put the size into ctx
        return _field_path(loc[:-1]), f"needs {ctx.get('expected', loc[-1] + 1)} values, got {len(value)}"
    if kind == "missing":
        return _field_path(loc), "required field is missing"
    if kind == "too_long" and ctx.get("field_type") == "Tuple":
        expected, got = ctx.get("max_length"), ctx.get("actual_length")
        return _field_path(loc), f"has too many values: expected {expected}, got {got}"
    if kind == "too_short" and ctx.get("field_type") == "Tuple":
        expected, got = ctx.get("min_length"), ctx.get("actual_length")
        return _field_path(loc), f"needs at least {expected} items, got {got}"
    if kind == "union_tag_invalid":
        tag, expected = ctx.get("tag"), ctx.get("expected_tags", "")
        what = "criterion" if loc and loc[0] == "criterion" else "device type"
        return _field_path(loc + ("type",)), f"unknown {what} {tag!r}; expected one of {expected}"
    if kind == "union_tag_not_found":
        kinds = " or ".join(repr(k) for k in DEVICE_KINDS)
        return _field_path(loc + ("type",)), f"required field is missing (the device type: {kinds})"
    if kind == "literal_error" and loc and loc[-1] == "capsules-auto":
        return _field_path(loc), f"must be 'auto' or a list of capsules, got {_describe(value)}"
    if kind in ("tuple_type", "list_type"):
        return _field_path(loc), f"should be a list, got {_describe(value)}"
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return _field_path(loc), f"should be a mapping of fields (key: value), got {_describe(value)}"
    if kind == "invalid_key":
        return _field_path(loc[:-1]) or "(top level)", f"field names must be text, got {_describe(loc[-1])}"
    if isinstance(value, (int, float, str, bool)) and kind not in ("value_error", "assertion_error"):
        msg += f" (got {_describe(value)})"
    return _field_path(loc), msg


def _is_short_tuple(err: dict) -> bool:
    loc = tuple(err["loc"])
    return (err["type"] == "missing" and bool(loc) and isinstance(loc[-1], int)
            and isinstance(err.get("input"), (list, tuple)))


def _merge_short_tuples(errors: list[dict]) -> list[dict]:
    """pydantic reports each absent position of a too-short fixed tuple; keep one error holding the size."""
    out: list[dict] = []
    for e in errors:
        if _is_short_tuple(e) and out and _is_short_tuple(out[-1]) and out[-1]["loc"][:-1] == e["loc"][:-1]:
            out[-1]["ctx"]["expected"] = e["loc"][-1] + 1
            continue
        if _is_short_tuple(e):
            e = {**e, "ctx": {"expected": e["loc"][-1] + 1}}
        out.append(e)
    return out


def _follow_on(err: dict) -> bool:
    """pydantic drops invalid items and then reports the list as too short: an echo of the item's error."""
    value, ctx = err.get("input"), err.get("ctx") or {}
    return (err["type"] == "too_short" and isinstance(value, (list, tuple))
            and len(value) >= ctx.get("min_length", 0))


def parse_cell(text: str, source: str, directory: Path | None) -> Cell:
    if len(text) > MAX_INPUT_BYTES:
        raise CellError(source, "", f"is too large ({len(text):,} characters; at most {MAX_INPUT_BYTES:,})")
    try:
        data = safe_load_yaml(text)
    except RecursionError:
        raise CellError(source, "YAML", f"lists and mappings are nested more than {MAX_DEPTH} deep") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "YAML"
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        if isinstance(exc, yaml.constructor.ConstructorError) and "constructor for the tag" in problem:
            tag = problem.split("tag", 1)[1].strip().strip("'").replace("tag:yaml.org,2002:", "!!")
            raise CellError(source, where, f"YAML tag {tag} is not allowed: a cell file holds plain data "
                                           "(mappings, lists, numbers, text)") from None
        kind = "YAML error" if isinstance(exc, yaml.constructor.ConstructorError) else "YAML syntax error"
        raise CellError(source, where, f"{kind}: {problem}") from None
    if data is None:
        raise CellError(source, "", "the file is empty")
    if not isinstance(data, dict):
        what = _TYPE_WORDS.get(type(data).__name__, type(data).__name__)
        raise CellError(source, "(top level)",
                        f"a cell file holds a mapping of fields (name: ..., robot: ...), not a {what}")
    try:
        data = _frozen(data, [MAX_VALUES])
    except _TooBig as exc:
        raise CellError(source, "(top level)", str(exc)) from None
    try:
        spec = CellSpec.model_validate(data, strict=True)
    except ValidationError as exc:
        errors = _merge_short_tuples([e for e in exc.errors() if not _follow_on(e)] or exc.errors())
        field, msg = _validation_problem(errors[0])
        more = f" (and {len(errors) - 1} more problem(s))" if len(errors) > 1 else ""
        raise CellError(source, field, msg + more) from None
    cell = Cell(spec, source, directory, hashlib.sha256(text.encode()).hexdigest())
    check_geometry(cell)
    return replace(cell, files=cell_files(cell, text))


def load_cell(name_or_path: str | Path) -> Cell:
    """A built-in cell by name (see ``BUILTIN_CELLS``) or a cell file by path."""
    ref = str(name_or_path)
    if ref in BUILTIN_CELLS:
        return parse_cell(builtin_text(ref), ref, None)
    path = Path(ref).expanduser()
    try:
        raw = read_input_bytes(path)
    except InputFileError as exc:
        if exc.problem == "no such file":
            raise CellError(ref, "", f"no such file, and not a built-in cell ({', '.join(BUILTIN_CELLS)})") from None
        if exc.problem.startswith("is a directory"):
            raise CellError(ref, "", "is a directory, not a cell file") from None
        raise CellError(ref, "", exc.problem) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise CellError(ref, f"line {line}, column {column}",
                        f"is not UTF-8 text (byte 0x{raw[exc.start]:02x}); save the file as UTF-8") from None
    return parse_cell(text, ref, path.resolve().parent)


def check_geometry(cell: Cell) -> None:
    """Checks that need more than one field: the URDF, the robot's program against its joints and their
    position and velocity limits, the robot's cycle time, the robots' names and the devices' ``stops``, the start
    pose and every named start point."""
    spec = cell.spec
    refuse_files_outside(cell)
    several = "robots" in spec.model_fields_set  # a robots list, even of one: its errors name robots[i]
    cycles = [_check_robot(cell, rs, f"robots[{i}]" if several else "robot") for i, rs in enumerate(spec.robots)]
    _check_robot_names(cell)
    _check_clock_windows(cell, cycles[0])
    _check_standing_point(cell, "human.start.xy", spec.human.start.xy)
    for i, s in enumerate(spec.human.starts):
        _check_standing_point(cell, f"human.starts[{i}].xy", s.xy)


def _check_robot(cell: Cell, rs, where: str) -> float:
    """One robot's URDF, program and capsules; errors name ``where`` (robot, or robots[i]) as the field. Returns
    the program's cycle time [s]."""
    src = cell.source
    urdf = resolve_urdf(rs.urdf, cell.files_dir)
    if not urdf.is_file():
        raise CellError(src, f"{where}.urdf", unknown_urdf_message(rs.urdf, urdf))
    try:
        robot = load_robot(urdf)
    except CellstressError as exc:
        raise CellError(src, f"{where}.urdf", str(exc)) from None
    except Exception as exc:  # pinocchio raises plain RuntimeError/ValueError for unreadable URDFs
        raise CellError(src, f"{where}.urdf", f"pinocchio cannot read it: {str(exc).splitlines()[0]}") from None
    _check_shapes(cell, rs, where, urdf, robot)
    try:
        traj = robot_program(src, robot, rs, cell.files_dir)
    except CellError as exc:  # the program's messages name the field from "robot."
        if where == "robot" or not exc.field.startswith("robot."):
            raise
        raise CellError(src, where + exc.field.removeprefix("robot"), exc.problem) from None
    if robot_stop(src, where, rs, robot, traj, cell.files_dir).hold:
        check_hold(cell, where)
    caps = rs.capsules if rs.capsules != "auto" else ()
    for i, c in enumerate(tuple(caps) + rs.extra_capsules):
        if c.link not in robot.link_joint:
            field = (f"{where}.capsules[{i}].link" if i < len(caps)
                     else f"{where}.extra_capsules[{i - len(caps)}].link")
            raise CellError(src, field, f"the robot has no link {c.link!r}; its links are "
                                        f"{', '.join(sorted(robot.link_joint))}")
    return float(traj.cycle)


def _check_clock_windows(cell: Cell, cycle: float) -> None:
    """A muting window runs on the cell's clock, (phase + t) modulo the first robot's cycle: it must start
    within the cycle and last no longer than one (a window of 500 s on a 2.4 s cycle describes nothing real)."""
    for i, d in enumerate(cell.spec.devices):
        field = f"devices[{i}]" + (".muting" if "muting" in type(d).model_fields else "")
        for c in _channels(d):
            if c.muted is None:
                continue
            start, until = (float(x) for x in c.muted)
            if start >= cycle:
                raise CellError(cell.source, field, f"the muting starts at {start:g} s, after the robot's cycle "
                                f"of {cycle:.3f} s has ended (times are of the cell's clock: 0 up to the cycle time)")
            if until - start > cycle + 1e-9:
                raise CellError(cell.source, field, f"the muting lasts {until - start:g} s ({start:g} to {until:g} "
                                f"s of the cell's clock), longer than the robot's cycle of {cycle:.3f} s")


def _check_shapes(cell: Cell, rs, where: str, urdf: Path, robot) -> None:
    """Every shape of the robot readable (meshes within bounds), and no moving part invisible: a moving link
    with a mass but no shape is refused unless the cell declares a capsule on it; fitted capsules need a shape
    somewhere."""
    declared = {c.link for c in (rs.capsules if rs.capsules != "auto" else ()) + rs.extra_capsules}
    try:
        geometry = robot_geometry(urdf)
        unseen = [g for g in geometry.unseen_links() if g.link not in declared]
        if unseen:
            raise CellstressError(unseen_message(geometry, robot, unseen[0]))
        if rs.capsules == "auto":
            fitted_capsules(robot)
    except CellstressError as exc:
        raise CellError(cell.source, f"{where}.urdf", str(exc)) from None


def _check_robot_names(cell: Cell) -> None:
    """Robot names unique; each device's ``stops`` names robots of the cell, each once. Several robots do not
    (yet) combine with a device that restarts the robots automatically or slows them (a warning field): the
    kernel keeps the restart and speed-reduction state for the first robot only."""
    spec, src = cell.spec, cell.source
    names = [r.name for r in spec.robots]
    for i, n in enumerate(names):
        if n in names[:i]:
            hint = " (give each robot a name)" if n == "robot" else ""
            raise CellError(src, f"robots[{i}].name", f"robot names must be unique: robots[{names.index(n)}] is "
                                                     f"also named {n!r}{hint}")
    for i, d in enumerate(spec.devices):
        stops = stops_of(d) or ()
        for j, n in enumerate(stops):
            if n not in names:
                raise CellError(src, f"devices[{i}].stops[{j}]", f"no robot is named {n!r}; the robots are "
                                                                 f"{', '.join(names)}")
            if n in stops[:j]:
                raise CellError(src, f"devices[{i}].stops[{j}]", f"names robot {n!r} twice")
        if len(names) > 1:
            for c in _channels(d):
                if c.separation is not None or c.speed != 0.0 or c.clear_time != float("inf"):
                    what = ("speed and separation monitoring" if c.separation is not None else
                            "a warning field" if c.speed != 0.0 else "an automatic restart")
                    raise CellError(src, f"devices[{i}]", f"has {what}; a cell with several robots takes devices "
                                                          "whose stops are manual only (not implemented yet)")


def _channels(d) -> tuple[Channel, ...]:
    return d.channels() if isinstance(d, Channels) else ()


def _check_standing_point(cell: Cell, where: str, xy) -> None:
    """A start point must be on the floor (the body's footprint inside it), off the table and clear of fences."""
    spec, src, r = cell.spec, cell.source, BODY_RADIUS
    x, y = xy
    fl = spec.floor
    if not (fl.xmin + r <= x <= fl.xmax - r and fl.ymin + r <= y <= fl.ymax - r):
        raise CellError(src, where, f"({x}, {y}) is not on the floor x {fl.xmin}..{fl.xmax}, "
                                    f"y {fl.ymin}..{fl.ymax} (keeping the body's {r} m radius inside)")
    n_table = 0 if spec.table is None else len(spec.table.polygons)
    for i, ob in enumerate(spec.solid_obstacles()):
        if polygon_distance(x, y, ob.footprint()) < r:
            field = f"table.polygons[{i}]" if i < n_table else f"obstacles[{i - n_table}]"
            raise CellError(src, where, f"({x}, {y}) is inside or touching {ob.name!r} ({field}), keeping the "
                                        f"body's {r} m radius clear")
    for i, fence in enumerate(spec.fences):
        for a, b in zip(fence.points, fence.points[1:], strict=False):
            if fence.bottom < WALK_BLOCK_HEIGHT and point_segment_distance(x, y, a, b) < r:
                raise CellError(src, where, f"({x}, {y}) is inside or touching a fence (fences[{i}])")


def with_criterion(cell: Cell, name: str | None) -> Cell:
    """``cell`` judged by the criterion ``name`` (its tolerances kept, its other options at their defaults); the
    cell itself if ``name`` is None or already its criterion. CellstressError for an unknown name."""
    if name is None or name == cell.spec.criterion.type:
        return cell
    if name not in CRITERIA:
        raise CellstressError(f"unknown criterion {name!r} (choose from {', '.join(CRITERIA)})")
    old = cell.spec.criterion
    crit = registry.load("criteria", name)(distance_tolerance=old.distance_tolerance,
                                           speed_tolerance=old.speed_tolerance)
    return replace(cell, spec=cell.spec.model_copy(update={"criterion": crit}))
