"""Analytic stems for the knot tests: round rings about a straight pith along Z."""

import numpy as np

from woodcam.inference.radial import _frame
from woodcam.inference.stem import StemField


def round_stem(pith_xy: tuple[float, float], size_mm, density: float = 1 / 3.0) -> StemField:
    """Round rings ``density`` per mm about a straight pith along Z through ``pith_xy`` (mm,
    block frame) in a block of ``size_mm`` (3,); years 0 on the pith."""
    K, M, P = 2, 0, 2
    coef = np.zeros((2 * K + 1) * (M + 1))
    coef[0] = density
    c = np.asarray(size_mm, float) / 2
    f = StemField(c, np.array([0.0, 0.0, 1.0]), float(np.linalg.norm(size_mm) / 2), np.zeros((2, 3)), K, M, P,
                  coef, np.zeros(P - 1), 50.0, 0.0)
    # move the pith: the centreline offset in the stem's own (b1, b2) frame
    _, b1, b2 = _frame(f.base_axis)
    off = np.array([pith_xy[0], pith_xy[1], 0.0]) - c
    f.curve = np.array([[off @ b1, 0, 0], [off @ b2, 0, 0]], float)
    return f
