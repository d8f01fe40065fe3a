"""Swept-tool envelopes min-updated into the height field by numba, for the tools whose
envelope has a closed form: ball and flat end mills (the finishing and roughing tools of most
programs).

The numpy path (:meth:`woodcam.toolpath.tools.Tool._sweep` over ``(moves, wy, wx)`` windows,
then one Python slice update per move) builds four float32 temporaries per window cell and
spent ~0.8 of the 20,000-move raster's whole-run CPU seconds; here each cell's envelope is
computed and applied in one pass (float64, the same formulas). Other tools keep the numpy path.
This module imports only numpy and numba.

Conventions as :func:`woodcam.toolpath.simulate._sweep_batch`: ``hm : (ny, nx)`` block-frame Z
(mm) at cell centres, ``a, b : (n, 3)`` tip positions (mm) of the moves, each move's window the
``wy x wx`` cells from ``(js, is_)``; kind 0 = ball (radius ``R``), 1 = flat.
"""

from __future__ import annotations

import math

import numba
import numpy as np

BALL, FLAT = 0, 1


@numba.njit(nogil=True, cache=True)
def sweep_update(hm, line_map, track, kind, R, a, b, js, is_, wy, wx, dx, dy, lines, depth):
    """Min-update ``hm`` with the envelopes of the ``n`` moves; ``depth[k]`` gets how far move
    ``k`` reaches below the stock it meets (``max(hm - envelope)`` over its covered cells,
    before its own update; ``-inf`` if it covers none); with ``track`` the cells a move lowers
    get its source line in ``line_map``. Returns the number of covered cells."""
    covered = 0
    R2 = R * R
    for k in range(a.shape[0]):
        ax, ay, az = a[k, 0], a[k, 1], a[k, 2]
        ex, ey, ez = b[k, 0] - ax, b[k, 1] - ay, b[k, 2] - az
        L = math.hypot(ex, ey)
        if L < 1e-9:  # vertical move: along = x, clipped to t = 0 below, so rho = |cell - p|
            ux, uy, s, z0, L = 1.0, 0.0, 0.0, min(az, b[k, 2]), 0.0
        else:
            ux, uy, s, z0 = ex / L, ey / L, ez / L, az
        tilt = s / math.sqrt(1.0 + s * s)
        deepest = -np.inf
        for jj in range(wy):
            j = js[k] + jj
            cy = (j + 0.5) * dy - ay
            for ii in range(wx):
                i = is_[k] + ii
                cx = (i + 0.5) * dx - ax
                along = cx * ux + cy * uy
                perp = cx * uy - cy * ux
                re2 = R2 - perp * perp
                if kind == BALL:
                    # sphere centre on the line: tangent at w = -s Re / sqrt(1 + s^2)
                    re = math.sqrt(max(re2, 0.0))
                    t = min(max(along - tilt * re, 0.0), L)
                    w = t - along
                    q = re2 - w * w
                    if q < 0:
                        continue
                    env = (z0 + R) + s * t - math.sqrt(q)
                else:
                    # the flat bottom's chord |t - along| <= Re, t in [0, L]: its lowest end
                    if re2 < 0:
                        continue
                    re = math.sqrt(re2)
                    lo = max(along - re, 0.0)
                    hi = min(along + re, L)
                    if lo > hi:
                        continue
                    env = z0 + s * (lo if s > 0 else hi)
                covered += 1
                cur = hm[j, i]
                if cur - env > deepest:
                    deepest = cur - env
                if env < cur:
                    hm[j, i] = env
                    if track:
                        line_map[j, i] = lines[k]
        depth[k] = deepest
    return covered
