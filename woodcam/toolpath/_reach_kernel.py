"""Compiled inner loops of the reach check (:mod:`woodcam.toolpath.reach`): the scan for the
next move near tall stock and one part's excess over a move's window.

The formulas are those the numpy version evaluated over the window (the move's frame, then the
lowest tip height over the stretch of the move that covers each cell), in the same order of
operations in float64, so the issues and their depths are the same to the bit. This module
imports only numpy and numba.

Conventions: ``hm : (ny, nx)`` block-frame Z (mm) at cell centres ``((i + 0.5) dx,
(j + 0.5) dy)``; a window is the cells ``j0..j1`` x ``i0..i1`` (inclusive, inside the grid).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(nogil=True, cache=True)
def first_tall(hm, moves, j0, j1, i0, i1, low, tol, start):
    """The first position ``c >= start`` in ``moves`` whose move ``k = moves[c]`` has stock
    in its window ``(j0[k]..j1[k], i0[k]..i1[k])`` higher than ``low[k] + tol`` (precisely:
    not ``low[k] >= max - tol``); ``len(moves)`` if none has."""
    for c in range(start, moves.shape[0]):
        k = moves[c]
        top = -np.inf
        for j in range(j0[k], j1[k] + 1):
            for i in range(i0[k], i1[k] + 1):
                if hm[j, i] > top:
                    top = hm[j, i]
        if not low[k] >= top - tol:
            return c
    return moves.shape[0]


@numba.njit(nogil=True, cache=True)
def part_excess(hm, j0, j1, i0, i1, dx, dy, a, b, r, bottom):
    """The largest ``excess = stock - (lowest tip height while a cylinder of radius ``r`` about
    the tool axis covers the cell + bottom)`` over the window (``-inf`` where the cylinder
    never covers a cell), and the squared distance of that cell (the first in row-major order
    on ties) from the move's line: ``(excess, d2)``; ``(-inf, d2 of the window's first cell)``
    when it covers none."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    L = math.hypot(ex, ey)
    plunge = L < 1e-9  # a plunge: length 0 at its lower end
    if plunge:
        ux, uy, s, z0, L = 0.0, 0.0, 0.0, min(a[2], b[2]), 0.0
    else:
        ux, uy, s, z0 = ex / L, ey / L, (b[2] - a[2]) / L, a[2]
    rr = r * r
    best, best_d2, first = -np.inf, 0.0, True
    for j in range(j0, j1 + 1):
        cy = (j + 0.5) * dy - a[1]
        for i in range(i0, i1 + 1):
            cx = (i + 0.5) * dx - a[0]
            if plunge:
                along = cx + 0.0 * cy
                d2 = cx * cx + cy * cy
            else:
                along = cx * ux + cy * uy
                perp = cx * uy - cy * ux
                d2 = perp * perp
            if first:
                best_d2, first = d2, False
            re = math.sqrt(max(rr - d2, 0.0))
            lo = max(along - re, 0.0)
            hi = min(along + re, L)
            if not (d2 <= rr and lo <= hi):
                continue
            z = z0 + s * (lo if s > 0 else hi)  # linear in t: the lower end of the stretch
            e = hm[j, i] - (z + bottom)
            if e > best:
                best, best_d2 = e, d2
    return best, best_d2
