"""The reachable workspace of an arm, as a signed distance field in the shoulder frame.

The arm is the 5-DOF model of Klopcar & Lenarcic (2005) used by the paper: shoulder flexion and abduction,
upper-arm rotation, elbow flexion and wrist flexion, with the paper's segment lengths. Joint ranges are the
normal adult ranges of motion of the American Academy of Orthopaedic Surgeons (Greene & Heckman 1994), cited
in docs/cells.md. The workspace is every point the upper arm, forearm or hand can occupy. We rasterise it
once on a voxel grid (sampling joint space densely), close pinholes left by the sampling, and store the
signed Euclidean distance to its surface (scipy's exact distance transform). Looking up a point costs one
trilinear interpolation.

Shoulder frame (right arm): x forward, y to the body's left, z up along the trunk. The left arm is the mirror
image (y -> -y), so one field serves both.
"""

from __future__ import annotations

import hashlib
import io
import os
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from cellstress.core.io import atomic_write
from cellstress.core.jit import njit, prange

# Ranges of motion [deg] (AAOS normal values): flexion 180 / extension 60, abduction 180 / adduction 30,
# internal rotation 70 / external rotation 90, elbow flexion 0..150, wrist flexion 80 / extension 70.
SHOULDER_FLEXION = (-60.0, 180.0)
SHOULDER_ABDUCTION = (-30.0, 180.0)
UPPER_ARM_ROTATION = (-90.0, 70.0)
ELBOW_FLEXION = (0.0, 150.0)
WRIST_FLEXION = (-70.0, 80.0)
JOINT_RANGES_DEG = np.array([SHOULDER_FLEXION, SHOULDER_ABDUCTION, UPPER_ARM_ROTATION, ELBOW_FLEXION, WRIST_FLEXION])

GRID_SPACING = 0.02  # m
_CACHE_VERSION = 3  # 2: upper-arm rotation sampled every 10 deg (was 20: gaps of up to 2.5 voxels); 3: a checksum


@njit(cache=True)
def _turn(m, axis, c, s):
    """m @ R_axis(angle) in place, for 3x3 m, axis 0 (x), 1 (y) or 2 (z) and c, s = cos, sin of the angle."""
    i, j = (1, 2) if axis == 0 else ((2, 0) if axis == 1 else (0, 1))
    for r in range(3):
        a, b = m[r, i], m[r, j]
        m[r, i] = c * a + s * b
        m[r, j] = -s * a + c * b


@njit(cache=True)
def _rotate(m, axis, angle):
    """m @ R_axis(angle) in place, for 3x3 m and axis 0 (x), 1 (y) or 2 (z)."""
    _turn(m, axis, np.cos(angle), np.sin(angle))


@njit(cache=True)
def arm_points_into(q, lengths, rot, out):
    """Elbow, wrist and fingertip of the right arm in the shoulder frame for joint angles q [rad] -> out (3, 3).

    At q = 0 the whole arm hangs straight down (-z). Flexion swings it forward (+x), abduction sideways away
    from the body (-y), rotation turns it about its own axis, elbow and wrist flex towards the palm side.
    ``rot`` is 3x3 scratch space.
    """
    for r in range(3):
        for c in range(3):
            rot[r, c] = 1.0 if r == c else 0.0
    _rotate(rot, 0, -q[1])
    _rotate(rot, 1, -q[0])
    _rotate(rot, 2, q[2])
    px = py = pz = 0.0
    for k in range(3):
        if k == 1:
            _rotate(rot, 1, -q[3])
        elif k == 2:
            _rotate(rot, 1, -q[4])
        # the segment points along -z of the current frame
        px -= lengths[k] * rot[0, 2]
        py -= lengths[k] * rot[1, 2]
        pz -= lengths[k] * rot[2, 2]
        out[k, 0], out[k, 1], out[k, 2] = px, py, pz


@njit(cache=True)
def arm_points(q, lengths):
    out = np.empty((3, 3))
    arm_points_into(q, lengths, np.empty((3, 3)), out)
    return out


@njit(cache=True)
def _mark_segment(grid, origin, h, ax, ay, az, bx, by, bz):
    n = grid.shape[0]
    length = np.sqrt((bx - ax) ** 2 + (by - ay) ** 2 + (bz - az) ** 2)
    k = int(length / (0.5 * h)) + 1
    for i in range(k + 1):
        f = i / k
        ix = int(np.floor((ax + (bx - ax) * f - origin) / h + 0.5))
        iy = int(np.floor((ay + (by - ay) * f - origin) / h + 0.5))
        iz = int(np.floor((az + (bz - az) * f - origin) / h + 0.5))
        if 0 <= ix < n and 0 <= iy < n and 0 <= iz < n:
            grid[ix, iy, iz] = True


@njit(cache=True)
def _cos_sin(angles, sign):
    """cos and sin of sign * angles, exactly as _rotate computes them."""
    c = np.empty(angles.shape[0])
    s = np.empty(angles.shape[0])
    for i in range(angles.shape[0]):
        c[i] = np.cos(sign * angles[i])
        s[i] = np.sin(sign * angles[i])
    return c, s


@njit(cache=True)
def _copy3(src, dst):
    """dst[:, :] = src for 3x3 arrays (a slice assignment would compile numba's shape checks: seconds)."""
    for r in range(3):
        for c in range(3):
            dst[r, c] = src[r, c]


@njit(cache=True)
def _rasterise_part(grid, origin, h, lengths, start, stride, a0, a1, a2, a3, a4):
    """Mark every voxel the arm's three segments cross, for every combination of the five joints' samples,
    taking the first joint's every ``stride``-th sample from ``start``.

    The points are arm_points_into's, computed joint by joint with the same operations in the same order, so
    they are the same bit for bit. The elbow does not depend on the last three joints (rotation about the
    upper arm's axis leaves it in place) nor the wrist on the last, so the upper arm is marked once per pair
    of the first two joints' samples and the forearm once per four, not once per configuration of all five:
    the same voxels for about a quarter of the work (tests/human/test_reach_build.py keeps the plain loop)."""
    c0, s0 = _cos_sin(a0, -1.0)
    c1, s1 = _cos_sin(a1, -1.0)
    c2, s2 = _cos_sin(a2, 1.0)
    c3, s3 = _cos_sin(a3, -1.0)
    c4, s4 = _cos_sin(a4, -1.0)
    l0, l1, l2 = lengths[0], lengths[1], lengths[2]
    r01 = np.empty((3, 3))
    r012 = np.empty((3, 3))
    r0123 = np.empty((3, 3))
    for i0 in range(start, a0.shape[0], stride):
        for i1 in range(a1.shape[0]):
            for r in range(3):
                for c in range(3):
                    r01[r, c] = 1.0 if r == c else 0.0
            _turn(r01, 0, c1[i1], s1[i1])
            _turn(r01, 1, c0[i0], s0[i0])
            ex = ey = ez = 0.0  # accumulated as arm_points_into does, so the rounding is the same
            ex -= l0 * r01[0, 2]
            ey -= l0 * r01[1, 2]
            ez -= l0 * r01[2, 2]
            _mark_segment(grid, origin, h, 0.0, 0.0, 0.0, ex, ey, ez)
            for i2 in range(a2.shape[0]):
                _copy3(r01, r012)
                _turn(r012, 2, c2[i2], s2[i2])
                for i3 in range(a3.shape[0]):
                    _copy3(r012, r0123)
                    _turn(r0123, 1, c3[i3], s3[i3])
                    wx, wy, wz = ex, ey, ez
                    wx -= l1 * r0123[0, 2]
                    wy -= l1 * r0123[1, 2]
                    wz -= l1 * r0123[2, 2]
                    _mark_segment(grid, origin, h, ex, ey, ez, wx, wy, wz)
                    for i4 in range(a4.shape[0]):
                        # the hand's direction: column 2 of r0123 turned by the wrist, as _turn does it
                        c, s = c4[i4], s4[i4]
                        tx, ty, tz = wx, wy, wz
                        tx -= l2 * (c * r0123[0, 2] + s * r0123[0, 0])
                        ty -= l2 * (c * r0123[1, 2] + s * r0123[1, 0])
                        tz -= l2 * (c * r0123[2, 2] + s * r0123[2, 0])
                        _mark_segment(grid, origin, h, wx, wy, wz, tx, ty, tz)


_RASTER_PARTS = 8  # grids marked in parallel, then united: a union does not depend on the order of marking


@njit(cache=True, parallel=True)
def _rasterise(grid, origin, h, lengths, a0, a1, a2, a3, a4):
    """Mark every voxel the arm's three segments cross, for every combination of the five joints' samples (a
    grid of joint space walked in place: as an array it would take ~250 MB at the coarse step). The first
    joint's samples are dealt out in turn to _RASTER_PARTS grids marked in parallel, then OR'ed into grid."""
    n = grid.shape[0]
    parts = np.zeros((_RASTER_PARTS, n, n, n), dtype=np.bool_)
    for p in prange(_RASTER_PARTS):
        # np.int64: the parallel loop's index may be typed unsigned, which would compile the part twice
        _rasterise_part(parts[p], origin, h, lengths, np.int64(p), _RASTER_PARTS, a0, a1, a2, a3, a4)
    for p in range(_RASTER_PARTS):
        for x in range(n):
            for y in range(n):
                for z in range(n):
                    if parts[p, x, y, z]:
                        grid[x, y, z] = True


def _joint_axes(step_deg: tuple[float, float, float, float, float]) -> list[np.ndarray]:
    """Each joint's samples [rad]: its range at the given step, always with both ends."""
    axes = [np.deg2rad(np.arange(lo, hi + 1e-9, s)) for (lo, hi), s in zip(JOINT_RANGES_DEG, step_deg, strict=True)]
    for ax, (_lo, hi) in zip(axes, np.deg2rad(JOINT_RANGES_DEG), strict=True):
        ax[-1] = hi  # always include the range ends
    return axes


# The lookup the simulator's kernels inline into their hot loop (and ReachField.distance calls): it is the
# field's own interpolation, so it lives with the field.
@njit(cache=True, error_model="numpy", inline="always")
def _grid_coord(c, origin, hi, h, n):
    """(clamped cell index, fraction, squared distance outside the grid) along one axis."""
    out2 = 0.0
    if c < origin:
        out2 = (origin - c) ** 2
        c = origin
    elif c > hi:
        out2 = (c - hi) ** 2
        c = hi
    g = (c - origin) / h
    i = int(g)
    if i > n - 2:
        i = n - 2
    return i, g - i, out2


@njit(cache=True, error_model="numpy", inline="always")
def reach_lookup(vals, origin, h, px, py, pz):
    """Trilinear signed distance at p (shoulder frame); beyond the grid, the distance to it is added."""
    n = vals.shape[0]
    hi = origin + (n - 1) * h
    i, fx, ex = _grid_coord(px, origin, hi, h, n)
    j, fy, ey = _grid_coord(py, origin, hi, h, n)
    k, fz, ez = _grid_coord(pz, origin, hi, h, n)
    c00 = vals[i, j, k] * (1 - fx) + vals[i + 1, j, k] * fx
    c10 = vals[i, j + 1, k] * (1 - fx) + vals[i + 1, j + 1, k] * fx
    c01 = vals[i, j, k + 1] * (1 - fx) + vals[i + 1, j, k + 1] * fx
    c11 = vals[i, j + 1, k + 1] * (1 - fx) + vals[i + 1, j + 1, k + 1] * fx
    c0 = c00 * (1 - fy) + c10 * fy
    c1 = c01 * (1 - fy) + c11 * fy
    return c0 * (1 - fz) + c1 * fz + np.sqrt(ex + ey + ez)


@dataclass(frozen=True)
class ReachField:
    """Signed distance [m] to the arm's reachable workspace, on a cube grid in the shoulder frame."""

    values: np.ndarray  # float32 (n, n, n); negative inside
    origin: float  # coordinate of the first grid node on every axis
    spacing: float
    arm_length: float

    @property
    def nbytes(self) -> int:
        return int(self.values.nbytes)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Trilinear lookup for points (m, 3) in the right shoulder frame (reference, not the hot path)."""
        return np.array([reach_lookup(self.values, self.origin, self.spacing, *(float(c) for c in p)) for p in points])


def _build(lengths: tuple[float, float, float], spacing: float) -> ReachField:
    origin = _grid(lengths, spacing)[1]
    return ReachField(_signed_distance(_occupied(lengths, spacing), spacing), origin, spacing, float(sum(lengths)))


def _occupied(lengths: tuple[float, float, float], spacing: float) -> np.ndarray:
    """The voxels (of the field's grid) the arm's segments cross at the joint samples, bool (n, n, n)."""
    reach = float(sum(lengths))
    n, origin = _grid(lengths, spacing)
    occupied = np.zeros((n, n, n), dtype=np.bool_)
    lengths_arr = np.asarray(lengths, dtype=float)
    # The whole workspace at a coarse joint step, then the outer shell (straight elbow and wrist, where the
    # arm reaches furthest) at a step fine enough to leave no gap wider than a voxel at full reach.
    # Upper-arm rotation swings the bent forearm and hand (up to 0.5 m from its axis): a 20 deg step left
    # holes of up to 2.5 voxels in the surface that the closing below cannot fill; 10 deg leaves none.
    _rasterise(occupied, origin, spacing, lengths_arr, *_joint_axes((6.0, 6.0, 10.0, 10.0, 10.0)))
    fine = np.rad2deg(spacing / reach) * 0.9
    _rasterise(occupied, origin, spacing, lengths_arr, *_joint_axes((fine, fine, 200.0, 200.0, 200.0)))
    return occupied


def _signed_distance(occupied: np.ndarray, spacing: float) -> np.ndarray:
    """The rasterised arm closed (pinholes between samples), filled, and its signed distance, float32."""
    from scipy import ndimage

    occupied = ndimage.binary_closing(occupied, structure=np.ones((3, 3, 3)), iterations=1)
    occupied = ndimage.binary_fill_holes(occupied)
    outside = ndimage.distance_transform_edt(~occupied, sampling=spacing)
    inside = ndimage.distance_transform_edt(occupied, sampling=spacing)
    # Voxel centres are samples of a surface that lies half a voxel beyond the outermost occupied centre.
    return np.where(occupied, -(inside - 0.5 * spacing), outside - 0.5 * spacing).astype(np.float32)


def _grid(lengths: tuple[float, float, float], spacing: float) -> tuple[int, float]:
    """Nodes per axis and the first node's coordinate of the field's cube grid (3 voxels beyond full reach)."""
    half = float(sum(lengths)) + 3 * spacing
    n = int(np.ceil(2 * half / spacing)) + 1
    return n, -0.5 * (n - 1) * spacing


def _cache_dir() -> Path | None:
    root = os.environ.get("CELLSTRESS_CACHE") or os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    path = Path(root) / "cellstress"
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return path


def _checksum(values: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(values).tobytes()).hexdigest()


def _load_cached(file: Path, lengths: tuple[float, float, float], spacing: float) -> ReachField | None:
    """The cached field, or None unless the file is exactly what ``_build`` would give for these lengths: the
    cache folder is writable by anyone who runs as the user, so a damaged or edited file must not change a
    result. Its shape, dtype, grid, arm length and the checksum of its values are all checked, pickles are
    refused, and a file larger than the field could be is not read."""
    n, origin = _grid(lengths, spacing)
    try:
        if not file.is_file() or file.stat().st_size > 4 * n**3 + 65536:
            return None
        with np.load(file, allow_pickle=False) as z:
            if set(z.files) != {"values", "origin", "spacing", "arm_length", "sha256"}:
                return None
            values = z["values"]
            meta = [z[k] for k in ("origin", "spacing", "arm_length", "sha256")]
        if values.dtype != np.float32 or values.shape != (n, n, n) or any(m.shape != () for m in meta):
            return None
        if (float(meta[0]), float(meta[1]), float(meta[2])) != (origin, spacing, float(sum(lengths))):
            return None
        if str(meta[3]) != _checksum(values) or not np.isfinite(values).all():
            return None
        return ReachField(values, origin, spacing, float(sum(lengths)))
    except (OSError, ValueError, KeyError, EOFError, TypeError):
        return None  # a damaged entry is rebuilt


@lru_cache(maxsize=4)
def reach_field(upper_arm: float, forearm: float, hand: float, spacing: float = GRID_SPACING) -> ReachField:
    """The field for these segment lengths, built once and kept in memory and in a disk cache (checked before
    use, rebuilt when it does not check out)."""
    lengths = (upper_arm, forearm, hand)
    key = hashlib.sha256(repr((_CACHE_VERSION, upper_arm, forearm, hand, spacing,
                               JOINT_RANGES_DEG.tolist())).encode()).hexdigest()[:16]
    cache = _cache_dir()
    file = cache / f"reach-{key}.npz" if cache else None
    if file is not None:
        cached = _load_cached(file, lengths, spacing)
        if cached is not None:
            return cached
    field = _build(lengths, spacing)
    if file is not None:
        buf = io.BytesIO()
        np.savez(buf, values=field.values, origin=field.origin, spacing=field.spacing,
                 arm_length=field.arm_length, sha256=_checksum(field.values))
        try:
            atomic_write(file, buf.getvalue())
        except OSError:
            pass
    return field
