"""Numba kernels of the height-field stock view (:mod:`woodcam.view.stockview`): a z-buffer
triangle rasteriser, a deferred shading pass and a depth-tested line drawer.

Written by hand because the one renderer installed (VTK, through pyvista) costs ~1 s of imports
and ~2 s of off-screen rendering for one picture of a 1.6 M-triangle height field, more than the
whole simulation; a z-buffer over the height field's own grid needs no mesh at all. This module
imports only numpy, numba and the height field's surface (:mod:`woodcam.toolpath.surface`).

Conventions. ``cam : (16,) float64`` = camera position (3), right (3), up (3), forward (3, unit,
into the scene), focal length ``f`` in pixels, principal point ``(cx, cy)`` px, near distance
(mm). A block-frame point ``p`` maps to camera coordinates ``x = (p - pos) . right``,
``y = (p - pos) . up``, ``z = (p - pos) . forward`` (depth, mm) and to the pixel
``(cx + f x / z, cy - f y / z)`` (x right, y down, pixel ``(r, c)`` centred at ``(c + .5,
r + .5)``). Buffers are flat ``(h * w,)`` arrays: ``depth`` (camera z, ``inf`` where empty),
``pos`` ``(h * w, 3)`` the block-frame point seen, ``sid`` the surface id (``-1`` empty;
:data:`TOP` .. :data:`RIGHT` the stock's six charts, in the order of
:class:`woodcam.toolpath.mesh.HeightfieldCharts`).

The height field ``hm : (ny, nx)`` holds block-frame Z at cell centres over ``[0, W] x [0, D]``;
its surface is the vertex grid of :mod:`woodcam.toolpath.mesh` (cell centres plus a border row
and column on the stock's faces carrying the nearest cell's height, quads split v00-v01-v11 /
v00-v11-v10), drawn here without building it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..toolpath.surface import surface_point, vertex_x, vertex_z

TOP, BOTTOM, FRONT, BACK, LEFT, RIGHT = range(6)


@numba.njit(inline="always")
def _project(cam, x, y, z):
    dx, dy, dz = x - cam[0], y - cam[1], z - cam[2]
    xc = dx * cam[3] + dy * cam[4] + dz * cam[5]
    yc = dx * cam[6] + dy * cam[7] + dz * cam[8]
    zc = dx * cam[9] + dy * cam[10] + dz * cam[11]
    if zc <= cam[15]:
        return 0.0, 0.0, -1.0
    return cam[13] + cam[12] * xc / zc, cam[14] - cam[12] * yc / zc, zc


@numba.njit(nogil=True)
def _triangle(cam, clip, w, h, depth, pos, sid, s, ax, ay, az, bx, by, bz, qx, qy, qz,
              sx0, sy0, z0, sx1, sy1, z1, sx2, sy2, z2):
    """Draw one triangle (block-frame corners a, b, q, projected to ``(sx, sy, z)`` by
    :func:`_project`) of surface ``s`` into the buffers. Triangles facing away from the camera
    are skipped: the stock is closed with outward, counter-clockwise faces, and where the cut
    opens it the opaque section covers its inside. Fragments on the positive side of the plane
    ``clip = (nx, ny, nz, d)`` (n . p > d) are dropped (a cutaway), as are triangles with a
    corner behind the near distance."""
    if z0 <= 0.0 or z1 <= 0.0 or z2 <= 0.0:
        return
    area = (sx1 - sx0) * (sy2 - sy0) - (sy1 - sy0) * (sx2 - sx0)
    if area > -1e-12:  # facing away (y grows downwards: front faces have area < 0) or edge-on
        return
    c0 = max(0, int(math.ceil(min(sx0, sx1, sx2) - 0.5)))
    c1 = min(w - 1, int(math.floor(max(sx0, sx1, sx2) - 0.5)))
    r0 = max(0, int(math.ceil(min(sy0, sy1, sy2) - 0.5)))
    r1 = min(h - 1, int(math.floor(max(sy0, sy1, sy2) - 0.5)))
    if c1 < c0 or r1 < r0:
        return
    inv = 1.0 / area
    iz0, iz1, iz2 = 1.0 / z0, 1.0 / z1, 1.0 / z2
    # barycentrics are linear in the pixel: l_i = ga_i x + gb_i y + gc_i (a slanted sliver's
    # bounding box is mostly empty, so each row walks only its own span)
    ga0, gb0, gc0 = (sy1 - sy2) * inv, (sx2 - sx1) * inv, (sx1 * sy2 - sy1 * sx2) * inv
    ga1, gb1, gc1 = (sy2 - sy0) * inv, (sx0 - sx2) * inv, (sx2 * sy0 - sy2 * sx0) * inv
    ga2, gb2, gc2 = (sy0 - sy1) * inv, (sx1 - sx0) * inv, (sx0 * sy1 - sy0 * sx1) * inv
    eps = -1e-9
    for r in range(r0, r1 + 1):
        py = r + 0.5
        lo = c0 + 0.5
        hi = c1 + 0.5
        for ga, rest in ((ga0, gb0 * py + gc0), (ga1, gb1 * py + gc1), (ga2, gb2 * py + gc2)):
            if ga > 1e-15:
                lo = max(lo, (eps - rest) / ga)
            elif ga < -1e-15:
                hi = min(hi, (eps - rest) / ga)
            elif rest < eps:
                hi = -1.0
        if hi < lo:
            continue
        ca = max(c0, int(math.ceil(lo - 0.5)))
        cb = min(c1, int(math.floor(hi - 0.5)))
        for c in range(ca, cb + 1):
            px = c + 0.5
            l0 = ga0 * px + gb0 * py + gc0
            l1 = ga1 * px + gb1 * py + gc1
            l2 = ga2 * px + gb2 * py + gc2
            if l0 < eps or l1 < eps or l2 < eps:
                continue
            iz = l0 * iz0 + l1 * iz1 + l2 * iz2
            zc = 1.0 / iz
            k = r * w + c
            if zc >= depth[k]:
                continue
            b0, b1, b2 = l0 * iz0 * zc, l1 * iz1 * zc, l2 * iz2 * zc
            x = b0 * ax + b1 * bx + b2 * qx
            y = b0 * ay + b1 * by + b2 * qy
            z = b0 * az + b1 * bz + b2 * qz
            if clip[0] * x + clip[1] * y + clip[2] * z > clip[3]:
                continue
            depth[k] = zc
            pos[k, 0] = x
            pos[k, 1] = y
            pos[k, 2] = z
            sid[k] = s


@numba.njit(nogil=True, cache=True)
def draw_heightfield(hm, W, D, cam, clip, w, h, depth, pos, sid):
    """Rasterise the height field's top surface (surface :data:`TOP`): its ``(ny + 1) x
    (nx + 1)`` vertex-grid quads as two triangles each, every vertex projected once (two rows
    of projections kept)."""
    ny, nx = hm.shape
    nyv, nxv = ny + 2, nx + 2
    prev = np.empty((nxv, 3))
    cur = np.empty((nxv, 3))
    for j in range(nyv):
        y1 = vertex_x(j, nyv, D)
        for i in range(nxv):
            cur[i, 0], cur[i, 1], cur[i, 2] = _project(cam, vertex_x(i, nxv, W), y1,
                                                       vertex_z(hm, j, i))
        if j > 0:
            y0 = vertex_x(j - 1, nyv, D)
            for i in range(nxv - 1):
                x0, x1 = vertex_x(i, nxv, W), vertex_x(i + 1, nxv, W)
                z00, z01 = vertex_z(hm, j - 1, i), vertex_z(hm, j - 1, i + 1)
                z10, z11 = vertex_z(hm, j, i), vertex_z(hm, j, i + 1)
                _triangle(cam, clip, w, h, depth, pos, sid, TOP,
                          x0, y0, z00, x1, y0, z01, x1, y1, z11,
                          prev[i, 0], prev[i, 1], prev[i, 2], prev[i + 1, 0], prev[i + 1, 1],
                          prev[i + 1, 2], cur[i + 1, 0], cur[i + 1, 1], cur[i + 1, 2])
                _triangle(cam, clip, w, h, depth, pos, sid, TOP,
                          x0, y0, z00, x1, y1, z11, x0, y1, z10,
                          prev[i, 0], prev[i, 1], prev[i, 2], cur[i + 1, 0], cur[i + 1, 1],
                          cur[i + 1, 2], cur[i, 0], cur[i, 1], cur[i, 2])
        prev, cur = cur, prev


@numba.njit(nogil=True, cache=True)
def draw_triangles(tri, surface, cam, clip, w, h, depth, pos, sid):
    """Rasterise triangles ``tri : (m, 3, 3)`` (block frame, mm; counter-clockwise seen from
    outside) of surfaces ``surface : (m,) int``."""
    for t in range(tri.shape[0]):
        ax, ay, az = tri[t, 0, 0], tri[t, 0, 1], tri[t, 0, 2]
        bx, by, bz = tri[t, 1, 0], tri[t, 1, 1], tri[t, 1, 2]
        qx, qy, qz = tri[t, 2, 0], tri[t, 2, 1], tri[t, 2, 2]
        sx0, sy0, z0 = _project(cam, ax, ay, az)
        sx1, sy1, z1 = _project(cam, bx, by, bz)
        sx2, sy2, z2 = _project(cam, qx, qy, qz)
        _triangle(cam, clip, w, h, depth, pos, sid, surface[t], ax, ay, az, bx, by, bz,
                  qx, qy, qz, sx0, sy0, z0, sx1, sy1, z1, sx2, sy2, z2)


@numba.njit(inline="always")
def _bilinear(img, x0, y0, cw, ch, u, v, out):
    """Bilinear sample of the ``cw x ch`` rectangle of ``img`` at ``(x0, y0)`` at texel
    coordinates ``(u, v)`` inside it (texel centres at ``+ .5``), clamped to the rectangle."""
    u = min(max(u - 0.5, 0.0), cw - 1.0)
    v = min(max(v - 0.5, 0.0), ch - 1.0)
    i0 = min(int(u), cw - 1)
    j0 = min(int(v), ch - 1)
    i1 = min(i0 + 1, cw - 1)
    j1 = min(j0 + 1, ch - 1)
    fu, fv = u - i0, v - j0
    for k in range(3):
        a = img[y0 + j0, x0 + i0, k] * (1 - fu) + img[y0 + j0, x0 + i1, k] * fu
        b = img[y0 + j1, x0 + i0, k] * (1 - fu) + img[y0 + j1, x0 + i1, k] * fu
        out[k] = a * (1 - fv) + b * fv


@numba.njit(inline="always")
def _top_normal(hm, W, D, x, y, n):
    """Unit normal of the top at ``(x, y)``: the cells' central-difference gradients,
    interpolated bilinearly between cell centres (smooth shading, as the exported mesh's
    vertex normals)."""
    ny, nx = hm.shape
    dx, dy = W / nx, D / ny
    u = min(max(x / dx - 0.5, 0.0), nx - 1.0)
    v = min(max(y / dy - 0.5, 0.0), ny - 1.0)
    i0, j0 = min(int(u), nx - 1), min(int(v), ny - 1)
    fu, fv = u - i0, v - j0
    gx = 0.0
    gy = 0.0
    for dj in range(2):
        for di in range(2):
            j = min(j0 + dj, ny - 1)
            i = min(i0 + di, nx - 1)
            wgt = (fu if di else 1 - fu) * (fv if dj else 1 - fv)
            ia, ib = max(i - 1, 0), min(i + 1, nx - 1)
            ja, jb = max(j - 1, 0), min(j + 1, ny - 1)
            if ib > ia:
                gx += wgt * (hm[j, ib] - hm[j, ia]) / ((ib - ia) * dx)
            if jb > ja:
                gy += wgt * (hm[jb, i] - hm[ja, i]) / ((jb - ja) * dy)
    s = 1.0 / math.sqrt(gx * gx + gy * gy + 1.0)
    n[0], n[1], n[2] = -gx * s, -gy * s, s


@numba.njit(nogil=True, cache=True)
def shade(depth, pos, sid, w, h, cam, hm, size, atlas, charts, lights, material,
          section, section_axis, section_at, section_span, block_rgba, waste_alpha,
          background, out):
    """Colour every pixel: the lit stock (atlas texel times the light), the wood of the cut
    plane (unlit; opaque inside the stock, ``waste_alpha`` outside it), the block's faces
    (``block_rgba``, unlit, entry and exit), composited back to front over ``background``.

    ``charts : (6, 4) int`` the atlas rectangles ``(x0, y0, width, height)`` px of the six
    surfaces; ``lights : (k, 4)`` directions (block frame, unit, towards the light) and
    intensities; ``material = (ambient, diffuse, specular, specular power)``; ``section :
    (nv, nu, 3) float32`` the wood on the cut plane ``X`` / ``Y`` / ``Z = section_at``
    (``section_axis`` 0 / 1 / 2; ``-1``: none) sampled over its two other axes (in XYZ order)
    with ``section_span`` mm; ``depth`` is updated with the opaque section (for the lines drawn
    after). ``out : (h * w, 3) float32`` in 0..255.
    """
    W, D, H = size[0], size[1], size[2]
    col = np.empty(3)
    nrm = np.empty(3)
    sec = np.empty(3)
    scratch = np.empty(3)
    for r in range(h):
        for c in range(w):
            k = r * w + c
            # the pixel's ray: from the camera through the pixel centre, t = camera depth
            dxc = (c + 0.5 - cam[13]) / cam[12]
            dyc = -(r + 0.5 - cam[14]) / cam[12]
            rx = cam[9] + dxc * cam[3] + dyc * cam[6]
            ry = cam[10] + dxc * cam[4] + dyc * cam[7]
            rz = cam[11] + dxc * cam[5] + dyc * cam[8]
            zc = depth[k]
            s = sid[k]
            if s >= 0:
                x, y, z = pos[k, 0], pos[k, 1], pos[k, 2]
                if s == TOP:
                    u, v = x / W, (D - y) / D
                    _top_normal(hm, W, D, x, y, nrm)
                elif s == BOTTOM:
                    u, v = x / W, y / D
                    nrm[0], nrm[1], nrm[2] = 0.0, 0.0, -1.0
                elif s == FRONT:
                    u, v = x / W, (H - z) / H
                    nrm[0], nrm[1], nrm[2] = 0.0, -1.0, 0.0
                elif s == BACK:
                    u, v = (W - x) / W, (H - z) / H
                    nrm[0], nrm[1], nrm[2] = 0.0, 1.0, 0.0
                elif s == LEFT:
                    u, v = (D - y) / D, (H - z) / H
                    nrm[0], nrm[1], nrm[2] = -1.0, 0.0, 0.0
                else:
                    u, v = y / D, (H - z) / H
                    nrm[0], nrm[1], nrm[2] = 1.0, 0.0, 0.0
                cw, ch = charts[s, 2], charts[s, 3]
                _bilinear(atlas, charts[s, 0], charts[s, 1], cw, ch, u * cw, v * ch, col)
                # Lambert + Phong over the lights; the viewer looks along -ray
                lr = math.sqrt(rx * rx + ry * ry + rz * rz)
                vx, vy, vz = -rx / lr, -ry / lr, -rz / lr
                if nrm[0] * vx + nrm[1] * vy + nrm[2] * vz < 0:  # seen from behind
                    nrm[0], nrm[1], nrm[2] = -nrm[0], -nrm[1], -nrm[2]
                diff = 0.0
                spec = 0.0
                for li in range(lights.shape[0]):
                    lx, ly, lz, li_i = lights[li, 0], lights[li, 1], lights[li, 2], lights[li, 3]
                    nl = nrm[0] * lx + nrm[1] * ly + nrm[2] * lz
                    if nl <= 0:
                        continue
                    diff += li_i * nl
                    # reflection of the light about the normal, against the view direction
                    rvx, rvy, rvz = 2 * nl * nrm[0] - lx, 2 * nl * nrm[1] - ly, 2 * nl * nrm[2] - lz
                    rv = rvx * vx + rvy * vy + rvz * vz
                    if rv > 0:
                        spec += li_i * rv ** material[3]
                lit = material[0] + material[1] * diff
                for ch_ in range(3):
                    col[ch_] = min(255.0, col[ch_] * lit + 255.0 * material[2] * spec)
            else:
                col[0], col[1], col[2] = background[0], background[1], background[2]
            # the cut plane
            if section_axis >= 0:
                o = cam[section_axis]
                d = rx if section_axis == 0 else (ry if section_axis == 1 else rz)
                if abs(d) > 1e-12:
                    t = (section_at - o) / d  # camera depth of the plane along the ray
                    if 0 < t < zc:
                        qx, qy, qz = cam[0] + t * rx, cam[1] + t * ry, cam[2] + t * rz
                        if (-1e-9 <= qx <= W + 1e-9 and -1e-9 <= qy <= D + 1e-9
                                and -1e-9 <= qz <= H + 1e-9):
                            if section_axis == 0:
                                su, sv, inside = qy, qz, qz <= surface_point(hm, W, D, qx, qy, scratch)
                            elif section_axis == 1:
                                su, sv, inside = qx, qz, qz <= surface_point(hm, W, D, qx, qy, scratch)
                            else:
                                su, sv, inside = qx, qy, surface_point(hm, W, D, qx, qy, scratch) >= qz
                            nv, nu = section.shape[0], section.shape[1]
                            _bilinear(section, 0, 0, nu, nv,
                                      su / section_span[0] * (nu - 1) + 0.5,
                                      sv / section_span[1] * (nv - 1) + 0.5, sec)
                            if inside:
                                col[0], col[1], col[2] = sec[0], sec[1], sec[2]
                                zc = t
                                depth[k] = t
                            else:
                                for ch_ in range(3):
                                    col[ch_] += waste_alpha * (sec[ch_] - col[ch_])
            # the block's faces, translucent: the exit face behind the plane, the entry face
            # in front (the plane's waste lies between them)
            if block_rgba[3] > 0:
                t0, t1 = -1e300, 1e300
                hit = True
                for a in range(3):
                    o = cam[a]
                    d = rx if a == 0 else (ry if a == 1 else rz)
                    if abs(d) < 1e-15:
                        if o < 0 or o > size[a]:
                            hit = False
                        continue
                    ta, tb = (0.0 - o) / d, (size[a] - o) / d
                    if ta > tb:
                        ta, tb = tb, ta
                    t0, t1 = max(t0, ta), min(t1, tb)
                if hit and t0 <= t1:
                    # a block face on the stock's own face (an uncut top, the walls) is not
                    # in front of it: only faces clearly nearer tint (no z-fighting speckle)
                    front = zc * (1.0 - 1e-5) - 1e-3
                    for t in (t1, t0):
                        if 0 < t < front:
                            for ch_ in range(3):
                                col[ch_] += block_rgba[3] * (block_rgba[ch_] - col[ch_])
            out[k, 0], out[k, 1], out[k, 2] = col[0], col[1], col[2]


@numba.njit(nogil=True, cache=True)
def draw_lines(seg, rgb, alpha, width, bias, cam, w, h, depth, out):
    """Blend segments ``seg : (k, 2, 3)`` (block frame, mm) into ``out : (h * w, 3)`` in
    ``rgb`` with ``alpha``, ``width`` px wide, where they lie at least ``bias`` mm in front of
    ``depth`` (a negative ``bias`` lets lines on a surface show). Dots every half pixel,
    depth interpolated perspective-correctly; a pixel is painted once per call."""
    painted = np.zeros(h * w, np.bool_)
    half = (width - 1) // 2
    for s in range(seg.shape[0]):
        sx0, sy0, z0 = _project(cam, seg[s, 0, 0], seg[s, 0, 1], seg[s, 0, 2])
        sx1, sy1, z1 = _project(cam, seg[s, 1, 0], seg[s, 1, 1], seg[s, 1, 2])
        if z0 <= 0 or z1 <= 0:
            continue
        length = math.sqrt((sx1 - sx0) ** 2 + (sy1 - sy0) ** 2)
        if length > 4.0 * (w + h):  # far outside the picture: no dots along it
            continue
        n = max(1, int(math.ceil(2 * length)))
        for q in range(n + 1):
            f = q / n
            px = sx0 + f * (sx1 - sx0)
            py = sy0 + f * (sy1 - sy0)
            zc = 1.0 / ((1 - f) / z0 + f / z1)
            c0, r0 = int(math.floor(px)), int(math.floor(py))
            for dr in range(-half, width - half):
                r = r0 + dr
                if r < 0 or r >= h:
                    continue
                for dc in range(-half, width - half):
                    c = c0 + dc
                    if c < 0 or c >= w:
                        continue
                    k = r * w + c
                    if painted[k] or zc > depth[k] - bias:
                        continue
                    painted[k] = True
                    for ch in range(3):
                        out[k, ch] += alpha * (rgb[ch] - out[k, ch])
