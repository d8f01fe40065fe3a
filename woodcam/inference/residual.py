"""Small-scale distortion: a regularised residual field on top of a smooth fit, kept per region
only where the faces say it predicts (issue 12, part 4; seed 000 Fig. 16b).

A smooth stem (:mod:`.stem`) or radial fit leaves a residual ``r_i = year_i - base(p_i)`` at the
ring points: wavy figure, a bulge, a local change of ring width. Part of it is noise no other face
can predict (trace jitter, mislabels, a ring the U-Net bent), part is a distortion that runs
through the wood and shows on the neighbouring faces too. This module fits the second and keeps
it only where a leave-one-face-out among the fit's own faces says it carries over:

- Field: trilinear interpolation of node values ``c_k`` on a coarse grid of ``n^3`` nodes
  spanning the block (:data:`~woodcam.tolerances.RESIDUAL_NODES` per axis)::

      r(p) = sum_k w_k(p) c_k,   w_k the trilinear hat of node k (a partition of unity)

- Fit: penalised least squares, years::

      min_c  sum_i rho(r_i - sum_k w_k(p_i) c_k)
             + lambda_s n_pts |D c|^2 + lambda_0 n_pts |c|^2

  ``D`` the second differences of the node grid along each axis (a smooth correction, not a
  bump per node; :data:`~woodcam.tolerances.RESIDUAL_SMOOTHNESS`), a ridge pulling every value
  to 0 where no ring point pins it (:data:`~woodcam.tolerances.RESIDUAL_RIDGE`), and ``rho`` a
  Huber loss (two reweighting rounds, :data:`~woodcam.tolerances.RESIDUAL_HUBER_YEARS`) so a
  mislabelled ring is not spread over its region.
- Gate, per region: a region is a node's cell (the points nearest to it on the grid). For each
  observed face ``f`` the residual is refitted on the other faces and predicts ``f``'s ring
  points; a node is kept when, summed over those folds, the points of its region come closer to
  their ring lines (mean error, mm, through the base field's gradient) by at least
  :data:`~woodcam.tolerances.RESIDUAL_MIN_GAIN_MM` with at least
  :data:`~woodcam.tolerances.RESIDUAL_MIN_POINTS` points behind it. The final residual is the
  full fit multiplied by the gate interpolated with the same hats (a smooth 0..1 blend): where no
  held-out face vouches for it, the base field is returned unchanged.

The base stays fixed during the gate (refitting it per inner fold costs a stem fit each): it has
seen the inner held-out face, so its residual there is smaller than on a truly unseen face and
the gate errs towards rejecting, which is the safe side.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._types import ArrayLike
from ..fields.base import central_gradient, check_points
from ..tolerances import (RESIDUAL_HUBER_YEARS, RESIDUAL_MIN_GAIN_MM, RESIDUAL_MIN_GAIN_SHARE,
                          RESIDUAL_MIN_POINTS,
                          RESIDUAL_NODES, RESIDUAL_RIDGE, RESIDUAL_SMOOTHNESS)
from .observations import RingObservations

#: Finite-difference step (mm) of the base field's gradient that turns years into mm.
_GRAD_STEP_MM = 0.25


def _hats(points_mm: np.ndarray, size_mm: np.ndarray, n: int):
    """``(idx (m, 8) int, w (m, 8) float)``: the 8 nodes around each point of an ``n^3`` grid
    spanning the block and their trilinear weights (points outside clamp to the border cells)."""
    u = np.clip(points_mm / size_mm * (n - 1), 0.0, n - 1 - 1e-9)
    i0 = np.floor(u).astype(int)
    f = u - i0
    idx, w = [], []
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                ii = (i0[:, 0] + dx) * n * n + (i0[:, 1] + dy) * n + (i0[:, 2] + dz)
                ww = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
                      * (f[:, 2] if dz else 1 - f[:, 2]))
                idx.append(ii)
                w.append(ww)
    return np.stack(idx, 1), np.stack(w, 1)


def _design(points_mm: np.ndarray, size_mm: np.ndarray, n: int):
    """Sparse ``(m, n^3)`` trilinear interpolation matrix."""
    from scipy import sparse

    idx, w = _hats(points_mm, size_mm, n)
    rows = np.repeat(np.arange(len(points_mm)), 8)
    return sparse.csr_matrix((w.ravel(), (rows, idx.ravel())), shape=(len(points_mm), n ** 3))


def _second_differences(n: int):
    """Sparse second differences of an ``n^3`` node grid along each of the three axes."""
    from scipy import sparse

    d1 = sparse.diags([1.0, -2.0, 1.0], [0, 1, 2], shape=(max(n - 2, 0), n))
    eye = sparse.identity(n)
    return sparse.vstack([sparse.kron(sparse.kron(d1, eye), eye),
                          sparse.kron(sparse.kron(eye, d1), eye),
                          sparse.kron(sparse.kron(eye, eye), d1)]).tocsr()


@dataclass
class RegionalResidual:
    """``r(p) = gate(p) * sum_k w_k(p) c_k`` (module docstring), years; block frame mm.

    values : (n^3,) node values ``c`` (years); gate : (n^3,) 1 for kept regions, 0 otherwise
    """

    size_mm: np.ndarray
    n: int
    values: np.ndarray
    gate: np.ndarray

    @property
    def kept(self) -> int:
        """Number of regions kept by the gate."""
        return int(np.sum(self.gate > 0))

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        p = check_points(points_mm)
        if not self.kept:
            return np.zeros(len(p))
        idx, w = _hats(p, self.size_mm, self.n)
        return np.sum(w * self.values[idx], axis=1) * np.sum(w * self.gate[idx], axis=1)


class FieldPlusResidual:
    """``base(p) + residual(p)``, the base's other attributes (``axis``...) passed through."""

    def __init__(self, base: Callable, residual: RegionalResidual):
        self.base, self.residual = base, residual
        self.axis = getattr(base, "axis", (0.0, 0.0, 1.0))

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        p = check_points(points_mm)
        return np.asarray(self.base(p), float) + self.residual(p)


def _solve(A, res: np.ndarray, n: int, smoothness: float, ridge: float) -> np.ndarray:
    """Node values of the penalised Huber fit (module docstring) of residuals ``res (m,)``."""
    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    m = max(len(res), 1)
    D = _second_differences(n)
    P = smoothness * m * (D.T @ D) + ridge * m * sparse.identity(n ** 3)
    wts = np.ones(len(res))
    c = np.zeros(n ** 3)
    for _ in range(3):  # least squares, then two Huber reweightings
        W = sparse.diags(wts)
        c = spsolve((A.T @ W @ A + P).tocsc(), A.T @ (wts * res))
        e = np.abs(res - A @ c)
        wts = np.minimum(1.0, RESIDUAL_HUBER_YEARS / np.maximum(e, 1e-12))
    return np.asarray(c, float)


def fit_regional_residual(obs: RingObservations, base: Callable, size_mm: ArrayLike,
                          n: int = RESIDUAL_NODES, smoothness: float = RESIDUAL_SMOOTHNESS,
                          ridge: float = RESIDUAL_RIDGE,
                          min_gain_mm: float = RESIDUAL_MIN_GAIN_MM) -> RegionalResidual:
    """Fit the residual of ``base`` on labelled ``obs`` and gate it per region (module docstring).

    obs : numbered ring observations, block frame mm; base : ``(m, 3) mm -> (m,) years``
    size_mm : (3,) block size; n : nodes per axis (>= 2)

    Returns a :class:`RegionalResidual`; its ``gate`` is all zeros when no region predicts (or
    fewer than two faces carry rings, so nothing can be held out).
    """
    size = np.asarray(size_mm, float)
    pts = obs.points_mm
    ok = np.isfinite(obs.years)
    pts, yrs, face = pts[ok], obs.years[ok], obs.face[ok]
    g, grad = central_gradient(base, pts, _GRAD_STEP_MM)
    res = yrs - g
    mm_per_year = 1.0 / np.maximum(np.linalg.norm(grad, axis=1), 1e-6)
    A = _design(pts, size, n)
    values = _solve(A, res, n, smoothness, ridge) if len(res) else np.zeros(n ** 3)
    gate = np.zeros(n ** 3)
    faces, counts = np.unique(face, return_counts=True)
    faces = faces[counts >= RESIDUAL_MIN_POINTS]
    if len(faces) >= 2:
        gain = np.zeros(n ** 3)
        err = np.zeros(n ** 3)
        count = np.zeros(n ** 3)
        region = _hats(pts, size, n)
        nearest = region[0][np.arange(len(pts)), np.argmax(region[1], axis=1)]
        for f in faces:
            held = face == f
            c = _solve(A[~held], res[~held], n, smoothness, ridge)
            before = np.abs(res[held]) * mm_per_year[held]
            after = np.abs(res[held] - A[held] @ c) * mm_per_year[held]
            np.add.at(gain, nearest[held], before - after)
            np.add.at(err, nearest[held], before)
            np.add.at(count, nearest[held], 1.0)
        gain, err = gain / np.maximum(count, 1.0), err / np.maximum(count, 1.0)
        gate = ((count >= RESIDUAL_MIN_POINTS) & (gain >= min_gain_mm)
                & (gain >= RESIDUAL_MIN_GAIN_SHARE * err)).astype(float)
    return RegionalResidual(size, n, values, gate)


def regional_residual_recipe(base_recipe: Callable, size_mm: ArrayLike) -> Callable:
    """``RingObservations -> base + gated residual``: the base refitted by ``base_recipe`` on the
    same observations (a recipe that remembers its last fit shares it with the base hypothesis)."""
    def refit(obs: RingObservations):
        base = base_recipe(obs)
        return FieldPlusResidual(base, fit_regional_residual(obs, base, size_mm))
    return refit


__all__ = ["FieldPlusResidual", "RegionalResidual", "fit_regional_residual", "regional_residual_recipe"]
