"""Safety devices: a horizontal laser scanner and a vertical light curtain, as arrays for the kernel.

Each device latches a stop request when it sees a body capsule; the stop takes effect after its response
time. A scanner sees only what crosses its scan plane inside its field polygon (in practice the legs); a
light curtain sees any body capsule that touches its rectangle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.cell.schema import LaserScannerSpec, LightCurtainSpec

SCANNER, CURTAIN = 0, 1  # device kinds in the kernel


@dataclass(frozen=True)
class DeviceArrays:
    kind: np.ndarray  # (nd,) int64
    response: np.ndarray  # (nd,) s
    rect: np.ndarray  # (nd, 6): curtain x0 y0 x1 y1 bottom top; scanner [4] = scan height
    poly: np.ndarray  # (nd, 2) int64: start and count of each scanner polygon in verts
    verts: np.ndarray  # (V, 2)
    names: tuple[str, ...]


def pack_polygons(polys) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate polygons into one vertex array plus (start, count) rows."""
    verts, index = [], []
    for p in polys:
        index.append((len(verts), len(p)))
        verts.extend(p)
    return np.asarray(verts, dtype=float).reshape(-1, 2), np.asarray(index, dtype=np.int64).reshape(-1, 2)


def device_arrays(devices: tuple[LaserScannerSpec | LightCurtainSpec, ...]) -> DeviceArrays:
    kinds, resp, rects, polys = [], [], [], []
    for d in devices:
        resp.append(d.response_time)
        if d.type == "laser-scanner":
            kinds.append(SCANNER)
            rects.append((0.0, 0.0, 0.0, 0.0, d.height, d.height))
            polys.append(d.polygon)
        else:
            kinds.append(CURTAIN)
            rects.append((*d.start, *d.end, d.bottom, d.top))
            polys.append(())
    verts, index = pack_polygons(polys)
    return DeviceArrays(np.asarray(kinds, dtype=np.int64), np.asarray(resp, dtype=float),
                        np.asarray(rects, dtype=float).reshape(-1, 6), index, verts,
                        tuple(d.name for d in devices))
