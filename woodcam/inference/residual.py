"""Fit the small-scale distortion a smooth field leaves on the faces (issue 12 part 4).

The residual of a base field at the ring points, ``years - base(p)``, is fitted by
:class:`~woodcam.fields.residual.FaceResidual` (one bicubic B-spline per face, Gaussian fall-off
into the block) by penalised least squares: P-splines (Eilers & Marx 1996: a ridge, first- and
second-difference penalties on the coefficients, :data:`~woodcam.tolerances.RESIDUAL_RIDGE`,
``_SLOPE``, ``_CURVATURE``) with a Huber loss by reweighting. Written here because no library
fits B-spline surfaces on six coupled faces (scipy's smoothing splines are 1-D or one surface
without such coupling); the algebra is a few sparse products and one sparse solve.

Whether a fitted residual is kept is the evidence's call:
:func:`woodcam.inference.evidence.fit_evidence` (``residual=True``) refits it in each
leave-one-face-out fold and keeps it only when the held-out faces score higher with it.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .._types import ArrayLike
from ..errors import WoodcamError
from ..fields.residual import FaceResidual, face_geometry, face_spline_knots, face_weight
from ..frames import FACE_AXIS, FACES
from ..tolerances import (RESIDUAL_CURVATURE, RESIDUAL_DEPTH_MM, RESIDUAL_HUBER_YEARS, RESIDUAL_MAX_POINTS,
                          RESIDUAL_RIDGE, RESIDUAL_SLOPE, RESIDUAL_SPACING_MM)
from .observations import RingObservations
from .rbf import thin_out

#: Reweighting rounds of the Huber fit (the second barely moves after the first).
_IRLS_ROUNDS = 2

#: Relative residual of the conjugate-gradient solve: coefficients to ~1e-7 years of a direct
#: solve (an 80 x 60 x 70 mm block: 4242 coefficients, 0.02 s against SuperLU's 0.4-1.3 s).
_CG_RTOL = 1e-8


def _solve_spd(A, b, x0):
    """``A x = b`` for the sparse symmetric positive definite normal equations: conjugate
    gradients with a Jacobi preconditioner (the penalty's ridge keeps ``A`` well conditioned),
    a direct solve if it does not converge."""
    from scipy.sparse.linalg import LinearOperator, cg, spsolve

    d = A.diagonal()
    M = LinearOperator(A.shape, matvec=lambda v: v / d)
    x, info = cg(A, b, x0=x0, M=M, rtol=_CG_RTOL, maxiter=10 * A.shape[0])
    return x if info == 0 else spsolve(A.tocsc(), b)


def _difference_penalty(n: int, order: int):
    """``D^T D`` of the ``order``-th differences of ``n`` coefficients, sparse ``(n, n)``."""
    from scipy import sparse

    if n <= order:
        return sparse.csr_array((n, n))
    d = sparse.eye_array(n, format="csr")
    for _ in range(order):
        d = d[1:] - d[:-1]
    return (d.T @ d).tocsr()


@functools.lru_cache(maxsize=32)
def _face_penalty(nu: int, nv: int, ridge: float, slope: float, curvature: float):
    """Penalty ``(nu nv, nu nv)`` of one face's coefficients (C order, as ``NdBSpline``'s)."""
    from scipy import sparse

    iu, iv = sparse.eye_array(nu), sparse.eye_array(nv)
    pen = ridge * sparse.eye_array(nu * nv)
    for w, order in ((slope, 1), (curvature, 2)):
        pen = pen + w * (sparse.kron(_difference_penalty(nu, order), iv)
                         + sparse.kron(iu, _difference_penalty(nv, order)))
    return pen


def fit_face_residual(obs: RingObservations, base: Callable, size_mm: ArrayLike,
                      spacing_mm: float = RESIDUAL_SPACING_MM, depth_mm: float = RESIDUAL_DEPTH_MM,
                      max_points: int = RESIDUAL_MAX_POINTS, seed: int = 0) -> FaceResidual:
    """The residual ``years - base(p)`` of numbered ring points as a :class:`FaceResidual`.

    Parameters
    ----------
    obs : ring points with years (labelled or numbered), block frame mm; at most
        ``max_points`` of them (a fixed random subset) are used.
    base : the smooth field, ``(n, 3) mm -> (n,) years``.
    size_mm : (3,) block size.
    spacing_mm : knot spacing (mm) of each face's residual B-spline (default
        :data:`~woodcam.tolerances.RESIDUAL_SPACING_MM`, 3 mm).
    depth_mm : depth (mm) of the residual's fall-off ``exp(-(d / depth_mm)^2)`` from its face
        (default :data:`~woodcam.tolerances.RESIDUAL_DEPTH_MM`, 5 mm).
    seed : the random subset of ``max_points`` (default 0).

    Minimises ``sum_i w_i huber(r(p_i) - res_i) + c^T P c`` over every face's coefficients
    ``c``: ``w_i`` makes each face's points weigh one per knot cell in all, ``P`` the P-spline
    penalty of each face (module docstring). Every face gets a residual, observed or not: an
    unobserved face's is pinned only near its edges, by its neighbours' points.
    """
    from scipy import sparse
    from scipy.interpolate import NdBSpline

    size = np.asarray(size_mm, float)
    keep = thin_out(len(obs.points_mm), max_points, seed)
    p, face_of = obs.points_mm[keep], obs.face[keep]
    res = obs.years[keep] - np.asarray(base(p), float)
    ok = np.isfinite(res)
    if not ok.any():
        raise WoodcamError(f"obs must hold ring points with years to fit a residual to; got {len(obs.years)} points "
                           "and none with a finite year and base value; number unlabelled rings first "
                           "(woodcam.inference.radial.number_observations)")
    p, face_of, res = p[ok], face_of[ok], res[ok]
    # each face's points weigh one per knot cell of that face in all
    w_data = np.zeros(len(p))
    for i in np.unique(face_of):
        sel = face_of == i
        other = [a for a in range(3) if a != FACE_AXIS[FACES[int(i)]]]
        cells = np.prod(np.ceil(size[other] / spacing_mm))
        w_data[sel] = cells / sel.sum()
    blocks, pens, shapes = [], [], {}
    for face in FACES:
        knots = face_spline_knots(size, face, spacing_mm)
        nu, nv = (len(t) - 4 for t in knots)
        shapes[face] = (nu, nv)
        d, uv = face_geometry(p, size, face)
        wt = face_weight(d, depth_mm)  # as FaceResidual evaluates it
        dm = NdBSpline.design_matrix(uv, knots, 3)
        # scipy sizes the matrix by the last basis function the points touch: give it every one
        dm = sparse.csr_array((dm.data, dm.indices, dm.indptr), shape=(len(uv), nu * nv))
        blocks.append(sparse.diags_array(wt) @ dm)
        pens.append(_face_penalty(nu, nv, RESIDUAL_RIDGE, RESIDUAL_SLOPE, RESIDUAL_CURVATURE))
    J = sparse.hstack(blocks, format="csr")
    pen = sparse.block_diag(pens, format="csc")
    w = w_data.copy()
    coef = np.zeros(J.shape[1])
    for _ in range(_IRLS_ROUNDS + 1):
        Jw = (sparse.diags_array(w) @ J).T.tocsr()
        coef = _solve_spd((Jw @ J + pen).tocsr(), Jw @ res, coef)
        err = np.abs(J @ coef - res)
        w = w_data * np.minimum(1.0, RESIDUAL_HUBER_YEARS / np.maximum(err, 1e-12))
    coefs, at = {}, 0
    for face in FACES:
        nu, nv = shapes[face]
        coefs[face] = coef[at:at + nu * nv].reshape(nu, nv)
        at += nu * nv
    return FaceResidual(size, spacing_mm, depth_mm, coefs)


__all__ = ["fit_face_residual"]
