"""Solid (3D) value noise for fibre streaks and pores, compiled with numba.

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
TABLE = np.random.default_rng(20241121).uniform(-1.0, 1.0, 1 << _TABLE_BITS).astype(np.float32)
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
    return _value_noise_kernel(q, TABLE, np.int64(seed))


@numba.njit(nogil=True, fastmath=True, cache=True)
def noise_at(x, y, z, table, seed):  # pragma: no cover - compiled
    """Value noise at one lattice point ``(x, y, z)``; callable from other compiled kernels."""
    fx, fy, fz = np.floor(x), np.floor(y), np.floor(z)
    tx, ty, tz = x - fx, y - fy, z - fz
    wx = tx * tx * (3 - 2 * tx)  # smoothstep weights: C1 across cells
    wy = ty * ty * (3 - 2 * ty)
    wz = tz * tz * (3 - 2 * tz)
    mask = table.shape[0] - 1
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
    return y0 + wz * (y1 - y0)


@numba.njit(nogil=True, fastmath=True, cache=True)
def _value_noise_kernel(q, table, seed):  # pragma: no cover - compiled
    # A compiled loop, not numpy: the vectorised numpy form makes 8 separate gathers with
    # their temporaries and runs ~10x slower. Serial and GIL-free: callers parallelise over
    # chunks with threads (Wood.color), which a numba-parallel kernel would oversubscribe.
    out = np.empty(q.shape[0], np.float32)
    for i in range(q.shape[0]):
        out[i] = noise_at(q[i, 0], q[i, 1], q[i, 2], table, seed)
    return out
