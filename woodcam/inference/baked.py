"""Baking a fitted growth field to a grid (:class:`woodcam.fields.GridField`) over a block.

A fitted field (an RBF with thousands of centres, the radial model) is sampled once on a grid of
``BAKE_SPACING_MM`` covering the block plus a margin; the grid field is fast to evaluate, saves
to ``.npz`` and is what ``woodcam bake`` reads back.

A thin-plate spline of ring points (the RBF hypothesis, or the residual on a stem or a radial
fit: :class:`~woodcam.fields.residual.ResidualField`) has its centres on the block's faces, so
it is smooth deep inside: there it is sampled on a coarser grid and interpolated
(:data:`~woodcam.tolerances.BAKE_SMOOTH_DEPTH_MM`), while every node near a face, where the
rings are seen, is evaluated exactly. Its kernel has one term per centre (1000 in the evidence
fit), so it was most of a knotted block's bake: 4.8 of its ~6 CPU-s (seed 57131 block 11).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import WoodcamError
from ..fields.grid import GridField
from ..frames import check_size
from ..tolerances import BAKE_MARGIN_MM, BAKE_SMOOTH_DEPTH_MM, BAKE_SMOOTH_SPACING_MM, BAKE_SPACING_MM
from .._types import ArrayLike, GrowthFieldLike


def bake(field: GrowthFieldLike, size_mm: ArrayLike, spacing_mm: float = BAKE_SPACING_MM,
         margin_mm: float = BAKE_MARGIN_MM,
         workers: int = 1) -> GridField:
    """Sample ``field`` (``(n, 3) mm -> (n,) years``) on a grid over the block ``[0, size_mm]``.

    The grid has nodes every ``spacing_mm`` and at least ``margin_mm`` beyond every face, so its
    cubic splines are not at their border on the block's faces. ``workers > 1``: a share of
    the nodes in a forked process, for a field safe to use after a fork
    (:func:`woodcam.fields.base.evaluate`).
    """
    size = check_size(size_mm)
    if not spacing_mm > 0:
        raise WoodcamError(f"spacing_mm must be > 0; got {spacing_mm!r}")
    from .._threads import one_blas_thread

    margin = max(1, math.ceil(margin_mm / spacing_mm))
    base, spline = _face_spline(field, size)
    with one_blas_thread():  # the fields' products are small per batch: BLAS threads only spin
        grid = GridField.bake(base, (0.0, 0.0, 0.0), tuple(size), spacing_mm, margin_nodes=margin, workers=workers)
        if spline is None:
            return grid
        years = grid.years + _smooth_inside(spline, grid, size, workers)  # as ResidualField adds them
    return GridField(years, grid.origin_mm, grid.spacing_mm, grid.interpolation, grid.axis)


def _face_spline(field, size):
    """``(rest, spline)``: ``field``'s thin-plate spline whose centres all lie on the block's
    faces (itself, or a :class:`~woodcam.fields.residual.ResidualField`'s residual) and the rest
    of it (a zero field beside a lone spline), or ``(field, None)`` when it has none."""
    from ..fields.residual import ResidualField
    from .rbf import _ThinPlate

    spline, rest = (field.residual, field.base) if isinstance(field, ResidualField) else (field, None)
    if not isinstance(spline, _ThinPlate):
        return field, None
    if np.any(_depth_mm(np.asarray(spline.rbf.y, float), size) > 1e-6):  # a centre inside: not smooth there
        return field, None
    return (rest if rest is not None else _Zero(getattr(field, "axis", (0.0, 0.0, 1.0)))), spline


def _depth_mm(points_mm, size) -> np.ndarray:
    """``(n,)`` mm from each of ``points_mm (n, 3)`` to the nearest face of the block
    ``[0, size]``, negative outside it."""
    return np.min(np.minimum(points_mm, size - points_mm), axis=1)


class _Zero:
    """The zero field (what a lone thin-plate spline adds to)."""

    def __init__(self, axis):
        self.axis = axis

    def __call__(self, points_mm):
        return np.zeros(len(points_mm))


def _smooth_inside(spline, grid, size, workers: int) -> np.ndarray:
    """``spline`` on ``grid``'s nodes: exactly within :data:`BAKE_SMOOTH_DEPTH_MM` of a face (and
    outside the block), deeper by cubic interpolation of its values on a grid of
    :data:`BAKE_SMOOTH_SPACING_MM` (where all its centres are that far or farther)."""
    from scipy import ndimage

    from ..fields.base import evaluate
    from ..fields.grid import _nodes_mm

    shape = grid.years.shape
    nodes = grid.nodes_mm()
    deep = _depth_mm(nodes, size) >= BAKE_SMOOTH_DEPTH_MM
    out = np.empty(len(nodes))
    if not deep.any():
        out[:] = evaluate(spline, nodes, workers=workers)
        return out.reshape(shape)
    h = BAKE_SMOOTH_SPACING_MM
    lo = nodes[deep].min(axis=0) - 2 * h  # two nodes beyond the deep region: the cubic's support
    n = np.ceil((nodes[deep].max(axis=0) + 2 * h - lo) / h).astype(int) + 1
    coarse = _nodes_mm(lo, (h,) * 3, n)
    # one call for both: its share of the points in a fork (the coarse grid alone is too few to fork)
    values = evaluate(spline, np.concatenate([nodes[~deep], coarse]), workers=workers)
    out[~deep] = values[:len(values) - len(coarse)]
    out[deep] = ndimage.map_coordinates(values[len(values) - len(coarse):].reshape(n), ((nodes[deep] - lo) / h).T,
                                        order=3, mode="nearest")
    return out.reshape(shape)
