"""Log centreline as Chebyshev series ``x(l), y(l)`` (seed 001 §3.3).

The log frame has ``z`` (= the log-centric ``l``, mm) along the log, ``0 <= l <= length``; the
centreline is ``(x(l), y(l), l)``. Seed 001 writes ``y(x), z(x)`` with ``x`` along the log; we
keep the project's convention of ``z`` along the log (``docs/conventions.md``, ``LogFrame``).
``l`` maps to the Chebyshev variable ``u = 2 l / length - 1``. The constant term ``T_0`` is left
out of the coefficients (the seed assumes a centred curve) and kept as a separate ``offset``,
so a fit to measured pith positions in any frame round-trips.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C

from ..errors import WoodcamError
from .._types import ArrayLike


def _u(l_mm, length_mm: float) -> np.ndarray:
    return 2.0 * np.asarray(l_mm, dtype=float) / length_mm - 1.0


@dataclass(frozen=True)
class Centreline:
    """Chebyshev centreline of a log.

    Attributes
    ----------
    length_mm : float
        Log length; ``l`` runs over ``[0, length_mm]``.
    coef_x, coef_y : (n,) float
        Coefficients (mm) of ``T_1 .. T_n`` for ``x(l)`` and ``y(l)``.
    offset_xy : (2,) float
        The ``T_0`` terms (mm), zero for a centred curve.
    """

    length_mm: float
    coef_x: np.ndarray
    coef_y: np.ndarray
    offset_xy: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        if not (np.isfinite(self.length_mm) and self.length_mm > 0):
            raise WoodcamError(f"length_mm must be > 0; got {self.length_mm!r}")
        cx, cy = np.asarray(self.coef_x, float), np.asarray(self.coef_y, float)
        if cx.ndim != 1 or cx.shape != cy.shape:
            raise WoodcamError(f"coef_x and coef_y must be 1-D of equal length; got {cx.shape} and {cy.shape}")
        object.__setattr__(self, "coef_x", cx)
        object.__setattr__(self, "coef_y", cy)

    def xy(self, l_mm) -> np.ndarray:
        """Centreline offset ``(n, 2)`` mm at heights ``l_mm : (n,)``."""
        u = _u(l_mm, self.length_mm).reshape(-1)
        x = C.chebval(u, np.r_[self.offset_xy[0], self.coef_x])
        y = C.chebval(u, np.r_[self.offset_xy[1], self.coef_y])
        return np.stack([x, y], axis=1)

    def points(self, l_mm) -> np.ndarray:
        """Centreline points ``(n, 3)`` in the log frame (mm) at heights ``l_mm : (n,)``."""
        l = np.asarray(l_mm, dtype=float).reshape(-1)
        return np.concatenate([self.xy(l), l[:, None]], axis=1)

    def to_log_frame(self, points_lcs) -> np.ndarray:
        """Log-centric ``(theta_rad, l_mm, rho_mm)`` ``(n, 3)`` -> log frame ``(x, y, z)`` mm.

        Cross-sections are taken perpendicular to the log axis ``z`` (not to the bent centreline),
        as seed 001's ``y(x), z(x)`` parametrisation implies; exact for a straight log.
        """
        p = np.asarray(points_lcs, dtype=float)
        c = self.xy(p[:, 1])
        return np.stack([c[:, 0] + p[:, 2] * np.cos(p[:, 0]), c[:, 1] + p[:, 2] * np.sin(p[:, 0]), p[:, 1]], axis=1)

    def to_log_centric(self, points_mm) -> np.ndarray:
        """Inverse of :meth:`to_log_frame`: log frame ``(n, 3)`` -> ``(theta_rad, l_mm, rho_mm)``."""
        p = np.asarray(points_mm, dtype=float)
        c = self.xy(p[:, 2])
        dx, dy = p[:, 0] - c[:, 0], p[:, 1] - c[:, 1]
        return np.stack([np.arctan2(dy, dx), p[:, 2], np.hypot(dx, dy)], axis=1)


def fit_centreline(l_mm: ArrayLike, xy_mm: ArrayLike, n_coef: int, length_mm: float | None = None) -> Centreline:
    """Least-squares Chebyshev centreline through pith samples (seed 001 §3.3).

    Parameters
    ----------
    l_mm : (k,) float
        Heights of the samples along the log.
    xy_mm : (k, 2) float
        Pith position at each height (any frame; the mean goes into ``offset_xy``).
    n_coef : int
        Number of non-constant coefficients per axis (``T_1 .. T_n``), ``k > n_coef``.
    length_mm : float, optional
        Log length; default ``max(l_mm)``.
    """
    l = np.asarray(l_mm, dtype=float).reshape(-1)
    xy = np.asarray(xy_mm, dtype=float)
    if xy.shape != (len(l), 2):
        raise WoodcamError(f"xy_mm must have shape ({len(l)}, 2) to match l_mm; got {xy.shape}")
    if not (1 <= n_coef < len(l)):
        raise WoodcamError(f"n_coef must lie in [1, {len(l) - 1}] (fewer than the samples); got {n_coef}")
    length = float(l.max() if length_mm is None else length_mm)
    V = C.chebvander(_u(l, length), n_coef)
    coef, *_ = np.linalg.lstsq(V, xy, rcond=None)
    return Centreline(length, coef[1:, 0], coef[1:, 1], (float(coef[0, 0]), float(coef[0, 1])))
