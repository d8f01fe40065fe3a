"""Baking a fitted growth field to a grid (:class:`woodcam.fields.GridField`) over a block.

A fitted field (an RBF with thousands of centres, the radial model) is sampled once on a grid of
``BAKE_SPACING_MM`` covering the block plus a margin; the grid field is fast to evaluate, saves
to ``.npz`` and is what ``woodcam bake`` reads back.
"""

from __future__ import annotations

import math

from ..errors import WoodcamError
from ..fields.grid import GridField
from ..frames import check_size
from ..tolerances import BAKE_MARGIN_MM, BAKE_SPACING_MM


def bake(field, size_mm, spacing_mm: float = BAKE_SPACING_MM, margin_mm: float = BAKE_MARGIN_MM,
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

    with one_blas_thread():  # the fields' products are small per batch: BLAS threads only spin
        return GridField.bake(field, (0.0, 0.0, 0.0), tuple(size), spacing_mm,
                              margin_nodes=max(1, math.ceil(margin_mm / spacing_mm)), workers=workers)
