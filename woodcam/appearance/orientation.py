"""Orientation-dependent blending of three per-axis colourings (eq. 10 of seed 000).

``RGB_XY`` is the colour a surface shows when its normal is +-Z (a cut in the XY plane),
``RGB_YZ`` when its normal is +-X, ``RGB_ZX`` when its normal is +-Y; all three in the block
frame. A surface with normal ``n`` gets

    RGB = (|n_z| RGB_XY + |n_x| RGB_YZ + |n_y| RGB_ZX) / (|n_x| + |n_y| + |n_z|)   (eq. 10)

so an axis-aligned surface shows exactly one colouring.
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError


def axis_weights(normals) -> np.ndarray:
    """Eq. 10 weights ``(n, 3)`` for the colourings of the planes normal to X, Y, Z.

    Column ``k`` weighs the colouring seen on a plane whose normal is block axis ``k``
    (column 0 = ``RGB_YZ``, 1 = ``RGB_ZX``, 2 = ``RGB_XY``); rows sum to 1. A zero normal
    (degenerate triangle) gets equal weights rather than a division by zero.
    """
    n = np.abs(np.asarray(normals, dtype=np.float32))
    if n.ndim != 2 or n.shape[1] != 3:
        raise WoodcamError(f"normals must have shape (n, 3); got {n.shape}")
    s = n.sum(axis=1, keepdims=True)
    return np.where(s > 0, n / np.where(s > 0, s, 1), np.float32(1.0 / 3.0))


def blend_axis_colors(rgb_yz, rgb_zx, rgb_xy, normals) -> np.ndarray:
    """Eq. 10: blend three ``(n, 3)`` colourings by the surface ``normals : (n, 3)``."""
    w = axis_weights(normals)
    return w[:, 0:1] * rgb_yz + w[:, 1:2] * rgb_zx + w[:, 2:3] * rgb_xy
