"""Exact reference for the height-field simulation: manifold3d booleans (tests, benchmarks).

A tool is convex, so the solid it sweeps along a straight move is exactly the convex hull of the
tool at the move's two ends. The reference stock is the box minus the union of those hulls
(``Manifold.batch_boolean``). Its only approximation is the tool's revolution into
``segments`` facets (a 64-gon's inscribed area is 0.16 % below the circle's), which is why the
tests compare volumes at 0.5 %.
"""

from __future__ import annotations

import numpy as np

from .gcode import Program
from .simulate import tool_lookup


def reference_stock(program: Program, tools, size_mm, *, work_offset_mm=None, segments: int = 96):
    """Remaining stock as a ``manifold3d.Manifold`` in the block frame (mm).

    Same arguments as :func:`woodcam.toolpath.simulate`; moves entirely above the stock are
    skipped (they cannot remove material).
    """
    from manifold3d import Manifold, OpType

    W, D, H = map(float, size_mm)
    off = np.array([0.0, 0.0, H]) if work_offset_mm is None else np.asarray(work_offset_mm, float)
    lookup = tool_lookup(program, tools)
    p0, p1 = program.start_mm + off, program.end_mm + off
    zmin = np.minimum(p0[:, 2], p1[:, 2])
    hulls = []
    solids = {}
    for k in np.flatnonzero(zmin < H):
        t = int(program.tool[k])
        top = H - zmin[k] + 1.0
        key = (t, round(top, 3))
        if key not in solids:
            solids[key] = lookup[t].solid(top, segments)
        s = solids[key]
        a, b = p0[k], p1[k]
        if np.allclose(a, b):
            hulls.append(s.translate(tuple(a)))
        else:
            hulls.append(Manifold.batch_hull([s.translate(tuple(a)), s.translate(tuple(b))]))
    stock = Manifold.cube((W, D, H))
    if not hulls:
        return stock
    return stock - Manifold.batch_boolean(hulls, OpType.Add)


def manifold_heightmap(solid, size_mm, shape) -> np.ndarray:
    """Top of a z-monotone solid at the cell centres of a ``shape = (ny, nx)`` grid (mm).

    Rasterises the solid's upward-facing triangles (vectorised barycentric test); cells no
    triangle covers (cut through) get 0.
    """
    from .._manifold import manifold_arrays

    v, f = manifold_arrays(solid)
    ny, nx = shape
    W, D, _ = map(float, size_mm)
    dx, dy = W / nx, D / ny
    tri = v[f]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    nz = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    tri = tri[nz > 1e-12]
    out = np.zeros(ny * nx)
    lo = np.ceil(tri[:, :, :2].min(axis=1) / (dx, dy) - 0.5 - 1e-9).astype(np.int64)
    hi = np.floor(tri[:, :, :2].max(axis=1) / (dx, dy) - 0.5 + 1e-9).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, (nx - 1, ny - 1))
    cnt_x, cnt_y = np.maximum(hi[:, 0] - lo[:, 0] + 1, 0), np.maximum(hi[:, 1] - lo[:, 1] + 1, 0)
    for start in range(0, len(tri), 20000):  # bounded memory
        sl = slice(start, start + 20000)
        cx, cy = cnt_x[sl], cnt_y[sl]
        n = cx * cy
        t_id = np.repeat(np.arange(len(n)), n)
        first = np.cumsum(n) - n
        local = np.arange(n.sum()) - first[t_id]
        ii = lo[sl][t_id, 0] + local % cx[t_id]
        jj = lo[sl][t_id, 1] + local // cx[t_id]
        px, py = (ii + 0.5) * dx, (jj + 0.5) * dy
        T = tri[sl][t_id]
        x0, y0 = T[:, 0, 0], T[:, 0, 1]
        a1, b1 = T[:, 1, 0] - x0, T[:, 1, 1] - y0
        a2, b2 = T[:, 2, 0] - x0, T[:, 2, 1] - y0
        det = a1 * b2 - a2 * b1
        u = ((px - x0) * b2 - (py - y0) * a2) / det
        w = (a1 * (py - y0) - b1 * (px - x0)) / det
        inside = (u >= -1e-9) & (w >= -1e-9) & (u + w <= 1 + 1e-9)
        z = T[:, 0, 2] + u * (T[:, 1, 2] - T[:, 0, 2]) + w * (T[:, 2, 2] - T[:, 0, 2])
        np.maximum.at(out, (jj * nx + ii)[inside], z[inside])
    return out.reshape(ny, nx)
