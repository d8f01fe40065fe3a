"""Bark cracks from the stress of growing (seed 004 sec. 4.4), carried from year to year.

Each simulated year has its grown surface (marching cubes). For every vertex its position a
year earlier is found by tracing the growth back (:func:`~woodcam.woodify.surfaces.trace_back`
with ``until_mm``), so each triangle has a deformation gradient ``F`` (2 x 2 in its plane)
from last year's shape to this year's. Bark does not grow with the wood, so the stretch
accumulates as stress, per triangle (sec. 4.4.1):

    sigma += E3 (F F^T - I) / 2 E3^T           (3 x 3, E3 = the triangle's in-plane basis)

The stress splits into its tensile and compressive parts (positive and negative
eigenvalues); each triangle pushes its corners with forces ``f = area sigma grad N_i`` (``N_i``
the barycentric shape function of corner ``i``), split the same way, and each vertex gets the
separation tensor (O'Brien & Hodgins' form of the seed's ``zeta``):

    zeta = 1/2 (sum m(f+) - sum m(f-)),        m(a) = a a^T / |a|

Vertices enter a priority queue keyed by the largest eigenvalue of ``zeta`` (sec. 4.4.2);
while the top exceeds the threshold a crack is inserted there: it runs through the vertex
perpendicular to the eigenvector (in the tangent plane) along the mesh edges that follow that
direction best, for a length that grows with the excess (edges play the seed's "merge a crack
that is too close to an edge"). The stress of the faces round a new crack is multiplied by the
relief factor (0 removes it, 1 keeps it) and those vertices re-enter the queue. Relaxation
(sec. 4.4.3) diffuses the remaining stress between neighbouring faces each year. Cracks and
stress are carried to the next year's mesh through the vertices' origins on the input (the
seed's coupling, sec. 4.6), and an existing crack widens as the bark keeps stretching.

Patterns: ``"stress"`` (crack along the direction the stress gives), ``"vertical"`` /
``"horizontal"`` (along / across ``up``), ``"random"`` (a random direction per vertex); the
largest eigenvalue decides where and when in every pattern, and each can be limited to a
region.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from dataclasses import field as dc_field
from typing import Literal

import numba
import numpy as np

from .._checks import received
from ..errors import WoodcamError

Pattern = Literal["stress", "vertical", "horizontal", "random"]
PATTERNS: tuple[str, ...] = ("stress", "vertical", "horizontal", "random")


@dataclass
class CrackedSurface:
    """The grown surface of the last simulated year with its cracks.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        Watertight surface, object frame, mm.
    origins_mm : (n, 3) float
        Origin of each vertex on the input surface.
    tri : (n,) int
        Input triangle of each origin.
    crack_edges : (m, 2) int
        Mesh edges (vertex pairs) that are cracked.
    crack_width : (n,) float
        Per-vertex crack opening in [0, 1] (0 = no crack).
    crack_directions : (k, 3) float
        Unit direction of every crack inserted (all years), with ``crack_points (k, 3)``.
    stress : (f, 3, 3) float
        Remaining per-triangle stress.
    threshold : float
        The eigenvalue that opened cracks.
    log : list of dict
        Per year: cracks inserted, largest eigenvalue.
    """

    mesh: object
    origins_mm: np.ndarray
    tri: np.ndarray
    crack_edges: np.ndarray
    crack_width: np.ndarray
    crack_directions: np.ndarray
    crack_points: np.ndarray
    stress: np.ndarray
    threshold: float
    log: list = dc_field(default_factory=list)


def _frames_of(tri):
    """Per-face orthonormal in-plane basis ``(f, 3, 2)`` (columns: along edge 01, then in-plane
    across it) and unit normal ``(f, 3)`` of triangles ``tri (f, 3, 3)`` mm."""
    u = tri[:, 1] - tri[:, 0]
    v = tri[:, 2] - tri[:, 0]
    e1 = u / np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-12)
    n = np.cross(u, v)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return np.stack([e1, np.cross(n, e1)], axis=2), n


def growth_stress(mesh, prev_positions) -> np.ndarray:
    """Per-face stress ``(f, 3, 3)`` of the stretch from ``prev_positions (n, 3)`` to ``mesh``."""
    tri = np.asarray(mesh.triangles)
    return _growth_stress(_frames_of(tri)[0], tri, np.asarray(prev_positions)[mesh.faces])


def _growth_stress(E, cur, old) -> np.ndarray:
    """:func:`growth_stress` on plain arrays: the faces' frames ``E (f, 3, 2)`` (:func:`_frames_of`
    of ``cur``), their corners now ``cur (f, 3, 3)`` and a year earlier ``old (f, 3, 3)``, mm.
    The crack loop passes the frames its year's surface already holds (:class:`_MeshArrays`)."""
    # edge matrices in the current face frame (2 x 2): columns are edges 01 and 02
    dc = np.stack([cur[:, 1] - cur[:, 0], cur[:, 2] - cur[:, 0]], axis=2)
    do = np.stack([old[:, 1] - old[:, 0], old[:, 2] - old[:, 0]], axis=2)
    Xc = np.einsum("fdk,fde->fke", E, dc)
    # the old edges in their own plane: project onto the old face's frame
    Eo, _ = _frames_of(old)
    Xo = np.einsum("fdk,fde->fke", Eo, do)
    det = np.linalg.det(Xo)
    good = np.abs(det) > 1e-12 * np.maximum(np.abs(np.linalg.det(Xc)), 1e-30)
    F = np.zeros_like(Xc)
    F[good] = Xc[good] @ np.linalg.inv(Xo[good])
    # align the old frame's rotation away: the left stretch F F^T is rotation-free
    B = F @ np.swapaxes(F, 1, 2)
    S2 = 0.5 * (B - np.eye(2))
    S2[~good] = 0.0
    return np.einsum("fik,fkl,fjl->fij", E, S2, E)


def _split(sig):
    """Tensile and compressive parts ``(f, 3, 3)`` of symmetric tensors."""
    w, V = np.linalg.eigh(sig)
    pos = np.einsum("fik,fk,fjk->fij", V, np.maximum(w, 0), V)
    neg = np.einsum("fik,fk,fjk->fij", V, np.minimum(w, 0), V)
    return pos, neg


def separation(mesh, stress) -> np.ndarray:
    """Per-vertex separation tensor ``(n, 3, 3)`` from per-face stress (module docstring)."""
    tri = np.asarray(mesh.triangles)
    return _separation(mesh.faces, tri, mesh.area_faces, _frames_of(tri)[1], stress, len(mesh.vertices))


def _separation(faces, tri, area, nrm, stress, n_vertices) -> np.ndarray:
    """:func:`separation` on plain arrays: ``faces (f, 3)`` int indexing ``n_vertices``,
    corners ``tri (f, 3, 3)`` mm, ``area (f,)``, unit normals ``nrm (f, 3)``, ``stress (f, 3, 3)``."""
    pos, neg = _split(stress)
    zeta = np.zeros((n_vertices, 3, 3))
    for i in range(3):
        a, b = tri[:, (i + 1) % 3], tri[:, (i + 2) % 3]
        edge = b - a
        # grad N_i: in-plane, perpendicular to the opposite edge, towards corner i, |.| = 1/height
        g = np.cross(nrm, edge)
        g /= np.maximum(2 * area, 1e-18)[:, None]
        for part, sign in ((pos, 1.0), (neg, -1.0)):
            f = area[:, None] * np.einsum("fij,fj->fi", part, g)
            mag = np.linalg.norm(f, axis=1)
            m = np.einsum("fi,fj->fij", f, f) / np.maximum(mag, 1e-18)[:, None, None]
            np.add.at(zeta, faces[:, i], 0.5 * sign * m)
    return zeta


def _crack_frame(zeta, normals, pattern, up, rng):
    """Largest eigenvalue ``(n,)`` and crack direction ``(n, 3)`` per vertex for a pattern."""
    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    w, V = np.linalg.eigh(zeta)
    lam = w[:, -1]
    if pattern == "stress":
        d = np.cross(n, V[:, :, -1])
    else:
        if pattern in ("vertical", "horizontal"):
            upv = np.broadcast_to(np.asarray(up, float), n.shape)
            along = upv - n * np.sum(upv * n, 1, keepdims=True)  # up in the tangent plane
            d = along if pattern == "vertical" else np.cross(n, along)
        else:
            r = rng.standard_normal(n.shape)
            d = r - n * np.sum(r * n, 1, keepdims=True)
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    return lam, d


def _walk(verts, neighbours, start, direction, length_mm, cracked_edges):
    """Follow mesh edges from ``start`` along ``direction`` for ``length_mm``; returns vertices.

    ``verts (n, 3)`` is a plain array (a trimesh ``TrackedArray`` re-hashes on every access);
    ``neighbours`` is the ``(ptr, idx)`` of :func:`_neighbours`. The edges walked are added to
    ``cracked_edges`` as ``(low, high)`` vertex pairs.

    Each step is :func:`_walk_kernel`'s, compiled: a woodify run makes ~60k walks of a few
    steps each, and the per-step numpy calls on a vertex's handful of neighbours were 11 % of
    ``woodcam woodify`` (profiled)."""
    ptr, idx = neighbours
    path = _walk_kernel(verts, ptr, idx, int(start), np.asarray(direction, np.float64), float(length_mm))
    if len(path) > 1:
        p = np.asarray(path)
        lo, hi = np.minimum(p[:-1], p[1:]).tolist(), np.maximum(p[:-1], p[1:]).tolist()
        cracked_edges.update(zip(lo, hi))
    return path


@numba.njit(cache=True, nogil=True)
def _walk_kernel(verts, ptr, idx, start, direction, length_mm):  # pragma: no cover - compiled
    """The steps of :func:`_walk`: at each vertex, the neighbour most along the direction (the
    first of equals, as ``argmax``: the lowest vertex index, :func:`_neighbours` listing them
    ascending) while its cosine is >= 0.6; the direction turns 30 % towards
    each edge taken. Lengths are ``sqrt((x^2 + y^2) + z^2)`` as ``np.linalg.norm`` sums them;
    the cosines' products are summed in order (numpy's BLAS product may round them 1 ulp
    apart, so an exact tie between two neighbours could in principle go the other way)."""
    path = [start]
    v = start
    travelled = 0.0
    d0, d1, d2 = direction[0], direction[1], direction[2]
    while travelled < length_mm:
        s, e = ptr[v], ptr[v + 1]
        if s == e:
            break
        best, best_cos, best_ln = -1, 0.0, 0.0
        b0 = b1 = b2 = 0.0
        for j in range(s, e):
            w = idx[j]
            x, y, z = verts[w, 0] - verts[v, 0], verts[w, 1] - verts[v, 1], verts[w, 2] - verts[v, 2]
            ln = np.sqrt((x * x + y * y) + z * z)
            c = ((x * d0 + y * d1) + z * d2) / max(ln, 1e-12)
            if best < 0 or c > best_cos or (c != c and best_cos == best_cos):
                best, best_cos, best_ln, b0, b1, b2 = j, c, ln, x, y, z
        if best_cos < 0.6:
            break
        nxt = idx[best]
        travelled += best_ln
        # keep the direction but let it follow the surface
        d0, d1, d2 = b0 / best_ln * 0.3 + d0 * 0.7, b1 / best_ln * 0.3 + d1 * 0.7, b2 / best_ln * 0.3 + d2 * 0.7
        nd = np.sqrt((d0 * d0 + d1 * d1) + d2 * d2)
        d0, d1, d2 = d0 / nd, d1 / nd, d2 / nd
        v = nxt
        path.append(v)
    return path


@dataclass
class _MeshArrays:
    """One year's surface as plain arrays, read once: trimesh re-hashes its arrays to check its
    cache on every property access, which cost more than the crack work itself."""

    verts: np.ndarray  # (n, 3) mm
    faces: np.ndarray  # (f, 3) int
    normals: np.ndarray  # (n, 3) vertex normals
    tri: np.ndarray  # (f, 3, 3) corners
    area: np.ndarray  # (f,)
    frames: np.ndarray  # (f, 3, 2) in-plane bases, as _frames_of
    face_normals: np.ndarray  # (f, 3) unit, as _frames_of
    vertex_faces: np.ndarray  # (n, k) int, -1 padded
    neighbours: tuple  # (ptr (n + 1,), idx) int64, each vertex's ascending (_neighbours)

    @classmethod
    def of(cls, mesh) -> _MeshArrays:
        tri = np.asarray(mesh.triangles).view(np.ndarray)
        E, nrm = _frames_of(tri)
        return cls(np.asarray(mesh.vertices).view(np.ndarray), np.asarray(mesh.faces).view(np.ndarray),
                   np.asarray(mesh.vertex_normals).view(np.ndarray), tri,
                   np.asarray(mesh.area_faces).view(np.ndarray), E, nrm,
                   np.asarray(mesh.vertex_faces).view(np.ndarray), _neighbours(mesh))


def _neighbours(mesh) -> tuple[np.ndarray, np.ndarray]:
    """The vertices sharing an edge with each vertex of ``mesh`` (``mesh.vertex_neighbors``'s
    sets), as CSR arrays ``(ptr (n + 1,), idx)`` int64: vertex ``v``'s are
    ``idx[ptr[v]:ptr[v + 1]]``, in ascending index order.

    The order decides the walks' ties (the first of equals, so the lowest index) and which ring
    vertex gets which draw of the random pattern: ascending says so. It was the order of a
    Python set per vertex, built in edge order as trimesh builds them (45 ms and
    arbitrary-looking on a 41k-vertex surface); one sort of the edges' ends now."""
    E = np.asarray(mesh.edges_unique).view(np.ndarray).astype(np.int64, copy=False)
    n = len(mesh.vertices)
    src = np.concatenate([E[:, 0], E[:, 1]])
    dst = np.concatenate([E[:, 1], E[:, 0]])
    order = np.argsort(src * n + dst, kind="stable")  # by vertex, then neighbour (both < n)
    ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(src, minlength=n), out=ptr[1:])
    return ptr, dst[order]


def _grow_ring(ring: np.ndarray, neighbours: tuple[np.ndarray, np.ndarray], steps: int) -> np.ndarray:
    """``ring`` (vertex indices) with its neighbours added ``steps`` times, as a sorted array of
    unique indices (the order the relief's random-pattern draws follow; a Python set's before).
    ``neighbours`` is the ``(ptr, idx)`` of :func:`_neighbours`."""
    ptr, idx = neighbours
    ring = np.unique(ring)
    for _ in range(steps):
        lens = ptr[ring + 1] - ptr[ring]
        # each ring vertex's run of idx, concatenated: its start, then counting on
        take = np.repeat(ptr[ring] - (np.cumsum(lens) - lens), lens) + np.arange(int(lens.sum()))
        ring = np.union1d(ring, idx[take])
    return ring


def simulate_cracks(woodification, years, *, pattern: Pattern = "stress", region=None,
                    threshold: float | None = None, relief: float = 0.3, diffusion: float = 0.25,
                    crack_length_voxels: float = 6.0, spacing_voxels: float = 3.0,
                    seed: int = 0) -> CrackedSurface:
    """Crack the bark over the grown surfaces of ``years`` (increasing; the first is a start).

    Parameters
    ----------
    woodification : Woodification
    years : sequence of float
        Years simulated, e.g. ``[35, 36, 37, 38, 39, 40]``; stress accumulates from the first.
    pattern : "stress", "vertical", "horizontal" or "random"
    region : (x, y, z, r) mm, optional
        Only vertices whose origin lies within this sphere (object frame) crack.
    threshold : float, optional
        Separation eigenvalue that opens a crack; default 2 x the median largest eigenvalue
        of the first simulated year (cracks open where stress concentrates, then spread).
    relief : float in [0, 1]
        Stress kept by the faces round a new crack (0 removes all of it, 1 none).
    diffusion : float in [0, 1)
        Share of the difference to the neighbours' mean stress moved per relaxation step.
    crack_length_voxels : float
        Length of a crack at the threshold, in voxels; longer with more excess.
    spacing_voxels : float
        Reach of the relief round a new crack (mesh rings of about a voxel): no second crack
        opens that close while the relief holds.
    seed : int
    """
    from scipy.spatial import cKDTree

    from .surfaces import trace_back

    if pattern not in PATTERNS:
        raise WoodcamError(f"pattern must be one of {list(PATTERNS)}; got {pattern!r}")
    if not 0.0 <= relief <= 1.0:
        raise WoodcamError(f"relief must lie in [0, 1] (0 removes the stress, 1 keeps it); got {relief!r}")
    if not 0.0 <= diffusion < 1.0:
        raise WoodcamError(f"diffusion must lie in [0, 1); got {diffusion!r}")
    ys = [float(y) for y in years]
    if len(ys) < 2 or np.any(np.diff(ys) <= 0) or ys[0] < 0 or ys[-1] > woodification.years:
        raise WoodcamError(f"years must be >= 2 increasing years within [0, {woodification.years:g}]; "
                           f"got {received(years)}")
    rng = np.random.default_rng(seed)
    wd = woodification
    h = wd.front.grid.spacing_mm
    up = np.asarray(wd.speed.up)
    prev = None
    thr = threshold
    log = []
    directions, points = [], []
    for k in range(1, len(ys)):
        mesh = wd.surface(ys[k])
        ma = _MeshArrays.of(mesh)
        V, csr = ma.verts, ma.neighbours
        origins, tri = wd.origins(V)
        old_pos, _ = trace_back(wd.front, V, wind=wd.speed.wind, until_mm=wd.tau(ys[k - 1]))
        stress = _growth_stress(ma.frames, ma.tri, old_pos[ma.faces])
        width = np.zeros(len(V))
        cracked_edges: set = set()
        if prev is not None:
            # carry last year's stress (per face, by face-centre origin) and cracks (per vertex)
            fo = origins[ma.faces].mean(1)
            _, j = cKDTree(prev.origins_mm[prev.mesh.faces].mean(1)).query(fo)
            stress = stress + prev.stress[j]
            # each old crack edge maps to the new vertices nearest its ends' origins, rejoined
            # along the new edges (the seed's coupling through unique vertex identities)
            tree = cKDTree(origins)
            _, ja = tree.query(prev.origins_mm[prev.crack_edges[:, 0]])
            _, jb = tree.query(prev.origins_mm[prev.crack_edges[:, 1]])
            old_w = np.maximum(prev.crack_width[prev.crack_edges[:, 0]],
                               prev.crack_width[prev.crack_edges[:, 1]])
            for a, b, wo in zip(ja, jb, old_w):
                if a == b:
                    continue
                seg = V[b] - V[a]
                ln = float(np.linalg.norm(seg))
                path = _walk(V, csr, int(a), seg / ln, ln * 0.99, cracked_edges)
                width[path] = np.maximum(width[path], wo)
        # an open crack keeps widening while the bark stretches, and carries no stress across
        cracked_v = width > 0
        if cracked_v.any():
            width = np.where(cracked_v, np.minimum(width + 0.25, 1.0), 0.0)
            on_crack = cracked_v[ma.faces].any(1)
            stress[on_crack] *= relief
        zeta = _separation(ma.faces, ma.tri, ma.area, ma.face_normals, stress, len(V))
        lam, d = _crack_frame(zeta, ma.normals, pattern, up, rng)
        allowed = np.ones(len(lam), bool)
        if region is not None:
            c = np.asarray(region[:3], float)
            allowed = np.linalg.norm(origins - c, axis=1) <= float(region[3])
        if thr is None:
            base = np.median(lam[allowed]) if allowed.any() else 0.0
            thr = 2.0 * float(base) if base > 0 else float(np.max(lam) + 1.0)
        heap = [(-lam[v], v) for v in np.nonzero(allowed & (lam > thr) & ~cracked_v)[0]]
        heapq.heapify(heap)
        vf = ma.vertex_faces
        inserted = 0
        current = lam.copy()
        while heap:
            neg, v = heapq.heappop(heap)
            if -neg != current[v] or current[v] <= thr or width[v] > 0:
                continue
            length = crack_length_voxels * h * min(current[v] / thr, 3.0)
            path = _walk(V, csr, v, d[v], length / 2, cracked_edges)[::-1][:-1]
            path += _walk(V, csr, v, -d[v], length / 2, cracked_edges)
            if len(path) < 2:
                current[v] = -np.inf
                continue
            inserted += 1
            directions.append(d[v])
            points.append(V[v])
            path = np.asarray(path)
            width[path] = np.maximum(width[path], 0.25)
            # relief: the faces round the crack keep only `relief` of their stress
            ring = _grow_ring(path, csr, max(1, round(spacing_voxels)))
            faces = np.unique(vf[ring])
            faces = faces[faces >= 0]
            stress[faces] *= relief
            # the separation of the ring from those same faces (not found again from the ring)
            z = _separation_round(ma.faces[faces], ma.tri[faces], ma.area[faces], ma.face_normals[faces],
                                  stress[faces], ring)
            lam_r, d_r = _crack_frame(z, ma.normals[ring], pattern, up, rng)
            current[ring] = lam_r
            d[ring] = d_r
            back = (lam_r > thr) & allowed[ring] & (width[ring] == 0)
            for a, la in zip(ring[back].tolist(), lam_r[back].tolist()):
                heapq.heappush(heap, (-la, a))
        stress = _diffuse(mesh, stress, diffusion)
        log.append({"year": ys[k], "cracks": inserted, "max_eigenvalue": float(np.max(lam)),
                    "threshold": thr})
        edges = np.array(sorted(cracked_edges), int).reshape(-1, 2)
        prev = CrackedSurface(mesh, origins, tri, edges, width, np.zeros((0, 3)), np.zeros((0, 3)),
                              stress, thr, log)
    prev.crack_directions = np.asarray(directions).reshape(-1, 3)
    prev.crack_points = np.asarray(points).reshape(-1, 3)
    return prev


def separation_local(mesh, stress, vertices) -> np.ndarray:
    """Separation tensors ``(k, 3, 3)`` of some vertices (recomputed after a relief): equal to
    ``separation(mesh, stress)[vertices]``, from the faces round those vertices only.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The surface, mm.
    stress : ndarray (f, 3, 3)
        Per-face stress (:func:`growth_stress`), one per face of ``mesh``.
    vertices : ndarray (k,) int
        Indices of vertices of ``mesh``.
    """
    import trimesh
    from trimesh.triangles import area as triangle_areas  # mesh.area_faces's own formula

    if not isinstance(mesh, trimesh.Trimesh):
        raise WoodcamError(f"separation_local: mesh must be a trimesh.Trimesh; got {type(mesh).__name__}")
    stress = np.asarray(stress, float)
    if stress.shape != (len(mesh.faces), 3, 3):
        raise WoodcamError(f"separation_local: stress must be (f, 3, 3) with f = {len(mesh.faces)} faces of "
                           f"mesh; got shape {stress.shape}; pass growth_stress(mesh, ...) of this mesh")
    vertices = np.asarray(vertices)
    if vertices.ndim != 1 or vertices.dtype.kind not in "iu" or (
            len(vertices) and not (0 <= vertices.min() and vertices.max() < len(mesh.vertices))):
        got = f"{vertices.dtype} array of shape {vertices.shape}"
        if vertices.size and vertices.dtype.kind in "iu":
            got += f", values {vertices.min()}..{vertices.max()}"
        raise WoodcamError(f"separation_local: vertices must be a 1-D integer array of vertex indices in "
                           f"[0, {len(mesh.vertices)}); got a {got}")
    # only the faces round the vertices are read (ascending, as vertex_faces lists them), not the
    # whole surface the crack loop reads once: on a 50k-face surface that read (neighbour lists,
    # frames, vertex normals) cost 25-50x the sums round a crack's ring
    faces = np.asarray(mesh.faces).view(np.ndarray)
    round_ = np.flatnonzero(np.isin(faces, vertices).any(axis=1))
    tri = np.asarray(mesh.vertices).view(np.ndarray)[faces[round_]]
    return _separation_round(faces[round_], tri, triangle_areas(tri), _frames_of(tri)[1], stress[round_],
                             vertices)


def _separation_round(faces, tri, area, nrm, stress, vertices) -> np.ndarray:
    """Separation tensors ``(k, 3, 3)`` of ``vertices (k,)`` from the faces round them, in
    ascending face order: ``faces (g, 3)`` int (whole-mesh vertex indices), their corners ``tri
    (g, 3, 3)`` mm, ``area (g,)``, unit normals ``nrm (g, 3)`` and ``stress (g, 3, 3)``."""
    # number the corners compactly (ascending, as a submesh would) so the sums run in the same
    # order as over the whole mesh
    used, local = np.unique(faces, return_inverse=True)
    z = _separation(local.reshape(-1, 3), tri, area, nrm, stress, len(used))
    return z[np.searchsorted(used, vertices)]


def _diffuse(mesh, stress, rate: float, steps: int = 2):
    """Relaxation: move stress towards the mean of the edge-neighbouring faces."""
    if rate <= 0:
        return stress
    adj = mesh.face_adjacency
    s = stress.copy()
    count = np.bincount(adj.ravel(), minlength=len(s)).astype(float)
    for _ in range(steps):
        acc = np.zeros_like(s)
        np.add.at(acc, adj[:, 0], s[adj[:, 1]])
        np.add.at(acc, adj[:, 1], s[adj[:, 0]])
        mean = acc / np.maximum(count, 1)[:, None, None]
        s = s + rate * (mean - s)
    return s
