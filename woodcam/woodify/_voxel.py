"""Compiled kernels: a triangle mesh on a voxel grid (narrow-band distance, inside test), and
grids sampled at points (the field, the back-trace).

Grid convention (the whole package): samples sit on grid NODES, node ``(i, j, k)`` at
``origin_mm + (i, j, k) * h`` (mm, block frame), arrays indexed ``[i, j, k]`` = ``[x, y, z]``.

Written by hand because no installed library gives a narrow-band signed distance with the
closest triangle for 20k triangles on 2M nodes in well under a second: trimesh's proximity
queries cost ~0.1 ms per point, and the inside test by ray parity needs exactly one pass over
the triangles here (Bridson's ``makelevelset3`` scheme).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _closest_on_triangle(px, py, pz, a, b, c):  # pragma: no cover - compiled
    """Closest point on triangle ``abc`` to ``p`` (Ericson, Real-Time Collision Detection 5.1.5)."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    apx, apy, apz = px - a[0], py - a[1], pz - a[2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return a[0], a[1], a[2]
    bpx, bpy, bpz = px - b[0], py - b[1], pz - b[2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return b[0], b[1], b[2]
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return a[0] + v * abx, a[1] + v * aby, a[2] + v * abz
    cpx, cpy, cpz = px - c[0], py - c[1], pz - c[2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return c[0], c[1], c[2]
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return a[0] + w * acx, a[1] + w * acy, a[2] + w * acz
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return a[0] + abx * v + acx * w, a[1] + aby * v + acy * w, a[2] + abz * v + acz * w


@numba.njit(cache=True, nogil=True)
def band_distance(verts, faces, origin, h, shape, band):  # pragma: no cover - compiled
    """Unsigned distance (mm) and closest point within ``band`` nodes of every triangle.

    Returns ``dist (nx, ny, nz) float64`` (``inf`` beyond the band), ``closest (nx, ny, nz, 3)
    float32`` (closest surface point, mm) and ``tri (nx, ny, nz) int32`` (its triangle, -1).
    """
    nx, ny, nz = shape[0], shape[1], shape[2]
    dist = np.full((nx, ny, nz), np.inf)
    closest = np.zeros((nx, ny, nz, 3), np.float32)
    tri = np.full((nx, ny, nz), -1, np.int32)
    for f in range(faces.shape[0]):
        a = verts[faces[f, 0]]
        b = verts[faces[f, 1]]
        c = verts[faces[f, 2]]
        lo = np.empty(3, np.int64)
        hi = np.empty(3, np.int64)
        for d in range(3):
            mn = min(a[d], b[d], c[d])
            mx = max(a[d], b[d], c[d])
            lo[d] = max(int(np.floor((mn - origin[d]) / h)) - band, 0)
            hi[d] = min(int(np.ceil((mx - origin[d]) / h)) + band, shape[d] - 1)
        for i in range(lo[0], hi[0] + 1):
            px = origin[0] + i * h
            for j in range(lo[1], hi[1] + 1):
                py = origin[1] + j * h
                for k in range(lo[2], hi[2] + 1):
                    pz = origin[2] + k * h
                    qx, qy, qz = _closest_on_triangle(px, py, pz, a, b, c)
                    dd = np.sqrt((px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2)
                    if dd < dist[i, j, k]:
                        dist[i, j, k] = dd
                        closest[i, j, k, 0] = qx
                        closest[i, j, k, 1] = qy
                        closest[i, j, k, 2] = qz
                        tri[i, j, k] = f
    limit = band * h
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                if dist[i, j, k] > limit:
                    dist[i, j, k] = np.inf
                    tri[i, j, k] = -1
    return dist, closest, tri


def inside_parity(verts, faces, origin, h, shape, face_sign=None):
    """Inside test of a closed mesh on the grid nodes: a node is inside where a ray along +X
    crosses its triangles an odd number of times, or where the shells it lies in wind round it
    (winding number > 0).

    Every node line ``(j, k)`` is a ray along X; each triangle it crosses flips the parity, and
    adds its orientation (``face_sign`` (m,) +-1 times the side it is crossed from: +1 entering
    a shell wound outward) to the winding, from the crossing on. Parity alone made the overlap
    of two closed shells (two bodies of one file, unmerged: a mug and its handle) outside, wood
    grown inside the part; the winding alone would drop a shell wound inside out among others.
    A cavity (an inner shell wound inward) stays outside by both. ``face_sign`` None: the faces'
    own winding, the mesh turned outward where its volume is negative. The line is nudged by an
    irrational fraction of a node so that vertices and edges on grid lines (an axis-aligned box)
    are never hit exactly. Meshes may extend beyond the grid. Returns ``inside (nx, ny, nz)
    bool``."""
    verts = np.ascontiguousarray(verts, np.float64)
    faces = np.ascontiguousarray(faces, np.int64)
    if face_sign is None:
        from trimesh.triangles import mass_properties  # the winding's signed volume, < 0 inside out

        volume = mass_properties(verts[faces], skip_inertia=True)["volume"]
        face_sign = np.full(len(faces), -1 if volume < 0 else 1, np.int64)
    return _inside(verts, faces, np.ascontiguousarray(face_sign, np.int64), np.asarray(origin, np.float64),
                   float(h), np.asarray(shape, np.int64))


@numba.njit(cache=True, nogil=True)
def _inside(verts, faces, face_sign, origin, h, shape):  # pragma: no cover - compiled
    nx, ny, nz = shape[0], shape[1], shape[2]
    flips = np.zeros((nx + 1, ny, nz), np.int32)
    wind = np.zeros((nx + 1, ny, nz), np.int32)
    ey = h * 1.2345e-6
    ez = h * 2.7183e-6
    for f in range(faces.shape[0]):
        a = verts[faces[f, 0]]
        b = verts[faces[f, 1]]
        c = verts[faces[f, 2]]
        jlo = max(int(np.ceil((min(a[1], b[1], c[1]) - origin[1] - ey) / h)), 0)
        jhi = min(int(np.floor((max(a[1], b[1], c[1]) - origin[1] - ey) / h)), ny - 1)
        klo = max(int(np.ceil((min(a[2], b[2], c[2]) - origin[2] - ez) / h)), 0)
        khi = min(int(np.floor((max(a[2], b[2], c[2]) - origin[2] - ez) / h)), nz - 1)
        for j in range(jlo, jhi + 1):
            y = origin[1] + j * h + ey
            for k in range(klo, khi + 1):
                z = origin[2] + k * h + ez
                # 2D barycentric coordinates of (y, z) in the projected triangle
                d0 = (b[1] - y) * (c[2] - z) - (b[2] - z) * (c[1] - y)
                d1 = (c[1] - y) * (a[2] - z) - (c[2] - z) * (a[1] - y)
                d2 = (a[1] - y) * (b[2] - z) - (a[2] - z) * (b[1] - y)
                if not ((d0 > 0 and d1 > 0 and d2 > 0) or (d0 < 0 and d1 < 0 and d2 < 0)):
                    continue
                s = d0 + d1 + d2
                x = (d0 * a[0] + d1 * b[0] + d2 * c[0]) / s
                i = int(np.ceil((x - origin[0]) / h))
                i = max(i, 0)
                if i <= nx:
                    flips[i, j, k] += 1
                    wind[i, j, k] += face_sign[f] * (-1 if s > 0 else 1)
    inside = np.zeros((nx, ny, nz), np.bool_)
    for j in range(ny):
        for k in range(nz):
            acc = 0
            w = 0
            for i in range(nx):
                acc += flips[i, j, k]
                w += wind[i, j, k]
                inside[i, j, k] = (acc & 1) == 1 or w > 0
    return inside


@numba.njit(cache=True, nogil=True)
def trilinear(grid, origin, h, points):  # pragma: no cover - compiled
    """Trilinear interpolation of node values ``grid (nx, ny, nz)`` at ``points (n, 3)`` (mm);
    points beyond the grid clamp to its border (scipy's ``mode="nearest"``). One compiled pass:
    ``map_coordinates`` spends most of its time on per-point overhead for order 1."""
    nx, ny, nz = grid.shape
    out = np.empty(points.shape[0], np.float64)
    for n in range(points.shape[0]):
        x = min(max((points[n, 0] - origin[0]) / h, 0.0), nx - 1.0)
        y = min(max((points[n, 1] - origin[1]) / h, 0.0), ny - 1.0)
        z = min(max((points[n, 2] - origin[2]) / h, 0.0), nz - 1.0)
        i = min(int(x), nx - 2)
        j = min(int(y), ny - 2)
        k = min(int(z), nz - 2)
        fx, fy, fz = x - i, y - j, z - k
        c00 = grid[i, j, k] * (1 - fx) + grid[i + 1, j, k] * fx
        c10 = grid[i, j + 1, k] * (1 - fx) + grid[i + 1, j + 1, k] * fx
        c01 = grid[i, j, k + 1] * (1 - fx) + grid[i + 1, j, k + 1] * fx
        c11 = grid[i, j + 1, k + 1] * (1 - fx) + grid[i + 1, j + 1, k + 1] * fx
        out[n] = (c00 * (1 - fy) + c10 * fy) * (1 - fz) + (c01 * (1 - fy) + c11 * fy) * fz
    return out


@numba.njit(cache=True, nogil=True)
def sample_linear4(g0, g1, g2, g3, q):  # pragma: no cover - compiled
    """Four grids ``(nx, ny, nz) float32`` sampled at the fractional node coordinates ``q
    (n, 3) float64``: ``(4, n) float32``, each row bit for bit
    ``scipy.ndimage.map_coordinates(g, q.T, order=1, mode="nearest")``.

    The back-trace of :func:`woodcam.woodify.surfaces.trace_back` samples the arrival time and
    its three partial derivatives at the same points every step: four map_coordinates calls
    worked out the same corners and weights four times, and cost a quarter of a crack run at
    resolution 200. Here once, in scipy's arithmetic (``ni_interpolation.c``: coordinates
    clamped to ``[0, len - 1]``, weights ``w0 = 1 - frac``, ``w1 = 1 - w0``, a corner beyond the
    last node mirrored onto ``len - 2`` with weight 0, corners summed last axis fastest as
    ``value * wx * wy * wz`` in float64, then rounded to float32), so the traces, and the cracks,
    stay the same bytes; :func:`trilinear`'s nested lerps round differently.
    """
    n = q.shape[0]
    out = np.empty((4, n), np.float32)
    nx, ny, nz = g0.shape
    f0, f1, f2, f3 = g0.ravel(), g1.ravel(), g2.ravel(), g3.ravel()
    off = np.empty(8, np.int64)
    for p in range(n):
        x0, x1, wx0, wx1 = _axis(q[p, 0], nx)
        y0, y1, wy0, wy1 = _axis(q[p, 1], ny)
        z0, z1, wz0, wz1 = _axis(q[p, 2], nz)
        k = 0
        for xi, wx in ((x0, wx0), (x1, wx1)):
            for yi, wy in ((y0, wy0), (y1, wy1)):
                for zi, wz in ((z0, wz0), (z1, wz1)):
                    off[k] = (xi * ny + yi) * nz + zi
                    k += 1
        t0 = t1 = t2 = t3 = 0.0
        k = 0
        for wx in (wx0, wx1):
            for wy in (wy0, wy1):
                for wz in (wz0, wz1):
                    o = off[k]
                    t0 += float(f0[o]) * wx * wy * wz
                    t1 += float(f1[o]) * wx * wy * wz
                    t2 += float(f2[o]) * wx * wy * wz
                    t3 += float(f3[o]) * wx * wy * wz
                    k += 1
        out[0, p] = np.float32(t0)
        out[1, p] = np.float32(t1)
        out[2, p] = np.float32(t2)
        out[3, p] = np.float32(t3)
    return out


@numba.njit(cache=True, nogil=True, inline="always")
def _axis(c, ln):  # pragma: no cover - compiled
    """Lower and upper node and their weights along one axis, as scipy's order-1 'nearest'."""
    if c < 0:
        c = 0.0
    elif c > ln - 1:
        c = float(ln - 1)
    s = int(np.floor(c))
    w0 = 1.0 - (c - np.floor(c))
    return s, (s + 1 if s + 1 < ln else ln - 2), w0, 1.0 - w0
