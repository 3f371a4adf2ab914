"""Mesh files named by a URDF, read within bounds before anything trusts them.

STL (binary and ASCII) is read here with numpy; its triangle count is checked against the file's size before a
triangle is read. Other formats (Collada .dae, .obj, .ply) go to coal's mesh loader (assimp), which pinocchio
uses too, but only after the file has been read by us as a regular file of bounded size; coal then reads that
copy, so it never opens a pipe or a device and never a file other than the one we checked. Every mesh must
have at least one triangle of non-zero area and finite vertices within ``MAX_EXTENT`` of its frame (after the
URDF's scale).

The vertices of an STL are returned exactly as coal gives them (so capsules fitted to them are bit for bit
those fitted before cellstress read STL itself): triangles with two equal corners dropped, identical vertices
merged, in order of first use. A test compares both on every STL of example-robot-data.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.core.io import InputFileError, read_input_bytes
from cellstress.robot.urdf_file import MAX_EXTENT, captured_fd2

MAX_MESH_BYTES = 32 * 1024 * 1024  # example-robot-data's largest mesh (Go1's trunk.dae) is 28.8 MB
MAX_MESH_TRIANGLES = 400_000  # per file (that trunk: 351,394)
MESH_FORMATS = (".stl", ".dae", ".obj", ".ply")
_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
_ASCII_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


class MeshError(CellstressError):
    """A mesh file that cannot be used; the message names the file and the cause."""

    def __init__(self, path: Path, problem: str):
        self.path = path
        self.problem = problem
        super().__init__(f"mesh {path}: {problem}")


@dataclass(frozen=True)
class Mesh:
    """A mesh's unique vertices (n, 3) in its own frame, scaled, and its triangles (m, 3) as vertex indices."""

    path: Path
    vertices: np.ndarray
    triangles: np.ndarray


def _stl_corners(path: Path, data: bytes) -> np.ndarray:
    """The corners (3 m, 3) of an STL's triangles, float32 as stored."""
    if len(data) >= 84:
        n = int.from_bytes(data[80:84], "little")
        if len(data) == 84 + 50 * n:
            if n == 0:
                raise MeshError(path, "the STL has no triangles")
            if n > MAX_MESH_TRIANGLES:
                raise MeshError(path, f"the STL has {n:,} triangles; cellstress reads at most {MAX_MESH_TRIANGLES:,} "
                                      "per mesh (simplify it)")
            return np.frombuffer(data, dtype=_STL_RECORD, count=n, offset=84)["v"].reshape(-1, 3)
    if not data.lstrip()[:5].lower() == b"solid":
        if len(data) >= 84:
            n = int.from_bytes(data[80:84], "little")
            raise MeshError(path, f"is not an STL file: as binary STL its header says {n:,} triangles "
                                  f"({84 + 50 * n:,} bytes), but the file has {len(data):,} bytes, and it is not "
                                  "ASCII STL (which starts with 'solid')")
        raise MeshError(path, f"is not an STL file ({len(data)} bytes, no 'solid' at the start)")
    facets = data.count(b"endfacet")
    if facets > MAX_MESH_TRIANGLES:
        raise MeshError(path, f"the STL has {facets:,} triangles; cellstress reads at most {MAX_MESH_TRIANGLES:,} per "
                              "mesh (simplify it)")
    found = _ASCII_VERTEX.findall(data)
    if not found:
        raise MeshError(path, "the ASCII STL has no triangles")
    if len(found) % 3:
        raise MeshError(path, f"the ASCII STL has {len(found)} vertices, not three per triangle")
    try:
        return np.asarray(found, dtype=np.float32)
    except ValueError:
        raise MeshError(path, "the ASCII STL has a vertex coordinate that is not a number") from None


def _join(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coal's (assimp's) vertices and triangles of an STL: triangles with two equal corners dropped, equal
    vertices merged in order of first use."""
    tri = corners.reshape(-1, 3, 3)
    flat = (np.all(tri[:, 0] == tri[:, 1], axis=1) | np.all(tri[:, 1] == tri[:, 2], axis=1)
            | np.all(tri[:, 0] == tri[:, 2], axis=1))
    kept = tri[~flat].reshape(-1, 3)
    if kept.shape[0] == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    # equal rows grouped by two stable integer sorts of their bits (-0 made +0 first, as == sees them equal):
    # np.unique(axis=0) does the same several times slower. The first row of a group in sorted order is its first
    # use, since stable sorts keep equal rows in index order.
    bits = (kept + np.float32(0.0)).view(np.uint32).astype(np.uint64)
    high = (bits[:, 0] << np.uint64(32)) | bits[:, 1]
    order = np.argsort(bits[:, 2], kind="stable")
    order = order[np.argsort(high[order], kind="stable")]
    rows = kept[order]
    starts = np.ones(len(rows), dtype=bool)
    starts[1:] = np.any(rows[1:] != rows[:-1], axis=1)
    first = order[starts]  # each distinct vertex's first use, in sorted order
    group = np.empty(len(kept), dtype=np.int64)
    group[order] = np.cumsum(starts) - 1
    by_use = np.argsort(first, kind="stable")
    rank = np.empty_like(by_use)
    rank[by_use] = np.arange(by_use.size)
    return kept[first[by_use]], rank[group].reshape(-1, 3).astype(np.int64)


def _with_coal(path: Path, data: bytes, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (scaled) and triangles of a non-STL mesh through coal, from a private copy of ``data``."""
    import coal  # heavy, and installed with pinocchio

    if path.suffix.lower() == ".dae" and b"<!ENTITY" in data:
        raise MeshError(path, "the Collada file declares XML entities; cellstress does not expand them")
    with tempfile.TemporaryDirectory(prefix="cellstress-mesh-") as tmp:
        copy = Path(tmp) / ("mesh" + path.suffix.lower())
        copy.write_bytes(data)
        with captured_fd2():
            try:
                model = coal.MeshLoader().load(str(copy), scale)
            except Exception:  # noqa: BLE001 - assimp reports any unreadable file as a plain exception
                # (its text names our private copy and coal's source lines, not the cause)
                raise MeshError(path, f"cannot be read as a mesh in the {path.suffix.lower()} format (assimp "
                                      "finds none in it)") from None
    n = int(model.num_tris)
    if n > MAX_MESH_TRIANGLES:
        raise MeshError(path, f"has {n:,} triangles; cellstress reads at most {MAX_MESH_TRIANGLES:,} per mesh")
    tris = np.asarray([tuple(model.tri_indices(i)[k] for k in range(3)) for i in range(n)], dtype=np.int64)
    return np.array(model.vertices(), dtype=float), tris.reshape(-1, 3)


@lru_cache(maxsize=64)
def _read(path: Path, scale: tuple[float, float, float]) -> Mesh:
    suffix = path.suffix.lower()
    if suffix not in MESH_FORMATS:
        kind = f"format {suffix!r}" if suffix else "file without an extension"
        raise MeshError(path, f"is a {kind}; cellstress reads meshes as STL, DAE (Collada), OBJ or PLY")
    try:
        data = read_input_bytes(path, MAX_MESH_BYTES)
    except InputFileError as exc:
        raise MeshError(path, exc.problem) from None
    if not data:
        raise MeshError(path, "is empty")
    s = np.asarray(scale, dtype=float)
    if suffix == ".stl":
        corners = _stl_corners(path, data)
        if not np.isfinite(corners).all():
            raise MeshError(path, "has a vertex that is not finite (NaN or infinity)")
        vertices, triangles = _join(corners)
        vertices = vertices.astype(np.float64) * s
    else:
        vertices, triangles = _with_coal(path, data, s)
        if not np.isfinite(vertices).all():
            raise MeshError(path, "has a vertex that is not finite (NaN or infinity)")
    if triangles.shape[0] == 0:
        raise MeshError(path, "has no triangle with three different corners")
    far = float(np.abs(vertices).max())
    if far > MAX_EXTENT:
        raise MeshError(path, f"has a vertex {far:.3g} m from its origin (after the URDF's scale); cellstress takes "
                              f"robot parts within {MAX_EXTENT:g} m (is the scale or the unit wrong?)")
    corners3 = vertices[triangles]
    area2 = np.linalg.norm(np.cross(corners3[:, 1] - corners3[:, 0], corners3[:, 2] - corners3[:, 0]), axis=1)
    if not (area2 > 0.0).any():
        raise MeshError(path, "has no extent: every triangle has zero area")
    vertices.setflags(write=False)
    triangles.setflags(write=False)
    return Mesh(path, vertices, triangles)


def read_mesh(path: Path, scale=(1.0, 1.0, 1.0)) -> Mesh:
    """The mesh at ``path`` with the URDF's ``scale``; MeshError naming the file and the cause otherwise."""
    return _read(Path(path), tuple(float(v) for v in scale))
