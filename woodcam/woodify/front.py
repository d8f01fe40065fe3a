"""Front propagation on a voxel grid: arrival time ``T(x)`` (mm of pseudo-time) of the growth front.

The growing surface of seed 004 (a deformable simplicial complex moved along its normals,
sec. 4.1) is replaced here by the arrival time of the front on grid nodes: the solid at
pseudo-time ``tau`` is ``{T <= tau}``. Topology changes (fronts merging, holes closing, seed
Fig. 5.5) need no special handling: the level set of a single-valued ``T`` changes topology by
itself. ``T`` solves ``g(x) (|grad T| + w(x) . grad T) = 1`` outside the input (see
:mod:`woodcam.woodify.speed`); inside the input ``T = -distance`` (<= 0, year 0).

Solvers (``method``):

- ``"fmm"``: scikit-fmm's second-order fast marching (``travel_time``), isotropic only
  (``w = 0``; any gain ``g``); obstacles are masked nodes.
- ``"anisotropic"``: woodcam's compiled fast marching (:mod:`._eikonal`) for the eccentric /
  brushed case ``w != 0``, second-order differences away from the input (first order next to
  it); no library solves this one. A flat face grows within 0.02 of a grid step of the exact
  offset; round a box's edges and corners (where ``T`` has a kink) it arrives up to 0.42 of a
  step off, as the grid scheme is there (DEVELOPERS.md).
- ``"offset"``: exact for a constant wind without obstacles or gain: the eccentric front at
  ``T`` is the input offset by ``T`` and shifted by ``w T``, so ``T(x)`` is the root of
  ``D(x - w T) = T`` with ``D`` the (scikit-fmm) distance to the input; solved by fixed-point
  iteration (a contraction with rate ``|w|``) on the interpolated ``D``.
- ``"auto"`` (default): ``"fmm"`` when the wind is zero everywhere; ``"offset"`` for a constant
  wind with no obstacles and no gain; else ``"anisotropic"``.

Measured accuracy and speed are in DEVELOPERS.md (woodify section) and the benchmark test.

Grid convention: nodes at ``origin_mm + (i, j, k) * spacing_mm``, arrays ``[x, y, z]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import field as dc_field
from typing import Literal

import numpy as np

from .._checks import check_number, not_a_mesh
from .._repr import summary_repr
from ..errors import WoodcamError
from ..limits import WOODIFY_RESOLUTION_RANGE
from ..tolerances import WOODIFY_BAND_NODES, WOODIFY_OBSTACLE_CLEARANCE_VOXELS, WOODIFY_ON_SURFACE_VOXELS
from ..units import say_length
from collections.abc import Callable, Sequence
from .._types import ArrayLike, Mesh

Method = Literal["auto", "fmm", "offset", "anisotropic"]
METHODS: tuple[str, ...] = ("auto", "fmm", "offset", "anisotropic")


def check_resolution(resolution) -> int:
    """``resolution`` (grid nodes along the longest side) as an int in
    :data:`woodcam.limits.WOODIFY_RESOLUTION_RANGE`, else a WoodcamError naming it."""
    lo, hi = WOODIFY_RESOLUTION_RANGE
    return int(check_number(resolution, "resolution", lo=lo, hi=hi, integer=True,
                            fix="grid nodes along the longest side; 128 is a good default"))


@dataclass(frozen=True)
class VoxelGrid:
    """A regular grid of nodes: ``origin_mm (3,)``, cubic ``spacing_mm``, ``shape (nx, ny, nz)``."""

    origin_mm: tuple[float, float, float]
    spacing_mm: float
    shape: tuple[int, int, int]

    @classmethod
    def around(cls, lo_mm, hi_mm, resolution: int) -> VoxelGrid:
        """Grid covering the box ``[lo_mm, hi_mm]`` with ``resolution`` nodes on its longest side,
        centred on the box: a shorter side's whole number of steps overshoots it by under one
        step, split evenly between its two ends.

        That overshoot was all on the high end (origin at ``lo_mm``): a box centred in the grid's
        box then met the nodes differently at its two ends (one face on a node plane, the other
        between two), and the front's error there differs, so a centred 40x22x30 box grew 0.27
        of a step off-centre (``woodcam woodify`` at resolution 27). Centred, a mirror-symmetric
        input meets the nodes the same way at both ends and grows as symmetric."""
        lo, hi = np.asarray(lo_mm, float), np.asarray(hi_mm, float)
        resolution = check_resolution(resolution)
        h = float(np.max(hi - lo)) / (resolution - 1)
        # the longest side is resolution - 1 steps exactly (a last-bit excess is no extra node)
        steps = np.maximum(np.ceil((hi - lo) / h - 1e-9), 0)
        origin = (lo + hi) / 2 - steps * h / 2
        return cls(tuple(float(v) for v in origin), h, tuple(int(n) + 1 for n in steps))

    def axes(self) -> list[np.ndarray]:
        """Node coordinates (mm) along X, Y, Z."""
        return [self.origin_mm[d] + self.spacing_mm * np.arange(self.shape[d]) for d in range(3)]

    def nodes(self) -> np.ndarray:
        """All node positions ``(nx * ny * nz, 3)`` mm, C order."""
        return np.stack(np.meshgrid(*self.axes(), indexing="ij"), axis=-1).reshape(-1, 3)

    def to_index(self, points_mm) -> np.ndarray:
        """Fractional node indices ``(n, 3)`` of points (mm)."""
        return (np.asarray(points_mm, float) - np.asarray(self.origin_mm)) / self.spacing_mm


@dataclass
class Front:
    """Arrival time of the growth front on a grid and what was rasterised to get it.

    Attributes
    ----------
    grid : VoxelGrid
    arrival_mm : (nx, ny, nz) float64
        ``T``: pseudo-time (mm) at which the front reaches each node; ``-distance`` inside the
        input; ``inf`` where it never arrives (sealed by obstacles, or beyond ``stop_mm``);
        on obstacle nodes the value of the nearest wood node (so the field stays continuous).
    inside : (nx, ny, nz) bool
        Nodes inside the input mesh.
    obstacle : (nx, ny, nz) bool
        Nodes inside an obstacle (no wood there).
    obstacle_sdf_mm : (nx, ny, nz) float32 or None
        Signed distance to the obstacles (negative inside), exact within the band.
    input_closest_mm : (nx, ny, nz, 3) float32
        Closest point on the input surface, valid where ``input_tri >= 0`` (the band).
    input_tri : (nx, ny, nz) int32
        The input triangle of that closest point, -1 beyond the band.
    method : str
        The solver used.

    ``arrival_mm`` is read-only once the front is built: the back-trace grids
    (:func:`woodcam.woodify.surfaces.trace_grids`) are derived from it once and kept in
    ``_trace_cache``, checked against the array's identity (assigning a new array rebuilds
    them; writing into this one in place would not).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    grid: VoxelGrid
    arrival_mm: np.ndarray
    inside: np.ndarray
    obstacle: np.ndarray
    obstacle_sdf_mm: np.ndarray | None
    input_closest_mm: np.ndarray
    input_tri: np.ndarray
    method: str
    _trace_cache: tuple | None = dc_field(default=None, init=False, repr=False, compare=False)


def pinched_vertices(mesh) -> np.ndarray:
    """Indices ``(k,) int`` of the vertices of a watertight trimesh round which the triangles form
    more than one fan (triangles joined by edges through the vertex): where two parts of it
    touch at a single point, such as two closed meshes sharing one corner once welded. Every
    edge of such a mesh is shared by exactly two triangles, so trimesh calls it watertight."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    faces = np.asarray(mesh.faces, np.int64)
    pairs = np.asarray(mesh.face_adjacency, np.int64).reshape(-1, 2)
    shared = np.asarray(mesh.face_adjacency_edges, np.int64).reshape(-1, 2)
    # a triangle corner is node 3 f + k; two triangles sharing edge (a, b) join their corners at
    # a and at b, so the corners round a vertex fall into one component per fan
    ends = []
    for side in (0, 1):
        f = pairs[:, side]
        ends.append(np.concatenate([3 * f + np.argmax(faces[f] == shared[:, e:e + 1], axis=1)
                                    for e in (0, 1)]))
    n = 3 * len(faces)
    graph = coo_matrix((np.ones(len(ends[0]), np.int8), (ends[0], ends[1])), shape=(n, n))
    _, fan = connected_components(graph, directed=False)
    vertex_fans = np.unique(np.stack([faces.ravel(), fan], axis=1), axis=0)[:, 0]
    vertex, count = np.unique(vertex_fans, return_counts=True)
    return vertex[count > 1]


def check_watertight(mesh, name: str, *, fix: str | None = None):
    """Return ``mesh`` as a trimesh if it is a closed, consistently oriented manifold volume,
    else raise: open or non-manifold edges, or a vertex where parts of it touch at one point
    (:func:`pinched_vertices`, which trimesh's watertight test passes). ``fix`` ends the message
    (default: the repair hint of each case): a caller that knows why it is not a manifold solid
    says the fix that is."""
    import trimesh

    if not isinstance(mesh, trimesh.Trimesh):
        raise not_a_mesh(name, mesh, "pass a closed (watertight) mesh, e.g. trimesh.creation.icosphere(3, 20.0)")
    if len(mesh.faces) == 0:
        raise WoodcamError(f"{name} has no triangles; give a closed (watertight) mesh")
    bad = ~np.isfinite(np.asarray(mesh.vertices, float)).all(axis=1)
    if bad.any():  # a NaN corner made the grid's box NaN: an error about the grid, or none
        raise WoodcamError(f"{name} has {int(bad.sum())} of {len(bad)} vertices that are not finite "
                           "numbers (NaN or inf); fix or drop them (a mesh must be closed and finite)")
    if not mesh.is_watertight:
        # counted and named, with a fix the user can do: it said 'open or non-manifold edges;
        # repair it first (e.g. trimesh.repair.fill_holes ...)', a Python function to a CAD user
        uses = np.bincount(np.asarray(mesh.edges_unique_inverse), minlength=len(mesh.edges_unique))
        n_open, n_shared = int(np.count_nonzero(uses == 1)), int(np.count_nonzero(uses > 2))
        found = [f"{n} {what}" for n, what in (
            (n_open, f"open edge{'' if n_open == 1 else 's'} (on one triangle only: holes in its surface)"),
            (n_shared, f"edge{'' if n_shared == 1 else 's'} shared by more than two triangles (bodies "
                       "touching along an edge, or a surface inside the solid)")) if n]
        steps = " and ".join(t for t, n in (
            ("close its holes in the CAD program (export a closed solid, not surfaces)", n_open),
            ("make the bodies overlap or move them apart in the CAD program", n_shared)) if n)
        tools = " and ".join(t for t, n in (("Close Holes", n_open), ("Repair non Manifold Edges", n_shared)) if n)
        default = f"{steps}, or repair it in a mesh program (e.g. MeshLab's {tools}), and export again"
        raise WoodcamError(
            f"{name} must be watertight (every edge shared by exactly two triangles) so its inside "
            f"is defined; this one has {len(mesh.faces)} triangles, {' and '.join(found)}; "
            f"{fix or default}")
    pinched = pinched_vertices(mesh)
    if len(pinched):
        at = say_length(np.asarray(mesh.vertices, float)[pinched[0]], ".4g", form="({}, {}, {})")
        fix = fix or ("move those parts apart (leave a gap) or merge them into one solid in the CAD program, "
                      "and export again")
        raise WoodcamError(
            f"{name} must be a manifold solid (the triangles round each vertex forming one fan); this "
            f"one has {len(mesh.faces)} triangles, and at {len(pinched)} "
            f"vert{'ex' if len(pinched) == 1 else 'ices'} (the first at {at}) parts of it touch at a "
            "single point (non-manifold vertex); "
            f"{fix}")
    return mesh


def _rasterise(mesh, grid: VoxelGrid, band: int):
    from ._voxel import band_distance, inside_parity

    v = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    # Each triangle's corners in one canonical order (lexicographic by coordinates): the
    # kernels ignore the winding, but their rounding does not, and scikit-fmm's second-order
    # march turns last-bit differences of the distance into up to 1.5 mm of arrival time (a
    # 20x20x80 box wound inside out, or its corners listed from another one, at resolution 24).
    rank = np.empty(len(v), np.int64)
    rank[np.lexsort(v.T[::-1])] = np.arange(len(v))
    order = np.argsort(rank[f], axis=1)
    # the winding the reorder drops, kept for the inside test: +1 where the order is a rotation
    # of (0, 1, 2), -1 where it swaps two corners; and the mesh turned outward if wound inside out
    turn = np.where((order == (order[:, :1] + np.arange(3)) % 3).all(axis=1), 1, -1)
    if float(mesh.volume) < 0:
        turn = -turn
    f = np.ascontiguousarray(np.take_along_axis(f, order, axis=1))
    o = np.asarray(grid.origin_mm, np.float64)
    shape = np.asarray(grid.shape, np.int64)
    dist, closest, tri = band_distance(v, f, o, grid.spacing_mm, shape, band)
    inside = inside_parity(v, f, o, grid.spacing_mm, shape, turn)
    return dist, closest, tri, inside


def obstacle_names_of(obstacles, names=None) -> list[str]:
    """What messages call each of ``obstacles``: ``names`` (one a mesh) if given, else
    ``obstacles[i]``, the keyword of :func:`propagate` and :func:`woodcam.woodify.woodify`."""
    if names is None:
        return [f"obstacles[{i}]" for i in range(len(obstacles))]
    names = [str(n) for n in names]
    if len(names) != len(obstacles):
        raise WoodcamError(f"obstacle_names must name each of the {len(obstacles)} obstacles; got "
                           f"{len(names)} names; pass one a mesh, or none")
    return names


def propagate(mesh: Mesh, grid: VoxelGrid, *, wind: ArrayLike | None = None, gain: ArrayLike | None = None,
              obstacles: Sequence[Mesh] = (), method: Method = "auto", stop_mm: float = np.inf,
              paint: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
              obstacle_names: Sequence[str] | None = None) -> Front:
    """Arrival time of the front grown from ``mesh`` (see module docstring).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Watertight input, block frame, mm.
    grid : VoxelGrid
    wind : (3,) or (nx, ny, nz, 3) float, optional
        Direction part ``w`` of the normal speed ``g (1 + w . n)``; ``|w| < 1``.
    gain : float or (nx, ny, nz) float, optional
        Speed gain ``g > 0`` (brushes); default 1.
    obstacles : sequence of trimesh.Trimesh
        Watertight obstacles: the front stops on contact and wraps round them.
    obstacle_names : sequence of str, optional
        What the messages call each obstacle (default ``obstacles[i]``; the CLI's is the option
        and the file, ``--obstacle 'post.stl'``).
    method : "auto", "fmm" or "anisotropic"
    stop_mm : float
        March only up to this pseudo-time (mm); later nodes stay ``inf``.
    paint : callable, optional
        ``paint(origin_mm (m, 3), tri (m,)) -> (gain (m,), wind (m, 3))`` evaluated at each
        node's closest input-surface point (brushes, :func:`woodcam.woodify.brushes.paint`);
        multiplies ``gain`` and adds to ``wind``.
    """
    if method not in METHODS:
        raise WoodcamError(f"method must be one of {list(METHODS)}; got {method!r}")
    mesh = check_watertight(mesh, "mesh")
    h = grid.spacing_mm
    dist, closest, tri, inside = _rasterise(mesh, grid, WOODIFY_BAND_NODES)
    obstacle = np.zeros(grid.shape, bool)
    obst_sdf = None
    if obstacles:
        import trimesh

        names = obstacle_names_of(obstacles, obstacle_names)
        obs = [check_watertight(o, name) for o, name in zip(obstacles, names)]
        allobs = trimesh.util.concatenate(obs) if len(obs) > 1 else obs[0]
        od, _, _, oin = _rasterise(allobs, grid, WOODIFY_BAND_NODES)
        far = WOODIFY_BAND_NODES * h
        obst_sdf = np.where(oin, -np.minimum(od, far), np.minimum(od, far)).astype(np.float32)
        # The grown solid keeps a small clearance from obstacles: the linearly interpolated
        # distance of a convex obstacle crosses zero slightly inside it (tolerances.py).
        obstacle = obst_sdf < WOODIFY_OBSTACLE_CLEARANCE_VOXELS * h
        if not np.any(inside & ~obstacle):
            one = len(names) == 1
            raise WoodcamError(
                f"{', '.join(names)} must leave part of the input mesh outside {'it' if one else 'them'}; "
                f"{'it contains' if one else 'together they contain'} the whole input mesh "
                f"({len(mesh.faces)} triangles), so nothing can grow; move or shrink "
                f"{'it' if one else 'them'}, or leave {'it' if one else 'one'} out")
        inside &= ~obstacle
    if not np.any(inside):
        raise WoodcamError(
            "mesh must enclose at least one grid node; it is smaller than the grid spacing "
            f"{say_length(h, '.3g')}; raise the resolution or scale the mesh up")
    w = np.zeros(3) if wind is None else np.asarray(wind, float)
    if w.shape not in ((3,), grid.shape + (3,)):
        raise WoodcamError(f"wind must have shape (3,) or {grid.shape + (3,)}; got {w.shape}")
    if np.max(np.linalg.norm(w.reshape(-1, 3), axis=1)) >= 1.0:
        raise WoodcamError("wind (eccentricity plus brushed directions) must have |w| < 1 so every "
                           "normal keeps growing; lower the eccentricity or the brush strengths")
    g = np.ones(()) if gain is None else np.asarray(gain, float)
    if g.shape not in ((), grid.shape) or np.any(~(g > 0)):
        raise WoodcamError(f"gain must be > 0, a scalar or of shape {grid.shape}; got shape {g.shape}")
    if paint is not None:
        from scipy import ndimage

        # each node takes the paint of its closest input point: that of the nearest band node
        _, near = ndimage.distance_transform_edt(tri < 0, return_indices=True)
        near = tuple(near)
        pg, pw = paint(closest[near].reshape(-1, 3).astype(float), tri[near].reshape(-1))
        g = g * np.asarray(pg, float).reshape(grid.shape)
        w = w + np.asarray(pw, float).reshape(grid.shape + (3,))
        if np.max(np.linalg.norm(w.reshape(-1, 3), axis=1)) >= 1.0:
            raise WoodcamError("eccentricity plus brushed strengths must stay below 1 everywhere "
                               "so every normal keeps growing; lower them")
    isotropic = not np.any(w)
    constant = w.ndim == 1 and g.ndim == 0 and float(g) == 1.0 and not obstacles
    if method == "auto":
        method = "fmm" if isotropic else ("offset" if constant else "anisotropic")
    if method == "offset" and not constant:
        raise WoodcamError("method 'offset' is exact only for a constant wind (eccentricity) "
                           "without obstacles or brushed gain; use method 'anisotropic' or 'auto'")
    if method == "fmm" and not isotropic:
        raise WoodcamError("method 'fmm' (scikit-fmm) solves the isotropic case only; with "
                           "eccentricity or brushed directions use method 'anisotropic' or 'auto'")
    d_in = np.where(np.isfinite(dist), dist, WOODIFY_BAND_NODES * h)
    # The march starts from the nodes inside AND those on the surface (a face on a node plane:
    # an axis-aligned box's, wherever the grid puts one). Those were inside or outside as the
    # parity test's nudge fell: inside on the faces met from below, outside on those met from
    # above (distance 0 or ~1e-15 either way). Started outside, such a face grew half a step too
    # far (scikit-fmm's second-order start; the anisotropic march's exact first layer began a
    # layer late), so a 40x30x20 box centred in its grid grew 0.18 of a step off-centre; started
    # from, each face grows the same at both ends, within 0.1 step of the exact offset.
    start = inside | ((d_in <= WOODIFY_ON_SURFACE_VOXELS * h) & ~obstacle)
    if method == "fmm":
        T = _fmm(d_in, start, obstacle, g, h, stop_mm)
    elif method == "offset":
        T = _offset(d_in, start, w, grid, stop_mm)
    else:
        T = _anisotropic(d_in, closest, start, obstacle, g, w, grid, stop_mm)
    T[start] = -d_in[start]
    if obstacles:
        T = _fill_obstacle(T, obstacle)
    return Front(grid, T, inside, obstacle, obst_sdf, closest, tri, method)


def _fmm(d_in, inside, obstacle, g, h, stop_mm):
    import skfmm

    # ``inside``: the march's start (inside or on the surface, see propagate), just inside
    phi = np.where(inside, -np.maximum(d_in, WOODIFY_ON_SURFACE_VOXELS * h), d_in)
    phi = np.ma.MaskedArray(phi, obstacle)
    speed = np.broadcast_to(g, phi.shape).astype(float)
    narrow = float(stop_mm) if np.isfinite(stop_mm) else 0.0
    t = skfmm.travel_time(phi, speed, dx=float(h), order=2, narrow=narrow)
    if np.ma.isMaskedArray(t):
        return np.ma.filled(t.astype(float), np.inf)
    return np.asarray(t, float)


def _offset(d_in, inside, w, grid, stop_mm):
    from scipy import ndimage

    h = grid.spacing_mm
    reach = stop_mm / (1.0 - np.linalg.norm(w)) if np.isfinite(stop_mm) else 0.0
    D = _fmm(d_in, inside, np.zeros_like(inside), np.ones(()), h, reach)
    D = np.where(inside, -d_in, D)
    D = np.where(np.isfinite(D), D, np.nanmax(np.where(np.isfinite(D), D, np.nan)))
    out = ~inside
    x = np.stack(np.nonzero(out), axis=1).astype(float)  # node indices
    T = D[out]
    shift = np.asarray(w, float) / h  # index units per mm of T
    for _ in range(200):
        Tn = ndimage.map_coordinates(D, (x - T[:, None] * shift).T, order=1, mode="nearest")
        done = np.max(np.abs(Tn - T)) < 1e-6 * h
        T = Tn
        if done:
            break
    res = np.full(grid.shape, np.inf)
    res[out] = T
    if np.isfinite(stop_mm):
        res[res > stop_mm] = np.inf
    return res


def _anisotropic(d_in, closest, inside, obstacle, g, w, grid, stop_mm):
    from ._eikonal import BLOCKED, FAR, FIXED, SOURCE, march

    h = grid.spacing_mm
    T = np.full(grid.shape, np.inf)
    state = np.full(grid.shape, FAR, np.int8)
    state[obstacle] = BLOCKED
    state[inside] = SOURCE
    T[inside] = -d_in[inside]
    # first layer: outside nodes next to an inside node start from the exact distance d along
    # the outward normal n, reached after d / (g (1 + w . n)).
    near = np.zeros_like(inside)
    for ax in range(3):
        for s in (1, -1):
            near |= np.roll(inside, s, axis=ax)
    first = near & ~inside & ~obstacle
    idx = np.nonzero(first)
    p = np.stack([grid.origin_mm[d] + h * idx[d] for d in range(3)], axis=1)
    dvec = p - closest[idx].astype(float)
    d = np.linalg.norm(dvec, axis=1)
    n = dvec / np.maximum(d, 1e-12)[:, None]
    wl = w if w.ndim == 1 else w[idx]
    gl = g if g.ndim == 0 else g[idx]
    T[idx] = d / (gl * (1.0 + np.sum(n * wl, axis=-1)))
    state[idx] = FIXED
    gain = np.asarray(g, float).reshape((1, 1, 1) if g.ndim == 0 else g.shape)
    wind = np.asarray(w, float).reshape((1, 1, 1, 3) if w.ndim == 1 else w.shape)
    march(T, state, np.ascontiguousarray(gain), np.ascontiguousarray(wind), float(h))
    if np.isfinite(stop_mm):
        T[T > stop_mm] = np.inf
    return T


def _fill_obstacle(T, obstacle):
    """Give obstacle nodes the arrival time of the nearest wood node (continuous field there)."""
    from scipy import ndimage

    _, idx = ndimage.distance_transform_edt(obstacle, return_distances=True, return_indices=True)
    out = T.copy()
    out[obstacle] = T[tuple(i[obstacle] for i in idx)]
    return out


def sphere_arrival(points_mm: ArrayLike, centre_mm: ArrayLike, radius_mm: float,
                   wind: ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Exact arrival time (mm) of the front grown from a sphere with normal speed ``1 + w . n``.

    The eccentric front at pseudo-time ``T`` is the sphere offset by ``T`` and shifted by
    ``w T`` (Minkowski sum with a ball of radius ``T`` centred at ``w T``), so ``T`` solves
    ``|x - c - w T| = r0 + T``: a quadratic. Negative inside the input sphere (``-distance``).
    ``points_mm``: ``(n, 3)`` mm; ``centre_mm`` (3,) and ``radius_mm``: the sphere ``c``,
    ``r0``; ``wind``: ``w`` (3,), ``|w| < 1``. Returns ``(n,)`` mm.
    """
    p = np.asarray(points_mm, float) - np.asarray(centre_mm, float)
    w = np.asarray(wind, float)
    # (1 - |w|^2) T^2 + 2 (r0 + p.w) T + r0^2 - |p|^2 = 0
    a = 1.0 - w @ w
    b = 2.0 * (radius_mm + p @ w)
    c = radius_mm ** 2 - np.einsum("ij,ij->i", p, p)
    t = (-b + np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))) / (2 * a)
    r = np.linalg.norm(p, axis=1)
    return np.where(r < radius_mm, r - radius_mm, t)


def offset_arrival(distance, points_mm, wind=(0.0, 0.0, 0.0), iterations: int = 50) -> np.ndarray:
    """Exact arrival time (mm) of the unobstructed front from any closed shape, by bisection.

    Without obstacles the front at ``T`` is the input offset by ``T`` and shifted by ``w T``,
    so ``T(x)`` is the root of ``dist(x - w T) = T`` (the left side minus ``T`` falls strictly
    for ``|w| < 1``). ``distance(points (n, 3)) -> (n,)`` is the exact distance to the shape
    (positive outside), e.g. the closed form of a box; ``points_mm (n, 3)`` lie outside it.
    A check for the grid solvers.
    """
    p = np.asarray(points_mm, float)
    w = np.asarray(wind, float)
    d0 = np.asarray(distance(p), float)
    lo = d0 / (1.0 + np.linalg.norm(w))
    hi = d0 / (1.0 - np.linalg.norm(w)) + 1e-12
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        beyond = np.asarray(distance(p - mid[:, None] * w), float) > mid
        lo = np.where(beyond, mid, lo)
        hi = np.where(beyond, hi, mid)
    return 0.5 * (lo + hi)
