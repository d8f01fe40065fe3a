"""Woodification of a watertight mesh: grow it for some years and keep everything it became.

:func:`woodify` sizes a grid round the input and its final growth, propagates the front once
(:mod:`.front`) and returns a :class:`Woodification`: the growth field of the grown object
(:class:`~woodcam.woodify.field.WoodifiedField`), grown surfaces at any year, origins of grown
points on the input (persistent texturing) and ring sections. Object frame = the input mesh's
frame, mm; years since the input surface.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import time
from dataclasses import dataclass
from dataclasses import field as dc_field

import numpy as np
from numpy.typing import ArrayLike

from .._repr import summary_repr
from .._types import Mesh
from ..errors import WoodcamError
from ..limits import WOODIFY_RESOLUTION_RANGE, check_grid, limit
from .brushes import Brush, check_vertex_paint, paint
from .field import WoodifiedField
from .front import Front, Method, VoxelGrid, check_resolution, check_watertight, obstacle_names_of, propagate
from .speed import GrowthSpeed, weibull_cdf

if TYPE_CHECKING:
    import trimesh

#: Nodes of margin kept between the final grown surface and the grid border.
_MARGIN_NODES = 4

#: Peak memory (bytes) of a woodify run per grid node, measured: ``woodcam woodify`` of a sphere
#: (stress cracks, default products) peaked at 0.60 GB on a 100^3 grid and 1.83 GB on 200^3,
#: 176 B a node: the front's arrays (arrival, distance, closest point, triangle, inside: ~40 B)
#: and the back-traces' gradients and fills (float64 grids, ~70 B) live at once. A 1024^3 grid
#: (the top of WOODIFY_RESOLUTION_RANGE, a cube-shaped input) would ask ~190 GB: refused ahead.
WOODIFY_BYTES_PER_NODE = 180


@dataclass
class Woodification:
    """Everything a woodification run produced (see module docstring).

    Attributes
    ----------
    mesh : trimesh.Trimesh
        The input, object frame, mm.
    speed : GrowthSpeed
    years : float
        Years grown.
    front : Front
    field : WoodifiedField
        Years at object-frame points (identity placement; :meth:`WoodifiedField.placed` cuts a
        block).
    obstacles : list of trimesh.Trimesh
    timings : dict
        Seconds per stage (wall clock).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    mesh: object
    speed: GrowthSpeed
    years: float
    front: Front
    field: WoodifiedField
    obstacles: list = dc_field(default_factory=list)
    timings: dict = dc_field(default_factory=dict)

    def tau(self, year: float) -> float:
        """Pseudo-time (mm) of ``year``."""
        return float(self.speed.tau(year))

    def surface(self, year: float) -> "trimesh.Trimesh":
        """The grown surface at ``year`` (0 = the input as voxelised) as a watertight trimesh."""
        from .surfaces import surface_at

        if not (np.isfinite(year) and 0 <= year <= self.years):
            raise WoodcamError(f"year must lie in [0, {self.years:g}] (the years grown); got {year!r}")
        return surface_at(self.front, self.tau(year))

    def origins(self, points_mm: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Origins ``(n, 3)`` on the input surface and their input triangles ``(n,)`` of grown
        points (characteristic back-trace, :func:`woodcam.woodify.surfaces.trace_back`)."""
        from ..fields.base import check_points
        from .surfaces import trace_back

        # a NaN point was numpy's cast warning, (n, 2) a broadcast error inside the back-trace
        return trace_back(self.front, check_points(points_mm), wind=self.speed.wind)

    def engulf_year(self, obstacle_index: int = 0, inside_box: ArrayLike | None = None) -> float:
        """Year by which the wood has closed round obstacle ``obstacle_index`` within the grid
        (every node touching it is wood): the latest arrival on its boundary, as years.

        ``inside_box`` ``(lo (3,), hi (3,))`` mm limits the check to part of the obstacle (a post
        that sticks out of the tree is engulfed only where the tree is)."""
        from ._voxel import inside_parity

        g = self.front.grid
        o = self.obstacles[obstacle_index]
        mine = inside_parity(np.asarray(o.vertices, float), np.asarray(o.faces, np.int64),
                             np.asarray(g.origin_mm, float), g.spacing_mm, np.asarray(g.shape))
        from scipy import ndimage

        rim = ndimage.binary_dilation(mine) & ~self.front.obstacle
        if inside_box is not None:
            lo, hi = (np.asarray(v, float) for v in inside_box)
            pts = g.nodes().reshape(g.shape + (3,))
            rim &= np.all((pts >= lo) & (pts <= hi), axis=-1)
        if not rim.any():
            raise WoodcamError(f"obstacle {obstacle_index} touches no wood node in the grid")
        return float(self.speed.years(np.max(self.front.arrival_mm[rim])))


def _grid_fits(grid: VoxelGrid) -> bool:
    """True when ``grid`` is within both limits :func:`~woodcam.limits.check_grid` applies to a
    woodify grid (its nodes, and their bytes at :data:`WOODIFY_BYTES_PER_NODE`)."""
    nodes = float(np.prod(np.asarray(grid.shape, float)))
    return nodes <= limit("MAX_GRID_CELLS") and nodes * WOODIFY_BYTES_PER_NODE <= limit("MAX_ALLOC_BYTES")


def _finest_fitting(top: int, fits) -> int | None:
    """The largest resolution ``n < top`` (at least the lowest allowed) with ``fits(n)``, by
    bisection (the grid grows with it); None when even the lowest does not fit."""
    lo = WOODIFY_RESOLUTION_RANGE[0]
    if not fits(lo):
        return None
    hi = top  # fits(lo), not fits(hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return lo


def woodify(mesh: Mesh, years: float, *, growth_mm: float | None = None, velocity_mm: float | None = None,
            time_scale_years: float | None = None, shape: float = 2.0, eccentricity: float = 0.0,
            up: ArrayLike = (0.0, 0.0, 1.0), obstacles: Sequence[Mesh] = (),
            brushes: tuple[Brush, ...] | list = (), vertex_gain: ArrayLike | None = None,
            vertex_direction: ArrayLike | None = None, resolution: int = 128,
            method: Method = "auto", obstacle_names: Sequence[str] | None = None) -> Woodification:
    """Grow a watertight ``mesh`` for ``years`` (seed 004 ch. 4 on a voxel grid).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Watertight input, mm.
    years : float
        Years to grow, > 0.
    growth_mm : float, optional
        How far a flat surface grows in ``years`` (mm); sets the velocity scale
        ``v = growth_mm / W(years / time_scale_years)``. Default: a quarter of the input's
        largest side. Give either this or ``velocity_mm``.
    velocity_mm : float, optional
        The Weibull velocity scale ``v`` (mm) directly.
    time_scale_years : float, optional
        ``lambda`` of the Weibull law; default ``years`` (growth slowing towards the end).
    shape, eccentricity, up :
        See :class:`~woodcam.woodify.speed.GrowthSpeed`.
    obstacles : sequence of trimesh.Trimesh
        Watertight obstacles (mm); the front stops on contact, wraps round and engulfs them.
    obstacle_names : sequence of str, optional
        What messages call each obstacle (default ``obstacles[i]``; ``woodcam woodify`` names
        the option and the file, ``--obstacle 'post.stl'``).
    brushes, vertex_gain, vertex_direction :
        User-defined growth (:mod:`woodcam.woodify.brushes`): a list of :class:`Brush`, a gain
        ``(n_vertices,)`` > 0 and a direction ``(n_vertices, 3)`` per vertex of ``mesh``.
    resolution : int
        Grid nodes along the longest side of the grown object's box.
    method : "auto", "fmm", "offset" or "anisotropic" (:mod:`woodcam.woodify.front`)
    """
    t0 = time.perf_counter()
    if not (isinstance(years, (int, float, np.integer, np.floating)) and np.isfinite(years) and years > 0):
        raise WoodcamError(f"years must be a number > 0 (years to grow); got {years!r}; e.g. 40")
    mesh = check_watertight(mesh, "mesh")
    resolution = check_resolution(resolution)
    if years <= 1:  # its wood, blocks, sections and leaves were one flat colour without a word
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"years (--years) = {years:g}: a ring is where one year's wood meets the next, so wood "
                      f"grown {years:g} year{'' if years == 1 else 's'} has none inside its bark: its sections, "
                      "and the blocks and veneers cut from it, show one flat colour; grow more than one year "
                      "(e.g. --years 5; --growth keeps the thickness grown)", WoodcamWarning, stacklevel=2)
    vertex_gain, vertex_direction = check_vertex_paint(vertex_gain, vertex_direction, len(mesh.vertices))
    lam = float(years) if time_scale_years is None else float(time_scale_years)
    if growth_mm is not None and velocity_mm is not None:
        raise WoodcamError("give growth_mm or velocity_mm, not both")
    lo, hi = mesh.bounds
    if velocity_mm is None:
        g_mm = 0.25 * float(np.max(hi - lo)) if growth_mm is None else float(growth_mm)
        cap = limit("MAX_BLOCK_SIZE_MM")
        if not (np.isfinite(g_mm) and 0 < g_mm <= cap):  # 1e20 divided by zero further on
            raise WoodcamError(f"growth_mm must be in (0, {cap:g}] (mm grown in `years`; "
                               f"raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); "
                               f"got {growth_mm!r}")
        if not lam > 0:
            raise WoodcamError(f"time_scale_years must be > 0; got {time_scale_years!r}")
        velocity_mm = g_mm / float(weibull_cdf(years / lam, shape))
    speed = GrowthSpeed(float(velocity_mm), lam, shape, float(eccentricity), tuple(up))
    tau_end = float(speed.tau(years))
    # one Brush (not in a list) was "'Brush' object is not iterable", a number an AttributeError
    strokes = [brushes] if isinstance(brushes, Brush) else list(brushes) if isinstance(brushes, (list, tuple)) else None
    if strokes is None or not all(isinstance(b, Brush) for b in strokes):
        raise WoodcamError(f"brushes must be a list of woodcam.woodify.Brush; got {brushes!r:.80}; "
                           "e.g. brushes=[Brush((0, 0, 10), radius_mm=5, gain=2)]")
    gmax = float(np.prod([max(b.gain, 1.0) for b in strokes])) if strokes else 1.0
    if vertex_gain is not None:
        gmax *= float(np.max(vertex_gain))
    wmax = abs(speed.eccentricity) + sum(b.strength for b in strokes)
    if vertex_direction is not None:
        wmax += float(np.max(np.linalg.norm(np.asarray(vertex_direction, float), axis=1)))
    if wmax >= 1.0:
        raise WoodcamError(f"eccentricity plus brush strengths must stay below 1; got {wmax:.3g}")
    reach = tau_end * gmax * (1.0 + wmax)
    ext = float(np.max(hi - lo)) + 2 * reach

    def grid_at(n: int) -> VoxelGrid:
        pad = reach + _MARGIN_NODES * ext / (n - 1 - 2 * _MARGIN_NODES)
        return VoxelGrid.around(lo - pad, hi + pad, n)

    grid = grid_at(resolution)
    # refused before any of it is allocated: the OOM killer, not an error, ended a fine grid;
    # the fix names the finest resolution within both limits (it said only 'lower the
    # resolution', and the raise of the limit it offered ran into the other one)
    if not _grid_fits(grid):
        best = _finest_fitting(resolution, lambda n: _grid_fits(grid_at(n)))
        fix = (f"lower the resolution to {best} or less" if best is not None else "lower the resolution")
        check_grid(grid.shape, f"woodify's grid at resolution {resolution}",
                   itemsize=WOODIFY_BYTES_PER_NODE, fix=f"{fix} (--resolution on the command line; default 128)")
    obstacle_names = obstacle_names_of(obstacles, obstacle_names)
    obstacles = [check_watertight(o, name) for o, name in zip(obstacles, obstacle_names)]
    paint_fn = None
    if strokes or vertex_gain is not None or vertex_direction is not None:
        def paint_fn(origin, tri):
            return paint(origin, strokes, vertex_gain=vertex_gain,
                         vertex_direction=vertex_direction, mesh=mesh, tri=tri)
    t1 = time.perf_counter()
    front = propagate(mesh, grid, wind=speed.wind, obstacles=obstacles, obstacle_names=obstacle_names, method=method,
                      stop_mm=tau_end + 2 * _MARGIN_NODES * grid.spacing_mm * gmax, paint=paint_fn)
    t2 = time.perf_counter()
    from .bark import stem_axis

    field = WoodifiedField(front.arrival_mm, grid.origin_mm, grid.spacing_mm, speed, float(years),
                           front.obstacle_sdf_mm, stem_axis=stem_axis(mesh))
    timings = {"setup_s": t1 - t0, "front_s": t2 - t1, "field_s": time.perf_counter() - t2}
    return Woodification(mesh, speed, float(years), front, field, obstacles, timings)
