"""The files a URDF pulls in: its collision meshes, found as the robot loader finds them.

Only the paths are worked out here, so that a cell can list (and hash) every file it reads
(``cell.files``); the meshes themselves are read by the robot loader (``robot.model.collision_vertices``). The
search follows pinocchio's ``retrieveResourcePath``: ``package://P/REST`` (and ``model://``) is ``DIR/P/REST``
in the first of the loader's package folders where that exists, ``file://PATH`` is ``PATH``, a relative path is
looked up in those folders the same way, an absolute path is itself. The folders are the URDF's own, then
example-robot-data's share folder and its parent, then those of ``ROS_PACKAGE_PATH`` and
``AMENT_PREFIX_PATH`` (pinocchio appends them).
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.etree import ElementTree

from cellstress.core.errors import CellstressError
from cellstress.robot.model import MAX_URDF_BYTES, example_robot_data_share


def _ros_paths() -> list[str]:
    out: list[str] = []
    for var in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
        for p in os.environ.get(var, "").split(os.pathsep) if os.environ.get(var) is not None else ():
            out.append(p)
            if p and os.path.exists(os.path.join(p, "package.xml")):
                out.append(os.path.join(p, ".."))
    return out


def package_dirs(urdf: Path) -> list[str]:
    """The folders the robot loader searches for a URDF's meshes, in its order."""
    dirs = [str(urdf.parent)]
    try:
        share = example_robot_data_share()
        dirs += [str(share), str(share.parent)]
    except CellstressError:
        pass
    return dirs + _ros_paths()


def _resolve(ref: str, dirs: list[str]) -> Path | None:
    scheme, sep, rest = ref.partition("://")
    if sep:
        if scheme in ("package", "model"):
            return next((Path(f"{d}/{rest}") for d in dirs if os.path.exists(f"{d}/{rest}")), None)
        return Path(rest) if scheme == "file" else None
    if not os.path.isabs(ref):
        return next((Path(f"{d}/{ref}") for d in dirs if os.path.exists(f"{d}/{ref}")), None)
    return Path(ref)


def referenced_meshes(urdf: Path) -> list[Path]:
    """The collision mesh files ``urdf`` names, as the robot loader resolves them, each once, in the file's
    order (a reference the loader cannot resolve is left out: loading the robot has already failed on it)."""
    with urdf.open("rb") as fh:
        data = fh.read(MAX_URDF_BYTES + 1)
    if len(data) > MAX_URDF_BYTES or b"<!ENTITY" in data:
        raise CellstressError(f"{urdf}: the URDF is larger than {MAX_URDF_BYTES // 2**20} MB or declares XML "
                              "entities")
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as exc:
        raise CellstressError(f"{urdf}: not well-formed XML ({exc})") from None
    dirs = package_dirs(urdf)
    out: list[Path] = []
    for mesh in root.findall("./link/collision/geometry/mesh"):
        path = _resolve(mesh.get("filename", ""), dirs)
        if path is not None and path not in out:
            out.append(path)
    return out
