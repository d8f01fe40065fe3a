"""Solid (3D) value noise for fibre streaks and pores, vectorised in numpy.

Written by hand because the noise packages on PyPI evaluate point by point in Python or C
loops without a vectorised batch API. The noise is a lattice of hashed random values
interpolated with a smoothstep, which is cheap (8 gathers a point) and band-limited near one
cycle per lattice cell; octaves add finer detail. It is a pure function of position, so a
surface cut anywhere through the block shows the same pores as its neighbours.
"""

from __future__ import annotations

import numpy as np

_TABLE_BITS = 16
_TABLE = np.random.default_rng(20241121).uniform(-1.0, 1.0, 1 << _TABLE_BITS).astype(np.float32)
_MASK = np.int64((1 << _TABLE_BITS) - 1)
# Large odd multipliers decorrelate the three lattice axes (spatial hashing of Teschner et al.).
_PX, _PY, _PZ = np.int64(73856093), np.int64(19349663), np.int64(83492791)


def value_noise(q: np.ndarray, seed: int = 0) -> np.ndarray:
    """Value noise in [-1, 1] at lattice coordinates ``q : (n, 3) float`` (one cell per unit).

    Returns
    -------
    noise : (n,) float32
    """
    q = np.asarray(q, dtype=np.float32)
    qf = np.floor(q)
    f = q - qf
    w = f * f * (3.0 - 2.0 * f)  # smoothstep weights: C1 across cells
    i = qf.astype(np.int64)
    hx0 = i[:, 0] * _PX + seed * 2654435761
    hy0 = i[:, 1] * _PY
    hz0 = i[:, 2] * _PZ
    hx1, hy1, hz1 = hx0 + _PX, hy0 + _PY, hz0 + _PZ
    wx, wy, wz = w[:, 0], w[:, 1], w[:, 2]

    def corner(hx, hy, hz):
        return _TABLE[(hx ^ hy ^ hz) & _MASK]

    x00 = corner(hx0, hy0, hz0) + wx * (corner(hx1, hy0, hz0) - corner(hx0, hy0, hz0))
    x10 = corner(hx0, hy1, hz0) + wx * (corner(hx1, hy1, hz0) - corner(hx0, hy1, hz0))
    x01 = corner(hx0, hy0, hz1) + wx * (corner(hx1, hy0, hz1) - corner(hx0, hy0, hz1))
    x11 = corner(hx0, hy1, hz1) + wx * (corner(hx1, hy1, hz1) - corner(hx0, hy1, hz1))
    y0 = x00 + wy * (x10 - x00)
    y1 = x01 + wy * (x11 - x01)
    return y0 + wz * (y1 - y0)


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
