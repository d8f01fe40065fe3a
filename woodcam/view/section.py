"""Pure-numpy geometry of a cut plane through a block and a part (no VTK: testable alone).

Frames and units: block frame, millimetres (``docs/conventions.md``). A plane is a point
``origin (3,)`` and a unit ``normal (3,)``; its in-plane axes ``(u, v)`` come from
:func:`plane_basis`. :func:`box_section_uv` is where it cuts the block ``[0, W] x [0, D] x
[0, H]``, :func:`cut_segments` where it cuts a triangle mesh, and :func:`signed_row_distance`
the signed distance of a sample grid to that outline (inside > 0). :mod:`woodcam.view.scene`
turns these into pyvista polydata.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import ON_FACE_TOL_MM

BOX_EDGES = np.array(
    [[0, 1], [2, 3], [4, 5], [6, 7],   # along X
     [0, 2], [1, 3], [4, 6], [5, 7],   # along Y
     [0, 4], [1, 5], [2, 6], [3, 7]]   # along Z
)


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit in-plane axes ``(u, v)`` with ``u x v = normal``.

    ``u`` is the block axis after the normal's dominant axis, projected onto the plane, so a
    plane normal to a block axis gets block axes as ``u, v`` and its sample grid covers the
    box's section exactly (no clipping needed).
    """
    k = int(np.argmax(np.abs(normal)))
    a = np.zeros(3)
    a[(k + 1) % 3] = 1.0
    u = a - np.dot(a, normal) * normal
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    return u, v


def box_section_uv(size: np.ndarray, origin: np.ndarray, normal: np.ndarray, u, v):
    """In-plane ``(u, v)`` coordinates (mm, relative to ``origin``) of the plane-box polygon.

    The vertices are where the plane crosses the box's 12 edges (corners on the plane count).
    Returns an ``(m, 2)`` array, ``m = 0`` when the plane misses the box.
    """
    bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
    corners = bits * size                                       # (8, 3) mm
    dist = (corners - origin) @ normal                           # (8,) signed distance, mm
    on = np.abs(dist) <= ON_FACE_TOL_MM
    pts = [corners[on]]
    d0, d1 = dist[BOX_EDGES[:, 0]], dist[BOX_EDGES[:, 1]]
    cross = (d0 * d1 < 0) & ~on[BOX_EDGES[:, 0]] & ~on[BOX_EDGES[:, 1]]
    t = d0[cross] / (d0[cross] - d1[cross])
    c0, c1 = corners[BOX_EDGES[cross, 0]], corners[BOX_EDGES[cross, 1]]
    pts.append(c0 + t[:, None] * (c1 - c0))
    p = np.concatenate(pts) - origin
    return np.stack([p @ u, p @ v], axis=1)


def cut_segments(points, triangles, origin, normal) -> np.ndarray:
    """Where a plane cuts a triangle mesh: segments ``(k, 2, 3)``, block frame mm.

    Vertices are classed above (``d > 0``) or not; a triangle with both classes is cut along
    its two edges whose ends differ, so a vertex on the plane never yields a degenerate
    crossing.
    """
    d = (points - origin) @ normal                               # (n,) mm
    above = d > 0
    n_above = (above[triangles[:, 0]].astype(np.uint8) + above[triangles[:, 1]]
               + above[triangles[:, 2]])                         # (m,) column adds: fast
    tri = triangles[(n_above == 1) | (n_above == 2)]
    if len(tri) == 0:
        return np.empty((0, 2, 3))
    # Each edge runs from its vertex above the plane to the other one, so the two triangles
    # sharing an edge compute the same crossing bit for bit (the scan lines rely on it).
    e0, e1 = tri, np.roll(tri, -1, axis=1)                       # (k, 3) corner -> next
    a_idx = np.where(above[e0], e0, e1)
    b_idx = np.where(above[e0], e1, e0)
    da, db = d[a_idx], d[b_idx]
    differs = above[a_idx] != above[b_idx]                       # exactly two per triangle
    w = np.where(differs, da / np.where(differs, da - db, 1.0), 0.0)
    pa, pb = points[a_idx], points[b_idx]                        # (k, 3, 3)
    cross = pa + w[..., None] * (pb - pa)
    return cross[differs].reshape(-1, 2, 3)


def signed_row_distance(seg_uv, su, sv) -> np.ndarray:
    """Signed distance (mm) along ``u`` from grid points to a closed outline, > 0 inside.

    The grid is ``su (n_u,) x sv (n_v,)`` (row ``j`` is ``v = sv[j]``). Each row is a scan
    line: the outline's crossings with it, sorted, give inside (odd count to the left) and the
    distance to the nearest crossing. Rows with no crossing are outside. Returns
    ``(n_u, n_v)``. Exact along ``u``; between rows a clip interpolates, so the outline is
    placed within one row spacing where it runs nearly along ``u``.
    """
    n_u, n_v = len(su), len(sv)
    far = float(su[-1] - su[0]) + 1.0
    out = np.full((n_u, n_v), -far)
    if len(seg_uv) == 0:
        return out
    v1, v2 = seg_uv[:, 0, 1], seg_uv[:, 1, 1]
    dv = (sv[-1] - sv[0]) / (n_v - 1)
    lo_j = np.floor((np.minimum(v1, v2) - sv[0]) / dv).astype(np.int64) - 1
    hi_j = np.ceil((np.maximum(v1, v2) - sv[0]) / dv).astype(np.int64) + 1
    lo_j, hi_j = lo_j.clip(0, n_v - 1), hi_j.clip(0, n_v - 1)
    count = np.maximum(hi_j - lo_j + 1, 0)
    seg = np.repeat(np.arange(len(seg_uv)), count)               # candidate (segment, row)
    row = lo_j[seg] + (np.arange(len(seg)) - np.repeat(np.cumsum(count) - count, count))
    vj = sv[row]
    a, b = seg_uv[seg, 0], seg_uv[seg, 1]
    hit = (a[:, 1] <= vj) != (b[:, 1] <= vj)                     # half-open: no double count
    seg, row, vj, a, b = seg[hit], row[hit], vj[hit], a[hit], b[hit]
    uc = a[:, 0] + (vj - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    uc = np.clip(uc, su[0] - 1.0, su[-1] + 1.0)                  # keeps the order in the row
    span = float(su[-1] - su[0]) + 3.0
    key = np.sort(row * span + (uc - su[0] + 1.0))               # rows apart, sorted by u
    grid_row = np.broadcast_to(np.arange(n_v), (n_u, n_v))
    grid_key = grid_row * span + (su[:, None] - su[0] + 1.0)
    first = np.searchsorted(key, np.arange(n_v) * span)          # (n_v,) row starts
    last = np.searchsorted(key, (np.arange(n_v) + 1) * span)     # (n_v,) row ends
    k = np.searchsorted(key, grid_key)                           # (n_u, n_v)
    left = k - first[None, :]                                    # crossings left of the point
    has_left = k > first[None, :]
    has_right = k < last[None, :]
    d_left = np.where(has_left, grid_key - key[np.maximum(k - 1, 0)], np.inf)
    d_right = np.where(has_right, key[np.minimum(k, len(key) - 1)] - grid_key, np.inf)
    dist = np.minimum(d_left, d_right)
    any_hit = np.isfinite(dist)
    out[any_hit] = np.where(left[any_hit] % 2 == 1, dist[any_hit], -dist[any_hit])
    return out


def part_triangles(part) -> tuple[np.ndarray, np.ndarray]:
    """``(points (n, 3) float mm, triangles (m, 3) int)`` of a part: pyvista, trimesh or a pair."""
    if isinstance(part, tuple) and len(part) == 2:
        return np.asarray(part[0], dtype=float), np.asarray(part[1], dtype=np.int64)
    if hasattr(part, "vertices") and hasattr(part, "faces") and not hasattr(part, "n_cells"):
        return np.asarray(part.vertices, dtype=float), np.asarray(part.faces, dtype=np.int64)
    if not part.is_all_triangles:
        part = part.triangulate()
    return np.asarray(part.points, dtype=float), np.asarray(part.regular_faces, dtype=np.int64)
