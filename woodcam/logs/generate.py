"""Random logs with known insides (seed 001 §4.2-4.3 "Generation").

:func:`generate_log` draws a :class:`GeneratedLog`: a Chebyshev centreline, a heightmap surface
(thickness eq. 6 + Fourier x Chebyshev base + knot bumps eq. 7-9 + Gabor grain) and knots of the
9-parameter model (:mod:`.knot`) grouped in whorls. Knot parameters follow the compound Gaussian
of eq. 10 at three levels (:class:`CompoundGaussian`): a log draws its own mean, each whorl draws
its mean around the log's, and the knots of a whorl scatter around the whorl's mean with the
covariance ``(sigma sigma^T) o P``. Knots of one whorl are therefore alike and whorls differ.
Distributions live in the unconstrained coordinates of :func:`.fit.params_to_unconstrained`
(log for lengths and ovality, logit for the incline ratios), so every draw satisfies the
model's constraints (``alpha >= 0``, concave curves).

Everything is in the log frame, mm: ``z`` (= log-centric ``l``) along the log from 0 to
``length_mm``, the centreline at ``(x(z), y(z))``, azimuth ``theta`` from ``+x`` towards ``+y``.
The same ``seed`` gives the identical log.

Default statistics (:data:`SPRUCE`) and their sources. The reference is the CT-measured
Norway spruce log ``Gran_1`` (Larsson et al. 2022, ``shared/data/trees``: 108 knots in 36
whorls over 4 m), whose knots we fitted with :func:`.fit.fit_gran_knots` (mean RMSE 1.28 mm,
knot origins within 1.5 mm of the data's):

* knot parameter means follow the medians of those fits where they are well identified: the
  end incline ``phi1`` (median 0.434, i.e. -11 degrees: this spruce's knots droop), a nearly
  straight start (``phi0`` median 0.08; we use 0.1), the ovality (median 0.88) and a steep
  start of the radius curve (``psi0`` mostly on its upper bound; we use 0.88). The raw
  spreads of the fits are not usable as they are: for nearly straight knots ``rho_max``
  hardly matters (fitted 1-580 mm) and size trades off between ``r_max``, ``rho_max`` and
  ``psi1``, so their fitted spreads are mostly non-identifiability.
  :func:`knot_stats_from_fits` gives those raw estimates; the defaults instead take
  ``rho_max`` = 40 mm, ``r_max`` = 6 mm and ``psi1`` = 0.4, which end a typical knot with the
  fits' median end radius (13-14 mm), and spreads chosen by eye so generated knots look like
  Gran_1's. Whorl-to-whorl spread exceeds the within-whorl spread, as seed 001 §4.2 intends
  (knots of a whorl are alike); in Gran_1 the whorl-to-whorl spread of size is large too
  (0.9 in ``log r_max``) but its within-whorl spread is larger still (1.1), partly from the
  trade-offs above. Log-to-log spread: half the whorl-to-whorl spread (one log cannot tell;
  an assumption). Knot radius at the surface is capped at ``max_knot_radius_mm`` by scaling
  ``r_max`` (the radius curve is linear in it).
* whorls: Gran_1's whorl spacing is 110 +- 39 mm with 3.0 knots per whorl; we use
  110 +- 40 mm and 1 + Poisson(2) knots (~108 knots per 4 m).
* radius 125 +- 15 mm and taper -0.004 mm/mm: Gran_1 (mean radius 126 mm at the butt, 120 mm
  at the top after its butt swell) and the common ~1 cm per m diameter taper of sawlogs.
* base-shape and centreline coefficient spreads: magnitudes of a 10 x 10 base fit
  (RMSE 2.4 mm) and a 4-term centreline fit to Gran_1 (``fit_surface_base``,
  ``fit_centreline``).
* death: a knot dies at a per-whorl fraction ``N(0.85, 0.25)`` (clipped to [0.3, 1]) of its
  length (a whorl's branches share the crown's history); Gran_1's death fraction has median
  0.78 and 38 % of its knots live to their end. A tenth of the whorls are overgrown, their
  knots ending at ``U(0.45, 0.8)`` of the way to the surface (9 % of Gran_1's knots end
  before 100 mm). Only knots that reach the surface make a bump.
* surface bumps (eq. 7-9) and grain: chosen by eye (no heightmap of a debarked log here).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from .._checks import check_number, real_numbers
from .._repr import summary_repr
from .._types import ArrayLike
from ..errors import WoodcamError
from ..fields.skeleton import KNOT_TABLE_SAMPLES, BranchStrand, LogSkeleton
from .centreline import Centreline
from .fit import unconstrained_to_params
from .knot import Knot, KnotShape
from .surface import SurfaceBase, SurfaceKnot, Thickness, add_surface_knots, gabor_noise, heightmap_axes

#: Order of the generated knot parameters (unconstrained; ``l0`` comes from the whorl).
GEN_PARAM_NAMES = ("s0_mm", "log_gamma", "log_rho_max", "logit_phi0", "logit_phi1", "log_r_max",
                   "logit_psi0", "logit_psi1")


@dataclass(frozen=True)
class CompoundGaussian:
    """Three-level compound Gaussian of seed 001 eq. 10 over a parameter vector ``(p,)``.

    ``mu_log ~ N(mean, sd_log^2)``; ``mu_whorl ~ N(mu_log, sd_whorl^2)``; the within-whorl SD
    of a log is ``sigma = sd_knot * exp(N(0, sd_knot_logsd^2))`` (the "sigma ~ N(mu_2, sigma_2)"
    level, kept positive); knots ``X ~ N(mu_whorl, (sigma sigma^T) o corr)``.
    """

    mean: np.ndarray
    sd_log: np.ndarray
    sd_whorl: np.ndarray
    sd_knot: np.ndarray
    corr: np.ndarray
    sd_knot_logsd: float = 0.15

    def __post_init__(self):
        p = len(self.mean)
        for name in ("sd_log", "sd_whorl", "sd_knot"):
            v = np.asarray(getattr(self, name), float)
            if v.shape != (p,) or np.any(v < 0):
                raise WoodcamError(f"{name} must be ({p},) non-negative like mean; got {v!r}")
        c = np.asarray(self.corr, float)
        if c.shape != (p, p) or not np.allclose(c, c.T) or np.any(np.linalg.eigvalsh(c) < -1e-9):
            raise WoodcamError(f"corr must be a symmetric positive semi-definite ({p}, {p}) matrix")

    def sample_log(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``(mu_log (p,), sigma_log (p,))`` for one log."""
        mu = np.asarray(self.mean) + np.asarray(self.sd_log) * rng.standard_normal(len(self.mean))
        sig = np.asarray(self.sd_knot) * np.exp(self.sd_knot_logsd * rng.standard_normal(len(self.mean)))
        return mu, sig

    def sample_whorl(self, rng: np.random.Generator, mu_log) -> np.ndarray:
        """Mean ``(p,)`` of one whorl of a log with mean ``mu_log``."""
        return mu_log + np.asarray(self.sd_whorl) * rng.standard_normal(len(mu_log))

    def sample_knots(self, rng: np.random.Generator, mu_whorl, sigma, n: int) -> np.ndarray:
        """``(n, p)`` knots of one whorl: ``N(mu_whorl, (sigma sigma^T) o corr)``."""
        cov = np.outer(sigma, sigma) * np.asarray(self.corr)
        w, v = np.linalg.eigh(cov)
        L = v * np.sqrt(np.clip(w, 0, None))
        return mu_whorl + rng.standard_normal((n, len(mu_whorl))) @ L.T


def group_whorls(start_heights_mm, gap_mm: float = 40.0) -> np.ndarray:
    """Whorl index ``(n,)`` of knots by start height: a new whorl where sorted heights jump > ``gap_mm``."""
    h = np.asarray(start_heights_mm, dtype=float).reshape(-1)
    order = np.argsort(h)
    ids = np.empty(len(h), dtype=int)
    ids[order] = np.concatenate([[0], np.cumsum(np.diff(h[order]) > gap_mm)]) if len(h) else []
    return ids


def knot_stats_from_fits(params, whorl, *, shrink: float = 0.5, logit_clip: float = 4.0) -> CompoundGaussian:
    """Estimate the knot-level :class:`CompoundGaussian` from fitted knots of one log (seed 001 §4.2).

    Parameters
    ----------
    params : (n, 9) float
        :class:`KnotShape` vectors (e.g. from :func:`.fit.fit_knot`).
    whorl : (n,) int
        Whorl index of each knot (:func:`group_whorls`).
    shrink : float
        Weight of the identity in the within-whorl correlation (few knots per whorl make the
        raw estimate noisy).
    logit_clip : float
        Ratios fitted on their bounds are pulled to ``|logit| <= logit_clip`` first.

    Within-whorl SD is pooled over whorls with >= 2 knots; whorl-to-whorl SD is the SD of the
    whorl means less the within-whorl part; log-to-log SD is not estimable from one log and is
    set to half the whorl-to-whorl SD (an assumption).
    """
    from .fit import params_to_unconstrained

    P = np.asarray(params, dtype=float)
    w = np.asarray(whorl, dtype=int)
    z = np.array([params_to_unconstrained(KnotShape.from_array(p)) for p in P])
    z = np.delete(z, 1, axis=1)  # drop l0: it comes from the whorl height
    z[:, [3, 4, 6, 7]] = np.clip(z[:, [3, 4, 6, 7]], -logit_clip, logit_clip)
    ids = np.unique(w)
    means = np.array([z[w == i].mean(0) for i in ids])
    counts = np.array([(w == i).sum() for i in ids])
    resid = np.concatenate([z[w == i] - z[w == i].mean(0) for i in ids if (w == i).sum() >= 2])
    dof = int(sum(c - 1 for c in counts if c >= 2))
    sd_knot = np.sqrt((resid**2).sum(0) / max(dof, 1))
    between = means.var(0, ddof=1) - sd_knot**2 * np.mean(1.0 / counts)
    sd_whorl = np.sqrt(np.clip(between, 0.0, None))
    sd = resid.std(0)
    ok = sd > 1e-12
    corr = np.eye(z.shape[1])
    if len(resid) > 2 and ok.sum() > 1:
        r = resid[:, ok] / sd[ok]
        corr[np.ix_(ok, ok)] = r.T @ r / len(r)
    corr = (1 - shrink) * corr + shrink * np.eye(z.shape[1])
    np.fill_diagonal(corr, 1.0)
    return CompoundGaussian(z.mean(0), 0.5 * sd_whorl, sd_whorl, sd_knot, corr)


@dataclass(frozen=True)
class LogStats:
    """Statistics of a species' logs used by :func:`generate_log` (see module docstring)."""

    knots: CompoundGaussian
    radius_mm: tuple[float, float] = (125.0, 15.0)          # butt radius mean, SD
    taper: tuple[float, float] = (-0.004, 0.0015)           # mm of radius per mm of length
    whorl_spacing_mm: tuple[float, float] = (110.0, 40.0)   # mean, SD; clipped at 40 mm
    knots_per_whorl: float = 2.0                            # 1 + Poisson(this), at most 8
    l0_jitter_mm: float = 8.0                               # knot start height around its whorl
    azimuth_jitter_rad: float = 0.3                         # around the even split of a whorl
    whorl_bulge_mm: tuple[float, float] = (1.5, 0.7)        # eq. 6 alpha_i (mean, SD), >= 0
    whorl_bulge_width_mm: tuple[float, float] = (50.0, 10.0)  # eq. 6 gamma_i
    overgrown_fraction: float = 0.1
    overgrown_end: tuple[float, float] = (0.45, 0.8)        # uniform fraction of the way out
    max_knot_radius_mm: float = 30.0
    death_fraction: tuple[float, float] = (0.85, 0.25)      # clipped to [0.3, 1]
    centreline_sd_mm: tuple[float, ...] = (8.0, 3.0, 2.0, 0.6)
    fourier_sd_mm: tuple[float, ...] = (0.0, 3.5, 3.5, 1.5, 1.5, 0.6, 0.6, 0.3, 0.3, 0.2)
    cheb_decay: tuple[float, ...] = (1.0, 0.8, 0.5, 0.35, 0.25, 0.2, 0.15, 0.12, 0.1, 0.08)
    bump_alpha: tuple[float, float] = (0.3, 0.5)            # uniform range, both axes
    bump_m: tuple[float, float] = (2.0, 4.0)                # uniform range
    bump_height_frac: tuple[float, float] = (0.08, 0.2)     # bump height / knot radius, uniform
    grain_amplitude_mm: float = 0.25
    grain_wavelength_mm: float = 10.0


def _spruce_knot_stats() -> CompoundGaussian:
    # Order GEN_PARAM_NAMES; sources in the module docstring. Ratios as logits.
    def logit(p):
        return float(np.log(p / (1 - p)))

    mean = np.array([0.0, np.log(0.88), np.log(40.0), logit(0.1), logit(0.434), np.log(6.0), logit(0.88), logit(0.4)])
    sd_whorl = np.array([0.0, 0.12, 0.25, 0.5, 0.2, 0.4, 0.5, 0.5])
    sd_knot = np.array([0.0, 0.06, 0.15, 0.3, 0.1, 0.2, 0.3, 0.3])
    return CompoundGaussian(mean, 0.5 * sd_whorl, sd_whorl, sd_knot, np.eye(8))


#: Default statistics: Norway spruce sawlogs (sources in the module docstring).
SPRUCE = LogStats(knots=_spruce_knot_stats())


@dataclass(frozen=True)
class GeneratedKnot:
    """A knot of a generated log, with what a growth-field converter needs (log frame, mm).

    Attributes
    ----------
    knot : Knot
        The 9-parameter model (log-centric).
    whorl : int
        Index of its whorl (0 at the butt).
    end_mm : float
        Distance from the pith where the knot ends (on the surface, or inside if overgrown).
    death_mm : float
        Distance from the pith where the branch died (``<= end_mm``).
    reaches_surface : bool
    centreline : Centreline
        The log's centreline (to place the knot in the log frame).
    """

    knot: Knot
    whorl: int
    end_mm: float
    death_mm: float
    reaches_surface: bool
    centreline: Centreline = field(repr=False)

    @property
    def start_height_mm(self) -> float:
        """Height where the knot leaves the pith (``l0``)."""
        return self.knot.params.l0_mm

    @property
    def start_azimuth_rad(self) -> float:
        """Azimuth (rad) where the knot leaves the pith: its mean azimuth (generated knots have
        ``s0 = 0``, so the azimuth is the same all along the knot)."""
        return self.knot.theta_mean_rad

    def height(self, rho_mm) -> np.ndarray:
        """Height (mm) of the knot centre at distance ``rho_mm : (n,)`` from the pith."""
        return self.knot.height(rho_mm)

    def azimuth(self, rho_mm) -> np.ndarray:
        """Azimuth (rad) of the knot centre at ``rho_mm : (n,)`` (constant: no twist)."""
        return self.knot.azimuth(rho_mm)

    def radius(self, rho_mm) -> np.ndarray:
        """Knot radius (mm, horizontal semi-axis) at ``rho_mm : (n,)``; vertical is ``gamma`` times it."""
        return self.knot.radius(rho_mm)

    def vertical_radius(self, rho_mm) -> np.ndarray:
        """Vertical semi-axis (mm) at ``rho_mm : (n,)``."""
        return self.knot.params.gamma * self.knot.radius(rho_mm)

    def centerline(self, rho_mm) -> np.ndarray:
        """Knot centre points ``(n, 3)`` in the log frame (mm) at ``rho_mm : (n,)`` from the pith."""
        return self.centreline.to_log_frame(self.knot.centerline_lcs(rho_mm))


@dataclass(frozen=True)
class GeneratedLog:
    """A generated log (module docstring for frames and units).

    Attributes
    ----------
    length_mm : float
    centreline : Centreline
    thickness : Thickness
        Mean radius along the log (eq. 6).
    base : SurfaceBase
        Out-of-round shape (its Fourier constant column is zero: the mean is ``thickness``).
    knots : tuple[GeneratedKnot, ...]
    surface_knots : tuple[SurfaceKnot, ...]
    heightmap_mm : (n_l, n_theta) float
        Full surface radius on the grid of :func:`.surface.heightmap_axes`.
    seed : int or None
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    length_mm: float
    centreline: Centreline
    thickness: Thickness
    base: SurfaceBase
    knots: tuple[GeneratedKnot, ...]
    surface_knots: tuple[SurfaceKnot, ...]
    heightmap_mm: np.ndarray = field(repr=False)
    seed: int | None = None

    @property
    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Heights ``(n_l,)`` mm and azimuths ``(n_theta,)`` rad of :attr:`heightmap_mm`."""
        return heightmap_axes(self.length_mm, *self.heightmap_mm.shape)

    def to_skeleton(self, *, z_step_mm: float = 5.0, azimuths: int = 360,
                    samples: int = KNOT_TABLE_SAMPLES, name: str = "generated") -> LogSkeleton:
        """This log as the knot field's input (:class:`woodcam.fields.skeleton.LogSkeleton`).

        The pith is sampled every ``z_step_mm``, the outer radius on ``azimuths`` directions,
        each knot's axis and diameter on ``samples`` pith distances (denser near the pith).
        The knot model there is round: a knot's diameter is that of the circle of equal area,
        ``2 radius sqrt(gamma)`` (``gamma``: vertical over horizontal semi-axis). Both share the
        log frame (``z`` along the log, azimuth counter-clockwise from ``+x``, mm).
        """
        L = float(self.length_mm)
        z = np.arange(0.0, L + 0.5 * z_step_mm, z_step_mm)
        z[-1] = min(z[-1], L)
        pith = np.asarray(self.centreline_points(z), float)[:, :2]
        th = 2 * np.pi * np.arange(azimuths) / azimuths
        zz, tt = np.meshgrid(z, th, indexing="ij")
        radii = np.asarray(self.outer_radius(zz.ravel(), tt.ravel()), float).reshape(zz.shape)
        strands = []
        for k in self.knots:
            end = float(k.end_mm)
            r = max(end, 1.0) * np.linspace(0.0, 1.0, samples) ** 2
            rho = np.maximum(r, 1e-6)
            hgt = np.asarray(k.height(rho), float)
            az = np.asarray(k.azimuth(rho), float)
            diam = 2.0 * np.asarray(k.radius(rho), float) * np.sqrt(max(float(k.knot.params.gamma), 0.0))
            diam[0] = 0.0
            strands.append(BranchStrand(float(hgt[0]), float(az[0]), r, hgt - hgt[0], az - az[0],
                                        np.maximum(diam, 0.0), end, float(k.death_mm)))
        return LogSkeleton(z, pith, radii, tuple(strands), name)

    def base_radius(self, l_mm: ArrayLike, theta_rad: ArrayLike) -> np.ndarray:
        """Smooth outer radius ``(n,)`` mm (thickness + base shape, no bumps or grain)."""
        l = real_numbers(l_mm, "l_mm").reshape(-1)
        t = real_numbers(theta_rad, "theta_rad").reshape(-1)
        return self.thickness(l) + self.base.at(l, t)

    def outer_radius(self, l_mm: ArrayLike, theta_rad: ArrayLike,
                     detail: Literal["full", "base"] = "full") -> np.ndarray:
        """Outer radius ``(n,)`` mm at ``(l_mm[i], theta_rad[i])``, measured from the centreline.

        ``detail="full"`` interpolates the heightmap bilinearly (periodic in azimuth);
        ``"base"`` is the smooth :meth:`base_radius`.
        """
        if detail == "base":
            return self.base_radius(l_mm, theta_rad)
        if detail != "full":
            raise WoodcamError(f"detail must be 'full' or 'base'; got {detail!r}")
        # None or NaN was cast to a height-map index (numpy's RuntimeWarning and another cell)
        l = real_numbers(l_mm, "l_mm", finite=True).reshape(-1)
        t = real_numbers(theta_rad, "theta_rad", finite=True).reshape(-1)
        n_l, n_t = self.heightmap_mm.shape
        fi = np.clip(l / self.length_mm * (n_l - 1), 0, n_l - 1 - 1e-9)
        fj = np.mod(t, 2 * np.pi) / (2 * np.pi) * n_t
        i0, j0 = np.floor(fi).astype(int), np.floor(fj).astype(int) % n_t
        i1, j1 = np.minimum(i0 + 1, n_l - 1), (j0 + 1) % n_t
        wi, wj = fi - np.floor(fi), fj - np.floor(fj)
        h = self.heightmap_mm
        return ((1 - wi) * ((1 - wj) * h[i0, j0] + wj * h[i0, j1]) + wi * ((1 - wj) * h[i1, j0] + wj * h[i1, j1]))

    def centreline_points(self, l_mm: ArrayLike) -> np.ndarray:
        """Pith points ``(n, 3)`` in the log frame at heights ``l_mm : (n,)``."""
        return self.centreline.points(l_mm)


def _surface_distances(knots: list[Knot], base_radius, iterations: int = 6) -> np.ndarray:
    """Distances ``(k,)`` from the pith where each knot's centre meets the smooth surface.

    Fixed-point iteration ``rho <- R(l(rho), theta)``: converges because the radius changes
    slowly along the log (|dR/dl| << 1/|dl/drho|).
    """
    theta = np.array([k.theta_mean_rad for k in knots])
    rho = base_radius(np.array([k.params.l0_mm for k in knots]), theta)
    for _ in range(iterations):
        l = np.array([k.height(rho[i:i + 1])[0] for i, k in enumerate(knots)])
        rho = base_radius(l, theta)
    return rho


def generate_log(seed: int | np.random.Generator | None = 0, *, length_mm: float = 4000.0,
                 stats: LogStats = SPRUCE, heightmap_shape: tuple[int, int] | None = None) -> GeneratedLog:
    """Draw a random log (seed 001 §4); same integer ``seed`` -> identical log.

    Parameters
    ----------
    seed : int, numpy Generator or None
    length_mm : float
        Log length (mm), > 100.
    stats : LogStats
        Distributions; default :data:`SPRUCE`.
    heightmap_shape : (n_l, n_theta), optional
        Heightmap grid; default one row per 5 mm and one column per degree.
    """
    if isinstance(length_mm, bool) or not isinstance(length_mm, numbers.Real) \
            or not (np.isfinite(length_mm) and length_mm > 100):  # '100' was np.isfinite's TypeError
        raise WoodcamError(f"length_mm must be a number > 100 mm; got {length_mm!r}; e.g. length_mm=4000")
    if not isinstance(stats, LogStats):  # None or a dict was an AttributeError mid-way
        raise WoodcamError(f"stats must be a woodcam.logs.generate.LogStats; got {type(stats).__name__}; "
                           "leave it out for the spruce statistics, or replace(SPRUCE, ...) to change some")
    if not (seed is None or isinstance(seed, np.random.Generator)):  # "a" was numpy's TypeError
        seed = check_number(seed, "generate_log: seed", lo=0, integer=True,
                            fix="pass an integer >= 0 (same seed, same log), a numpy Generator or None")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    if heightmap_shape is None:
        n_l, n_t = int(np.ceil(length_mm / 5.0)) + 1, 360
    else:  # (10,) was an unpacking ValueError, 'ab' float()'s
        hs = tuple(heightmap_shape) if isinstance(heightmap_shape, (tuple, list, np.ndarray)) else ()
        if len(hs) != 2 or not all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in hs):
            raise WoodcamError(f"heightmap_shape must be two whole counts (n_l, n_theta) or None; got "
                               f"{heightmap_shape!r}; e.g. (801, 360)")
        n_l, n_t = int(hs[0]), int(hs[1])
    from ..limits import check_grid

    check_grid((n_l, n_t), "the log's surface height map", fix="generate a shorter log (length_mm)")
    if n_l < 10 or n_t < 16:
        raise WoodcamError(f"heightmap_shape must be at least (10, 16); got {(n_l, n_t)}")
    l_ax, t_ax = heightmap_axes(length_mm, n_l, n_t)

    # log level
    r0 = float(np.clip(rng.normal(*stats.radius_mm), 40.0, 400.0))
    taper = float(rng.normal(*stats.taper))
    csd = np.asarray(stats.centreline_sd_mm)
    centreline = Centreline(length_mm, csd * rng.standard_normal(len(csd)), csd * rng.standard_normal(len(csd)))
    fsd = np.asarray(stats.fourier_sd_mm)[None, :] * np.asarray(stats.cheb_decay)[:, None]
    base = SurfaceBase(length_mm, fsd * rng.standard_normal(fsd.shape))
    mu_log, sigma_log = stats.knots.sample_log(rng)

    # whorls
    heights = []
    h = rng.uniform(0.2, 1.0) * stats.whorl_spacing_mm[0]
    while h < length_mm - 20.0:
        heights.append(h)
        h += max(rng.normal(*stats.whorl_spacing_mm), 40.0)
    heights = np.array(heights)
    nw = len(heights)
    bulge = np.abs(rng.normal(*stats.whorl_bulge_mm, size=nw))
    width = np.clip(rng.normal(*stats.whorl_bulge_width_mm, size=nw), 10.0, None)
    shift = rng.normal(0.0, 10.0, size=nw)
    thickness = Thickness(taper, r0, heights, bulge, shift, width)

    def base_radius(l, t):
        return thickness(l) + base.at(l, t)

    drawn: list[tuple[Knot, int, bool, float, float]] = []
    for w, hw in enumerate(heights):
        n = int(min(1 + rng.poisson(stats.knots_per_whorl), 8))
        mu_w = stats.knots.sample_whorl(rng, mu_log)
        z = stats.knots.sample_knots(rng, mu_w, sigma_log, n)
        az0 = rng.uniform(0, 2 * np.pi)
        az = az0 + 2 * np.pi * np.arange(n) / n + rng.normal(0, stats.azimuth_jitter_rad, n)
        l0 = hw + rng.normal(0, stats.l0_jitter_mm, n)
        overgrown = bool(rng.uniform() < stats.overgrown_fraction)
        end_frac = rng.uniform(*stats.overgrown_end) if overgrown else 1.0
        death_frac = float(np.clip(rng.normal(*stats.death_fraction), 0.3, 1.0))
        for i in range(n):  # s0 = 0: the knot's azimuth is its drawn azimuth (z[:, 0] unused)
            p = unconstrained_to_params(np.r_[0.0, l0[i], z[i, 1:]])
            drawn.append((Knot(p, float(np.mod(az[i], 2 * np.pi))), w, overgrown, end_frac, death_frac))
    rho_s = _surface_distances([d[0] for d in drawn], base_radius) if drawn else np.zeros(0)
    for i, ((k, *rest), r) in enumerate(zip(drawn, rho_s)):
        r_end = float(k.radius(np.array([r]))[0])
        if r_end > stats.max_knot_radius_mm:  # cap: K_r is linear in r_max
            p = k.params
            k = Knot(replace(p, r_max_mm=p.r_max_mm * stats.max_knot_radius_mm / r_end), k.theta_mean_rad)
            drawn[i] = (k, *rest)
    knots = [GeneratedKnot(k, w, float(r * ef), float(r * ef * df), not og, centreline)
             for (k, w, og, ef, df), r in zip(drawn, rho_s)]

    # surface: thickness + base + bumps + grain
    hm = thickness(l_ax)[:, None] + base.grid(l_ax, t_ax)
    bumps = []
    for gk in knots:
        if not gk.reaches_surface:
            continue
        rho = np.array([gk.end_mm])
        lk = float(gk.height(rho)[0])
        if not (0.0 <= lk <= length_mm):
            continue
        r = float(gk.radius(rho)[0])
        stretch = float(np.sqrt(1 + gk.knot.height_slope(rho)[0] ** 2))
        a_l, a_s = rng.uniform(*stats.bump_alpha, size=2)
        bumps.append(SurfaceKnot(lk, float(gk.azimuth(rho)[0]), gk.knot.params.gamma * r * stretch, r,
                                 float(a_l), float(a_s), float(rng.uniform(*stats.bump_m)),
                                 float(r * rng.uniform(*stats.bump_height_frac))))
    hm = add_surface_knots(hm, l_ax, t_ax, bumps, arc_radius_mm=r0)
    ds = 2 * np.pi * r0 / n_t
    hm += gabor_noise(n_l, n_t, l_ax[1] - l_ax[0], ds, rng, wavelength_mm=stats.grain_wavelength_mm,
                      amplitude_mm=stats.grain_amplitude_mm)
    return GeneratedLog(float(length_mm), centreline, thickness, base, tuple(knots), tuple(bumps), hm,
                        seed if isinstance(seed, (int, np.integer)) else None)
