"""The 9-parameter knot model of seed 001 (§3.2, eq. 1-5) in log-centric coordinates.

Log-centric coordinates (seed 001 §3.1): ``theta`` the azimuth around the log centreline
(radians), ``l`` the longitudinal position along the log (mm; the log frame's height ``z``) and
``rho`` the distance from the centreline (mm). Knots are modelled in the *modified* coordinates
``(s, l, rho)`` where ``s = (theta - theta_mean) * rho`` is an arc length (mm, eq. 1) and
``theta_mean`` is the knot's mean azimuth; the three are treated as Cartesian axes, so a knot is
a tube there.

Model (eq. 2-5), with ``g(x; X, alpha, E, L) = alpha * (1 - exp(-E x / max(0, X - x))) + L x``:

* centre curve: ``(s0, l0 + K_l(rho), rho)`` with ``K_l = g(rho; rho_max, alpha_l, E_l, L_l)``;
* radius: ``K_r = g(c; c_max, alpha_r, E_r, L_r)`` where ``c`` is the arc length of the centre
  curve from the pith and ``c_max = c(rho_max)``; the cross-section is an ellipse perpendicular
  to the curve, semi-axis ``K_r`` along ``s`` and ``gamma * K_r`` in the ``(l, rho)`` plane.

The exponential phase ends at ``X`` (``g(X) = alpha + L X``); after it ``g`` is linear.

Bounded reparameterisation (seed 001 describes it, its supplement with the derivation is not
available, so this is our own derivation with the same two constraints):

* ``alpha >= 0`` and ``g`` concave. ``g'' = alpha E X e^{-u} (2 (X - x) - E X) / (X - x)^4``
  (``u = E x / (X - x)``), so for ``alpha > 0`` concavity on ``[0, X]`` holds iff ``E >= 2``.
* Trajectory ``K_l(rho)``: ``phi1`` in [0, 1] maps the end incline angle
  ``beta1 = (2 phi1 - 1) * MAX_INCLINE`` (so ``L_l = tan beta1`` may be negative: drooping
  spruce knots); ``phi0`` in [0, 1] maps the start incline angle between ``beta1`` (straight
  knot) and ``MAX_INCLINE``: ``beta0 = beta1 + phi0 (MAX_INCLINE - beta1)``. With
  ``E_l = 2`` (the smoothest concave curve) ``alpha_l = (tan beta0 - tan beta1) rho_max / 2 >= 0``
  and ``delta_l = alpha_l + L_l rho_max`` (eq. 2) follows.
* Radius ``K_r(c)``: anchored at ``K_r(c_max) = r_max`` (eq. 4); ``psi1`` in [0, 1] maps the end
  slope ``L_r`` between 0 and ``r_max / c_max`` (the largest keeping ``alpha_r >= 0``);
  ``psi0`` in [0, 1] maps the start slope ``L_r + alpha_r E_r / c_max`` between its concave
  minimum ``E_r = 2`` and ``E_r = MAX_RADIUS_EXPONENT``.

The nine parameters (:class:`KnotShape`): ``s0, l0, gamma, rho_max, phi0, phi1, r_max, psi0,
psi1``. ``theta_mean`` is not a parameter: it is the mean azimuth of the knot's points.
Eq. 5 as printed mixes ``c`` and ``rho``; we use ``c`` throughout, as its text says.
"""

from __future__ import annotations

from dataclasses import astuple, dataclass, fields

import numpy as np

from ..errors import WoodcamError
from ..tolerances import KNOT_SURFACE_TOL_MM

#: Largest incline angle of a knot trajectory against the radial direction (rad). 80 degrees:
#: a knot steeper than that would run along the pith, which branches do not do.
MAX_INCLINE = np.deg2rad(80.0)

#: Exponent of the trajectory's exponential phase: 2 is the smallest value that keeps the
#: curve concave (see module docstring), i.e. the smoothest admissible curve.
TRAJECTORY_EXPONENT = 2.0

#: Upper end of the radius exponent ``E_r`` mapped by ``psi0`` (lower end 2, concavity).
MAX_RADIUS_EXPONENT = 40.0

#: Samples of the arc-length table along ``rho`` (trapezoid rule); the curve is smooth, 257
#: samples give arc lengths to < 1e-4 relative on the slopes ``MAX_INCLINE`` allows.
_ARC_SAMPLES = 257

PARAM_NAMES = ("s0_mm", "l0_mm", "gamma", "rho_max_mm", "phi0", "phi1", "r_max_mm", "psi0", "psi1")


@dataclass(frozen=True)
class KnotShape:
    """The nine knot parameters of seed 001 §3.2 (lengths in mm, ratios in [0, 1]).

    Attributes
    ----------
    s0_mm : arc-length offset of the knot centre from ``theta_mean`` (mm, eq. 1).
    l0_mm : longitudinal position of the knot origin on the centreline (mm).
    gamma : ovality, vertical (``l``-plane) over horizontal (``s``) semi-axis, > 0.
    rho_max_mm : end of the trajectory's exponential phase (mm, > 0).
    phi0, phi1 : start / end incline ratios of the trajectory, in [0, 1].
    r_max_mm : knot radius (horizontal semi-axis) at ``rho_max`` (mm, > 0).
    psi0, psi1 : start / end slope ratios of the radius curve, in [0, 1].
    """

    s0_mm: float
    l0_mm: float
    gamma: float
    rho_max_mm: float
    phi0: float
    phi1: float
    r_max_mm: float
    psi0: float
    psi1: float

    def __post_init__(self):
        for name in ("gamma", "rho_max_mm", "r_max_mm"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise WoodcamError(f"{name} must be a finite number > 0; got {v!r}; pass a positive value")
        for name in ("phi0", "phi1", "psi0", "psi1"):
            v = getattr(self, name)
            if not (0.0 <= v <= 1.0):
                raise WoodcamError(f"{name} is an incline ratio and must lie in [0, 1]; got {v!r}; clip it")

    def to_array(self) -> np.ndarray:
        """(9,) float in the order of :data:`PARAM_NAMES`."""
        return np.array(astuple(self), dtype=float)

    @classmethod
    def from_array(cls, a) -> "KnotShape":
        a = np.asarray(a, dtype=float).reshape(-1)
        if a.shape != (9,):
            raise WoodcamError(f"knot parameter vector must have 9 entries {PARAM_NAMES}; got shape {a.shape}")
        return cls(*map(float, a))


def growth_curve(x, x_max, alpha, exponent, slope) -> np.ndarray:
    """Exponential-then-linear curve of eq. 3 / eq. 5, ``(n,)`` for ``x : (n,)`` (mm).

    ``alpha (1 - exp(-E x / max(0, x_max - x))) + L x``; equals ``alpha + L x`` for
    ``x >= x_max`` (the ``max(0, .)`` extension of seed 001).
    """
    x = np.asarray(x, dtype=float)
    d = x_max - x
    pos = d > 0
    e = np.where(pos, np.exp(-exponent * np.where(pos, x, 0.0) / np.where(pos, d, 1.0)), 0.0)
    return alpha * (1.0 - e) + slope * x


def growth_curve_slope(x, x_max, alpha, exponent, slope) -> np.ndarray:
    """Derivative ``d/dx`` of :func:`growth_curve`, ``(n,)``."""
    x = np.asarray(x, dtype=float)
    d = x_max - x
    pos = d > 0
    dd = np.where(pos, d, 1.0)
    e = np.where(pos, np.exp(-exponent * np.where(pos, x, 0.0) / dd), 0.0)
    return np.where(pos, alpha * exponent * x_max * e / dd**2, 0.0) + slope


def trajectory_coefficients(rho_max, phi0, phi1):
    """``(alpha_l, E_l, L_l)`` of eq. 2-3 from the bounded parameters (module docstring)."""
    beta1 = (2.0 * np.asarray(phi1, float) - 1.0) * MAX_INCLINE
    beta0 = beta1 + np.asarray(phi0, float) * (MAX_INCLINE - beta1)
    slope = np.tan(beta1)
    alpha = (np.tan(beta0) - slope) * rho_max / TRAJECTORY_EXPONENT
    return alpha, TRAJECTORY_EXPONENT, slope


def radius_coefficients(r_max, psi0, psi1, c_max):
    """``(alpha_r, E_r, L_r)`` of eq. 4-5 from the bounded parameters (module docstring)."""
    slope = np.asarray(psi1, float) * r_max / c_max
    exponent = 2.0 + np.asarray(psi0, float) * (MAX_RADIUS_EXPONENT - 2.0)
    alpha = r_max - slope * c_max
    return alpha, exponent, slope


@dataclass(frozen=True)
class Knot:
    """One knot: :class:`KnotShape` plus its mean azimuth, evaluated in log-centric coordinates.

    Attributes
    ----------
    params : KnotShape
    theta_mean_rad : float
        Mean azimuth of the knot (rad), the origin of its arc-length coordinate ``s`` (eq. 1).
    """

    params: KnotShape
    theta_mean_rad: float = 0.0

    # -- trajectory -----------------------------------------------------------------------
    def _traj(self):
        p = self.params
        return trajectory_coefficients(p.rho_max_mm, p.phi0, p.phi1)

    def delta_l_mm(self) -> float:
        """``delta_l`` of eq. 2: rise of the centre curve between the pith and ``rho_max`` (mm)."""
        a, _, L = self._traj()
        return float(a + L * self.params.rho_max_mm)

    def height(self, rho_mm) -> np.ndarray:
        """Longitudinal position ``l`` (mm) of the knot centre at ``rho_mm : (n,)`` (eq. 3)."""
        a, E, L = self._traj()
        return self.params.l0_mm + growth_curve(rho_mm, self.params.rho_max_mm, a, E, L)

    def height_slope(self, rho_mm) -> np.ndarray:
        """``dl/drho`` of the centre curve at ``rho_mm : (n,)`` (dimensionless)."""
        a, E, L = self._traj()
        return growth_curve_slope(rho_mm, self.params.rho_max_mm, a, E, L)

    def azimuth(self, rho_mm) -> np.ndarray:
        """Azimuth (rad) of the knot centre at ``rho_mm : (n,)``: ``theta_mean + s0 / rho``.

        The arc offset ``s0`` becomes an angle ``s0 / rho``; it is clipped to +-pi/2 near the
        pith where that ratio would blow up (there the knot is thinner than ``|s0|`` anyway).
        """
        rho = np.maximum(np.asarray(rho_mm, float), 1e-9)
        return self.theta_mean_rad + np.clip(self.params.s0_mm / rho, -np.pi / 2, np.pi / 2)

    def arc_length(self, rho_mm) -> np.ndarray:
        """Arc length ``c`` (mm) of the centre curve from the pith to ``rho_mm : (n,)``."""
        rho = np.asarray(rho_mm, dtype=float)
        top = max(float(np.max(rho, initial=0.0)), self.params.rho_max_mm)
        grid = np.linspace(0.0, top, _ARC_SAMPLES)
        ds = np.sqrt(1.0 + self.height_slope(grid) ** 2)
        c = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(grid))])
        return np.interp(rho, grid, c)

    def c_max_mm(self) -> float:
        """Arc length at ``rho_max`` (``c_max`` of eq. 4)."""
        return float(self.arc_length(np.array([self.params.rho_max_mm]))[0])

    def radius_at_length(self, c_mm) -> np.ndarray:
        """Horizontal semi-axis (mm) at arc length ``c_mm : (n,)`` (eq. 5)."""
        p = self.params
        cm = self.c_max_mm()
        a, E, L = radius_coefficients(p.r_max_mm, p.psi0, p.psi1, cm)
        return growth_curve(c_mm, cm, a, E, L)

    def radius(self, rho_mm) -> np.ndarray:
        """Horizontal knot radius (mm, along ``s``) at distance ``rho_mm : (n,)`` from the pith.

        The vertical semi-axis is ``gamma`` times this (:attr:`KnotShape.gamma`).
        """
        return self.radius_at_length(self.arc_length(rho_mm))

    def centerline_lcs(self, rho_mm) -> np.ndarray:
        """Centre curve as ``(n, 3)`` log-centric ``(theta_rad, l_mm, rho_mm)``."""
        rho = np.asarray(rho_mm, dtype=float).reshape(-1)
        return np.stack([self.azimuth(rho), self.height(rho), rho], axis=1)

    # -- surface --------------------------------------------------------------------------
    def surface_points_slr(self, rho_mm, n_around: int = 16) -> np.ndarray:
        """Points on the knot's elliptic tube, ``(len(rho) * n_around, 3)`` as ``(s, l, rho)`` mm.

        At each centre point the ellipse lies in the plane perpendicular to the centre curve:
        semi-axis ``K_r`` along ``s``, ``gamma K_r`` along the in-plane normal of ``(l, rho)``.
        """
        p = self.params
        rho = np.asarray(rho_mm, dtype=float).reshape(-1, 1)
        k = self.height_slope(rho)
        norm = np.sqrt(1.0 + k**2)
        r = self.radius(rho)
        phi = np.linspace(0.0, 2 * np.pi, n_around, endpoint=False)[None, :]
        u = r * np.cos(phi)
        v = p.gamma * r * np.sin(phi)
        s = p.s0_mm + u
        l = self.height(rho) + v / norm
        rr = rho - v * k / norm
        return np.stack([s, l, rr], axis=-1).reshape(-1, 3)

    def surface_points(self, rho_mm, n_around: int = 16, min_rho_mm: float = 0.5) -> np.ndarray:
        """Like :meth:`surface_points_slr` but as log-centric ``(theta_rad, l_mm, rho_mm)``.

        Near the pith a thick knot wraps around the centreline, where eq. 1 cannot represent
        it: points within ``min_rho_mm`` of the centreline (or beyond it), or more than a
        quarter turn (``|s| > pi rho / 2``) from ``theta_mean``, are dropped, so the result may
        have fewer than ``len(rho) * n_around`` rows. Where the tube bends more sharply than
        its own radius, some cross-section points fall inside neighbouring sections; they are
        not on the knot's surface (the envelope) and are dropped too.
        """
        slr = self.surface_points_slr(rho_mm, n_around)
        slr = slr[(slr[:, 2] > min_rho_mm) & (np.abs(slr[:, 0]) < 0.5 * np.pi * slr[:, 2])]
        slr = slr[self.surface_residuals(slr) > -KNOT_SURFACE_TOL_MM]
        return np.stack([self.theta_mean_rad + slr[:, 0] / slr[:, 2], slr[:, 1], slr[:, 2]], axis=1)

    def surface_residuals(self, points_slr, iterations: int = 6) -> np.ndarray:
        """Signed distances (mm) of ``points_slr : (n, 3)`` ``(s, l, rho)`` to the knot surface.

        Each point is projected onto the centre curve (Gauss-Newton on ``|p - C(rho)|^2``,
        started at the point's own ``rho``); the residual is the distance from that centre
        point minus the ellipse's radius in the point's direction (exact for points on the
        tube, positive outside).
        """
        pts = np.asarray(points_slr, dtype=float)
        p = self.params
        sp, lp, rp = pts[:, 0], pts[:, 1], pts[:, 2]
        # start each projection at the nearest centre sample, 1 mm apart (a point's own
        # rho can sit in the wrong basin where the curve bends sharply near the pith)
        top = max(float(rp.max(initial=0.0)), 1e-6) * 1.05 + 1.0
        grid = np.linspace(0.0, top, int(np.clip(np.ceil(top), 65, 257)))
        d2 = (lp[:, None] - self.height(grid)[None, :]) ** 2 + (rp[:, None] - grid[None, :]) ** 2
        rho = grid[np.argmin(d2, axis=1)]
        for _ in range(iterations):
            k = self.height_slope(rho)
            step = ((lp - self.height(rho)) * k + (rp - rho)) / (1.0 + k**2)
            rho = np.maximum(rho + step, 0.0)
        k = self.height_slope(rho)
        norm = np.sqrt(1.0 + k**2)
        u = sp - p.s0_mm
        dl = lp - self.height(rho)
        v = (dl - (rp - rho) * k) / norm
        dist = np.sqrt(u**2 + v**2)
        r = self.radius(rho)
        cos2 = np.where(dist > 0, (u / np.where(dist > 0, dist, 1.0)) ** 2, 1.0)
        r_dir = r / np.sqrt(cos2 + (1.0 - cos2) / p.gamma**2)
        return dist - r_dir


def to_slr(points_lcs, theta_mean_rad: float | None = None):
    """Log-centric ``(theta, l, rho)`` ``(n, 3)`` -> modified ``(s, l, rho)`` and ``theta_mean``.

    ``theta_mean`` defaults to the circular mean of the points' azimuths (eq. 1).
    """
    p = np.asarray(points_lcs, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise WoodcamError(f"points_lcs must have shape (n, 3) as (theta_rad, l_mm, rho_mm); got {p.shape}")
    if theta_mean_rad is None:
        theta_mean_rad = float(np.arctan2(np.sin(p[:, 0]).mean(), np.cos(p[:, 0]).mean()))
    dtheta = np.angle(np.exp(1j * (p[:, 0] - theta_mean_rad)))
    return np.stack([dtheta * p[:, 2], p[:, 1], p[:, 2]], axis=1), theta_mean_rad


def param_field_names() -> tuple[str, ...]:
    """Names of the nine parameters, in vector order."""
    return tuple(f.name for f in fields(KnotShape))
