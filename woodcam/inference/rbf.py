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
from .._types import GrowthFieldLike


def thin_out(n: int, max_points: int, seed: int = 0) -> np.ndarray:
    """Indices of at most ``max_points`` of ``n`` items, a fixed random subset (sorted)."""
    if n <= max_points:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, max_points, replace=False))


def fit_rbf(obs: RingObservations, kernel: str = "thin_plate_spline", smoothing: float = 0.0,
            max_points: int = RBF_MAX_POINTS) -> GrowthFieldLike:
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
    if len(np.unique(obs.face)) < 2:  # its linear tail is singular on one plane (a LinAlgError)
        raise WoodcamError("method 'rbf' needs rings on at least two faces (a thin-plate spline cannot "
                           "extend one plane's rings into the block); use 'radial' or 'evidence'")
    i = thin_out(len(obs.points_mm), max_points)
    pts, yrs = obs.points_mm[i], obs.years[i]
    # Duplicate points (a ring traced twice) make the interpolation matrix singular.
    _, uniq = np.unique(np.round(pts, 6), axis=0, return_index=True)
    return _thin_plate_field(RBFInterpolator(pts[uniq], yrs[uniq], kernel=kernel, smoothing=smoothing))


#: Evaluation points per block of :class:`_ThinPlate` (a 256 x 2500 kernel block is 5 MB).
_TPS_CHUNK = 256


class _ThinPlate:
    """A fitted :class:`scipy.interpolate.RBFInterpolator` with the thin-plate kernel and its
    degree-1 tail, evaluated ~6x faster: ``(n, 3) mm -> (n,) years``.

    scipy builds the kernel pair by pair (a square root and a log each) in a compiled loop and
    multiplies blocks of ~1000 points; baking a chosen RBF (or an RBF residual) on a block's
    1 mm grid took 5-7 CPU-s of a 15 s evidence fit. Here the squared distances come from one
    matrix product about the centres' mean, ``r^2 log r = r^2 log(r^2) / 2`` takes one log, and
    blocks of :data:`_TPS_CHUNK` points stay in cache. Written by hand because no library
    evaluates scipy's fitted coefficients faster; it reads them from the interpolator
    (``y``, ``_coeffs``, ``_shift``, ``_scale``: :func:`_thin_plate_field` checks they are there).
    Values agree with scipy's to ~1e-11 years (rounding of the expanded distance; checked in
    ``tests/inference/test_fit_speed.py``).
    """

    def __init__(self, rbf):
        self.rbf = rbf
        y = np.asarray(rbf.y, float)
        coef = np.asarray(rbf._coeffs, float)[:, 0]
        self._centre = y.mean(axis=0)
        self._yc = y - self._centre
        self._yy = np.einsum("ij,ij->i", self._yc, self._yc)
        self._w = 0.5 * coef[:len(y)]          # r^2 log r = 0.5 r^2 log r^2
        self._tail = coef[len(y):]             # 1, x, y, z of the shifted, scaled points
        self._shift, self._scale = np.asarray(rbf._shift, float), np.asarray(rbf._scale, float)

    def __call__(self, points_mm) -> np.ndarray:
        from .._threads import one_blas_thread

        x = np.asarray(points_mm, float).reshape(-1, 3)
        out = np.empty(len(x))
        m2yc = -2.0 * self._yc.T
        with one_blas_thread():  # small products: BLAS threads only spin (11x the CPU, measured)
            self._blocks(x, m2yc, out)
        return out

    def _blocks(self, x, m2yc, out) -> None:
        for i in range(0, len(x), _TPS_CHUNK):
            xc = x[i:i + _TPS_CHUNK] - self._centre
            d2 = xc @ m2yc
            d2 += self._yy
            d2 += np.einsum("ij,ij->i", xc, xc)[:, None]
            np.maximum(d2, 1e-300, out=d2)     # (coincident points: 0, as scipy's kernel)
            k = np.log(d2)
            k *= d2
            xs = (x[i:i + _TPS_CHUNK] - self._shift) / self._scale
            out[i:i + _TPS_CHUNK] = k @ self._w + self._tail[0] + xs @ self._tail[1:]


def _thin_plate_field(rbf):
    """``rbf`` (a fitted :class:`scipy.interpolate.RBFInterpolator`) as a field evaluated by
    :class:`_ThinPlate` when it is the thin-plate spline with a degree-1 tail and one value
    per point fitted on all points (what :func:`fit_rbf` and the evidence fit's residual make);
    otherwise ``rbf`` itself."""
    powers = getattr(rbf, "powers", None)
    ok = (getattr(rbf, "kernel", None) == "thin_plate_spline" and getattr(rbf, "neighbors", 0) is None
          and getattr(rbf, "epsilon", None) == 1.0
          and all(hasattr(rbf, a) for a in ("y", "_coeffs", "_shift", "_scale"))
          and np.asarray(rbf.y).ndim == 2 and np.asarray(rbf.y).shape[1] == 3
          and np.asarray(rbf._coeffs).ndim == 2 and np.asarray(rbf._coeffs).shape[1] == 1
          and powers is not None and np.array_equal(np.asarray(powers), np.vstack([np.zeros(3), np.eye(3)])))
    return _ThinPlate(rbf) if ok else rbf
