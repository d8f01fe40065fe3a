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
from .._types import ArrayLike, Mesh


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


#: Order of the faces :func:`_heightfield_arrays` emits, one contiguous run per chart.
_CHART_ORDER = ("top", "front", "right", "back", "left", "bottom")


def _heightfield_arrays(grid, size_mm, flat_tol_mm):
    """The closed surface of :func:`heightfield_mesh` over the vertex grid ``grid = (xs, ys,
    z)`` of :func:`_vertex_grid` (the caller builds it once) as arrays, built without trimesh and
    with few full-grid temporaries (the 167 x 208 mm relief's 3.5 M-vertex grid took 490 MB
    through trimesh): ``(vertices (n, 3) float64, faces (m, 3) int64, grid_index (n,) int64,
    runs)``. ``grid_index`` is each vertex's flat index into the ``(ny + 2) x (nx + 2)``
    vertex grid (``-1`` for the bottom ring and centre); ``runs`` maps each name of
    :data:`_CHART_ORDER` to its face range ``(start, stop)``."""
    from .surface import quad_faces

    xs, ys, z = grid
    nyv, nxv = z.shape
    fans = []

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
        ring = (1 + bj[:, None] * s + pj[None, :]) * nxv + 1 + bi[:, None] * s + pi[None, :]
        centre = (1 + bj * s + s // 2) * nxv + 1 + bi * s + s // 2
        nxt = np.roll(ring, -1, axis=1)
        fans.append(np.stack([np.broadcast_to(centre[:, None], ring.shape), ring, nxt],
                             axis=-1).reshape(-1, 3))
    n_fan = sum(len(f) for f in fans)
    n_quads = int(covered.size - np.count_nonzero(covered))

    # walls (quad strips from the boundary vertices down to their copies at Z = 0), wall by
    # wall, then the bottom fan
    bj_ = np.concatenate([np.zeros(nxv - 1, int), np.arange(nyv - 1), np.full(nxv - 1, nyv - 1),
                          np.arange(nyv - 1, 0, -1)])
    bi_ = np.concatenate([np.arange(nxv - 1), np.full(nyv - 1, nxv - 1), np.arange(nxv - 1, 0, -1),
                          np.zeros(nyv - 1, int)])
    top = bj_ * nxv + bi_
    base = nyv * nxv
    P = len(top)
    bot = base + np.arange(P)
    centre = base + P
    tq, bq = np.roll(top, -1), np.roll(bot, -1)
    n_top = n_fan + 2 * n_quads
    faces = np.empty((n_top + 3 * P, 3), np.int64)
    at = 0
    for f in fans:
        faces[at:at + len(f)] = f
        at += len(f)
    quad_faces(covered, nxv, faces[at:n_top])
    runs = {"top": (0, n_top)}
    at = n_top
    walls = np.cumsum([0, nxv - 1, nyv - 1, nxv - 1, nyv - 1])
    for name, lo, hi in zip(("front", "right", "back", "left"), walls[:-1], walls[1:]):
        k = hi - lo
        faces[at:at + k] = np.column_stack([bot[lo:hi], bq[lo:hi], tq[lo:hi]])
        faces[at + k:at + 2 * k] = np.column_stack([bot[lo:hi], tq[lo:hi], top[lo:hi]])
        runs[name] = (at, at + 2 * k)
        at += 2 * k
    faces[at:] = np.column_stack([np.full(P, centre), bq, bot])
    runs["bottom"] = (at, at + P)

    # keep only the vertices some face uses (the interiors of merged blocks go), renumbered
    used = np.zeros(base + P + 1, bool)
    used[faces.ravel()] = True
    keep = np.flatnonzero(used)
    remap = np.cumsum(used) - 1
    np.take(remap, faces, out=faces)
    del remap, used
    grid = keep[keep < base]
    W, D, _ = size_mm
    verts = np.empty((len(keep), 3))
    g = len(grid)
    verts[:g, 0] = xs[grid % nxv]
    verts[:g, 1] = ys[grid // nxv]
    verts[:g, 2] = z.ravel()[grid]
    extra = keep[g:] - base  # bottom ring (0 .. P-1) and the centre (P)
    ring = extra < P
    verts[g:, 0] = np.where(ring, xs[bi_[np.minimum(extra, P - 1)]], W / 2)
    verts[g:, 1] = np.where(ring, ys[bj_[np.minimum(extra, P - 1)]], D / 2)
    verts[g:, 2] = 0.0
    grid_index = np.full(len(keep), -1, np.int64)
    grid_index[:g] = grid
    return verts, faces, grid_index, runs


def heightfield_mesh(heightmap: ArrayLike, size_mm: ArrayLike, *, flat_tol_mm: float = 1e-9) -> Mesh:
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
    verts, faces, _, _ = _heightfield_arrays(_vertex_grid(hm, size_mm), size_mm, flat_tol_mm)
    return trimesh.Trimesh(verts, faces, process=False)


#: Texels between charts of the height-field atlas (the bake's dilation fills them).
_CHART_PAD_PX = 8

#: Texel density of the walls and of the bottom as a share of the top's (per axis). The top is
#: where the toolpath left its detail and what every view looks at; the walls are the sawn
#: block's flat faces (a quarter of the texels at 0.5: 0.2 mm texels at the default 10 per mm,
#: still several per latewood band), and the bottom is seen only when the model is turned over.
#: On the 100 x 80 x 30 mm raster this cuts the wood colour lookups from 2.7 M to 1.1 M.
WALL_TEXEL_SHARE = 0.5
BOTTOM_TEXEL_SHARE = 0.25


class HeightfieldCharts:
    """Planar texture charts of a height-field stock (its own parameterisation, no unwrap).

    Six charts: the top seen from +Z (texel = XY) at ``texels_per_mm``, the bottom (at
    :data:`BOTTOM_TEXEL_SHARE` of it) and the four walls (texel = position along the wall, Z;
    at :data:`WALL_TEXEL_SHARE`). The top sits at the atlas's top-left corner, the others in
    columns to its right. ``uv_px : (n, 2)`` are the mesh vertices' texel coordinates (x right,
    y down, pixel corners at integers), ``size_px = (width, height)`` the atlas.
    :meth:`texel_points` gives every chart texel's block-frame point and normal, exactly on the
    mesh (the top is the vertex grid's triangles, split as in :func:`heightfield_mesh`).
    """

    def __init__(self, heightmap, size_mm, texels_per_mm):
        W, D, H = (float(v) for v in size_mm)
        self.size_mm = (W, D, H)
        self.hm = np.asarray(heightmap, float)
        t = float(texels_per_mm)

        def px(mm, share):
            return max(1, int(np.ceil(mm * t * share)))

        wall, bottom = WALL_TEXEL_SHARE, BOTTOM_TEXEL_SHARE
        # chart: name -> (origin x, origin y, width px, height px, span u mm, span v mm)
        sizes = {"top": (px(W, 1), px(D, 1), W, D),
                 "bottom": (px(W, bottom), px(D, bottom), W, D),
                 "front": (px(W, wall), px(H, wall), W, H), "back": (px(W, wall), px(H, wall), W, H),
                 "left": (px(D, wall), px(H, wall), D, H), "right": (px(D, wall), px(H, wall), D, H)}
        pad = _CHART_PAD_PX
        tw, th = sizes["top"][:2]
        charts = {"top": (pad, pad, tw, th, W, D)}
        # the others top to bottom in columns right of the top, a new column when one would
        # grow taller than the top (or the tallest chart)
        limit = max(th, max(h for _, h, _, _ in sizes.values()))
        x0, y0, col_w = pad + tw + pad, pad, 0
        for name, (w, h, su, sv) in sizes.items():
            if name == "top":
                continue
            if y0 > pad and y0 + h > pad + limit:
                x0, y0, col_w = x0 + col_w + pad, pad, 0
            charts[name] = (x0, y0, w, h, su, sv)
            y0 += h + pad
            col_w = max(col_w, w)
        self.charts = charts
        self.size_px = (max(c[0] + c[2] for c in charts.values()) + pad,
                        max(c[1] + c[3] for c in charts.values()) + pad)

    def fill_gutters(self, atlas, coverage):
        """Paint the texels outside the charts of ``atlas : (h, w, 3)``: a ring of half the
        :data:`_CHART_PAD_PX` gap around each chart with its nearest chart texel (clamped
        coordinates: the nearest point of a rectangle), the unused rest with the charts' mean
        colour. Within the rings this is what the general nearest-texel transform
        (:func:`woodcam.bake.bake`'s dilation) paints, at a fraction of its cost."""
        out = atlas.copy()
        filled = coverage.copy()
        hh, ww = atlas.shape[:2]
        pad = _CHART_PAD_PX // 2  # charts are _CHART_PAD_PX apart: each paints half the gap
        for x0, y0, w, h, _su, _sv in self.charts.values():
            ya, yb = max(0, y0 - pad), min(hh, y0 + h + pad)
            xa, xb = max(0, x0 - pad), min(ww, x0 + w + pad)
            x1, y1 = x0 + w, y0 + h
            # the ring lies in the gutter between charts (charts are pad apart): strips
            # repeat the edge rows/columns, then the rows above/below repeat the widened edge
            out[y0:y1, xa:x0] = out[y0:y1, x0:x0 + 1]
            out[y0:y1, x1:xb] = out[y0:y1, x1 - 1:x1]
            out[ya:y0, xa:xb] = out[y0:y0 + 1, xa:xb]
            out[y1:yb, xa:xb] = out[y1 - 1:y1, xa:xb]
            filled[ya:yb, xa:xb] = True
        if not filled.all():
            out[~filled] = atlas[coverage].mean(axis=0).round().astype(atlas.dtype)
        return out

    def uv(self, name, u_mm, v_mm):
        """Texel coordinates of chart ``name`` at ``(u, v)`` mm (v measured downwards)."""
        x0, y0, w, h, su, sv = self.charts[name]
        return np.column_stack([x0 + np.asarray(u_mm) * (w / su), y0 + np.asarray(v_mm) * (h / sv)])

    def texel_points(self):
        """Yield ``(flat texel indices (k,), points_mm (k, 3), normals (k, 3))`` per chart."""
        W, D, H = self.size_mm
        width = self.size_px[0]
        for name, (x0, y0, w, h, su, sv) in self.charts.items():
            ii, jj = np.meshgrid(np.arange(w), np.arange(h))
            u = (ii.ravel() + 0.5) * (su / w)
            v = (jj.ravel() + 0.5) * (sv / h)
            idx = (y0 + jj.ravel()) * width + x0 + ii.ravel()
            n = len(u)
            nrm = np.zeros((n, 3))
            if name == "top":
                from .surface import top_chart_points

                pts, nrm = top_chart_points(np.ascontiguousarray(self.hm, float), W, D, w, h)
            elif name == "bottom":
                pts = np.column_stack([u, v, np.zeros(n)])
                nrm[:, 2] = -1
            else:
                zz = H - v
                pts = {"front": lambda: np.column_stack([u, np.zeros(n), zz]),
                       "back": lambda: np.column_stack([W - u, np.full(n, D), zz]),
                       "left": lambda: np.column_stack([np.zeros(n), D - u, zz]),
                       "right": lambda: np.column_stack([np.full(n, W), u, zz])}[name]()
                axis, sign = {"front": (1, -1), "back": (1, 1), "left": (0, -1),
                              "right": (0, 1)}[name]
                nrm[:, axis] = sign
            yield idx, pts, nrm


def _split_sharp_corners(p, uv, faces, n):
    """Give a triangle corner whose smooth normal leaves its face by more than the crease
    angle (:data:`woodcam.tolerances.CREASE_ANGLE_DEG`) a vertex of its own, as
    :func:`woodcam.export.crease_normals` splits a mesh: the grid's central-difference normal
    of a vertex on a cut's rim leans half-way down the wall, so the flat top beside it and the
    wall below shaded as neither (1.4 % of a cut's area had normal . face normal < 0.5).

    ``p (n, 3)`` vertices (mm), ``uv (n, 2)``, ``faces (m, 3)``, ``n (n, 3)`` unit normals;
    returns them with the split vertices appended (same position and uv) and those corners
    re-pointed. A split corner's normal is the angle-weighted mean of the face normals at its
    vertex within the crease angle of its own face (its side of the edge); the other corners
    keep the smooth normal."""
    import math

    from scipy import sparse

    from ..tolerances import CREASE_ANGLE_DEG

    cos_min = math.cos(math.radians(CREASE_ANGLE_DEG))
    tri = p[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cross, axis=1)
    fn = cross / np.maximum(area2, 1e-300)[:, None]
    # a zero-area face has no direction to disagree with
    bad = (np.einsum("fkj,fj->fk", n[faces], fn) < cos_min) & (area2 > 1e-14)[:, None]
    if not bad.any():
        return p, uv, faces, n
    corners = faces.reshape(-1)
    at_bad = np.flatnonzero(np.isin(corners, np.unique(faces[bad])))  # every corner there
    vid = np.unique(corners[at_bad], return_inverse=True)[1].reshape(-1)
    inc = sparse.csr_matrix((np.ones(len(at_bad)), (np.arange(len(at_bad)), vid)))
    same = (inc @ inc.T).tocoo()
    fa, fb = at_bad[same.row] // 3, at_bad[same.col] // 3
    keep = np.einsum("ij,ij->i", fn[fa], fn[fb]) >= cos_min
    e1 = np.roll(tri, -1, axis=1) - tri
    e2 = np.roll(tri, 1, axis=1) - tri
    angle = np.arccos(np.clip(np.einsum("fij,fij->fi", e1, e2) / np.maximum(
        np.linalg.norm(e1, axis=2) * np.linalg.norm(e2, axis=2), 1e-300), -1.0, 1.0)).reshape(-1)
    w = fn[fb[keep]] * angle[at_bad[same.col[keep]], None]
    mean = np.zeros((len(at_bad), 3))
    for k in range(3):
        mean[:, k] = np.bincount(same.row[keep], weights=w[:, k], minlength=len(at_bad))
    mean /= np.maximum(np.linalg.norm(mean, axis=1), 1e-300)[:, None]
    # the split corners: one new vertex per (vertex, normal)
    split = bad.reshape(-1)[at_bad]
    which, normal = at_bad[split], mean[split]
    key = np.column_stack([corners[which], np.round(normal * 1e6).astype(np.int64)])
    _, first, new = np.unique(key, axis=0, return_index=True, return_inverse=True)
    src = corners[which[first]]
    out = corners.copy()
    out[which] = len(p) + new.reshape(-1)
    return (np.vstack([p, p[src]]), np.vstack([uv, uv[src]]), out.reshape(-1, 3),
            np.vstack([n, normal[first]]))


def heightfield_mesh_charts(heightmap, size_mm, texels_per_mm, *, flat_tol_mm: float = 1e-9):
    """:func:`heightfield_mesh` with planar texture charts:
    ``(mesh, uv_px (n, 2), charts, vertex_normals (n, 3))``.

    Vertices are split where charts meet (top/wall edges, wall corners, bottom), so every
    vertex has one texel coordinate; the geometry is the same closed surface. The top's shading
    normals are the grid's central-difference gradient (smooth; at 0.1 mm cells a sharp edge
    blurs over one cell), split at sharp edges (a cut's rim: :func:`_split_sharp_corners`), the
    walls' and bottom's their face normals.
    """
    import trimesh

    hm = np.asarray(heightmap, float)
    if hm.ndim != 2 or min(hm.shape) < 1:
        raise WoodcamError(f"heightfield_mesh_charts: heightmap must be (ny, nx), got {hm.shape}")
    charts = HeightfieldCharts(hm, size_mm, texels_per_mm)
    W, D, H = charts.size_mm
    xs, ys, zg = _vertex_grid(hm, (W, D, H))  # once: the mesh and its top's shading normals
    V, F, grid_index, runs = _heightfield_arrays((xs, ys, zg), (W, D, H), flat_tol_mm)
    nxv = len(xs)
    axis_normal = {"bottom": (0, 0, -1), "front": (0, -1, 0), "back": (0, 1, 0),
                   "left": (-1, 0, 0), "right": (1, 0, 0)}
    parts = []
    remap = np.full(len(V), -1, np.int64)
    for nm in _CHART_ORDER:
        lo, hi = runs[nm]
        if hi <= lo:
            continue
        fc = F[lo:hi]
        # this chart's own copy of its vertices, in index order (O(n), no sort)
        used_mask = np.zeros(len(V), bool)
        used_mask[fc.ravel()] = True
        used = np.flatnonzero(used_mask)
        del used_mask
        remap[used] = np.arange(len(used))
        p = V[used]
        u, v = {"top": (p[:, 0], D - p[:, 1]), "bottom": (p[:, 0], p[:, 1]),
                "front": (p[:, 0], H - p[:, 2]), "back": (W - p[:, 0], H - p[:, 2]),
                "left": (D - p[:, 1], H - p[:, 2]), "right": (p[:, 1], H - p[:, 2])}[nm]
        if nm == "top":
            # smooth shading normals from the grid's central differences at each vertex
            g = grid_index[used]
            j, i = g // nxv, g % nxv
            jm, jp = np.maximum(j - 1, 0), np.minimum(j + 1, len(ys) - 1)
            im, ip = np.maximum(i - 1, 0), np.minimum(i + 1, nxv - 1)
            gx = (zg[j, ip] - zg[j, im]) / (xs[ip] - xs[im])
            gy = (zg[jp, i] - zg[jm, i]) / (ys[jp] - ys[jm])
            n = np.column_stack([-gx, -gy, np.ones(len(p))])
            n /= np.linalg.norm(n, axis=1, keepdims=True)
            p, uv, top_faces, n = _split_sharp_corners(p, charts.uv(nm, u, v), remap[fc], n)
            parts.append((p, uv, top_faces, n))
            continue
        n = np.broadcast_to(np.array(axis_normal[nm], float), p.shape)
        parts.append((p, charts.uv(nm, u, v), remap[fc], n))
    base = np.cumsum([0] + [len(q[0]) for q in parts])
    out = trimesh.Trimesh(np.vstack([q[0] for q in parts]),
                          np.vstack([q[2] + b for q, b in zip(parts, base)]), process=False)
    return (out, np.vstack([q[1] for q in parts]), charts,
            np.vstack([np.asarray(q[3]) for q in parts]))
