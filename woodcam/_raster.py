"""Conservative triangle rasterisation in texel space, compiled with numba (used by
:mod:`woodcam.bake`).

Written by hand because no installed library rasterises with the footprint the baker needs (every
texel whose centre lies within L-infinity distance ``reach`` of a triangle, owned by the nearest
triangle); the numpy version it replaces built (triangle x texel) candidate arrays and took
1.0 CPU-s on the 32k-triangle bowl, this kernel walks each triangle's rows once.
This module imports only numpy and numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(nogil=True, cache=True)
def rasterise_kernel(p, valid, width, height, reach, first, last, owner, best_out, best_tri):
    """Rasterise triangles ``first .. last - 1`` into ``owner`` / ``best_out`` / ``best_tri``.

    Parameters
    ----------
    p : (f, 3, 2) float64
        Triangle corners in texel coordinates (x right, y down; texel (r, c) centre at
        (c + .5, r + .5)).
    valid : (f,) bool
        Triangles to draw (non-degenerate in uv).
    width, height : int
        Atlas size in texels.
    reach : float
        Footprint half-width in texels: a texel is touched when its centre lies in the Minkowski
        sum of the triangle and the square ``[-reach, reach]^2`` (each edge pushed out by
        ``reach (|n_x| + |n_y|)``, the bounding box grown by ``reach``).
    owner : (height * width,) int64, in/out
        Triangle whose interior (or edge, within 1e-6 texel) holds the texel centre; the last
        such triangle drawn wins. -1 where none.
    best_out, best_tri : (height * width,) float64 / int64, in/out
        For touched texels outside every triangle: the smallest outward edge distance seen and
        its triangle (the nearest triangle, first drawn on ties).
    """
    for t in range(first, last):
        if not valid[t]:
            continue
        x0, y0 = p[t, 0, 0], p[t, 0, 1]
        x1, y1 = p[t, 1, 0], p[t, 1, 1]
        x2, y2 = p[t, 2, 0], p[t, 2, 1]
        det = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
        sgn = 1.0 if det > 0 else -1.0
        # outward distance to edge i (opposite corner i): o_i = a_i + gx_i * x + gy_i * y
        a = np.empty(3)
        gx = np.empty(3)
        gy = np.empty(3)
        sup = np.empty(3)
        for i in range(3):
            if i == 0:
                ax, ay, bx, by = x1, y1, x2, y2
            elif i == 1:
                ax, ay, bx, by = x2, y2, x0, y0
            else:
                ax, ay, bx, by = x0, y0, x1, y1
            ex = bx - ax
            ey = by - ay
            length = math.sqrt(ex * ex + ey * ey)
            if length < 1e-300:
                length = 1e-300
            gx[i] = sgn * ey / length
            gy[i] = -sgn * ex / length
            a[i] = -sgn * (ey * ax - ex * ay) / length
            sup[i] = reach * (abs(ex) + abs(ey)) / length
        lo_x = min(x0, x1, x2)
        hi_x = max(x0, x1, x2)
        c0 = max(0, int(math.ceil(lo_x - 0.5 - reach)))
        c1 = min(width - 1, int(math.floor(hi_x - 0.5 + reach)))
        r0 = max(0, int(math.ceil(min(y0, y1, y2) - 0.5 - reach)))
        r1 = min(height - 1, int(math.floor(max(y0, y1, y2) - 0.5 + reach)))
        for r in range(r0, r1 + 1):
            y = r + 0.5
            # the columns where every edge test can hold (widened by 1e-9, re-tested below)
            xlo = c0 + 0.5
            xhi = c1 + 0.5
            empty = False
            for i in range(3):
                rhs = sup[i] - a[i] - gy[i] * y
                if gx[i] > 1e-12:
                    xhi = min(xhi, rhs / gx[i] + 1e-9)
                elif gx[i] < -1e-12:
                    xlo = max(xlo, rhs / gx[i] - 1e-9)
                elif rhs < -1e-9:
                    empty = True
            if empty or xhi < xlo:
                continue
            ca = max(c0, int(math.ceil(xlo - 0.5)))
            cb = min(c1, int(math.floor(xhi - 0.5)))
            base = r * width
            for c in range(ca, cb + 1):
                x = c + 0.5
                out = -1e300
                ok = True
                for i in range(3):
                    o = a[i] + gx[i] * x + gy[i] * y
                    if o > sup[i]:
                        ok = False
                        break
                    if o > out:
                        out = o
                if not ok:
                    continue
                k = base + c
                if out <= 1e-6:
                    owner[k] = t
                elif out < best_out[k]:
                    best_out[k] = out
                    best_tri[k] = t
