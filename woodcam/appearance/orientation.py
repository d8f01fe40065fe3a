"""Orientation-dependent blending of three per-axis colourings (eq. 10 of seed 000).

``RGB_XY`` is the colour a surface shows when its normal is +-Z (a cut in the XY plane),
``RGB_YZ`` when its normal is +-X, ``RGB_ZX`` when its normal is +-Y; all three in the block
frame. A surface with normal ``n`` gets

    RGB = (|n_z| RGB_XY + |n_x| RGB_YZ + |n_y| RGB_ZX) / (|n_x| + |n_y| + |n_z|)   (eq. 10)

so an axis-aligned surface shows exactly one colouring.

:func:`eq10_weights` is the one implementation of the weights: :func:`axis_weights` (and so
:func:`blend_axis_colors`) and the colour map's compiled kernel both call it.
"""

from __future__ import annotations

import numba
import numpy as np

from ..errors import WoodcamError
from .._types import ArrayLike


@numba.njit(cache=True, inline="always")
def eq10_weights(nx, ny, nz):  # pragma: no cover - compiled
    """Eq. 10 weights ``(w_x, w_y, w_z)`` of one normal: ``|n_k| / sum |n|``; equal thirds for a
    zero normal (a degenerate triangle) rather than a division by zero."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    s = ax + ay + az
    if s > 0:
        return ax / s, ay / s, az / s
    return 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0


@numba.njit(nogil=True, cache=True)
def _weights_kernel(n, out):  # pragma: no cover - compiled
    for i in range(n.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = eq10_weights(n[i, 0], n[i, 1], n[i, 2])


def axis_weights(normals: ArrayLike) -> np.ndarray:
    """Eq. 10 weights ``(n, 3)`` for the colourings of the planes normal to X, Y, Z.

    Column ``k`` weighs the colouring seen on a plane whose normal is block axis ``k``
    (column 0 = ``RGB_YZ``, 1 = ``RGB_ZX``, 2 = ``RGB_XY``); rows sum to 1. A zero normal
    (degenerate triangle) gets equal weights rather than a division by zero. ``normals``:
    ``(n, 3)`` surface normals (block frame; need not be unit length).
    """
    n = np.ascontiguousarray(normals, dtype=np.float32)
    if n.ndim != 2 or n.shape[1] != 3:
        raise WoodcamError(f"normals must have shape (n, 3); got {n.shape}")
    out = np.empty(n.shape, np.float32)
    _weights_kernel(n, out)
    return out


def blend_axis_colors(rgb_yz: ArrayLike, rgb_zx: ArrayLike, rgb_xy: ArrayLike, normals: ArrayLike) -> np.ndarray:
    """Eq. 10: blend three ``(n, 3)`` colourings by the surface ``normals : (n, 3)`` (block
    frame): ``rgb_yz``, ``rgb_zx``, ``rgb_xy`` as seen on the planes normal to X, Y and Z,
    weighted by :func:`axis_weights`."""
    w = axis_weights(normals)
    return w[:, 0:1] * rgb_yz + w[:, 1:2] * rgb_zx + w[:, 2:3] * rgb_xy
