"""A URDF file read and checked by us before any third-party parser sees it.

The URDF parser inside pinocchio (urdfdom) writes ``Error: ...`` lines to file descriptor 2 and then fails with
a message that does not say why; for some files it crashes the process (10,000 joints). So the file is read
here once, bounded (size, element counts), and checked for what urdfdom would trip over or what would make the
robot meaningless: well-formed UTF-8 XML without entity declarations, unique link and joint names, one tree
(one root, no link with two parents, no cycle, nothing disconnected), finite numbers everywhere, joint axes
that are not zero, origins and shapes within ``MAX_EXTENT``. Every problem is a CellstressError naming the
file and the element, in our words. Pinocchio then parses the checked text, not the file again, with its
file descriptor 2 captured (``captured_fd2``).

``resolve_mesh`` is the one place a mesh reference (``package://``, ``file://``, absolute or relative) becomes a
path; ``UrdfDoc.mesh_references`` lists every mesh a URDF names.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import math
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from xml.etree import ElementTree

from cellstress.core.errors import CellstressError
from cellstress.core.io import InputFileError, read_input_bytes

MAX_URDF_BYTES = 20 * 1024 * 1024  # the largest URDF of example-robot-data is about 0.2 MB
MAX_URDF_LINKS = 500  # example-robot-data's largest robot (TIAGo dual) has 130 links
MAX_URDF_JOINTS = 500  # ... and 129 joints; urdfdom crashes the process at about 10,000
MAX_URDF_SHAPES = 2000  # <collision> and <visual> elements together (TIAGo dual: about 240)
MAX_EXTENT = 100.0  # m: no joint origin, shape size or mesh vertex of a robot lies farther out
MAX_MESH_SCALE = 1000.0
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
SHAPE_KINDS = ("box", "cylinder", "sphere", "capsule", "mesh")


@lru_cache(maxsize=1)
def example_robot_data_share() -> Path:
    """The folder that holds example-robot-data's ``robots/`` tree (installed by pip as a cmeel package)."""
    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError as exc:
        raise CellstressError("the package example-robot-data is not installed") from exc
    for f in files:
        parts = Path(str(f)).parts
        if "robots" in parts and str(f).endswith(".urdf"):
            located = Path(str(f.locate()))
            root = located
            while root.name != "robots":
                root = root.parent
            return root.parent
    raise CellstressError("example-robot-data is installed but holds no robots/ folder")


def package_dirs(urdf: Path) -> tuple[Path, ...]:
    """Where ``package://NAME/...`` is looked up, in order: the URDF's folder, example-robot-data's share folder
    and its parent (so ``package://example-robot-data/robots/...`` resolves)."""
    dirs = [urdf.parent]
    try:
        share = example_robot_data_share()
        dirs += [share, share.parent]
    except CellstressError:
        pass
    return tuple(dirs)


def resolve_mesh(filename: str, urdf: Path) -> Path:
    """The file a URDF's ``<mesh filename=...>`` names: ``package://NAME/REST`` is ``DIR/NAME/REST`` in the
    first of ``package_dirs`` where that exists (else in the first), ``file://PATH`` and an absolute path are
    themselves, a relative path is taken from the URDF's folder. Nothing is opened here."""
    if filename.startswith("package://"):
        rest = filename[len("package://"):]
        candidates = [d / rest for d in package_dirs(urdf)]
        return next((c for c in candidates if c.exists()), candidates[0])
    if filename.startswith("file://"):
        return Path(filename[len("file://"):])
    path = Path(filename)
    return path if path.is_absolute() else urdf.parent / path


@dataclass(frozen=True)
class ShapeSpec:
    """One ``<collision>`` or ``<visual>`` element: its shape in the link frame.

    ``size``: box (x, y, z) full edge lengths; cylinder and capsule (radius, length); sphere (radius,); mesh
    the scale (x, y, z). ``xyz`` and ``rpy`` the element's ``<origin>``."""

    link: str
    source: str  # "collision" or "visual"
    index: int  # its position among the link's elements of that source
    kind: str
    size: tuple[float, ...]
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    filename: str = ""


@dataclass(frozen=True)
class UrdfDoc:
    """A checked URDF: its text, and per link its mass (None: no ``<inertial>``) and shapes."""

    path: Path
    text: str
    links: tuple[str, ...]
    masses: dict[str, float | None]
    collision: dict[str, tuple[ShapeSpec, ...]]
    visual: dict[str, tuple[ShapeSpec, ...]]
    mimics: dict[str, tuple[str, float, float]]  # mimic joint: (master, multiplier, offset)

    def mesh_references(self) -> tuple[ShapeSpec, ...]:
        """Every ``<mesh>`` element, collision ones first."""
        return tuple(s for group in (self.collision, self.visual) for shapes in group.values() for s in shapes
                     if s.kind == "mesh")


def quoted(name: str, limit: int = 60) -> str:
    """A name from the file as it appears in a message: quoted, escaped, and cut short."""
    return repr(name if len(name) <= limit else name[:limit] + "...")


def _fail(urdf: Path, where: str, problem: str) -> CellstressError:
    return CellstressError(f"{urdf}: {where}: {problem}" if where else f"{urdf}: {problem}")


def _numbers(urdf: Path, where: str, text: str | None, n: int, default: tuple[float, ...] | None = None,
             ) -> tuple[float, ...]:
    """``n`` finite numbers from a space-separated attribute (``default`` when it is absent)."""
    if text is None:
        if default is None:
            raise _fail(urdf, where, "is missing")
        return default
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise _fail(urdf, where, f"is not {n} number{'s' if n > 1 else ''}") from None
    if len(values) != n:
        raise _fail(urdf, where, f"has {len(values)} values, not {n}")
    if not all(math.isfinite(v) for v in values):
        raise _fail(urdf, where, "is not finite (NaN or infinity)")
    return values


def _origin(urdf: Path, where: str, el) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    origin = el.find("origin")
    if origin is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    xyz = _numbers(urdf, f"{where} <origin xyz>", origin.get("xyz"), 3, (0.0, 0.0, 0.0))
    rpy = _numbers(urdf, f"{where} <origin rpy>", origin.get("rpy"), 3, (0.0, 0.0, 0.0))
    if max(abs(v) for v in xyz) > MAX_EXTENT:
        raise _fail(urdf, f"{where} <origin xyz>", f"lies more than {MAX_EXTENT:g} m away")
    return xyz, rpy  # type: ignore[return-value]


def _shape(urdf: Path, link: str, source: str, index: int, el) -> ShapeSpec:
    where = f"link {quoted(link)} <{source}> {index}"
    geometry = el.find("geometry")
    shapes = [] if geometry is None else [g for g in geometry if g.tag in SHAPE_KINDS]
    if len(shapes) != 1:
        raise _fail(urdf, where, f"needs exactly one <geometry> of {', '.join(SHAPE_KINDS)}")
    g = shapes[0]
    xyz, rpy = _origin(urdf, where, el)
    gw = f"{where} <{g.tag}>"
    if g.tag == "box":
        size = _numbers(urdf, f"{gw} size", g.get("size"), 3)
    elif g.tag in ("cylinder", "capsule"):
        size = (_numbers(urdf, f"{gw} radius", g.get("radius"), 1)[0],
                _numbers(urdf, f"{gw} length", g.get("length"), 1)[0])
    elif g.tag == "sphere":
        size = _numbers(urdf, f"{gw} radius", g.get("radius"), 1)
    else:
        filename = g.get("filename") or ""
        if not filename:
            raise _fail(urdf, gw, "has no filename")
        scale = _numbers(urdf, f"{gw} scale", g.get("scale"), 3, (1.0, 1.0, 1.0))
        if not all(0.0 < abs(s) <= MAX_MESH_SCALE for s in scale):
            raise _fail(urdf, f"{gw} scale", f"must be non-zero and at most {MAX_MESH_SCALE:g} in size")
        return ShapeSpec(link, source, index, "mesh", scale, xyz, rpy, filename)
    if not all(0.0 <= v <= MAX_EXTENT for v in size) or (g.tag != "capsule" and not all(v > 0.0 for v in size)):
        raise _fail(urdf, gw, f"sizes must be positive and at most {MAX_EXTENT:g} m (got "
                              f"{' '.join(f'{v:g}' for v in size)})")
    return ShapeSpec(link, source, index, g.tag, size, xyz, rpy)


def _check_link(urdf: Path, link, name: str) -> float | None:
    inertial = link.find("inertial")
    if inertial is None:
        return None
    _origin(urdf, f"link {quoted(name)} <inertial>", inertial)
    mass_el = inertial.find("mass")
    mass = 0.0 if mass_el is None else _numbers(urdf, f"link {quoted(name)} <mass value>", mass_el.get("value"), 1)[0]
    if mass < 0.0:
        raise _fail(urdf, f"link {quoted(name)} <mass value>", f"is negative ({mass:g})")
    inertia = inertial.find("inertia")
    if inertia is not None:
        for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
            _numbers(urdf, f"link {quoted(name)} <inertia {key}>", inertia.get(key), 1, (0.0,))
    return mass


def _check_joint(urdf: Path, joint, name: str, links: set[str]) -> tuple[str, str]:
    kind = joint.get("type", "")
    where = f"joint {quoted(name)}"
    if kind not in JOINT_TYPES:
        raise _fail(urdf, where, f"has type {quoted(kind)}; a URDF joint is one of {', '.join(JOINT_TYPES)}")
    ends = []
    for end in ("parent", "child"):
        el = joint.find(end)
        link = "" if el is None else el.get("link", "")
        if not link:
            raise _fail(urdf, where, f"has no <{end} link=...>")
        if link not in links:
            raise _fail(urdf, where, f"names {end} link {quoted(link)}, which the URDF does not define")
        ends.append(link)
    if ends[0] == ends[1]:
        raise _fail(urdf, where, f"joins link {quoted(ends[0])} to itself")
    _origin(urdf, where, joint)
    axis_el = joint.find("axis")
    if axis_el is not None and kind not in ("fixed", "floating"):
        axis = _numbers(urdf, f"{where} <axis xyz>", axis_el.get("xyz"), 3, (1.0, 0.0, 0.0))
        if math.sqrt(sum(a * a for a in axis)) < 1e-9:
            raise _fail(urdf, f"{where} <axis xyz>", "is zero: a joint needs a direction to turn about or slide "
                                                     "along")
    limit = joint.find("limit")
    if kind in ("revolute", "prismatic") and limit is None:
        raise _fail(urdf, where, f"is {kind} but has no <limit>")
    if limit is not None:
        for key in ("lower", "upper", "velocity", "effort"):
            _numbers(urdf, f"{where} <limit {key}>", limit.get(key), 1, (0.0,))
    for tag, keys in (("dynamics", ("damping", "friction")), ("safety_controller", (
            "soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"))):
        el = joint.find(tag)
        for key in keys if el is not None else ():
            _numbers(urdf, f"{where} <{tag} {key}>", el.get(key), 1, (0.0,))
    return ends[0], ends[1]


def _mimic(urdf: Path, joint, name: str, joints: set[str]) -> tuple[str, float, float] | None:
    mimic = joint.find("mimic")
    if mimic is None:
        return None
    where = f"joint {quoted(name)} <mimic>"
    master = mimic.get("joint", "")
    if master not in joints:
        raise _fail(urdf, where, f"names joint {quoted(master)}, which the URDF does not define")
    try:
        mult = float(mimic.get("multiplier", "1"))
        off = float(mimic.get("offset", "0"))
    except ValueError:
        raise _fail(urdf, where, "its multiplier or offset is not a number") from None
    if not (math.isfinite(mult) and math.isfinite(off)):
        raise _fail(urdf, where, "its multiplier or offset is not finite")
    return master, mult, off


def _check_tree(urdf: Path, names: list[str], edges: list[tuple[str, str, str]]) -> None:
    """One root, each other link the child of exactly one joint, every link reachable from the root."""
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {}
    for joint, parent, child in edges:
        if child in parent_of:
            raise _fail(urdf, f"link {quoted(child)}", f"is the child of two joints ({quoted(parent_of[child])} and "
                                                       f"{quoted(joint)}); a URDF is a tree")
        parent_of[child] = joint
        children.setdefault(parent, []).append(child)
    roots = [n for n in names if n not in parent_of]
    if not roots:
        raise _fail(urdf, "", "its joints form a cycle: every link has a parent, so there is no root link")
    if len(roots) > 1:
        raise _fail(urdf, "", f"is not connected: {len(roots)} links have no parent joint "
                              f"({', '.join(quoted(r) for r in roots[:4])}{', ...' if len(roots) > 4 else ''}); "
                              "a URDF is one tree")
    seen, todo = {roots[0]}, [roots[0]]
    while todo:
        for c in children.get(todo.pop(), ()):
            if c not in seen:
                seen.add(c)
                todo.append(c)
    lost = [n for n in names if n not in seen]
    if lost:
        raise _fail(urdf, f"link {quoted(lost[0])}", "lies on a cycle of joints, not on the tree from the root link "
                                               f"{quoted(roots[0])}")


def _decode(urdf: Path, data: bytes) -> str:
    if not data.strip():
        raise _fail(urdf, "", "is empty")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise _fail(urdf, "", "is UTF-16 text; save the URDF as UTF-8")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(urdf, "", f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})") from None


def parse_urdf(urdf: Path, data: bytes) -> UrdfDoc:
    """Check a URDF's bytes (see the module docstring); CellstressError for the first problem."""
    text = _decode(urdf, data)
    if "<!ENTITY" in text:
        raise _fail(urdf, "", "the URDF declares XML entities; cellstress does not expand them")
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise _fail(urdf, "", f"not well-formed XML ({exc})") from None
    if root.tag != "robot":
        raise _fail(urdf, "", f"its top element is <{root.tag[:40]}>, not <robot>")
    link_els, joint_els = root.findall("link"), root.findall("joint")
    if not link_els:
        raise _fail(urdf, "", "defines no <link>")
    if len(link_els) > MAX_URDF_LINKS or len(joint_els) > MAX_URDF_JOINTS:
        raise _fail(urdf, "", f"has {len(link_els):,} links and {len(joint_els):,} joints; cellstress reads at most "
                              f"{MAX_URDF_LINKS} of each")
    n_shapes = sum(len(link.findall("collision")) + len(link.findall("visual")) for link in link_els)
    if n_shapes > MAX_URDF_SHAPES:
        raise _fail(urdf, "", f"has {n_shapes:,} <collision> and <visual> elements; cellstress reads at most "
                              f"{MAX_URDF_SHAPES}")
    names: list[str] = []
    masses: dict[str, float | None] = {}
    collision: dict[str, tuple[ShapeSpec, ...]] = {}
    visual: dict[str, tuple[ShapeSpec, ...]] = {}
    for link in link_els:
        name = link.get("name", "")
        if not name:
            raise _fail(urdf, "", "a <link> has no name")
        if name in masses:
            raise _fail(urdf, f"link {quoted(name)}", "is defined twice")
        names.append(name)
        masses[name] = _check_link(urdf, link, name)
        collision[name] = tuple(_shape(urdf, name, "collision", i, el)
                                for i, el in enumerate(link.findall("collision")))
        visual[name] = tuple(_shape(urdf, name, "visual", i, el) for i, el in enumerate(link.findall("visual")))
    joint_names = [j.get("name", "") for j in joint_els]
    edges = []
    for joint, name in zip(joint_els, joint_names, strict=True):
        if not name:
            raise _fail(urdf, "", "a <joint> has no name")
        if joint_names.count(name) > 1:
            raise _fail(urdf, f"joint {quoted(name)}", "is defined twice")
        edges.append((name, *_check_joint(urdf, joint, name, set(masses))))
    _check_tree(urdf, names, edges)
    mimics = {}
    for joint, name in zip(joint_els, joint_names, strict=True):
        m = _mimic(urdf, joint, name, set(joint_names))
        if m is not None:
            mimics[name] = m
    return UrdfDoc(urdf, text, tuple(names), masses, collision, visual, mimics)


@lru_cache(maxsize=8)
def read_urdf(urdf: Path) -> UrdfDoc:
    """The checked URDF at ``urdf`` (a regular file of at most MAX_URDF_BYTES)."""
    try:
        data = read_input_bytes(urdf, MAX_URDF_BYTES)
    except InputFileError as exc:
        raise _fail(urdf, "", exc.problem) from None
    return parse_urdf(urdf, data)


@contextlib.contextmanager
def captured_fd2(max_bytes: int = 65536) -> Iterator[list[str]]:
    """Everything written to file descriptor 2 inside the block (by a C++ library: urdfdom, assimp) goes to a
    temporary file instead of the user's terminal; its first lines are in the yielded list afterwards."""
    lines: list[str] = []
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with tempfile.TemporaryFile() as tmp:
            os.dup2(tmp.fileno(), 2)
            try:
                yield lines
            finally:
                os.dup2(saved, 2)
                tmp.seek(0)
                lines.extend(tmp.read(max_bytes).decode("utf-8", "replace").splitlines())
    finally:
        os.close(saved)


def parser_reason(lines: list[str], exc: BaseException) -> str:
    """A short, printable reason from a third-party parser's captured lines (their first ``Error:`` line) or its
    exception: control characters dropped, at most 200 characters."""
    said = [ln.strip() for ln in lines if ln.strip()]
    first = next((ln for ln in said if ln.lower().startswith("error")), said[0] if said else str(exc))
    first = first.removeprefix("Error:").strip() or type(exc).__name__
    clean = "".join(ch if ch.isprintable() else " " for ch in first)
    return clean[:200]
