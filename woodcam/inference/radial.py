"""Our fitter: an explicit radial growth field fitted by least squares (extends eqs. 7-9 of seed 000).

Model, block frame, mm -> years::

    years(p) = a + rho(p) * s(phi(p), zeta(p)),
    s(phi, zeta) = sum_{k <= K, m <= M} c_km * trig_k(phi) * zeta**m

where ``rho``, ``phi`` and ``zeta`` are the distance from, the azimuth around and the normalised
position along a straight pith axis (point + direction: 4 degrees of freedom). ``s`` is the
inverse ring width (rings per mm): a low-order Fourier series in the azimuth (eq. 7's r(phi))
times a polynomial along the axis (eq. 9 blends two radius functions linearly along z; its
reciprocal is close to a quadratic). ``a`` is an age offset (seed eq. 5).

For a fixed axis the model is *linear* in ``(a, c)``, so the fit is a variable projection: the
outer problem is the axis alone (4 parameters, :func:`scipy.optimize.least_squares`), the inner a
ridge-regularised linear least squares (higher harmonics cost more, so a pith outside the block
that shows only a narrow wedge of azimuths stays well posed). Starting axes come from a grid of
directions on the hemisphere, each with its pith placed by an algebraic fit of concentric circles
(radius linear in year) to the points projected along that direction.

Robustness: traces whose median misfit exceeds half a year are renumbered and the fit repeated
(mislabelled traces); the final coefficients take the strongest ridge that raises the residual
by at most 5 % (jittered traces on a few faces otherwise let high harmonics swing where no face
sees the rings).

Growth history: real trees lay down a different ring width each year, the same all around the
stem, so the final model is ``years = h(a + rho * s)`` with ``h`` a monotone cubic warp
through one level per observed year (identity for the eq. 7-9 family; continued with slope
1 beyond the observed years), fitted by alternating with ``s``.

Unlabelled rings (traces without years, ring-map components) are fitted with one unknown level
per ring group instead of the year, with the inverse ring width's mean over the data fixed to 1
(no collapse to a flat field); the levels are then turned into years by the ring spacing
(:func:`number_rings`), and the labelled fit is run on those years.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._parallel import map_processes
from ..errors import WoodcamError
from ..fields.base import check_points
from ..tolerances import (NUMBERING_MIN_STEP, NUMBERING_RESEARCHES, NUMBERING_STEP_MARGIN, RING_HISTORY_MIN_STEP,
                          RING_HISTORY_PRIOR_POINTS, RING_HISTORY_ROUNDS)
from .observations import RingObservations
from .._types import ArrayLike, GrowthFieldLike


# -- the field --------------------------------------------------------------------------------

def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of two 3-vectors, the same products and differences (bit for bit) without
    its axis handling, which cost ~0.1 ms a call: the fits build a frame per residual call."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _frame(direction) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    e1 = _cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return d, e1, _cross(d, e1)


def _trig_powers(phi: np.ndarray, t: np.ndarray, K: int, M: int, out: np.ndarray | None = None) -> np.ndarray:
    """``(n, (2K+1)(M+1))``: ``trig_k(phi) t^m`` with ``trig = 1, cos(k phi).., sin(k phi)..``
    (``k = 1..K``), ``m = 0..M`` fastest; ``phi, t`` ``(n,)``. Written into ``out`` (a view of
    that shape) when given.

    Every residual call of the axis and stem searches builds this basis. The products are the
    same ``trig * t**m`` as a broadcast ``trig[:, :, None] * t**m[:, None, :]``, bit for bit, but
    each power is written in place: the broadcast's inner loop of length ``M + 1`` cost as much
    as the cosines (profiled), and the angles ``k phi`` are formed once for both. (Not
    computed as powers of ``exp(i phi)``: that moved results by 1e-15, which the searches'
    finite differences turned into reordered radial basins on a dev block.)"""
    n = len(phi)
    B = np.empty((n, 2 * K + 1, M + 1)) if out is None else out.reshape(n, 2 * K + 1, M + 1)
    trig = B[:, :, 0]  # m = 0: t**0 is 1, so trig itself
    trig[:, 0] = 1.0
    kphi = phi[:, None] * np.arange(1, K + 1)
    # contiguous in and out, as before: numpy's SIMD cos/sin need not match its strided loop
    trig[:, 1:K + 1], trig[:, K + 1:] = np.cos(kphi), np.sin(kphi)
    tp = t[:, None] ** np.arange(M + 1)  # the same powers as before (t**1 is t exactly)
    for m in range(1, M + 1):
        np.multiply(trig, tp[:, m:m + 1], out=B[:, :, m])
    return B.reshape(n, -1)


def _design(points, pith, d, e1, e2, z_scale, K: int, M: int, out: np.ndarray | None = None):
    """rho (n,) and the basis ``trig_k(phi) zeta^m`` (n, (2K+1)(M+1)) at ``points`` (n, 3)
    (:func:`_trig_powers`, into ``out`` when given)."""
    return _axis_design(points, pith, d, e1, e2, z_scale, K, M, out)[4:]


def _axis_design(points, pith, d, e1, e2, z_scale, K: int, M: int, out: np.ndarray | None = None):
    """:func:`_design` with the coordinates it is made of: ``(q, a1, a2, zq, rho, B)``, the
    points about the pith ``q (n, 3)``, their coordinates along ``e1, e2`` and ``d`` (mm), rho
    and the basis (what the radial Jacobian differentiates)."""
    q = points - pith
    a1, a2, zq = q @ e1, q @ e2, q @ d
    rho = np.hypot(a1, a2)
    return q, a1, a2, zq, rho, _trig_powers(np.arctan2(a2, a1), zq / z_scale, K, M, out)


def _penalty_weights(K: int, M: int) -> np.ndarray:
    """Ridge weight per basis function: grows with harmonic order k and axial order m."""
    k = np.concatenate([[0], np.arange(1, K + 1), np.arange(1, K + 1)]).astype(float)
    m = np.arange(M + 1, dtype=float)
    return (k[:, None] ** 2 + 2.0 * m[None, :] ** 2).reshape(-1)


@dataclass
class RadialField:
    """``years = offset + rho * s(phi, zeta)`` about a straight pith (see module docstring).

    Attributes
    ----------
    pith_mm : (3,) a point on the pith axis, block frame
    axis : (3,) unit direction of the pith axis
    z_scale_mm : length that maps axial distance to ``zeta`` (half the block diagonal)
    K, M : Fourier order in azimuth, polynomial order along the axis
    coef : ((2K+1)(M+1),) coefficients of ``s`` (rings per mm)
    offset : age offset ``a`` (years at the pith)
    """

    pith_mm: np.ndarray
    axis: np.ndarray
    z_scale_mm: float
    K: int
    M: int
    coef: np.ndarray
    offset: float = 0.0
    history_levels: np.ndarray | None = None
    history_years: np.ndarray | None = None

    def linear(self, points_mm) -> np.ndarray:
        """``offset + rho * s`` (years before the growth-history warp), ``(n,)``."""
        p = check_points(points_mm)
        d, e1, e2 = _frame(self.axis)
        rho, B = _design(p, self.pith_mm, d, e1, e2, self.z_scale_mm, self.K, self.M)
        return self.offset + rho * (B @ self.coef)

    def __call__(self, points_mm) -> np.ndarray:
        lin = self.linear(points_mm)
        if self.history_levels is None:
            return lin
        return _warp(lin, self.history_levels, self.history_years)

    def to_dict(self) -> dict:
        """Plain-JSON state (see :mod:`woodcam.fields.state`)."""
        d = {"pith_mm": np.asarray(self.pith_mm, float).tolist(),
             "axis": np.asarray(self.axis, float).tolist(), "z_scale_mm": float(self.z_scale_mm),
             "K": int(self.K), "M": int(self.M), "coef": np.asarray(self.coef, float).tolist(),
             "offset": float(self.offset)}
        if self.history_levels is not None:
            d["history_levels"] = np.asarray(self.history_levels, float).tolist()
            d["history_years"] = np.asarray(self.history_years, float).tolist()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "RadialField":
        hl, hy = d.get("history_levels"), d.get("history_years")
        return cls(np.asarray(d["pith_mm"], float), np.asarray(d["axis"], float), float(d["z_scale_mm"]),
                   int(d["K"]), int(d["M"]), np.asarray(d["coef"], float), float(d["offset"]),
                   None if hl is None else np.asarray(hl, float), None if hy is None else np.asarray(hy, float))

    def grain_direction(self, points_mm) -> np.ndarray:
        p = check_points(points_mm)
        return np.broadcast_to(self.axis / np.linalg.norm(self.axis), p.shape).copy()


def _warp(linear: np.ndarray, levels: np.ndarray, years: np.ndarray) -> np.ndarray:
    """Growth-history warp ``h``: scipy's monotone cubic (PCHIP) through ``(levels, years)``
    (both increasing; smooth growth between ring boundaries, never folding back), continued
    outside them with slope 1 (the mean ring width of the linear model)."""
    from scipy.interpolate import PchipInterpolator

    out = PchipInterpolator(levels, years, extrapolate=False)(linear)
    lo, hi = linear < levels[0], linear > levels[-1]
    out[lo] = years[0] + (linear[lo] - levels[0])
    out[hi] = years[-1] + (linear[hi] - levels[-1])
    return out


# -- the fit ----------------------------------------------------------------------------------

class _LabelledSystem(NamedTuple):
    """:meth:`_Problem._labelled_system`: the pith line's frame ``(d, e1, e2)``, the points
    about the pith ``q (n, 3)``, their coordinates ``a1, a2`` (along ``e1, e2``) and ``zq``
    (along ``d``, mm), ``rho (n,)``, the basis ``B (n, p)``, the ridge weights ``pen (p,)``,
    ``median(rho)`` and the system ``lhs (n + p, p + 1)``, ``rhs (n + p,)``."""

    frame: tuple
    q: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    zq: np.ndarray
    rho: np.ndarray
    B: np.ndarray
    pen: np.ndarray
    med: float
    lhs: np.ndarray
    rhs: np.ndarray


@dataclass
class _Problem:
    points: np.ndarray          # (n, 3)
    years: np.ndarray | None    # (n,) labelled, or None
    group: np.ndarray | None    # (n,) ring groups for unlabelled fits
    centre: np.ndarray
    z_scale: float
    K: int
    M: int
    ridge: float

    def axis_of(self, theta, base):
        d0, b1, b2 = base
        d = d0 + theta[0] * b1 + theta[1] * b2
        d /= np.linalg.norm(d)
        pith = self.centre + theta[2] * b1 + theta[3] * b2
        return pith, d

    def solve(self, pith, d):
        """Inner linear problem; returns (residuals incl. penalty rows, coef, offset, levels)."""
        if self.years is not None:
            system = self._labelled_system(pith, d)
            sol = _lstsq(system.lhs, system.rhs)
            return system.lhs @ sol - system.rhs, sol[1:], sol[0], None
        dd, e1, e2 = _frame(d)
        rho, B = _design(self.points, pith, dd, e1, e2, self.z_scale, self.K, self.M)
        pen = np.sqrt(self.ridge * len(B)) * _penalty_weights(self.K, self.M) * np.median(rho)
        A = rho[:, None] * B
        # Unlabelled: rho * B c = t_g with mean(B c) = 1 over the data: c = c0 + Z y.
        bbar = B.mean(axis=0)
        c0 = bbar / (bbar @ bbar)
        _, _, vt = np.linalg.svd(bbar[None, :])
        Z = vt[1:].T
        G = np.zeros((len(A), int(self.group.max()) + 1))
        G[np.arange(len(A)), self.group] = 1.0
        X = np.concatenate([A @ Z, -G], axis=1)
        P = np.concatenate([np.diag(pen) @ Z, np.zeros((len(pen), G.shape[1]))], axis=1)
        lhs = np.concatenate([X, P])
        rhs = np.concatenate([-(A @ c0), -(pen * c0)])
        sol = _lstsq(lhs, rhs)
        coef = c0 + Z @ sol[:Z.shape[1]]
        return lhs @ sol - rhs, coef, 0.0, sol[Z.shape[1]:]

    def residual_and_jacobian(self, theta, base) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        """Labelled problems: :meth:`solve`'s residuals at :meth:`axis_of` ``(theta, base)`` and
        a function returning their exact derivative ``(n + p, 4)`` over ``theta`` (computed
        only when asked: a rejected step needs none), the variable-projection Jacobian
        (Golub & Pereyra 1973: ``J = (I - P) dA c - A^+' dA' r``, ``A`` the ridge system,
        ``c`` its solution, ``r`` the residual, ``P`` the projection on ``A``'s columns, and
        the change of the normal equations' small jitter).

        ``least_squares`` took it by forward differences before: four more solves per step,
        80 % of the radial searches' time (profiled). Here it costs about one more product
        with the design: the angle derivatives of ``trig_k(phi) zeta^m`` are the same columns
        permuted and scaled (no further cosines). The frame's spin about the axis is not a
        degree of freedom (a turn of ``phi`` is a rotation inside each harmonic's pair, which
        neither the fit nor the ridge weights see), so the frame is differentiated without
        spin: a change ``delta d`` of the axis moves ``e1`` by ``-(e1 . delta d) d``, likewise ``e2``."""
        system = self._labelled_system(*self.axis_of(theta, base))
        sol, solve_normal = _lstsq_factored(system.lhs, system.rhs)
        r = system.lhs @ sol - system.rhs
        return r, lambda: self._jacobian(theta, base, system, sol, r, solve_normal)

    def _labelled_system(self, pith, d) -> _LabelledSystem:
        """The labelled ridge system at a pith line, ``lhs = [[1, rho B], [0, diag(pen)]]``
        written in place (the same matrix as stacking them; :func:`_design`'s arithmetic), with
        the coordinates the Jacobian reads."""
        dd, e1, e2 = _frame(d)
        q, a1, a2, zq, rho, B = _axis_design(self.points, pith, dd, e1, e2, self.z_scale, self.K, self.M)
        n, p = B.shape
        med = np.median(rho)
        pen = np.sqrt(self.ridge * n) * _penalty_weights(self.K, self.M) * med
        lhs = np.zeros((n + p, p + 1))
        lhs[:n, 0] = 1.0
        np.multiply(rho[:, None], B, out=lhs[:n, 1:])
        lhs[np.arange(n, n + p), np.arange(1, p + 1)] = pen
        rhs = np.concatenate([self.years, np.zeros(p)])
        return _LabelledSystem((dd, e1, e2), q, a1, a2, zq, rho, B, pen, med, lhs, rhs)

    def _jacobian(self, theta, base, system: _LabelledSystem, sol, r, solve_normal) -> np.ndarray:
        d0, b1, b2 = base
        nv = np.linalg.norm(d0 + theta[0] * b1 + theta[1] * b2)  # the tilt's length before normalising
        (d, e1, e2), q, a1, a2, zq, rho, B, pen, med, lhs, _ = system
        K, M = self.K, self.M
        n, p = B.shape
        c = sol[1:]
        # derivatives of (a1, a2, zeta) over theta = (tilt 1, tilt 2, pith 1, pith 2), (n, 4)
        dds = [(b - d * (d @ b)) / nv for b in (b1, b2)]  # the unit axis' change per tilt
        da1 = np.stack([-(e1 @ x) * zq for x in dds] + [np.full(n, -(e1 @ b)) for b in (b1, b2)], axis=1)
        da2 = np.stack([-(e2 @ x) * zq for x in dds] + [np.full(n, -(e2 @ b)) for b in (b1, b2)], axis=1)
        dz = np.stack([q @ x for x in dds] + [np.full(n, -(d @ b)) for b in (b1, b2)], axis=1) / self.z_scale
        drho = (a1[:, None] * da1 + a2[:, None] * da2) / rho[:, None]
        dphi = (a1[:, None] * da2 - a2[:, None] * da1) / (rho ** 2)[:, None]
        # s and its angle and axial derivatives: the design's columns, permuted and scaled
        C = c.reshape(2 * K + 1, M + 1)
        k = np.arange(1, K + 1)[:, None]
        c_phi = np.zeros_like(C)
        c_phi[1:K + 1], c_phi[K + 1:] = k * C[K + 1:], -k * C[1:K + 1]
        c_z = np.zeros_like(C)
        c_z[:, :M] = C[:, 1:] * np.arange(1, M + 1)
        s, s_phi, s_z = (B @ np.stack([C.ravel(), c_phi.ravel(), c_z.ravel()], axis=1)).T
        # dA c: the data rows' model change at fixed coefficients, the ridge rows' pen change
        dmed = _median_derivative(rho, drho)
        dAc = np.empty((n + p, 4))
        dAc[:n] = drho * s[:, None] + rho[:, None] * (s_phi[:, None] * dphi + s_z[:, None] * dz)
        dAc[n:] = (pen * c)[:, None] * (dmed / med)[None, :]
        # dA' r: B' (drho r) + B_phi' (rho dphi r) + B_z' (rho dz r), the last two from B' by
        # the same permutation; the ridge rows' pen change times their residual
        rd = r[:n]
        G = B.T @ np.concatenate([drho * rd[:, None], (rho * rd)[:, None] * dphi,
                                  (rho * rd)[:, None] * dz], axis=1)
        Gr, Gp, Gz = (x.reshape(2 * K + 1, M + 1, 4) for x in np.split(G, 3, axis=1))
        Ht = Gr.copy()
        Ht[1:K + 1] += -k[:, :, None] * Gp[K + 1:]
        Ht[K + 1:] += k[:, :, None] * Gp[1:K + 1]
        Ht[:, 1:] += Gz[:, :M] * np.arange(1, M + 1)[None, :, None]
        dAtr = np.zeros((p + 1, 4))
        dAtr[1:] = Ht.reshape(p, 4) + (pen * r[n:])[:, None] * (dmed / med)[None, :]
        # the normal equations' jitter (:func:`_lstsq`, 1e-10 of their mean diagonal) moves
        # with their trace: sum over the design of A dA, where sum_j B_j^2 = (K + 1) sum_m
        # zeta^2m, sum_j B_j dB_j/dphi = 0 (cos cos' + sin sin') and sum_j B_j dB_j/dzeta =
        # (K + 1) sum_m m zeta^(2m - 1)
        z = zq / self.z_scale
        m = np.arange(M + 1)
        s0 = (K + 1) * (z[:, None] ** (2 * m)).sum(axis=1)
        s1 = (K + 1) * (m[1:] * z[:, None] ** (2 * m[1:] - 1)).sum(axis=1)
        dtrace = 2 * ((rho * s0) @ drho + (rho ** 2 * s1) @ dz + (pen @ pen) * dmed / med)
        djitter = 1e-10 * dtrace / (p + 1)
        return dAc - lhs @ solve_normal(lhs.T @ dAc + dAtr + sol[:, None] * djitter[None, :])


def _median_derivative(values: np.ndarray, dvalues: np.ndarray) -> np.ndarray:
    """Derivative ``(k,)`` of ``np.median(values)`` given ``dvalues (n, k)``: that of the middle
    element, or the mean of the two middle ones (even ``n``)."""
    n = len(values)
    mid = np.argpartition(values, [(n - 1) // 2, n // 2])[[(n - 1) // 2, n // 2]]
    return dvalues[mid].mean(axis=0)


def _hemisphere(n: int) -> np.ndarray:
    """``n`` roughly uniform unit vectors on the upper hemisphere (Fibonacci spiral)."""
    i = np.arange(n) + 0.5
    z = 1 - i / n
    r = np.sqrt(1 - z ** 2)
    a = np.pi * (3 - np.sqrt(5)) * i
    return np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)


def _circle_pith(points, years, group, d, centre):
    """Pith (block frame) from an algebraic fit of concentric circles in the plane normal to ``d``.

    Labelled: ``|x|^2 = 2 p.x + C + alpha y^2 + beta y`` (radius linear in year);
    unlabelled: ``|x|^2 = 2 p.x + t_g`` (one radius per ring group). Linear least squares.
    """
    d, e1, e2 = _frame(d)
    q = points - centre
    x = np.stack([q @ e1, q @ e2], axis=1)
    if years is not None:
        y = years - years.mean()
        X = np.concatenate([2 * x, np.ones((len(x), 1)), (y ** 2)[:, None], y[:, None]], axis=1)
    else:
        G = np.zeros((len(x), int(group.max()) + 1))
        G[np.arange(len(x)), group] = 1.0
        X = np.concatenate([2 * x, G], axis=1)
    sol = _lstsq(X, (x ** 2).sum(1))
    p = sol[:2]
    # A pith more than 10 block sizes away means straight rings; keep it finite.
    lim = 10 * np.linalg.norm(centre) + 1.0
    if np.linalg.norm(p) > lim:
        p = p / np.linalg.norm(p) * lim
    return centre + p[0] * e1 + p[1] * e2


def _lstsq_factored(lhs: np.ndarray, rhs: np.ndarray):
    """:func:`_lstsq` and a function solving further normal equations ``(lhs' lhs) x = b``
    (``b`` ``(p,)`` or ``(p, k)``) with the same factor (the radial Jacobian's projections)."""
    from scipy.linalg import get_lapack_funcs

    AtA, Atb = lhs.T @ lhs, lhs.T @ rhs
    AtA.flat[::len(AtA) + 1] += 1e-10 * (np.trace(AtA) / len(AtA) + 1e-30)
    if not (np.isfinite(AtA).all() and np.isfinite(Atb).all()):  # as scipy's check_finite
        raise ValueError("array must not contain infs or NaNs")
    potrf, potrs = get_lapack_funcs(("potrf", "potrs"), (AtA,))
    c, info = potrf(AtA, lower=False, overwrite_a=False, clean=False)
    if info > 0:  # not positive definite (cho_factor's LinAlgError)
        return np.linalg.lstsq(lhs, rhs, rcond=None)[0], lambda b: np.linalg.pinv(AtA) @ b
    if info < 0:
        raise ValueError(f"LAPACK reported an illegal argument ({info}) in the normal equations")

    def solve_normal(b):
        x, err = potrs(c, b, lower=False, overwrite_b=False)
        if err != 0:
            raise ValueError(f"LAPACK reported an illegal argument ({err}) in the normal equations")
        return x
    return solve_normal(Atb), solve_normal


def _lstsq(lhs: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Least squares by the normal equations: the systems here are tall (n >> p <= ~150) and
    ridge-regularised, and LAPACK's SVD-based lstsq was 50x slower on them (profiled).

    The Cholesky factor and solve are LAPACK's ``potrf``/``potrs``, called as
    ``scipy.linalg.cho_factor``/``cho_solve`` call them (upper factor), without their wrappers'
    per-call checks (a third of the cost on these small systems; finiteness is checked once)."""
    return _lstsq_factored(lhs, rhs)[0]


def _cost(prob: _Problem, pith, d) -> float:
    r, *_ = prob.solve(pith, d)
    return float(r @ r)


def _refine(prob: _Problem, pith, d, max_nfev: int):
    """Local least squares over the axis (4 dof) around a starting pith and direction."""
    from scipy.optimize import least_squares

    d, b1, b2 = _frame(d)
    base = (d, b1, b2)
    off = pith - prob.centre
    off = off - d * (off @ d)
    theta0 = np.array([0.0, 0.0, off @ b1, off @ b2])
    scale = np.array([0.05, 0.05, 5.0, 5.0])
    if prob.years is None:  # unlabelled (levels per ring group): forward differences
        res = least_squares(lambda th: prob.solve(*prob.axis_of(th, base))[0], theta0,
                            x_scale=scale, diff_step=1e-4, max_nfev=max_nfev, method="trf", ftol=1e-6, xtol=1e-6)
    else:  # labelled: the exact variable-projection Jacobian, computed with the residual
        last: dict = {}

        def both(th):
            key = th.tobytes()
            if key not in last:
                last.clear()
                last[key] = prob.residual_and_jacobian(th, base)
            return last[key]
        res = least_squares(lambda th: both(th)[0], theta0, jac=lambda th: both(th)[1](),
                            x_scale=scale, max_nfev=max_nfev, method="trf", ftol=1e-6, xtol=1e-6)
    pith, d = prob.axis_of(res.x, base)
    return pith, d, float(res.cost * 2)


def fit_axis_and_shape(obs: RingObservations, size_mm, K: int, M: int, ridge: float,
                       n_directions: int = 120, n_search: int = 600, n_fit: int = 2000,
                       n_starts: int = 6, coarse_K: int = 2, n_final: int = 2, n_grid_directions: int = 20,
                       pith_grid: int = 9, seed: int = 0, n_basins: int = 0, workers: int = 1):
    """Search + refine the pith axis; returns ``(RadialField, levels or None, group ids used)``.

    n_basins : 0 returns the best fit as above; ``n >= 1`` returns a list of such triples, the
        ``n`` best distinct axis basins finished at full order, best (lowest cost) first: the
        pith hypotheses that :mod:`woodcam.inference.evidence` judges by held-out faces.
    workers : processes the starts' and the basins' descents may use (:mod:`woodcam._parallel`;
        the same fits bit for bit)

    For labelled observations the returned field is the final least-squares fit. For unlabelled
    ones, ``levels`` are the fitted per-group values of ``rho * s`` (mm-like units, the field's
    ``offset`` is 0 and ``s`` has mean 1 over the data): see :func:`number_rings`.
    """
    size = np.asarray(size_mm, float)
    centre = size / 2
    z_scale = float(np.linalg.norm(size) / 2)
    labelled = obs.labelled
    rng = np.random.default_rng(seed)

    def take(n):
        i = (np.sort(rng.choice(len(obs.points_mm), n, replace=False)) if len(obs.points_mm) > n
             else np.arange(len(obs.points_mm)))
        g = None
        if not labelled:
            _, g = np.unique(obs.group[i], return_inverse=True)
        return i, g

    i_s, g_s = take(n_search)
    coarse = _Problem(obs.points_mm[i_s], obs.years[i_s] if labelled else None, g_s, centre, z_scale,
                      min(K, coarse_K), min(M, 1), ridge)
    starts = []
    # The block axes first: sawn wood's grain runs near one (the stem model's tilt prior), and
    # the spiral may miss them by a few degrees, which a ring-count-consistent basin needs.
    for d in np.concatenate([np.eye(3), _hemisphere(n_directions)]):
        pith = _circle_pith(coarse.points, coarse.years, coarse.group, d, centre)
        starts.append((_cost(coarse, pith, d), pith, d))
    starts.sort(key=lambda s: s[0])
    # The circle fit misplaces the pith when the traced faces see only a narrow wedge of rings;
    # for the best directions also try a grid of pith positions (+-1.6 block sizes).
    span = 1.6 * float(size.max())
    offs = np.linspace(-span, span, pith_grid)
    for j, (c, p, d) in enumerate(starts[:n_grid_directions]):
        _, b1, b2 = _frame(d)
        for u in offs:
            for v in offs:
                q = centre + u * b1 + v * b2
                cq = _cost(coarse, q, d)
                if cq < c:
                    c, p = cq, q
        starts[j] = (c, p, d)
    starts.sort(key=lambda s: s[0])
    mid = _Problem(coarse.points, coarse.years, coarse.group, centre, z_scale, min(K, 4), M, ridge)
    # Refine the best starts whose directions differ by > ~10 deg: the cost landscape over the
    # axis has several basins when only some faces are traced (a single best start got stuck).
    chosen = []
    for c in starts:
        if all(abs(c[2] @ o[2]) < np.cos(np.deg2rad(10)) for o in chosen):
            chosen.append(c)
        if len(chosen) == n_starts:
            break
    if n_basins:  # pith hypotheses: the best start near a block axis is always one of them
        near = [c for c in starts if np.max(np.abs(c[2])) >= np.cos(np.deg2rad(10))]
        if near and all(abs(near[0][2] @ o[2]) < np.cos(np.deg2rad(10)) for o in chosen):
            chosen.append(near[0])
    # each start's descent is independent: on a fit's cores (woodcam._parallel), bit for bit
    refined = map_processes(lambda c: _refine(mid, c[1], c[2], max_nfev=30), chosen, workers)
    refined.sort(key=lambda r: r[2])
    i_f, g_f = take(n_fit)
    fine = _Problem(obs.points_mm[i_f], obs.years[i_f] if labelled else None, g_f, centre, z_scale, K, M, ridge)
    # The low-order ranking can put the true basin second (seen with three faces traced), so
    # the best n_final basins are finished at full order and compared there.
    pick = refined[:max(n_final, n_basins + 1)]
    if n_basins:  # ... and the best refined axis near a block axis (a real block's likely grain)
        axial = [r for r in refined if np.max(np.abs(r[1])) >= np.cos(np.deg2rad(_AXIAL_DEG))]
        if axial and not any(r is axial[0] for r in pick):
            pick.append(axial[0])
    finals = map_processes(lambda r: _refine(fine, r[0], r[1], max_nfev=60), pick, workers)
    finals.sort(key=lambda r: r[2])
    distinct = []  # basins that refined into the same axis are one hypothesis
    for r in finals:
        if all(not _same_axis(r[0], r[1], o[0], o[1], centre) for o in distinct):
            distinct.append(r)
    out = []
    for pith, d, _ in distinct[:max(1, n_basins)]:
        _, coef, offset, levels = fine.solve(pith, d)
        out.append((RadialField(pith, _frame(d)[0], z_scale, K, M, coef, float(offset)), levels,
                    (obs.group[i_f] if not labelled else None)))
    return out if n_basins else out[0]


def _same_axis(p1, d1, p2, d2, centre, angle_deg: float = 3.0, offset_mm: float = 2.0) -> bool:
    """True when two pith lines agree within ``angle_deg`` and pass within ``offset_mm`` of each
    other at the block centre."""
    d1, d2 = d1 / np.linalg.norm(d1), d2 / np.linalg.norm(d2)
    if abs(d1 @ d2) < np.cos(np.deg2rad(angle_deg)):
        return False
    q1 = p1 + d1 * ((centre - p1) @ d1)  # point of each line nearest the centre
    q2 = p2 + d2 * ((centre - p2) @ d2)
    return bool(np.linalg.norm(q1 - q2) < offset_mm)


#: A refined pith axis within this angle (degrees) of a block axis is "near a block axis": one
#: such basin is always kept as a pith hypothesis (sawn blocks are cut along the grain, give or
#: take the 10-20 degrees of spiral grain and a leaning stem).
_AXIAL_DEG = 20.0


def step_consistency(obs: RingObservations, n_points: int = 4000, seed: int = 0) -> float:
    """Share (0-1) of ring points whose nearest point on *another* ring of the same face is
    exactly one year away: a year-free check of a numbering on the faces it numbers.

    Neighbouring rings on a face are consecutive years (a ring the map missed makes a step of
    2, pieces of one ring left unlinked a step of 0). A numbering from a wrong pith axis counts
    rings that are not there (steps of 2-3 between neighbours: H11 with its top face held out,
    56 % of steps >= 2) or merges neighbours into one year (steps of 0: 93 % on another fold),
    while the in-sample cost of the level fit cannot tell (each ring has a free level).

    obs : numbered observations (``years`` per point, ``group`` per ring piece, ``face``).
    n_points : ring points sampled (spread over the faces by their share of points).
    """
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    n = len(obs.points_mm)
    hits = total = 0
    for f in np.unique(obs.face):
        on = np.flatnonzero(obs.face == f)
        if len(np.unique(obs.group[on])) < 2:
            continue
        pts, grp, yrs = obs.points_mm[on], obs.group[on], obs.years[on]
        s = rng.choice(len(on), min(len(on), max(1, n_points * len(on) // n)), replace=False)
        k = min(len(on), _STEP_NEIGHBOURS)
        _, ii = cKDTree(pts).query(pts[s], k=k)
        other = grp[ii] != grp[s][:, None]
        ok = other.any(axis=1)
        first = ii[np.arange(len(s)), np.argmax(other, axis=1)]
        step = np.abs(yrs[first] - yrs[s])[ok]
        hits += int(np.count_nonzero(step == 1))
        total += len(step)
    return hits / total if total else 0.0


#: Neighbours searched for the nearest point of another ring (ring points are 0.5 mm apart;
#: 64 reach ~16 mm along a ring, past any ring spacing).
_STEP_NEIGHBOURS = 64


def _initial_numbering(obs: RingObservations, shape_field) -> tuple[RingObservations, float, float, float]:
    """Number an unlabelled axis fit's rings: ``(numbered observations, k, a, consistency)``
    with years ``round(k * level + a)`` per ring group (``level`` = the group's median of
    ``shape_field``) and the numbering's :func:`step_consistency`.

    :func:`number_rings` picks the ring scale ``k`` by how well the levels align with integers,
    which is ambiguous where the faces' rings are irregular (H11: a count of 23 rings across a
    face showing 14). Every other clear alignment peak is tried too, and the one whose
    numbering makes neighbouring rings one year apart (:func:`step_consistency`) is taken,
    :func:`number_rings`' own choice unless another beats it by more than
    :data:`~woodcam.tolerances.NUMBERING_STEP_MARGIN`.
    """
    n = obs.n_groups
    lev = _group_medians(shape_field(obs.points_mm), obs.group, n)
    wts = np.bincount(obs.group, minlength=n).astype(float)
    spacing = ring_spacing_mm(obs)
    cands = [number_rings(lev, wts, spacing)] + _alignment_peaks(lev, wts, spacing)
    best = None
    for j, (k, a) in enumerate(cands):
        years = np.round(k * lev + a)
        num = RingObservations(obs.points_mm, years[obs.group], obs.group, obs.face)
        c = step_consistency(num)
        if best is None or c - (NUMBERING_STEP_MARGIN if j else 0.0) > best[0]:
            best = (c - (NUMBERING_STEP_MARGIN if j else 0.0), num, k, a, c)
    return best[1], best[2], best[3], best[4]


def _alignment_peaks(levels: np.ndarray, weights: np.ndarray, spacing_mm: float,
                     min_share: float = 0.5) -> list[tuple[float, float]]:
    """``(k, a)`` at every local maximum of :func:`number_rings`' alignment that reaches
    ``min_share`` of the best: the other ring scales the levels could mean."""
    ks, z = _alignment(levels, weights, spacing_mm)
    score = np.abs(z)
    inner = (score[1:-1] >= score[:-2]) & (score[1:-1] >= score[2:]) & (score[1:-1] >= min_share * score.max())
    idx = np.flatnonzero(inner) + 1
    return [(float(ks[i]), float(np.mod(-np.angle(z[i]) / (2 * np.pi), 1.0))) for i in idx]


def _alignment(levels: np.ndarray, weights: np.ndarray, spacing_mm: float):
    """Ring scales ``ks`` searched by :func:`number_rings` and the alignment ``z(k)`` (complex)."""
    ks = np.linspace(0.4 / spacing_mm, 2.5 / spacing_mm, 2000)
    w = weights / weights.sum()
    return ks, np.exp(2j * np.pi * np.outer(ks, levels)) @ w


def _numbered_basins(obs: RingObservations, size_mm, K: int, M: int, ridge: float, seed: int, n_basins: int,
                     workers: int = 1, **search) -> tuple[list, tuple | None]:
    """:func:`fit_axis_and_shape`'s ``n_basins`` basins ordered by :func:`_by_numbering`; for
    unlabelled rings whose best numbering has fewer than
    :data:`~woodcam.tolerances.NUMBERING_MIN_STEP` of its neighbouring rings one year apart,
    the search is repeated on other subsets of the points (seeds ``seed + 1``, ...; at most
    :data:`~woodcam.tolerances.NUMBERING_RESEARCHES`) and their distinct basins join the
    comparison, the first search's basins first; the ``n_basins`` best are returned.

    Why: the search fits a 600-point subset, and on a real cube one subset can miss the basins
    every other finds (H11 from its six ring maps, seed 2: one basin numbering 0.28 of the
    neighbouring rings one year apart, where seeds 0, 1, 3-5 find basins of 0.67-0.73; the
    evidence fit on it then reproduced 14 % of its own ring-map ridges within 2 px, against
    75-77 % with the other seeds). The step consistency judges a numbering on the rings
    themselves, whichever subset found it."""
    n_basins = max(1, int(n_basins))  # 0 would make the search return one triple, not a list
    found = fit_axis_and_shape(obs, size_mm, K, M, ridge, seed=seed, n_basins=n_basins, workers=workers, **search)
    if obs.labelled or not found:
        return _by_numbering(obs, found)
    centre = np.asarray(size_mm, float) / 2
    nums = [_initial_numbering(obs, f[0]) for f in found]
    for extra in range(1, NUMBERING_RESEARCHES + 1):
        if max(n[3] for n in nums) >= NUMBERING_MIN_STEP:
            break
        for f in fit_axis_and_shape(obs, size_mm, K, M, ridge, seed=seed + extra, n_basins=n_basins,
                                    workers=workers, **search):
            if all(not _same_axis(f[0].pith_mm, f[0].axis, o[0].pith_mm, o[0].axis, centre) for o in found):
                found.append(f)
                nums.append(_initial_numbering(obs, f[0]))
    order, numbering = _by_numbering(obs, found, nums)
    return order[:n_basins], numbering


def _by_numbering(obs: RingObservations, found: list, nums: list | None = None) -> tuple[list, tuple | None]:
    """Axis fits ``found`` (lowest in-sample cost first) reordered so the first numbers the
    rings consistently: the lowest-cost basin whose :func:`step_consistency` is within
    :data:`~woodcam.tolerances.NUMBERING_STEP_MARGIN` of the best basin's. With unlabelled
    rings every basin fits its own free ring levels, so its in-sample cost says little about
    its numbering; the faces' neighbouring rings do (issue 12: H11's bistable folds).

    Returns ``(reordered fits, the first one's _initial_numbering)``; the numbering is None
    where none was computed (labelled rings, a single basin), and is handed to
    :func:`_finish_radial` so the chosen basin is not numbered twice.
    """
    if obs.labelled or not found:
        return found, None
    if len(found) < 2:  # nothing to reorder; a numbering already made is handed on, not made again
        return found, nums[0] if nums else None
    nums = nums or [_initial_numbering(obs, f[0]) for f in found]
    best = max(n[3] for n in nums)
    good = [i for i, n in enumerate(nums) if n[3] >= best - NUMBERING_STEP_MARGIN]
    order = good + [i for i in range(len(found)) if i not in good]
    return [found[i] for i in order], nums[order[0]]


#: Ring spacings (mm) of recent observation sets, keyed by their content (points, ring groups,
#: faces; not the years, which numbering changes): the numbering compares several pith basins
#: on the same rings and the joint stem + knot-bend fit refits the stem on them several times
#: per fold; the spacing was a quarter of each warm-started stem refit's time.
_SPACING_CACHE: dict[str, float] = {}
_SPACING_CACHE_SIZE = 16


def ring_spacing_mm(obs: RingObservations) -> float:
    """Median distance (mm) from a ring point to the nearest point of another ring on its face.

    This is the ring width seen on the faces (>= the true radial width where a face cuts rings
    obliquely, twice it across a missing ring), used only to bracket the ring-width search.
    Remembered by content (:data:`_SPACING_CACHE`).
    """
    import hashlib

    h = hashlib.blake2b(digest_size=16)
    for a in (obs.points_mm, obs.group, obs.face):
        h.update(np.ascontiguousarray(a).tobytes())
    key = h.hexdigest()
    if key not in _SPACING_CACHE:
        if len(_SPACING_CACHE) >= _SPACING_CACHE_SIZE:
            _SPACING_CACHE.pop(next(iter(_SPACING_CACHE)))  # the oldest
        _SPACING_CACHE[key] = _ring_spacing(obs)
    return _SPACING_CACHE[key]


def _ring_spacing(obs: RingObservations) -> float:
    """:func:`ring_spacing_mm`, computed: about 20 points of each ring (every ``n // 20``-th),
    each one's distance to the nearest point of another ring on its face. One tree per face,
    asked for a point's :data:`_SPACING_NEIGHBOURS` nearest points (the first of another ring
    is the answer); only a point whose neighbours are all its own ring asks a tree of the other
    rings (one tree per ring was 1.3 of a knotted block's 18 CPU-s, seed 91841 block 2)."""
    from scipy.spatial import cKDTree

    dists = []
    for f in np.unique(obs.face):
        on = obs.face == f
        pts, grp = obs.points_mm[on], obs.group[on]
        groups = np.unique(grp)
        if len(groups) < 2:
            continue
        ask = np.concatenate([(idx := np.flatnonzero(grp == g))[:: max(1, len(idx) // 20)] for g in groups])
        k = min(_SPACING_NEIGHBOURS, len(pts))
        dd, ii = cKDTree(pts).query(pts[ask], k)
        dd, ii = dd.reshape(len(ask), k), ii.reshape(len(ask), k)
        other = grp[ii] != grp[ask][:, None]
        found = other.any(axis=1)
        dists.append(dd[found, np.argmax(other[found], axis=1)])
        crowded = ask[~found]  # every neighbour its own ring's: ask the other rings
        for g in np.unique(grp[crowded]):
            dists.append(cKDTree(pts[grp != g]).query(pts[crowded[grp[crowded] == g]])[0])
    if not dists:
        raise WoodcamError(
            "numbering unlabelled rings needs at least two rings on one face to measure the ring "
            "width; got a single ring: label its year or trace more rings"
        )
    return float(np.median(np.concatenate(dists)))


#: Nearest points asked for per ring point by :func:`_ring_spacing` before it falls back to a
#: tree of the other rings (a traced ring is ~1 point per 0.3 mm: 32 reach ~5 mm along it).
_SPACING_NEIGHBOURS = 32


def number_rings(levels: np.ndarray, weights: np.ndarray, spacing_mm: float):
    """Turn per-ring levels (mm-like) into years ``k * level + a`` with integer rings.

    ``k`` (rings per level unit) maximises the alignment ``|sum w exp(2 pi i k level)|`` of the
    levels with a lattice of integers. Every multiple of the true ``k`` aligns as well (a field
    stretched so rings sit on every 2nd, 3rd ... integer) and ``k -> 0`` aligns everything; the
    guard is to search ``k`` only in ``[0.4, 2.5] / spacing_mm`` (the ring width seen on the faces
    brackets the true one) and take the *smallest* ``k`` within 10 % of the best alignment.

    Returns
    -------
    k : float, years per level unit
    a : float in [0, 1), the phase: ``years = k * level + a``
    """
    ks, z = _alignment(levels, weights, spacing_mm)
    score = np.abs(z)
    first = int(np.flatnonzero(score >= 0.9 * score.max())[0])
    # climb to the local maximum of that first peak
    while first + 1 < len(ks) and score[first + 1] >= score[first]:
        first += 1
    k = ks[first]
    a = float(np.mod(-np.angle(z[first]) / (2 * np.pi), 1.0))
    return float(k), a


def _refit_labelled(obs: RingObservations, size_mm, start: RadialField, ridge: float,
                    n_fit: int = 2000, seed: int = 0) -> RadialField:
    """Labelled least squares started from ``start``'s axis (no global search)."""
    size = np.asarray(size_mm, float)
    rng = np.random.default_rng(seed + 1)
    n = len(obs.points_mm)
    i = np.sort(rng.choice(n, n_fit, replace=False)) if n > n_fit else np.arange(n)
    prob = _Problem(obs.points_mm[i], obs.years[i], None, size / 2, start.z_scale_mm, start.K, start.M, ridge)
    pith, d, _ = _refine(prob, start.pith_mm, start.axis, max_nfev=40)
    _, coef, offset, _ = prob.solve(pith, d)
    return RadialField(pith, _frame(d)[0], start.z_scale_mm, start.K, start.M, coef, float(offset))


def _group_medians(values: np.ndarray, labels: np.ndarray, n: int) -> np.ndarray:
    """Median of ``values (m,)`` per label ``0..n-1`` (``labels (m,)`` int) -> ``(n,)``, as
    ``np.median`` per group but in one sort (a loop of ``values[labels == j]`` rescans every
    point per group: ring maps give ~100-1000 groups of ~10k points)."""
    values = np.asarray(values, float)
    order = np.lexsort((values, labels))
    v = values[order]
    counts = np.bincount(labels, minlength=n)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    lo, hi = starts + (counts - 1) // 2, starts + counts // 2
    out = (v[np.minimum(lo, len(v) - 1)] + v[np.minimum(hi, len(v) - 1)]) / 2
    out[counts == 0] = np.nan  # (an empty group's indices point past its start)
    return out


def _relabel(obs: RingObservations, field: RadialField) -> tuple[RingObservations, int]:
    """Move each ring group's year to the integer nearest the field's median on it, where the
    two differ by more than half a year (a mislabelled or misnumbered trace)."""
    med = _group_medians(field(obs.points_mm) - obs.years, obs.group, obs.n_groups)
    shift = np.round(med)
    changed = int(np.count_nonzero(shift))
    years = obs.years + shift[obs.group]
    return RingObservations(obs.points_mm, years, obs.group, obs.face), changed


def number_observations(obs: RingObservations, field: GrowthFieldLike) -> RingObservations:
    """Label every ring group of ``obs`` (block frame, mm) with the integer nearest ``field``'s
    median growth time on it (e.g. to hand unlabelled ring maps to a method that needs years,
    numbered by a radial fit)."""
    years = np.round(_group_medians(field(obs.points_mm), obs.group, obs.n_groups))
    return RingObservations(obs.points_mm, years[obs.group], obs.group, obs.face)


def fit_radial(obs: RingObservations, size_mm: ArrayLike, K: int = 12, M: int = 1, ridge: float = 1e-8,
               max_relabel_rounds: int = 2, seed: int = 0, history: bool = True,
               **search) -> RadialField:
    """Fit the radial model to labelled or unlabelled ring observations of a block.

    Labelled: axis search + variable-projection least squares; then traces whose median misfit
    exceeds half a year are renumbered to the fitted year and the fit is repeated (robust to a
    few mislabelled traces). Unlabelled: the levels of the shape fit are numbered by
    :func:`number_rings` and the result is fitted as labelled; the integer age offset is then
    chosen so the pith sits at year ~0 (exact for fields of the eq. 7-9 family, otherwise the
    rings are right "up to the age offset").

    obs : ring observations of the block (block frame, mm), labelled with years or not
    size_mm : (3,) block size, mm
    K, M : Fourier order in azimuth and polynomial order along the axis of the speed ``s``
        (:class:`~woodcam.fields.radial.RadialField`; default 12 and 1)
    ridge : weight of the ridge penalty on the coefficients (higher harmonics cost more;
        default 1e-8, scaled by the number of points and the median pith distance)
    max_relabel_rounds : rounds of renumbering the traces that misfit by over half a year and
        refitting (default 2)
    seed : the random point subsets and starts of the axis search (default 0): the same seed,
        the same fit
    history : also fit the tree's growth history, a monotone warp of the years that gives every
        year its own ring width (:func:`_fit_growth_history`); False keeps the plain model.
    """
    with _one_blas_thread():
        return _fit_radial(obs, size_mm, K, M, ridge, max_relabel_rounds, seed, history, search)


def _one_blas_thread():
    """BLAS on one thread: the systems here are small (<= 2000 x 180); see
    :mod:`woodcam._threads`."""
    from .._threads import one_blas_thread

    return one_blas_thread()


#: Pith-axis basins whose numberings :func:`fit_radial` compares for unlabelled rings.
_NUMBERING_BASINS = 3


def _fit_radial(obs, size_mm, K, M, ridge, max_relabel_rounds, seed, history, search) -> RadialField:
    if obs.labelled:
        found = fit_axis_and_shape(obs, size_mm, K, M, ridge, seed=seed, **search)
    else:  # unlabelled: the basin that numbers the rings consistently (:func:`_by_numbering`)
        ordered, numbering = _numbered_basins(obs, size_mm, K, M, ridge, seed, _NUMBERING_BASINS, **search)
        return _finish_radial(obs, size_mm, ordered[0], K, M, ridge, max_relabel_rounds, seed, history,
                              numbering=numbering)[0]
    return _finish_radial(obs, size_mm, found, K, M, ridge, max_relabel_rounds, seed, history)[0]


def fit_radial_hypotheses(obs: RingObservations, size_mm, n_basins: int = 3, K: int = 12, M: int = 1,
                          ridge: float = 1e-8, max_relabel_rounds: int = 2, seed: int = 0,
                          history: bool = True, workers: int = 1,
                          **search) -> tuple[list[RadialField], RingObservations]:
    """Radial fits from the ``n_basins`` best distinct pith-axis basins (pith hypotheses).

    The first is :func:`fit_radial`'s answer (lowest in-sample cost). Unlabelled rings are
    numbered once, by that first fit, and every other basin is fitted to the same numbers, so
    the hypotheses differ in their stem, not in their ring numbering. ``search``: options of
    :func:`fit_axis_and_shape`; ``workers``: processes for its descents and for finishing the
    basins after the first (:mod:`woodcam._parallel`; the same fits bit for bit).

    Returns
    -------
    fields : list of RadialField, best in-sample first (fewer when the search found fewer basins)
    numbered : the observations with the years the fits used (relabelled traces corrected)
    """
    with _one_blas_thread():
        found, numbering = _numbered_basins(obs, size_mm, K, M, ridge, seed, n_basins, workers, **search)
        first, numbered = _finish_radial(obs, size_mm, found[0], K, M, ridge, max_relabel_rounds, seed, history,
                                         numbering=numbering)

        def finish(shape_field):
            if obs.labelled:  # its own mislabel correction, not the first hypothesis'
                return _finish_radial(obs, size_mm, (shape_field, None, None), K, M, ridge,
                                      max_relabel_rounds, seed, history)[0]
            # coefficients in level units: refit to the shared numbers, no renumbering
            start = _refit_labelled(numbered, size_mm, shape_field, ridge, seed=seed)
            return _finish_radial(numbered, size_mm, (start, None, None), K, M, ridge,
                                  max_relabel_rounds, seed, history, relabel=False)[0]
        fields = [first] + map_processes(lambda f: finish(f[0]), found[1:], workers)
    return fields, numbered


def _finish_radial(obs, size_mm, found, K, M, ridge, max_relabel_rounds, seed, history, relabel=True,
                   numbering=None):
    """Number (unlabelled), relabel, smooth and warp the axis fit ``found`` (a triple of
    :func:`fit_axis_and_shape`); returns ``(field, observations with the years used)``.

    numbering : ``_initial_numbering(obs, found[0])`` where the caller has it already
        (:func:`_by_numbering`), else None to compute it here."""
    labelled_in = obs.labelled
    if labelled_in:
        field = found[0]
    else:
        shape_field = found[0]
        # Levels of every group from the fitted shape (groups not in the fitting subset too).
        obs, k, a, _ = numbering if numbering is not None else _initial_numbering(obs, shape_field)
        start = RadialField(shape_field.pith_mm, shape_field.axis, shape_field.z_scale_mm, K, M,
                            shape_field.coef * k, a)
        field = _refit_labelled(obs, size_mm, start, ridge, seed=seed)
    numbered = not labelled_in
    for _ in range(max_relabel_rounds if relabel else 0):
        obs, changed = _relabel(obs, field)
        if not changed:
            break
        field = _refit_labelled(obs, size_mm, field, ridge, seed=seed)
    field = _smooth_with_history(obs, field, seed, history)
    if numbered:
        # Our own numbering: pick the integer age offset that puts the pith at year ~0 (seed
        # eq. 5 fits an integer offset too); rings are unchanged by it.
        shift = float(np.round(field(field.pith_mm[None])[0]))
        field.offset -= shift
        if field.history_levels is not None:
            field.history_levels = field.history_levels - shift
            field.history_years = field.history_years - shift
        obs = RingObservations(obs.points_mm, obs.years - shift, obs.group, obs.face)
    return field, obs


#: Ridge strengths tried on the final fit (relative units of :meth:`_Problem.solve`'s penalty).
_FINAL_RIDGES = (1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3)

#: The final fit takes the strongest ridge whose residual sum of squares stays within this
#: factor of the weakest ridge's: smoothing that the traces cannot tell from the best fit.
_FINAL_RSS_FACTOR = 1.05


class _AxisDesign:
    """The radial model's linear system at one fixed axis (pith and direction) over ``obs``:
    :func:`_smoothest_coefficients` and every round of :func:`_fit_growth_history` solve at the
    same axis, so its design is built once per fit instead of once per round (the same arrays,
    so the same results bit for bit).

    ``X``, ``w``, ``XtX``: the ridge problem of :func:`_smoothest_coefficients` on its fixed
    random subset ``i`` of ``n_fit`` points; :meth:`linear` is ``field.linear(obs.points_mm)``
    for a field on this axis."""

    def __init__(self, obs: RingObservations, field: RadialField, seed: int, n_fit: int = 3000):
        rng = np.random.default_rng(seed + 2)
        n = len(obs.points_mm)
        self.i = np.sort(rng.choice(n, n_fit, replace=False)) if n > n_fit else np.arange(n)
        self.obs, self.pith, self.axis = obs, np.asarray(field.pith_mm), np.asarray(field.axis)
        self.frame = _frame(field.axis)
        rho, B = _design(obs.points_mm[self.i], field.pith_mm, *self.frame, field.z_scale_mm, field.K, field.M)
        self.X = np.concatenate([np.ones((len(rho), 1)), rho[:, None] * B], axis=1)
        self.w = np.concatenate([[0.0], _penalty_weights(field.K, field.M)]) * np.median(rho)
        self.XtX = self.X.T @ self.X
        self._all: tuple | None = None

    def fits(self, obs: RingObservations, field: RadialField) -> bool:
        """Whether this is the system of ``obs`` at ``field``'s axis."""
        return obs is self.obs and bool(np.array_equal(field.pith_mm, self.pith)
                                        and np.array_equal(field.axis, self.axis))

    def linear(self, field: RadialField) -> np.ndarray:
        """``(n,)`` ``field.linear(obs.points_mm)`` with the design at every point built once."""
        if self._all is None:
            self._all = _design(check_points(self.obs.points_mm), field.pith_mm, *self.frame, field.z_scale_mm,
                                field.K, field.M)
        rho, B = self._all
        return field.offset + rho * (B @ field.coef)


def _smoothest_coefficients(obs: RingObservations, field: RadialField, seed: int,
                            n_fit: int = 3000, targets=None, system: _AxisDesign | None = None) -> RadialField:
    """Re-solve the coefficients at the fitted axis with the strongest ridge the traces allow.

    Why: with jittered traces on only some faces, a weak ridge lets the high azimuthal
    harmonics swing where no traced face sees the rings (three faces, 0.3 mm jitter: growth-time
    error at the 90th percentile 3.7 years with ridge 1e-8, 0.24 with 1e-5, for a 2 % rise of the
    rms misfit). Generalised cross-validation picked the weak ridge there (it only scores the
    traced faces), so the rule is a discrepancy one: the smoothest fit whose residual sum of
    squares is within :data:`_FINAL_RSS_FACTOR` of the least-smoothed one.

    targets : (n,) values the linear model is fitted to (default ``obs.years``).
    system : the :class:`_AxisDesign` of ``obs`` at ``field``'s axis when already built.
    """
    if system is None or not system.fits(obs, field):
        system = _AxisDesign(obs, field, seed, n_fit)
    X, w, XtX = system.X, system.w, system.XtX
    yrs = (obs.years if targets is None else np.asarray(targets, float))[system.i]
    Xty = X.T @ yrs
    fits = []
    for ridge in _FINAL_RIDGES:
        A = XtX + np.diag(ridge * len(X) * w ** 2)
        A[np.diag_indices_from(A)] += 1e-10 * np.trace(A) / len(A)
        try:
            sol = np.linalg.solve(A, Xty)
        except np.linalg.LinAlgError:
            continue
        fits.append((float(np.sum((X @ sol - yrs) ** 2)), sol))
    if not fits:
        return field
    rss0 = fits[0][0]
    sol = [f for f in fits if f[0] <= _FINAL_RSS_FACTOR * rss0][-1][1]
    return RadialField(field.pith_mm, field.axis, field.z_scale_mm, field.K, field.M, sol[1:], float(sol[0]))


def _smooth_with_history(obs: RingObservations, field: RadialField, seed: int, history: bool) -> RadialField:
    """:func:`_smoothest_coefficients`, then (``history``) :func:`_fit_growth_history`, at
    ``field``'s axis: one :class:`_AxisDesign` for all their solves."""
    system = _AxisDesign(obs, field, seed)
    field = _smoothest_coefficients(obs, field, seed, system=system)
    return _fit_growth_history(obs, field, seed, system=system) if history else field


def _fit_growth_history(obs: RingObservations, field: RadialField, seed: int,
                        system: _AxisDesign | None = None) -> RadialField:
    """Add the tree's growth history: ``years = h(offset + rho * s)`` with ``h`` monotone
    through one level per observed year (:func:`_warp`).

    Why: real trees grow a different ring width every year, the same all around the stem (a wet
    year is wide everywhere), which a model linear in ``rho`` cannot follow. Measured: on an
    eq. 7-9 field warped by such a history (tests), the 90th-percentile interior error falls from
    0.32-0.54 to 0.05-0.10 year; on the Mokume cube CN03 (all faces), ring-map ridge pixels
    within 1 px of a ring line rise from 16.6 to 20.8 %, though its held-out faces do not gain
    (6.2 -> 4.8 %, near the 4.5 % chance level either way). Alternating fit: each year's level
    is the median of the linear model on that ring's points, shrunk towards the year itself by
    :data:`RING_HISTORY_PRIOR_POINTS` (a ring seen on a few points stays near the mean width) and
    made increasing (scipy's isotonic regression); then ``s`` is refitted to those levels.
    ``system``: the :class:`_AxisDesign` at ``field``'s axis when already built (every round
    solves at that axis).
    """
    from scipy.optimize import isotonic_regression

    years, idx, counts = np.unique(obs.years, return_inverse=True, return_counts=True)
    if len(years) < 3:
        return field
    if system is None or not system.fits(obs, field):
        system = _AxisDesign(obs, field, seed)

    def levels(f: RadialField) -> np.ndarray:
        med = _group_medians(system.linear(f), idx, len(years))  # one per year
        lev = (counts * med + RING_HISTORY_PRIOR_POINTS * years) / (counts + RING_HISTORY_PRIOR_POINTS)
        # strictly increasing for the interpolation
        return isotonic_regression(lev, weights=counts).x + np.arange(len(years)) * RING_HISTORY_MIN_STEP

    for _ in range(RING_HISTORY_ROUNDS):
        field = _smoothest_coefficients(obs, field, seed, targets=levels(field)[idx], system=system)
    field.history_levels, field.history_years = levels(field), years.astype(float)
    return field
