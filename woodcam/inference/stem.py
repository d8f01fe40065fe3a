"""A stem with a curved, tilted pith and growth that varies by year and direction (issue 12, part 2).

The radial fit (:mod:`.radial`) has a straight pith and a flexible ring shape (12 azimuthal
harmonics); with three faces its in-sample cost is *lower* on wrong, steeply tilted axes than on
the true one (dev blocks of seed 21: the wrong axis 45 degrees off fits the three faces to
99 % within 2 mm and predicts the three unseen ones to 15-43 %): the shape's freedom absorbs
the tilt. This model is the log generator's own family (``woodcam.logs`` / ``woodcam.synth``:
a Chebyshev centreline, cross-sections perpendicular to the log axis, growth speed per
(height, azimuth), ring width changing with the radius and by year) with few shape terms, so
the pith is pinned by the rings' roundness rather than by the shape's flexibility.

Model, block frame, mm -> years. A base direction ``d0`` (a block axis, or a given axis) with
perpendicular unit vectors ``b1, b2``; the axial coordinate ``t = (p - c) . d0`` about the block
centre ``c``, ``tau = t / L`` (``L`` half the block diagonal). The pith at height ``t``::

    pith(t) = c + t d0 + sum_{j=0..2} (u_j b1 + v_j b2) tau^j

(offset, tilt, curvature: a quadratic centreline, seed 001 §3.3's Chebyshev centreline to
second order over a block). Cross-sections are perpendicular to ``d0`` as the generator's
(``Centreline.to_log_centric``): ``rho`` and ``phi`` are the polar coordinates of ``p -
pith(t)`` in ``(b1, b2)``. Then::

    g(p)     = a + rho s(phi, tau) + sum_{j=2..P} e_j (rho / rho_0)^j
    s        = sum_{k <= K, m <= M} c_km trig_k(phi) tau^m        (rings per mm by direction, height)
    years(p) = h(g(p))                                             (growth history, monotone)

``s`` is the generator's speed per (height, azimuth) (``KnottedLogField``'s bark-radius speed,
the analytic log's eccentricity and lobes), the powers of ``rho`` its ring width changing with
the radius (``AnalyticLogField``'s ``width_slope``), ``h`` the year-to-year ring width (the
same all around the stem), fitted as the radial model's warp (:func:`.radial._warp`).

Fit: for a fixed centreline ``g`` is linear in ``(a, c, e)``; the outer problem is the six
centreline parameters (variable projection, :func:`scipy.optimize.least_squares` with a
soft-L1 robust loss against stray traces) with Gaussian priors on the tilt (the grain of sawn
wood runs near a block axis: :data:`STEM_TILT_PRIOR_DEG`) and the curvature
(:data:`STEM_CURVE_PRIOR_MM`). Starts: each base axis with the pith from every face's ring
curvature (concentric circles fitted to the face's rings projected along the axis) and from a
grid of positions, in and far outside the block; the cheapest are finished at full order (with
``outward=True`` the cheapest of those whose growth time rises away from their pith, where any
does: :func:`_outward`). Then mislabelled traces are renumbered (as the radial fit does), the
coefficients are the posterior mean under their priors, and the growth history is fitted.
Labelled observations only (:mod:`.evidence` numbers unlabelled rings first).
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import field as dc_field
from itertools import islice

import numpy as np

from .._checks import as_floats, check_bool, check_number, real_numbers
from .._parallel import map_processes
from .._repr import summary_repr
from .._types import ArrayLike
from ..errors import WoodcamError
from ..fields.base import check_points
from ..frames import check_size
from ..tolerances import (RING_HISTORY_MIN_STEP, RING_HISTORY_PRIOR_POINTS, RING_HISTORY_ROUNDS,
                          STEM_AXIAL_SD, STEM_CURVE_PRIOR_MM, STEM_HARMONIC_SD, STEM_PRIOR_YEARS,
                          STEM_RADIAL_SD, STEM_TILT_PRIOR_DEG)
from .observations import RingObservations
from .radial import _circle_pith, _frame, _group_medians, _lstsq, _trig_powers, _warp, ring_spacing_mm


@dataclass
class StemField:
    """``years = h(a + rho s(phi, tau) + sum_j e_j (rho / rho_0)^j)`` about a quadratic pith
    centreline (module docstring). Block frame, mm.

    Attributes
    ----------
    centre_mm : (3,) the block centre ``c``; base_axis : (3,) unit ``d0``
    half_length_mm : ``L``; curve : (2, 3) ``[[u0, u1, u2], [v0, v1, v2]]`` mm
    K, M, P : azimuthal order, axial order of ``s``, highest power of ``rho``
    coef : ((2K+1)(M+1),) ``c``; rho_coef : (P-1,) ``e``; rho0_mm : ``rho_0``; offset : ``a``
    history_levels, history_years : the warp ``h`` (None: identity)
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    centre_mm: np.ndarray
    base_axis: np.ndarray
    half_length_mm: float
    curve: np.ndarray
    K: int
    M: int
    P: int
    coef: np.ndarray
    rho_coef: np.ndarray
    rho0_mm: float
    offset: float = 0.0
    history_levels: np.ndarray | None = None
    history_years: np.ndarray | None = None

    def pith_mm(self, t_mm: ArrayLike) -> np.ndarray:
        """``(n, 3)`` pith points (block frame) at axial positions ``t_mm (n,)`` about the centre."""
        d, b1, b2 = _frame(self.base_axis)
        t = real_numbers(t_mm, "t_mm").reshape(-1)  # None was a NaN pith point, 'a' numpy's ValueError
        tau = t / self.half_length_mm
        pw = tau[:, None] ** np.arange(3)
        return (np.asarray(self.centre_mm, float) + t[:, None] * d
                + (pw @ self.curve[0])[:, None] * b1 + (pw @ self.curve[1])[:, None] * b2)

    def pith_in_section_mm(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n, 3)`` the pith point in the cross-section of each of ``points_mm (n, 3)``."""
        p = check_points(points_mm)
        return self.pith_mm((p - self.centre_mm) @ _frame(self.base_axis)[0])

    @property
    def axis(self) -> np.ndarray:
        """(3,) unit pith direction at the block centre (the grain direction there)."""
        d, b1, b2 = _frame(self.base_axis)
        v = d + (self.curve[0, 1] * b1 + self.curve[1, 1] * b2) / self.half_length_mm
        return v / np.linalg.norm(v)

    def pith_distance_mm(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n,)`` mm: distance ``rho`` of each point from the pith in its cross-section."""
        p = check_points(points_mm)
        x1, x2, _ = _cross_section(p, self.centre_mm, _frame(self.base_axis), self.half_length_mm, self.curve)
        return np.hypot(x1, x2)

    def pith_years(self) -> float:
        """The growth time on the pith (``rho = 0``): the origin of times "from the pith"."""
        g = np.array([self.offset])
        return float(g[0] if self.history_levels is None else _warp(g, self.history_levels, self.history_years)[0])

    def linear(self, points_mm: ArrayLike) -> np.ndarray:
        """``g(p)``, the years before the growth-history warp, ``(n,)``."""
        p = check_points(points_mm)
        X = _design(p, self.centre_mm, _frame(self.base_axis), self.half_length_mm, self.curve,
                    self.K, self.M, self.P, self.rho0_mm)
        return self.offset + X[:, 1:] @ np.concatenate([self.rho_coef, self.coef])

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        g = self.linear(points_mm)
        return g if self.history_levels is None else _warp(g, self.history_levels, self.history_years)

    def grain_direction(self, points_mm: ArrayLike) -> np.ndarray:
        """``(n, 3)`` unit tangent of the centreline at each point's height."""
        p = check_points(points_mm)
        d, b1, b2 = _frame(self.base_axis)
        tau = ((p - self.centre_mm) @ d) / self.half_length_mm
        du = self.curve[0, 1] + 2 * self.curve[0, 2] * tau
        dv = self.curve[1, 1] + 2 * self.curve[1, 2] * tau
        v = d[None] + (du[:, None] * b1 + dv[:, None] * b2) / self.half_length_mm
        return v / np.linalg.norm(v, axis=1, keepdims=True)


def _cross_section(points, centre, frame, L, curve):
    """``x1, x2, tau``: the coordinates of ``points (n, 3)`` in their cross-section about the
    centreline ``curve (2, 3)`` (along ``b1, b2``) and their height ``tau``."""
    d, b1, b2 = frame
    q = points - centre
    tau = (q @ d) / L
    pw = tau[:, None] ** np.arange(3)
    return q @ b1 - pw @ curve[0], q @ b2 - pw @ curve[1], tau


def _design(points, centre, frame, L, curve, K, M, P, rho0):
    """``(n, 1 + (P - 1) + (2K+1)(M+1))``: columns ``1, (rho/rho0)^2..P, rho trig_k(phi) tau^m``."""
    x1, x2, tau = _cross_section(points, centre, frame, L, curve)
    rho = np.hypot(x1, x2)
    X = np.empty((len(rho), P + (2 * K + 1) * (M + 1)))  # the columns written in place
    X[:, 0] = 1.0
    X[:, 1:P] = (rho / rho0)[:, None] ** np.arange(2, P + 1)
    np.multiply(rho[:, None], _trig_powers(np.arctan2(x2, x1), tau, K, M), out=X[:, P:])
    return X


def _prior_sd(K, M, P, rho0, density) -> np.ndarray:
    """Prior standard deviation per column of :func:`_design` (inf: free), for rings of about
    ``density`` rings per mm: the offset and the mean ring density are free; the harmonics of
    ``s`` (eccentricity, lobes, the speed per azimuth) and its change along the stem are a few
    tenths of the mean at most (the generator: eccentricity <= 0.15, lobes <= 0.025, bark-radius
    speed within ~10 %); the ``rho`` powers change the ring width by <= 30 % over ``rho_0``.
    Without these, ``rho (a cos phi + b sin phi)`` is a plane for any pith: straight rings fit
    wherever the pith is put (seed 21 block 1)."""
    k = np.concatenate([[0], np.arange(1, K + 1), np.arange(1, K + 1)]).astype(float)
    m = np.arange(M + 1, dtype=float)
    kk, mm = np.meshgrid(k, m, indexing="ij")
    sd = np.where(kk == 0, STEM_AXIAL_SD * density, STEM_HARMONIC_SD * density / np.maximum(kk, 1))
    sd = np.where((kk == 0) & (mm == 0), np.inf, sd * np.where(mm > 0, 0.7, 1.0)).reshape(-1)
    return np.concatenate([[np.inf], np.full(P - 1, STEM_RADIAL_SD * density * rho0), sd])


@dataclass
class _StemProblem:
    points: np.ndarray
    years: np.ndarray
    centre: np.ndarray
    frame: tuple
    L: float
    K: int
    M: int
    P: int
    rho0: float
    prior_sd: np.ndarray  # per design column, see _prior_sd
    tilt_prior: float     # tan of the tilt prior's standard deviation (inf: none)
    curve_prior_mm: float
    # the last centreline's design, keyed by its bytes: after the search, the relabelling, the
    # coefficients and every growth-history round solve at one centreline (copies made for
    # other targets share it: same points)
    _last: dict = dc_field(default_factory=dict, repr=False)

    def curve_of(self, theta) -> np.ndarray:
        # theta = (u0, v0, u1, v1, u2, v2)
        return np.array([[theta[0], theta[2], theta[4]], [theta[1], theta[3], theta[5]]])

    def design(self, curve) -> np.ndarray:
        """:func:`_design` of the points about ``curve``, built once per centreline in a row."""
        key = np.asarray(curve, float).tobytes()
        if self._last.get("key") != key:
            self._last.update(key=key, X=_design(self.points, self.centre, self.frame, self.L, curve, self.K,
                                                 self.M, self.P, self.rho0))
        return self._last["X"]

    def solve(self, curve):
        X = self.design(curve)
        pen = STEM_PRIOR_YEARS * np.sqrt(len(X)) / self.prior_sd
        lhs = np.concatenate([X, np.diag(pen)])
        rhs = np.concatenate([self.years, np.zeros(len(pen))])
        sol = _lstsq(lhs, rhs)
        return X @ sol - self.years, sol

    def prior(self, curve) -> np.ndarray:
        """Prior residuals (years) of the tilt and curvature, weighted like ``n`` data points."""
        s = STEM_PRIOR_YEARS * np.sqrt(len(self.points))
        tilt = curve[:, 1] / self.L / self.tilt_prior
        return s * np.concatenate([tilt, curve[:, 2] / self.curve_prior_mm])

    def residuals(self, theta) -> np.ndarray:
        c = self.curve_of(theta)
        return np.concatenate([self.solve(c)[0], self.prior(c)])


def _robust_cost(r: np.ndarray, scale: float) -> float:
    """Soft-L1 cost of residuals ``r`` (years), as :func:`scipy.optimize.least_squares` sums it."""
    z = (r / scale) ** 2
    return float(np.sum(2 * scale ** 2 * (np.sqrt(1 + z) - 1)))


def _refine(prob: _StemProblem, theta0, max_nfev: int):
    from scipy.optimize import least_squares

    scale = np.array([5.0, 5.0, 2.0, 2.0, 1.0, 1.0])
    res = least_squares(prob.residuals, theta0, x_scale=scale, diff_step=1e-4, max_nfev=max_nfev,
                        method="trf", loss="soft_l1", f_scale=STEM_PRIOR_YEARS, ftol=1e-6, xtol=1e-6)
    return res.x, float(res.cost)


def _base_axes(base_axes) -> list[np.ndarray]:
    """``base_axes`` (one ``(3,)`` direction or ``(k, 3)`` of them) as unit vectors; the three
    block axes for None. A ``(k, 2)`` was an IndexError in the frame, a zero axis numpy's
    divide warning, a string its bare ValueError."""
    if base_axes is None:
        return [np.eye(3)[i] for i in range(3)]
    a = as_floats(base_axes)
    if a is not None and a.ndim == 1:
        a = a[None]
    norms = None if a is None or a.ndim != 2 or a.shape[1] != 3 or not len(a) or not np.all(np.isfinite(a)) \
        else np.linalg.norm(a, axis=1)
    if norms is None or np.any(norms < 1e-12):
        raise WoodcamError(f"base_axes must be finite non-zero directions, one (3,) or (k, 3); got {base_axes!r:.80}; "
                           "e.g. base_axes=[(0, 0, 1)], or None for the three block axes")
    return [r / np.linalg.norm(r) for r in a]  # row by row, as before: the same bits


def _starts(prob: _StemProblem, obs: RingObservations, sel: np.ndarray, size, n_keep: int):
    """Pith offsets ``(u0, v0)`` to start from for one base axis: every face's ring-curvature
    pith (concentric circles fitted to that face's rings, seen along the axis), all faces'
    together, and a grid up to 1.6 block sizes off the centre; the ``n_keep`` cheapest."""
    d, b1, b2 = prob.frame
    c = prob.centre
    cands = []
    faces = [obs.face[sel] == f for f in np.unique(obs.face[sel])] + [np.ones(len(sel), bool)]
    for m in faces:
        if m.sum() < 10 or len(np.unique(prob.years[m])) < 3:
            continue
        p = _circle_pith(prob.points[m], prob.years[m], None, d, c)
        cands.append(((p - c) @ b1, (p - c) @ b2))
    span = 1.6 * float(np.max(size))
    g = np.linspace(-span, span, 9)
    cands += [(u, v) for u in g for v in g]
    scored = []
    for u, v in cands:
        th = np.array([u, v, 0, 0, 0, 0], float)
        scored.append((_robust_cost(prob.residuals(th), STEM_PRIOR_YEARS), th))
    scored.sort(key=lambda s: s[0])
    kept = []
    for cost, th in scored:  # distinct starts (> 3 mm apart)
        if all(np.hypot(*(th[:2] - k[1][:2])) > 3.0 for k in kept):
            kept.append((cost, th))
        if len(kept) == n_keep:
            break
    return kept


def _outward(prob: _StemProblem, theta) -> bool:
    """Does the growth time of ``prob`` fitted about the centreline ``theta`` rise away from the
    pith (mean ring density ``c_00 > 0``)?

    Growth time counts from the pith, and a fit whose density is negative has put its pith
    beyond the side where the rings count the most years. Far from the pith the rings are
    nearly straight and such a fit follows them about as well (a clear block of fresh seed 57131,
    block 13: its cheapest stem falls, and keeping the cheapest that rises instead took the
    evidence fit from 99.4 to 97.4 % within 2 mm with three faces), but the knots' bend needs
    times from the pith (:func:`woodcam.inference.knots.fit_knotted_stem`). A start's density is
    checked, not imposed on the descents: a penalty on a negative density in every descent moved
    dev seed 21 block 1 (six faces) to a wrong axis (99.8 -> 75.7 %)."""
    return bool(prob.solve(prob.curve_of(theta))[1][prob.P] > 0)


def fit_stem(obs: RingObservations, size_mm: ArrayLike, base_axes: ArrayLike | None = None,
             K: int = 4, M: int = 1, P: int = 2, tilt_prior_deg: float = STEM_TILT_PRIOR_DEG,
             curve_prior_mm: float = STEM_CURVE_PRIOR_MM, n_search: int = 500,
             n_fit: int = 1000, n_starts: int = 2, n_final: int = 2, seed: int = 0,
             history: bool = True, offset_years: ArrayLike | None = None,
             init: StemField | None = None, workers: int = 1, outward: bool = False) -> StemField:
    """Fit the stem model (module docstring) to labelled ring observations of a block.

    The result depends on ``obs`` and the arguments only (no other face's data enters it), so
    it is its own honest leave-one-face-out recipe.

    Parameters
    ----------
    obs : labelled ring observations (block frame, mm; any subset of faces)
    size_mm : (3,) block size, mm
    base_axes : (k, 3) directions the pith is tilted from (default the three block axes: the
        grain of sawn wood runs near one of them); each is tried and the cheapest kept
    K, M, P : azimuthal order and axial order of the speed ``s``, highest power of ``rho``
    tilt_prior_deg : standard deviation (degrees) of the pith's tilt from its base axis
    curve_prior_mm : standard deviation (mm) of the centreline's sagitta over half the diagonal
    n_search, n_fit : points used for the start search and the refinement (fixed random subsets)
    n_starts : starts refined at low order per base axis
    n_final : of those, the cheapest finished at full order
    seed : int >= 0 (default 0) of the random point subsets and starts: the same seed, the
        same fit
    history : fit the growth-history warp ``h`` (year-to-year ring width, module docstring;
        default True); False leaves it the identity (``history_levels`` None)
    offset_years : (n,) years per observation the stem does not explain (e.g. the bend a knot
        puts into the rings round it: :func:`woodcam.inference.knots.fit_knotted_stem`): the stem
        is fitted to ``obs.years - offset_years``; default none
    init : a stem fitted to nearly the same targets: its base axis and centreline are the one
        start, refined at full order (no start search; about 4x cheaper)
    workers : processes the starts' and the finals' descents may use
        (:func:`woodcam._parallel.map_processes`; the same fit bit for bit)
    outward : finish only the starts whose growth time rises away from their pith, where any
        does (:func:`_outward`): what the knots' bend needs

    Returns
    -------
    StemField
    """
    if not isinstance(obs, RingObservations):
        raise WoodcamError(f"obs must be RingObservations (woodcam.inference.observations.gather_observations "
                           f"of a block); got {type(obs).__name__}")
    if not obs.labelled:
        raise WoodcamError("fit_stem needs year-labelled rings; number unlabelled rings first "
                           "(woodcam.inference.radial.number_observations or fit_evidence)")
    if len(obs.points_mm) < 20 or len(np.unique(obs.years)) < 3:
        raise WoodcamError(f"fit_stem needs at least 20 ring points on 3 rings; got {len(obs.points_mm)} "
                           f"points on {len(np.unique(obs.years))} rings: trace more rings")
    # the plain arguments by name: a size of 2 was a broadcast ValueError, K='4' a TypeError,
    # M=-1 an IndexError, n_search=0 a reshape ValueError, seed='a' numpy's TypeError, init=5
    # an AttributeError; n_starts=0 and workers=0 ran as if 1
    size_mm = check_size(size_mm)
    K, M, P = (int(check_number(v, name, lo=lo, integer=True, fix="the stem model's order, e.g. K=4, M=1, P=2"))
               for v, name, lo in ((K, "K", 0), (M, "M", 0), (P, "P", 1)))
    n_search, n_fit = (int(check_number(v, name, lo=20, integer=True, fix="ring points, e.g. 500"))
                       for v, name in ((n_search, "n_search"), (n_fit, "n_fit")))
    n_starts, n_final, workers = (int(check_number(v, name, lo=1, integer=True, fix="e.g. 2"))
                                  for v, name in ((n_starts, "n_starts"), (n_final, "n_final"), (workers, "workers")))
    seed = int(check_number(seed, "seed", lo=0, integer=True, fix="same seed, same fit"))
    history, outward = check_bool(history, "history"), check_bool(outward, "outward")
    if init is not None and not isinstance(init, StemField):
        raise WoodcamError(f"init must be a StemField (an earlier fit_stem) or None; got {type(init).__name__}")
    tilt_prior_deg, curve_prior_mm = (check_number(v, name, lo=0, lo_open=True, fix="a prior's standard deviation")
                                      for v, name in ((tilt_prior_deg, "tilt_prior_deg"),
                                                      (curve_prior_mm, "curve_prior_mm")))
    axes = _base_axes(base_axes) if init is None else []
    n = len(obs.points_mm)
    off = np.zeros(n) if offset_years is None else as_floats(offset_years)
    if off is None or off.reshape(-1).shape != (n,) or not np.all(np.isfinite(off)):
        raise WoodcamError(f"offset_years must be {n} finite years, one per observation; got "
                           f"{'shape ' + str(off.shape) if off is not None else repr(offset_years)[:60]}")
    off = off.reshape(-1)
    size = np.asarray(size_mm, float)
    centre = size / 2
    L = float(np.linalg.norm(size) / 2)
    rng = np.random.default_rng(seed)
    i_s = np.sort(rng.choice(n, n_search, replace=False)) if n > n_search else np.arange(n)
    i_f = np.sort(rng.choice(n, n_fit, replace=False)) if n > n_fit else np.arange(n)
    tp = np.tan(np.deg2rad(min(tilt_prior_deg, 89.0)))
    # rings per mm: the ring spacing seen on the faces is >= the true width (oblique cuts)
    density = 1.0 / ring_spacing_mm(obs)
    rho0 = float(np.median(np.linalg.norm(obs.points_mm - centre, axis=1))) + L

    def problem(idx, d0, k, m):
        return _StemProblem(obs.points_mm[idx], obs.years[idx] - off[idx], centre, _frame(d0), L, k, m, P, rho0,
                            _prior_sd(k, m, P, rho0, density), tp, curve_prior_mm)

    # every axis' cheapest starts, refined at low order; the best n_final finished at full order
    coarse = []
    if init is not None:  # warm start: one start, the given centreline
        coarse.append((0.0, np.asarray(init.curve, float).T.reshape(-1), np.asarray(init.base_axis, float), None))
    starts = []  # (problem, start, axis) of every base axis, each descent independent of the others
    for d0 in axes:
        prob = problem(i_s, d0, min(K, 2), 0)
        starts += [(prob, th, d0) for _, th in _starts(prob, obs, i_s, size, n_starts)]
    coarse += [(cost, th, d0, prob) for (th, cost), (prob, _, d0)
               in zip(map_processes(lambda s: _refine(s[0], s[1], 20), starts, workers), starts)]
    coarse.sort(key=lambda c: c[0])
    if outward and init is None:  # the finals: the cheapest starts whose time rises away from their pith, if any
        coarse = list(islice((c for c in coarse if _outward(c[3], c[1])), n_final)) or coarse
    finals = map_processes(lambda c: _refine(problem(i_f, c[2], K, M), c[1], 30), coarse[:n_final], workers)
    best = None
    for (th, cost), (_, _, d0, _) in zip(finals, coarse[:n_final]):
        if best is None or cost < best[0]:
            best = (cost, th, d0)
    _, th, d0 = best
    prob = problem(np.arange(n), d0, K, M)
    curve = prob.curve_of(th)
    obs = _relabel(obs, prob, curve)
    prob.years = obs.years - off
    field = _coefficients(prob, curve, StemField(centre, d0, L, curve, K, M, P, np.zeros(0), np.zeros(0), rho0))
    if history:
        field = _growth_history(obs, prob, field, off)
    return field


def _relabel(obs: RingObservations, prob: _StemProblem, curve) -> RingObservations:
    """Move each trace to the year nearest the fit's median on it where they differ by more
    than half a year (a mislabelled trace); one round."""
    r, _ = prob.solve(curve)
    med = _group_medians(r, obs.group, obs.n_groups)
    shift = np.round(np.nan_to_num(med))
    return RingObservations(obs.points_mm, obs.years + shift[obs.group], obs.group, obs.face)


def _coefficients(prob: _StemProblem, curve, f: StemField, targets=None) -> StemField:
    """``(a, e, c)`` at the fitted centreline: the posterior mean under the priors of
    :func:`_prior_sd` (a ridge with a reason per column)."""
    if targets is not None:
        prob = _StemProblem(**{**prob.__dict__, "years": np.asarray(targets, float)})
    _, sol = prob.solve(curve)
    return StemField(f.centre_mm, f.base_axis, f.half_length_mm, curve, f.K, f.M, f.P,
                     sol[f.P:], sol[1:f.P], f.rho0_mm, float(sol[0]))


def _growth_history(obs: RingObservations, prob: _StemProblem, f: StemField, off: np.ndarray) -> StemField:
    """The year-to-year ring width ``h``: as :func:`.radial._fit_growth_history` (levels per
    year shrunk to the year, made increasing, alternated with the coefficients). ``off`` (n,):
    the years the stem does not explain; ``h`` has slope about 1, so a point of year ``y`` sits
    at the level ``h^-1(y) - off``."""
    from scipy.optimize import isotonic_regression

    years, idx, counts = np.unique(obs.years, return_inverse=True, return_counts=True)
    if len(years) < 3:
        return f

    def linear(g: StemField) -> np.ndarray:  # g.linear(obs.points_mm), on the problem's cached design
        return g.offset + prob.design(g.curve)[:, 1:] @ np.concatenate([g.rho_coef, g.coef])

    def levels(g: StemField) -> np.ndarray:
        med = _group_medians(linear(g) + off, idx, len(years))
        lev = (counts * med + RING_HISTORY_PRIOR_POINTS * years) / (counts + RING_HISTORY_PRIOR_POINTS)
        return isotonic_regression(lev, weights=counts).x + np.arange(len(years)) * RING_HISTORY_MIN_STEP

    for _ in range(RING_HISTORY_ROUNDS):
        f = _coefficients(prob, f.curve, f, targets=levels(f)[idx] - off)
    f.history_levels, f.history_years = levels(f), years.astype(float)
    return f


__all__ = ["StemField", "fit_stem"]
