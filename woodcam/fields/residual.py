"""A smooth field plus a residual: small-scale distortion on top of a stem (issue 12 part 4).

Seed 000 (section 5.2, Fig. 16b) names what its growth-time field cannot reproduce: the
small-scale distortions of the rings seen on a block's faces (CN03's wavy figure). A smooth stem
model cannot either. :class:`ResidualField` adds a residual ``r(p)`` (years) to a base field;
:class:`FaceResidual` is the residual the evidence fit uses: one smooth 2-D field per block face,
carried into the block with a Gaussian fall-off over ``depth_mm``,

    r(p) = sum_f exp(-(d_f(p) / depth)^2) s_f(u_f(p)),

``d_f`` the distance (mm) from ``p`` to face ``f``'s plane (0 outside the block), ``u_f`` the
projection of ``p`` onto that face (clamped to it), ``s_f`` a bicubic B-spline on the face
(:class:`scipy.interpolate.NdBSpline`, knots every ``spacing_mm``). What the faces show of the
distortion is carried a few mm inward and nowhere deeper: nothing observed pins it there. The
Gaussian has no slope at the face, so it does not change the ring density the faces show.
Fitting it is :func:`woodcam.inference.residual.fit_face_residual`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._types import ArrayLike
from ..frames import FACE_AXIS, FACE_NORMAL, FACES

#: Weights below this are left out of evaluation and fits (3.7 depths from the face).
_MIN_WEIGHT = 1e-6


def face_knots(length_mm: float, spacing_mm: float) -> np.ndarray:
    """Clamped cubic B-spline knots over ``[0, length_mm]``, intervals of at most ``spacing_mm``."""
    n = max(1, int(np.ceil(length_mm / spacing_mm)))
    return np.concatenate([[0.0] * 3, np.linspace(0.0, length_mm, n + 1), [length_mm] * 3])


def face_spline_knots(size_mm: np.ndarray, face: str, spacing_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """The B-spline knots (:func:`face_knots`) of ``face``'s two axes, ascending, for a block of
    ``size_mm (3,)``."""
    return tuple(face_knots(size_mm[a], spacing_mm) for a in range(3) if a != FACE_AXIS[face])


def face_weight(d_mm: np.ndarray, depth_mm: float) -> np.ndarray:
    """Fall-off ``exp(-(d / depth)^2)`` of a face's residual at ``d_mm`` from it, 0 where below
    :data:`_MIN_WEIGHT` (what evaluation and fits both leave out)."""
    w = np.exp(-(np.asarray(d_mm, float) / depth_mm) ** 2)
    return np.where(w > _MIN_WEIGHT, w, 0.0)


def face_geometry(points_mm: np.ndarray, size_mm: np.ndarray, face: str):
    """``(d (n,), uv (n, 2))``: distance (mm, >= 0) from each point to ``face``'s plane (0 on or
    outside it) and the point projected onto the face, clamped to it, in the block frame's two
    other axes (ascending)."""
    ax = FACE_AXIS[face]
    d = size_mm[ax] - points_mm[:, ax] if FACE_NORMAL[face][ax] > 0 else points_mm[:, ax]
    other = [a for a in range(3) if a != ax]
    uv = np.ascontiguousarray(np.clip(points_mm[:, other], 0.0, size_mm[other]))
    return np.maximum(d, 0.0), uv


class FaceResidual:
    """``r(p)`` years, ``(n, 3) mm -> (n,)``, block frame (module docstring).

    size_mm : (3,) block size; spacing_mm : knot spacing of each face's B-spline; depth_mm : the
    Gaussian fall-off's depth; coefs : face name -> ``(nu, nv)`` B-spline coefficients (years)
    over :func:`face_knots` of the face's two axes.
    """

    def __init__(self, size_mm: ArrayLike, spacing_mm: float, depth_mm: float, coefs: dict[str, np.ndarray]):
        self.size_mm = np.asarray(size_mm, float)
        self.spacing_mm, self.depth_mm = float(spacing_mm), float(depth_mm)
        self.coefs = {f: np.asarray(c, float) for f, c in coefs.items()}
        self._splines = {f: self._spline(f, c) for f, c in self.coefs.items()}

    def knots(self, face: str) -> tuple[np.ndarray, np.ndarray]:
        """The B-spline knots of ``face``'s two axes."""
        return face_spline_knots(self.size_mm, face, self.spacing_mm)

    def _spline(self, face: str, c: np.ndarray):
        from scipy.interpolate import NdBSpline

        return NdBSpline(self.knots(face), c, 3)

    def weight(self, d_mm: np.ndarray) -> np.ndarray:
        """Fall-off of a face's residual at ``d_mm`` from it (:func:`face_weight`)."""
        return face_weight(d_mm, self.depth_mm)

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        p = np.asarray(points_mm, float).reshape(-1, 3)
        out = np.zeros(len(p))
        for face in FACES:
            if face not in self._splines:
                continue
            d, uv = face_geometry(p, self.size_mm, face)
            w = self.weight(d)
            near = w > 0  # deep points: no face's residual reaches them (nor its fit)
            if near.any():
                out[near] += w[near] * self._splines[face](uv[near])
        return out

    def amplitude_years(self) -> float:
        """Largest coefficient magnitude (years): a bound on ``|r|`` on any one face."""
        return float(max((np.abs(c).max() for c in self.coefs.values()), default=0.0))


class ResidualField:
    """``base(p) + residual(p)``: ``(n, 3) mm -> (n,) years``, block frame.

    base : the smooth field (a stem, a radial fit, a stem with its knots); residual : a callable
    of the same signature (a :class:`FaceResidual`, an RBF of what the base leaves). Every other
    attribute (``axis``, a stem's pith, knot strands and layers) is the base's: the residual
    moves ring lines by a fraction of a ring, not the pith or the knots.
    """

    def __init__(self, base: Callable, residual: Callable):
        self.base, self.residual = base, residual

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        p = np.asarray(points_mm, float)
        return np.asarray(self.base(p), float) + np.asarray(self.residual(p), float)

    def __getattr__(self, name: str):
        if name.startswith("_") or name in ("base", "residual"):  # no recursion while unpickling
            raise AttributeError(name)
        return getattr(self.base, name)


__all__ = ["FaceResidual", "ResidualField", "face_geometry", "face_knots", "face_spline_knots", "face_weight"]
