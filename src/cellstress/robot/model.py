"""A serial robot from a URDF, loaded with pinocchio and flattened into arrays for the compiled simulator.

Pinocchio gives the kinematic tree (joint placements, axes, limits) and the collision meshes. We keep the
chain as plain arrays so that the numba kernel can do forward kinematics without Python objects, and the tests
check that kernel against pinocchio itself.
"""

from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from cellstress.core.errors import CellstressError

# Short names for robots shipped by example-robot-data, resolved to files inside that package.
BUILTIN_URDFS = {
    "ur10": "robots/ur_description/urdf/ur10_robot.urdf",
    "ur5": "robots/ur_description/urdf/ur5_robot.urdf",
    "ur3": "robots/ur_description/urdf/ur3_robot.urdf",
}


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


def resolve_urdf(ref: str, base_dir: Path | None) -> Path:
    """A built-in short name (``ur10``) or a path, relative paths taken from the cell file's folder."""
    if ref in BUILTIN_URDFS:
        return example_robot_data_share() / BUILTIN_URDFS[ref]
    path = Path(ref).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    return path


_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class RobotModel:
    """A fixed-base chain of revolute joints.

    ``placements[j]`` is joint j's frame in its parent joint's frame at q = 0 (4x4), ``axes[j]`` its rotation
    axis in its own frame, ``parents[j]`` the parent joint index (-1 for the base).
    """

    urdf: Path
    joint_names: tuple[str, ...]
    parents: np.ndarray
    placements: np.ndarray
    axes: np.ndarray
    velocity_limits: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    link_joint: dict[str, int]
    link_in_joint: dict[str, np.ndarray]

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    def link_frame(self, link: str) -> tuple[int, np.ndarray]:
        """(joint index the link is fixed to, 4x4 placement of the link frame in that joint's frame)."""
        return self.link_joint[link], self.link_in_joint[link]


def _se3(placement) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = np.asarray(placement.rotation)
    m[:3, 3] = np.asarray(placement.translation)
    return m


def load_pinocchio(urdf: Path):
    """Pinocchio's model of the URDF (imported lazily: pinocchio is heavy)."""
    import pinocchio as pin

    return pin.buildModelFromUrdf(str(urdf))


@lru_cache(maxsize=8)
def load_robot(urdf: Path) -> RobotModel:
    model = load_pinocchio(urdf)
    names, parents, placements, axes = [], [], [], []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        short = joint.shortname().replace("JointModel", "")
        if short in _AXES:
            axis = _AXES[short]
        elif short == "RevoluteUnaligned":
            axis = tuple(np.asarray(joint.extract().axis, dtype=float))
        else:
            raise CellstressError(f"{urdf}: joint {model.names[j]!r} is of type {short}; "
                                  "only revolute joints are supported")
        names.append(model.names[j])
        parents.append(model.parents[j] - 1)
        placements.append(_se3(model.jointPlacements[j]))
        axes.append(axis)
    link_joint: dict[str, int] = {}
    link_in_joint: dict[str, np.ndarray] = {}
    import pinocchio as pin

    for frame in model.frames:
        if frame.type == pin.FrameType.BODY:
            link_joint[frame.name] = int(frame.parentJoint) - 1
            link_in_joint[frame.name] = _se3(frame.placement)
    return RobotModel(
        urdf=urdf,
        joint_names=tuple(names),
        parents=np.asarray(parents, dtype=np.int64),
        placements=np.asarray(placements),
        axes=np.asarray(axes, dtype=float),
        velocity_limits=np.asarray(model.velocityLimit, dtype=float),
        lower=np.asarray(model.lowerPositionLimit, dtype=float),
        upper=np.asarray(model.upperPositionLimit, dtype=float),
        link_joint=link_joint,
        link_in_joint=link_in_joint,
    )


def collision_vertices(urdf: Path) -> dict[str, np.ndarray]:
    """Collision-mesh vertices of each link, in that link's joint frame (via pinocchio's geometry loader)."""
    import pinocchio as pin

    model = load_pinocchio(urdf)
    package_dirs = [str(urdf.parent)]
    try:
        share = example_robot_data_share()
        package_dirs += [str(share), str(share.parent)]  # package://example-robot-data/... resolves from share/
    except CellstressError:
        pass
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=package_dirs)
    out: dict[str, list[np.ndarray]] = {}
    for obj in geom.geometryObjects:
        if not hasattr(obj.geometry, "vertices"):
            continue
        verts = np.asarray(obj.geometry.vertices(), dtype=float)
        if verts.size == 0:
            continue
        link = model.frames[obj.parentFrame].name
        placement = _se3(obj.placement)  # in the parent joint frame
        pts = verts @ placement[:3, :3].T + placement[:3, 3]
        out.setdefault(link, []).append(pts)
    return {k: np.concatenate(v) for k, v in out.items()}
