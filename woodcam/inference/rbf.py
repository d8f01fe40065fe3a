"""Baseline: radial-basis-function interpolation of labelled ring points (seed 000, section 4.3).

The seed compares its neural fit with "naive RBF interpolation" of the annotated ring points
``(x_k, g_k)``. Here that is scipy's :class:`~scipy.interpolate.RBFInterpolator` with the
thin-plate-spline kernel (and its degree-1 polynomial tail) on the labelled trace points, block
frame, mm -> years. Years must be labelled: the baseline has no way to number unlabelled rings.
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError
from ..tolerances import RBF_MAX_POINTS
from .observations import RingObservations


def thin_out(n: int, max_points: int, seed: int = 0) -> np.ndarray:
    """Indices of at most ``max_points`` of ``n`` items, a fixed random subset (sorted)."""
    if n <= max_points:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, max_points, replace=False))


def fit_rbf(obs: RingObservations, kernel: str = "thin_plate_spline", smoothing: float = 0.0,
            max_points: int = RBF_MAX_POINTS):
    """Interpolate labelled ring points with an RBF; returns a field ``(n, 3) mm -> (n,) years``.

    Parameters
    ----------
    obs : labelled ring observations (every year finite).
    kernel, smoothing : passed to :class:`scipy.interpolate.RBFInterpolator`.
    max_points : a fixed random subset of at most this many points is used (the dense solve is
        O(n^3); 2500 points at 0.5 mm spacing still sample every ring every ~1-2 mm).
    """
    from scipy.interpolate import RBFInterpolator

    if not obs.labelled:
        raise WoodcamError(
            "method 'rbf' needs year-labelled traces; this block's rings are unlabelled "
            "(traces without years or ring maps); use method 'radial', which numbers rings itself"
        )
    i = thin_out(len(obs.points_mm), max_points)
    pts, yrs = obs.points_mm[i], obs.years[i]
    # Duplicate points (a ring traced twice) make the interpolation matrix singular.
    _, uniq = np.unique(np.round(pts, 6), axis=0, return_index=True)
    return RBFInterpolator(pts[uniq], yrs[uniq], kernel=kernel, smoothing=smoothing)
