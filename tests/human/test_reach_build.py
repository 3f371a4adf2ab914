"""The reach field's fast build against the plain one it replaced: the same field, bit for bit.

The build rasterises the arm's segments for every combination of the joints' samples. It used to compute the
whole arm (arm_points_into) and mark all three segments for every configuration; it now marks the upper arm
once per sample pair of the first two joints and the forearm once per four, and splits the first joint's
samples over grids marked in parallel. The plain version is kept here, as it was, as the reference: the
voxels it marks, and the field made from them, must be exactly the build's (a cached field is checked against
a checksum of its values, so "close" would not do).
"""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.core.jit import njit
from cellstress.human import reach
from cellstress.human.reach import arm_points_into


@njit(cache=True)
def _reference_mark_segment(grid, origin, h, ax, ay, az, bx, by, bz):
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
def _reference_rasterise(grid, origin, h, lengths, a0, a1, a2, a3, a4):
    pts = np.empty((3, 3))
    rot = np.empty((3, 3))
    q = np.empty(5)
    for i0 in range(a0.shape[0]):
        q[0] = a0[i0]
        for i1 in range(a1.shape[0]):
            q[1] = a1[i1]
            for i2 in range(a2.shape[0]):
                q[2] = a2[i2]
                for i3 in range(a3.shape[0]):
                    q[3] = a3[i3]
                    for i4 in range(a4.shape[0]):
                        q[4] = a4[i4]
                        arm_points_into(q, lengths, rot, pts)
                        _reference_mark_segment(grid, origin, h, 0.0, 0.0, 0.0, pts[0, 0], pts[0, 1], pts[0, 2])
                        _reference_mark_segment(grid, origin, h, pts[0, 0], pts[0, 1], pts[0, 2],
                                                pts[1, 0], pts[1, 1], pts[1, 2])
                        _reference_mark_segment(grid, origin, h, pts[1, 0], pts[1, 1], pts[1, 2],
                                                pts[2, 0], pts[2, 1], pts[2, 2])


def reference_occupied(lengths, spacing):
    """The voxels the build marked before it was made fast (cellstress 41eb138), with its joint steps."""
    n, origin = reach._grid(lengths, spacing)
    occupied = np.zeros((n, n, n), dtype=np.bool_)
    arr = np.asarray(lengths, dtype=float)
    _reference_rasterise(occupied, origin, spacing, arr, *reach._joint_axes((6.0, 6.0, 10.0, 10.0, 10.0)))
    fine = np.rad2deg(spacing / float(sum(lengths))) * 0.9
    _reference_rasterise(occupied, origin, spacing, arr, *reach._joint_axes((fine, fine, 200.0, 200.0, 200.0)))
    return occupied


@pytest.mark.parametrize("seed", range(6))
def test_rasterise_marks_the_voxels_the_plain_one_does(seed):
    """On joint samples of every kind: random steps and offsets, ends included or not, a single sample (the
    fine pass's last three joints), other arms and grids, angles beyond the joints' ranges; more samples of
    the first joint than there are parallel parts, so that every part marks some."""
    rng = np.random.default_rng(seed)
    lengths = tuple(rng.uniform(0.1, 0.4, 3))
    spacing = float(rng.choice([0.015, 0.02, 0.03, 0.05]))
    n, origin = reach._grid(lengths, spacing)
    lo, hi = np.deg2rad(reach.JOINT_RANGES_DEG).T
    counts = [int(rng.integers(9, 21))] + [int(rng.integers(1, 9)) for _ in range(4)]  # every part gets some
    axes = [np.sort(rng.uniform(a - 0.3, b + 0.3, m)) for a, b, m in zip(lo, hi, counts, strict=True)]
    axes[int(rng.integers(1, 5))] = np.array([rng.uniform(-3.0, 3.0)])
    expected = np.zeros((n, n, n), dtype=np.bool_)
    _reference_rasterise(expected, origin, spacing, np.asarray(lengths), *axes)
    got = np.zeros((n, n, n), dtype=np.bool_)
    reach._rasterise(got, origin, spacing, np.asarray(lengths), *axes)
    assert expected.sum() > 50
    assert np.array_equal(got, expected), f"{np.sum(got != expected)} voxels differ"


@pytest.mark.slow
def test_build_is_bit_identical_to_the_plain_build():
    """The field users get (the default body on the default grid), through the whole build."""
    lengths, spacing = (0.30, 0.31, 0.18), reach.GRID_SPACING
    expected = reference_occupied(lengths, spacing)
    occupied = reach._occupied(lengths, spacing)
    assert np.array_equal(occupied, expected), f"{np.sum(occupied != expected)} voxels differ"
    field = reach._build(lengths, spacing)
    n, origin = reach._grid(lengths, spacing)
    assert (field.origin, field.spacing, field.arm_length) == (origin, spacing, float(sum(lengths)))
    assert np.array_equal(field.values, reach._signed_distance(expected, spacing))


def test_upper_arm_rotation_does_not_move_the_elbow():
    """What marking the upper arm once per pair of the first two joints rests on, bit for bit (and the wrist
    not moving with the wrist joint, for the forearm)."""
    rng = np.random.default_rng(3)
    lengths = np.array([0.30, 0.31, 0.18])
    lo, hi = np.deg2rad(reach.JOINT_RANGES_DEG).T
    for q in rng.uniform(lo, hi, (200, 5)):
        base = reach.arm_points(q, lengths)
        other = q.copy()
        other[2:] = rng.uniform(lo[2:], hi[2:])
        assert np.array_equal(reach.arm_points(other, lengths)[0], base[0])
        other = q.copy()
        other[4] = rng.uniform(lo[4], hi[4])
        assert np.array_equal(reach.arm_points(other, lengths)[1], base[1])
