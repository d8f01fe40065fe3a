"""Solid (3D) value noise for fibre streaks and pores, vectorised in numpy.

Written by hand because the noise packages on PyPI evaluate point by point from Python
without a batch API. The noise is a lattice of hashed random values
interpolated with a smoothstep, which is cheap (8 gathers a point) and band-limited near one
cycle per lattice cell; octaves add finer detail. It is a pure function of position, so a
surface cut anywhere through the block shows the same pores as its neighbours.
"""

from __future__ import annotations

import numba
import numpy as np

_TABLE_BITS = 16
_TABLE = np.random.default_rng(20241121).uniform(-1.0, 1.0, 1 << _TABLE_BITS).astype(np.float32)
# Large odd multipliers decorrelate the three lattice axes (spatial hashing of Teschner et al.).
_PX, _PY, _PZ = np.int64(73856093), np.int64(19349663), np.int64(83492791)


def value_noise(q: np.ndarray, seed: int = 0) -> np.ndarray:
    """Value noise in [-1, 1] at lattice coordinates ``q : (n, 3) float`` (one cell per unit).

    Returns
    -------
    noise : (n,) float32
    """
    q = np.ascontiguousarray(q, dtype=np.float32)
    if len(q) == 0:
        return np.empty(0, np.float32)
    return _value_noise_kernel(q, _TABLE, np.int64(seed))


@numba.njit(nogil=True, fastmath=True, cache=True)
def _value_noise_kernel(q, table, seed):  # pragma: no cover - compiled
    # A compiled loop, not numpy: the vectorised numpy form makes 8 separate gathers with
    # their temporaries and runs ~10x slower. Serial and GIL-free: callers parallelise over
    # chunks with threads (Wood.color), which a numba-parallel kernel would oversubscribe.
    n = q.shape[0]
    out = np.empty(n, np.float32)
    mask = table.shape[0] - 1
    for i in range(n):
        fx, fy, fz = np.floor(q[i, 0]), np.floor(q[i, 1]), np.floor(q[i, 2])
        tx, ty, tz = q[i, 0] - fx, q[i, 1] - fy, q[i, 2] - fz
        wx = tx * tx * (3 - 2 * tx)  # smoothstep weights: C1 across cells
        wy = ty * ty * (3 - 2 * ty)
        wz = tz * tz * (3 - 2 * tz)
        hx0 = np.int64(fx) * _PX + seed * 2654435761
        hy0 = np.int64(fy) * _PY
        hz0 = np.int64(fz) * _PZ
        hx1, hy1, hz1 = hx0 + _PX, hy0 + _PY, hz0 + _PZ
        c000 = table[(hx0 ^ hy0 ^ hz0) & mask]
        c100 = table[(hx1 ^ hy0 ^ hz0) & mask]
        c010 = table[(hx0 ^ hy1 ^ hz0) & mask]
        c110 = table[(hx1 ^ hy1 ^ hz0) & mask]
        c001 = table[(hx0 ^ hy0 ^ hz1) & mask]
        c101 = table[(hx1 ^ hy0 ^ hz1) & mask]
        c011 = table[(hx0 ^ hy1 ^ hz1) & mask]
        c111 = table[(hx1 ^ hy1 ^ hz1) & mask]
        x00 = c000 + wx * (c100 - c000)
        x10 = c010 + wx * (c110 - c010)
        x01 = c001 + wx * (c101 - c001)
        x11 = c011 + wx * (c111 - c011)
        y0 = x00 + wy * (x10 - x00)
        y1 = x01 + wy * (x11 - x01)
        out[i] = y0 + wz * (y1 - y0)
    return out


def grain_noise(points_mm: np.ndarray, grain: np.ndarray, across_mm: float, along_mm: float,
                seed: int = 0) -> np.ndarray:
    """Noise stretched along the grain: cells ``along_mm`` long and ``across_mm`` wide.

    Parameters
    ----------
    points_mm : (n, 3) float
    grain : (n, 3) float
        Unit fibre direction at each point.
    across_mm, along_mm : float
        Feature size across and along the fibres (streaks: along >> across).

    Returns
    -------
    noise : (n,) float32 in [-1, 1]
    """
    p = np.asarray(points_mm, dtype=np.float32)
    g = np.asarray(grain, dtype=np.float32)
    along = np.einsum("ij,ij->i", p, g)[:, None]
    # Scale the along-grain component by 1/along_mm and the rest by 1/across_mm.
    q = p / np.float32(across_mm) + along * g * np.float32(1.0 / along_mm - 1.0 / across_mm)
    return value_noise(q, seed)
