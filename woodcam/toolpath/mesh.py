"""Watertight mesh of a height-field stock: top surface, four walls, bottom (block frame, mm).

Vertex grid
-----------
The top surface's vertices sit on the cell centres of the height field plus one extra row/column
on each face of the stock (``X = 0``, ``X = W``, ``Y = 0``, ``Y = D``) carrying the height of the
nearest cell, so the top meets the walls exactly on the stock's faces. The vertex grid is
``(ny + 2) x (nx + 2)``; its ``(ny + 1) x (nx + 1)`` quads are split into two triangles each,
except where a quadtree finds aligned power-of-two blocks of quads that are planar (within
``flat_tol_mm``): such a block becomes a fan around its centre vertex through *every* grid vertex
on its perimeter. Because every block uses all grid vertices on its edges, neighbouring blocks of
any size share the same unit edges: no T-junctions, the mesh stays watertight, and for exactly
planar blocks (``flat_tol_mm`` ~ 0) the volume is unchanged by the merging.

The walls are quad strips between the boundary vertices and their copies at ``Z = 0``; the
bottom is a fan around ``(W/2, D/2, 0)``. Where the stock is cut through, the top surface lies
on ``Z = 0`` (zero-thickness), which keeps the mesh closed and its volume right.
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError


def _vertex_grid(heightmap, size_mm):
    ny, nx = heightmap.shape
    W, D, _ = size_mm
    dx, dy = W / nx, D / ny
    xs = np.concatenate([[0.0], (np.arange(nx) + 0.5) * dx, [W]])
    ys = np.concatenate([[0.0], (np.arange(ny) + 0.5) * dy, [D]])
    z = np.pad(np.asarray(heightmap, float), 1, mode="edge")
    return xs, ys, z


def _planar_levels(z, tol):
    """Planarity flags per quadtree level: ``levels[k] : (qy >> k, qx >> k) bool``."""
    qy, qx = z.shape[0] - 1, z.shape[1] - 1
    q0 = np.abs(z[:-1, :-1] + z[1:, 1:] - z[:-1, 1:] - z[1:, :-1]) <= tol
    levels = [q0]
    k = 1
    while (qy >> k) >= 1 and (qx >> k) >= 1:
        s = 1 << k
        by, bx = qy >> k, qx >> k
        prev = levels[-1][: by * 2, : bx * 2]
        kids = prev[0::2, 0::2] & prev[1::2, 0::2] & prev[0::2, 1::2] & prev[1::2, 1::2]
        if not kids.any():
            break
        c = lambda oy, ox: z[oy: oy + by * s: s, ox: ox + bx * s: s]  # noqa: E731
        c00, c01, c10, c11 = c(0, 0), c(0, s), c(s, 0), c(s, s)
        h = s // 2
        ok = np.abs(c00 + c11 - c01 - c10) <= tol
        for (oy, ox), (p, q) in {(0, h): (c00, c01), (s, h): (c10, c11), (h, 0): (c00, c10),
                                 (h, s): (c01, c11), (h, h): (c00, c11)}.items():
            ok &= np.abs(c(oy, ox) - 0.5 * (p + q)) <= tol
        levels.append(kids & ok)
        k += 1
    return levels


def heightfield_mesh(heightmap, size_mm, *, flat_tol_mm: float = 1e-9):
    """Watertight ``trimesh.Trimesh`` (block frame, mm) of the stock below ``heightmap``.

    Parameters
    ----------
    heightmap : (ny, nx) float
        Top of the stock at the cell centres, block-frame Z in mm (see
        :mod:`woodcam.toolpath.simulate`), values in ``[0, H]``.
    size_mm : (3,) float
        Stock size ``(W, D, H)``.
    flat_tol_mm : float
        Planarity tolerance for merging quads (module docstring). Larger values merge gently
        curved regions too, moving the surface by at most about this much per level.
    """
    import trimesh

    hm = np.asarray(heightmap, float)
    if hm.ndim != 2 or min(hm.shape) < 1:
        raise WoodcamError(f"heightfield_mesh: heightmap must be (ny, nx), got {hm.shape}")
    xs, ys, z = _vertex_grid(hm, size_mm)
    nyv, nxv = z.shape
    vid = np.arange(nyv * nxv).reshape(nyv, nxv)
    X, Y = np.meshgrid(xs, ys)
    verts = [np.column_stack([X.ravel(), Y.ravel(), z.ravel()])]
    faces = []

    # quadtree over the uniform interior (between cell centres); the half-cell border quads
    # (non-uniform spacing) stay plain quads. Interior vertex (j, i) is grid vertex (j+1, i+1).
    levels = _planar_levels(z[1:-1, 1:-1], flat_tol_mm) if min(nyv, nxv) > 3 else []
    qy, qx = nyv - 1, nxv - 1
    covered = np.zeros((qy, qx), bool)
    inner = covered[1:-1, 1:-1]
    for k in range(len(levels) - 1, 0, -1):
        s = 1 << k
        lev = levels[k]
        by, bx = lev.shape
        blk_cov = inner[: by * s, : bx * s].reshape(by, s, bx, s).any(axis=(1, 3))
        leaf = lev & ~blk_cov
        bj, bi = np.nonzero(leaf)
        if not len(bj):
            continue
        inner[: by * s, : bx * s] |= np.repeat(np.repeat(leaf, s, 0), s, 1)
        r = np.arange(s)
        # perimeter, counter-clockwise seen from +Z (row index grows with Y)
        pj = np.concatenate([np.zeros(s, int), r, np.full(s, s), s - r])
        pi = np.concatenate([r, np.full(s, s), s - r, np.zeros(s, int)])
        J = 1 + bj[:, None] * s + pj[None, :]
        I = 1 + bi[:, None] * s + pi[None, :]
        ring = vid[J, I]
        centre = vid[1 + bj * s + s // 2, 1 + bi * s + s // 2]
        nxt = np.roll(ring, -1, axis=1)
        faces.append(np.stack([np.broadcast_to(centre[:, None], ring.shape), ring, nxt],
                              axis=-1).reshape(-1, 3))
    qj, qi = np.nonzero(~covered)
    v00, v01 = vid[qj, qi], vid[qj, qi + 1]
    v10, v11 = vid[qj + 1, qi], vid[qj + 1, qi + 1]
    faces.append(np.column_stack([v00, v01, v11]))
    faces.append(np.column_stack([v00, v11, v10]))

    # walls and bottom
    bj_ = np.concatenate([np.zeros(nxv - 1, int), np.arange(nyv - 1), np.full(nxv - 1, nyv - 1),
                          np.arange(nyv - 1, 0, -1)])
    bi_ = np.concatenate([np.arange(nxv - 1), np.full(nyv - 1, nxv - 1), np.arange(nxv - 1, 0, -1),
                          np.zeros(nyv - 1, int)])
    top = vid[bj_, bi_]
    base = nyv * nxv
    P = len(top)
    bot = base + np.arange(P)
    verts.append(np.column_stack([xs[bi_], ys[bj_], np.zeros(P)]))
    centre = base + P
    W, D, _ = size_mm
    verts.append(np.array([[W / 2, D / 2, 0.0]]))
    tq, bq = np.roll(top, -1), np.roll(bot, -1)
    faces.append(np.column_stack([bot, bq, tq]))
    faces.append(np.column_stack([bot, tq, top]))
    faces.append(np.column_stack([np.full(P, centre), bq, bot]))
    mesh = trimesh.Trimesh(np.vstack(verts), np.vstack(faces), process=False)
    # drop vertices no face uses (interior of merged blocks) without merging coincident ones
    used = np.zeros(len(mesh.vertices), bool)
    used[mesh.faces.ravel()] = True
    remap = np.cumsum(used) - 1
    return trimesh.Trimesh(mesh.vertices[used], remap[mesh.faces], process=False)
