"""The height field's triangulated surface, evaluated point by point with numba.

The surface is the vertex grid of :mod:`woodcam.toolpath.mesh`: ``hm : (ny, nx)`` block-frame
Z (mm) at the cell centres over ``[0, W] x [0, D]``, plus a border row and column on the
stock's faces carrying the nearest cell's height; each quad is split v00-v01-v11 /
v00-v11-v10. Used for the top chart's texel points (the bake) and by the stock view
(:mod:`woodcam.view._zbuffer`), where the numpy version it replaced cost ~0.5 s per million
points in temporaries. This module imports only numpy and numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(inline="always")
def vertex_x(i: int, nv: int, L: float) -> float:
    """Coordinate (mm) of vertex ``i`` of ``nv`` along an axis of length ``L``: 0, the
    ``nv - 2`` cell centres, L."""
    if i <= 0:
        return 0.0
    if i >= nv - 1:
        return L
    return (i - 0.5) * L / (nv - 2)


@numba.njit(inline="always")
def vertex_z(hm: np.ndarray, j: int, i: int) -> float:
    """Z (mm) of vertex ``(j, i)``: the nearest cell's height (border vertices copy theirs)."""
    ny, nx = hm.shape
    return hm[min(max(j - 1, 0), ny - 1), min(max(i - 1, 0), nx - 1)]


@numba.njit(nogil=True, cache=True)
def surface_point(hm: np.ndarray, W: float, D: float, x: float, y: float, n: np.ndarray) -> float:
    """Height (mm) of the surface at block-frame ``(x, y)``; its triangle's unit normal goes
    to ``n : (3,)``."""
    ny, nx = hm.shape
    nyv, nxv = ny + 2, nx + 2
    i = min(max(int(math.floor(x * nx / W + 0.5)), 0), nxv - 2)
    j = min(max(int(math.floor(y * ny / D + 0.5)), 0), nyv - 2)
    x0, x1 = vertex_x(i, nxv, W), vertex_x(i + 1, nxv, W)
    y0, y1 = vertex_x(j, nyv, D), vertex_x(j + 1, nyv, D)
    hx, hy = x1 - x0, y1 - y0
    a = (x - x0) / hx
    b = (y - y0) / hy
    z00, z01 = vertex_z(hm, j, i), vertex_z(hm, j, i + 1)
    z10, z11 = vertex_z(hm, j + 1, i), vertex_z(hm, j + 1, i + 1)
    if a >= b:  # triangle v00, v01, v11
        gx, gy = (z01 - z00) / hx, (z11 - z01) / hy
        z = z00 + a * (z01 - z00) + b * (z11 - z01)
    else:
        gx, gy = (z11 - z10) / hx, (z10 - z00) / hy
        z = z00 + b * (z10 - z00) + a * (z11 - z10)
    s = 1.0 / math.sqrt(gx * gx + gy * gy + 1.0)
    n[0], n[1], n[2] = -gx * s, -gy * s, s
    return z


@numba.njit(nogil=True, cache=True)
def surface_points(hm: np.ndarray, W: float, D: float, x: np.ndarray,
                   y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`surface_point` at ``x, y : (k,)``: ``(z (k,), normals (k, 3))``."""
    z = np.empty(x.shape[0])
    nrm = np.empty((x.shape[0], 3))
    for k in range(x.shape[0]):
        z[k] = surface_point(hm, W, D, x[k], y[k], nrm[k])
    return z, nrm


@numba.njit(nogil=True, cache=True)
def top_chart_points(hm: np.ndarray, W: float, D: float, w: int,
                     h: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and normals ``(w h, 3)`` of the top chart's texels, row by row (row 0 at
    ``Y = D``): texel ``(r, c)`` sits at ``((c + .5) W / w, D - (r + .5) D / h)`` on the
    surface."""
    pts = np.empty((w * h, 3))
    nrm = np.empty((w * h, 3))
    for r in range(h):
        y = D - (r + 0.5) * D / h
        for c in range(w):
            k = r * w + c
            x = (c + 0.5) * W / w
            pts[k, 0] = x
            pts[k, 1] = y
            pts[k, 2] = surface_point(hm, W, D, x, y, nrm[k])
    return pts, nrm


@numba.njit(nogil=True, cache=True)
def quad_faces(covered: np.ndarray, nxv: int, out: np.ndarray) -> int:
    """The two triangles (v00, v01, v11) and (v00, v11, v10) of every quad ``(j, i)`` of the
    vertex grid not ``covered : (nyv - 1, nxv - 1) bool`` by a merged block, as flat vertex-grid
    indices into ``out : (2 k, 3)``, row by row."""
    t = 0
    for j in range(covered.shape[0]):
        for i in range(covered.shape[1]):
            if covered[j, i]:
                continue
            v00 = j * nxv + i
            v10 = v00 + nxv
            out[t, 0], out[t, 1], out[t, 2] = v00, v00 + 1, v10 + 1
            out[t + 1, 0], out[t + 1, 1], out[t + 1, 2] = v00, v10 + 1, v10
            t += 2
    return t
