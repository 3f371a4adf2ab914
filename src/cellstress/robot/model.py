"""A serial robot from a URDF, loaded with pinocchio and flattened into arrays for the compiled simulator.

Pinocchio gives the kinematic tree (joint placements, axes, limits), from the URDF text ``robot.urdf_file``
has checked first; the links' shapes are ``robot.geometry``'s. We keep the tree as plain arrays so that the
numba kernel can do forward kinematics without Python objects, and the tests check that kernel against
pinocchio itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.urdf_file import (
    captured_fd2,
    example_robot_data_share,
    parser_reason,
    read_urdf,
    resolve_mesh,
)

# Short names for the fixed-base serial arms shipped by example-robot-data, resolved to files inside that
# package.
BUILTIN_URDFS = {
    "ur3": "robots/ur_description/urdf/ur3_robot.urdf",
    "ur5": "robots/ur_description/urdf/ur5_robot.urdf",
    "ur10": "robots/ur_description/urdf/ur10_robot.urdf",
    "ur3-gripper": "robots/ur_description/urdf/ur3_gripper.urdf",
    "ur5-gripper": "robots/ur_description/urdf/ur5_gripper.urdf",
    "panda": "robots/panda_description/urdf/panda.urdf",
    "kinova": "robots/kinova_description/robots/kinova.urdf",
    "xarm7": "robots/xarm_description/urdf/xarm7.urdf",
    "z1": "robots/z1_description/urdf/z1.urdf",
    "so100": "robots/so_arm_description/urdf/so100.urdf",
    "so101": "robots/so_arm_description/urdf/so101.urdf",
}
BUILTIN_ROBOTS: tuple[str, ...] = tuple(BUILTIN_URDFS)


def looks_like_path(ref: str) -> bool:
    """Whether ``ref`` was meant as a file (a folder separator or a .urdf ending) rather than a short name."""
    return "/" in ref or "\\" in ref or ref.lower().endswith((".urdf", ".xml"))


def resolve_urdf(ref: str, base_dir: Path | None) -> Path:
    """A built-in short name (``ur10``) or a path, relative paths taken from the cell file's folder."""
    if ref in BUILTIN_URDFS:
        return example_robot_data_share() / BUILTIN_URDFS[ref]
    path = Path(ref).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    return path


def unknown_urdf_message(ref: str, path: Path) -> str:
    """The one-line error for a robot that is neither a short name nor an existing file."""
    names = ", ".join(BUILTIN_ROBOTS)
    if looks_like_path(ref):
        return f"URDF file not found: {path} (or use a built-in robot: {names})"
    return f"{ref!r} is neither a built-in robot ({names}) nor a file"


_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
REVOLUTE, PRISMATIC = "revolute", "prismatic"


@dataclass(frozen=True)
class RobotModel:
    """A fixed-base chain of revolute and prismatic joints.

    ``placements[j]`` is joint j's frame in its parent joint's frame at q = 0 (4x4), ``axes[j]`` its rotation
    (revolute) or sliding (prismatic) axis in its own frame, ``parents[j]`` the parent joint index (-1 for the
    base), ``kinds[j]`` REVOLUTE or PRISMATIC. Joint values are radians or metres. A URDF ``<mimic>`` joint m
    follows its master: q[m] = mimic_multiplier[m] * q[mimic_master[m]] + mimic_offset[m] (master -1: none).
    A continuous joint is a revolute one without limits (``lower`` -inf, ``upper`` inf); pinocchio keeps its
    angle as (cos, sin), so pinocchio takes ``pinocchio_q(q)``.
    """

    urdf: Path
    joint_names: tuple[str, ...]
    kinds: tuple[str, ...]
    parents: np.ndarray
    placements: np.ndarray
    axes: np.ndarray
    velocity_limits: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    mimic_master: np.ndarray
    mimic_multiplier: np.ndarray
    mimic_offset: np.ndarray
    continuous: np.ndarray  # (nj,) bool
    link_joint: dict[str, int]
    link_in_joint: dict[str, np.ndarray]

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    def link_frame(self, link: str) -> tuple[int, np.ndarray]:
        """(joint index the link is fixed to, 4x4 placement of the link frame in that joint's frame)."""
        return self.link_joint[link], self.link_in_joint[link]

    def pinocchio_q(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration vector for joint values q: (cos, sin) for a continuous joint."""
        if not self.continuous.any():
            return q
        parts = [np.array([np.cos(x), np.sin(x)]) if c else np.array([x]) for x, c in zip(q, self.continuous,
                                                                                          strict=True)]
        return np.concatenate(parts)

    def sampling_range(self) -> tuple[np.ndarray, np.ndarray]:
        """Finite joint ranges to choose values from: the limits, and one turn for a continuous joint."""
        return np.where(self.continuous, -np.pi, self.lower), np.where(self.continuous, np.pi, self.upper)

    def unit(self, j: int) -> str:
        """The unit a cell file gives joint j's values in."""
        return "deg" if self.kinds[j] == REVOLUTE else "m"


def base_matrix(xyz, yaw_deg) -> np.ndarray:
    """The 4x4 pose of a robot base at ``xyz``, turned by ``yaw_deg`` about the vertical."""
    c, s = np.cos(np.deg2rad(yaw_deg)), np.sin(np.deg2rad(yaw_deg))
    m = np.eye(4)
    m[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    m[:3, 3] = xyz
    return m


def _se3(placement) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = np.asarray(placement.rotation)
    m[:3, 3] = np.asarray(placement.translation)
    return m


def load_pinocchio(urdf: Path):
    """Pinocchio's model of the URDF, from the text ``read_urdf`` checked (imported lazily: pinocchio is heavy).
    urdfdom's own complaints on file descriptor 2 are captured; if it still fails, its first one is the reason
    of our one error."""
    import pinocchio as pin

    doc = read_urdf(urdf)
    with captured_fd2() as said:
        try:
            return pin.buildModelFromXML(doc.text)
        except Exception as exc:  # noqa: BLE001 - pinocchio raises plain RuntimeError/ValueError
            reason = exc
    raise CellstressError(f"{urdf}: pinocchio cannot read it: {parser_reason(said, reason)}")


def urdf_mimics(urdf: Path) -> dict[str, tuple[str, float, float]]:
    """{mimic joint: (master joint, multiplier, offset)} from the URDF's XML: pinocchio loads a mimic joint as
    an independent one."""
    return dict(read_urdf(urdf).mimics)


def mesh_paths(urdf: Path) -> tuple[Path, ...]:
    """Every mesh file the URDF names (collision and visual, each once, in order), resolved by ``resolve_mesh``;
    nothing is opened."""
    out: dict[Path, None] = {}
    for spec in read_urdf(urdf).mesh_references():
        out.setdefault(resolve_mesh(spec.filename, urdf), None)
    return tuple(out)


def _joint_kind_axis(urdf: Path, name: str, joint) -> tuple[str, tuple[float, float, float]]:
    short = joint.shortname().replace("JointModel", "")
    if short in ("RX", "RY", "RZ", "PX", "PY", "PZ", "RUBX", "RUBY", "RUBZ"):
        return (REVOLUTE if short[0] == "R" else PRISMATIC), _AXES[short[-1]]
    if short in ("RevoluteUnaligned", "PrismaticUnaligned", "RevoluteUnboundedUnaligned"):
        kind = REVOLUTE if short.startswith("R") else PRISMATIC
        return kind, tuple(float(x) for x in np.asarray(joint.extract().axis, dtype=float))
    raise CellstressError(f"{urdf}: joint {name!r} is of type {short}; only revolute, prismatic and fixed "
                          "joints (and <mimic> joints of those) are supported")


def _mimic_arrays(urdf: Path, names: list[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    index = {n: j for j, n in enumerate(names)}
    master = np.full(len(names), -1, dtype=np.int64)
    mult, off = np.ones(len(names)), np.zeros(len(names))
    for name, (of, m, o) in urdf_mimics(urdf).items():
        if name not in index:
            continue  # a mimic joint pinocchio did not load (a fixed one)
        if of not in index:
            raise CellstressError(f"{urdf}: joint {name!r} mimics {of!r}, which is not a joint of the chain")
        master[index[name]], mult[index[name]], off[index[name]] = index[of], m, o
    for j in range(len(names)):
        if master[j] >= 0 and master[master[j]] >= 0:
            raise CellstressError(f"{urdf}: joint {names[j]!r} mimics {names[master[j]]!r}, itself a mimic "
                                  "joint; cellstress takes one level of <mimic>")
    return master, mult, off


@lru_cache(maxsize=8)
def load_robot(urdf: Path) -> RobotModel:
    import pinocchio as pin

    model = load_pinocchio(urdf)
    names, kinds, parents, placements, axes, vmax, lower, upper, continuous = [], [], [], [], [], [], [], [], []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        kind, axis = _joint_kind_axis(urdf, model.names[j], joint)
        names.append(model.names[j])
        kinds.append(kind)
        parents.append(model.parents[j] - 1)
        placements.append(_se3(model.jointPlacements[j]))
        axes.append(axis)
        vmax.append(model.velocityLimit[joint.idx_v])
        # a continuous joint (nq 2: cos, sin) has no angle limits; pinocchio's bounds are those of cos and sin
        continuous.append(joint.nq == 2)
        lower.append(-np.inf if joint.nq == 2 else model.lowerPositionLimit[joint.idx_q])
        upper.append(np.inf if joint.nq == 2 else model.upperPositionLimit[joint.idx_q])
    for name, v, lo, hi, cont in zip(names, vmax, lower, upper, continuous, strict=True):
        if not (np.isfinite(v) and v > 0.0):
            raise CellstressError(f"{urdf}: joint {name!r} has no velocity limit (<limit velocity=...> > 0)")
        if not cont and not (np.isfinite(lo) and np.isfinite(hi)):
            raise CellstressError(f"{urdf}: joint {name!r} has no finite position limits (<limit lower=... "
                                  "upper=...>)")
        if not cont and lo > hi:
            raise CellstressError(f"{urdf}: joint {name!r}: its lower limit {lo:g} is above its upper limit {hi:g}")
    master, mult, off = _mimic_arrays(urdf, names)
    link_joint: dict[str, int] = {}
    link_in_joint: dict[str, np.ndarray] = {}
    for frame in model.frames:
        if frame.type == pin.FrameType.BODY:
            link_joint[frame.name] = int(frame.parentJoint) - 1
            link_in_joint[frame.name] = _se3(frame.placement)
    return RobotModel(
        urdf=urdf,
        joint_names=tuple(names),
        kinds=tuple(kinds),
        parents=np.asarray(parents, dtype=np.int64),
        placements=np.asarray(placements),
        axes=np.asarray(axes, dtype=float),
        velocity_limits=np.asarray(vmax, dtype=float),
        lower=np.asarray(lower, dtype=float),
        upper=np.asarray(upper, dtype=float),
        mimic_master=master,
        mimic_multiplier=mult,
        mimic_offset=off,
        continuous=np.asarray(continuous, dtype=bool),
        link_joint=link_joint,
        link_in_joint=link_in_joint,
    )
