"""The files a URDF pulls in: the meshes the robot loader reads, found as it finds them.

Only the paths are worked out here, so that a cell can list (and hash) every file it reads (``cell.files``)
and refuse one outside its folder before anything opens it; the meshes themselves are read by
``robot.geometry`` (a link's collision shapes, or its visual shapes where it has no collision shape), and each
reference becomes a path in one place, ``robot.urdf_file.resolve_mesh``.
"""

from __future__ import annotations

from pathlib import Path

from cellstress.robot.urdf_file import read_urdf, resolve_mesh


def referenced_meshes(urdf: Path) -> list[Path]:
    """The mesh files the robot loader reads for ``urdf``, each once, in the file's order of links (the checked
    URDF is read; no mesh is opened)."""
    doc = read_urdf(urdf)
    out: dict[Path, None] = {}
    for link in doc.links:
        for shape in doc.collision[link] or doc.visual[link]:
            if shape.kind == "mesh":
                out.setdefault(resolve_mesh(shape.filename, urdf), None)
    return list(out)
