"""Log surface as a heightmap in log-centric coordinates (seed 001 §3.4, eq. 6-9).

A heightmap ``radius_mm : (n_l, n_theta) float`` gives the distance (mm) from the centreline
to the log surface at heights ``l_i = i * length / (n_l - 1)`` (both ends included) and azimuths
``theta_j = 2 pi j / n_theta`` (rad, ``theta = 0`` along the log frame's ``+x``, growing
towards ``+y``; no duplicated column). Its parts, from coarse to fine:

* base shape: each row a Fourier series in ``theta`` with ``n_fourier`` terms
  ``1, cos t, sin t, cos 2t, sin 2t, ...``, whose coefficients vary along ``l`` as Chebyshev
  series with ``n_cheb`` terms (:class:`SurfaceBase`, ``n_cheb x n_fourier`` numbers);
* log thickness (eq. 6): mean radius per height, a line plus a Gaussian bulge at every knot
  cluster (:class:`Thickness`);
* surface knots: a difference of Gaussians (eq. 7-9) where a knot reaches the surface
  (:class:`SurfaceKnot`);
* grain: multi-octave Gabor noise with its ridges along the log (:func:`gabor_noise`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C
from scipy.optimize import least_squares

from ..errors import WoodcamError
from .._types import ArrayLike


def heightmap_axes(length_mm: float, n_l: int, n_theta: int) -> tuple[np.ndarray, np.ndarray]:
    """Heights ``(n_l,)`` mm and azimuths ``(n_theta,)`` rad of a heightmap grid (module docstring)."""
    return np.linspace(0.0, length_mm, n_l), 2 * np.pi * np.arange(n_theta) / n_theta


def fourier_basis(theta_rad, n_fourier: int) -> np.ndarray:
    """Real Fourier basis ``(len(theta), n_fourier)``: ``1, cos t, sin t, cos 2t, sin 2t, ...``."""
    t = np.asarray(theta_rad, dtype=float).reshape(-1)
    cols = [np.ones_like(t)]
    for k in range(1, n_fourier):
        h = (k + 1) // 2
        cols.append(np.cos(h * t) if k % 2 else np.sin(h * t))
    return np.stack(cols, axis=1)


def chebyshev_basis(l_mm, length_mm: float, n_cheb: int) -> np.ndarray:
    """Chebyshev basis ``(len(l), n_cheb)`` in ``u = 2 l / length - 1``."""
    u = 2.0 * np.asarray(l_mm, dtype=float).reshape(-1) / length_mm - 1.0
    return C.chebvander(u, n_cheb - 1)


@dataclass(frozen=True)
class SurfaceBase:
    """Base shape: ``radius(l, t) = sum_jk coef[j, k] T_j(u(l)) F_k(t)`` (seed 001 §3.4).

    Attributes
    ----------
    length_mm : float
    coef : (n_cheb, n_fourier) float, mm
    """

    length_mm: float
    coef: np.ndarray

    def __post_init__(self):
        c = np.asarray(self.coef, dtype=float)
        if c.ndim != 2:
            raise WoodcamError(f"coef must have shape (n_cheb, n_fourier); got {c.shape}")
        object.__setattr__(self, "coef", c)

    def grid(self, l_mm, theta_rad) -> np.ndarray:
        """Radius ``(len(l), len(theta))`` mm on the grid ``l_mm x theta_rad``."""
        m, n = self.coef.shape
        return chebyshev_basis(l_mm, self.length_mm, m) @ self.coef @ fourier_basis(theta_rad, n).T

    def at(self, l_mm, theta_rad) -> np.ndarray:
        """Radius ``(n,)`` mm at the point pairs ``(l_mm[i], theta_rad[i])``."""
        m, n = self.coef.shape
        T = chebyshev_basis(l_mm, self.length_mm, m)
        F = fourier_basis(theta_rad, n)
        return np.einsum("ij,jk,ik->i", T, self.coef, F)


def fit_surface_base(radius_mm: ArrayLike, l_mm: ArrayLike, theta_rad: ArrayLike, *,
                     n_fourier: int = 10, n_cheb: int = 10,
                     length_mm: float | None = None) -> SurfaceBase:
    """Fit the base shape to a heightmap in the two steps of seed 001 §4.3.

    Each row ``radius_mm[i, :]`` is least-squares fitted with ``n_fourier`` Fourier terms, then
    each coefficient's curve along ``l`` with ``n_cheb`` Chebyshev terms. Both steps are linear,
    so a heightmap made by a :class:`SurfaceBase` of the same sizes is recovered exactly.

    ``radius_mm`` is ``(n_l, n_theta)`` mm, sampled at heights ``l_mm (n_l,)`` along the log
    and azimuths ``theta_rad (n_theta,)``; ``length_mm``: the log's length the Chebyshev
    variable spans (default ``max(l_mm)``).
    """
    h = np.asarray(radius_mm, dtype=float)
    l = np.asarray(l_mm, dtype=float).reshape(-1)
    t = np.asarray(theta_rad, dtype=float).reshape(-1)
    if h.shape != (len(l), len(t)):
        raise WoodcamError(f"radius_mm must have shape (len(l_mm), len(theta_rad)) = {(len(l), len(t))}; got {h.shape}")
    if n_fourier > len(t) or n_cheb > len(l):
        raise WoodcamError(f"n_fourier <= {len(t)} and n_cheb <= {len(l)} are needed; got {n_fourier}, {n_cheb}")
    length = float(l.max() if length_mm is None else length_mm)
    rows, *_ = np.linalg.lstsq(fourier_basis(t, n_fourier), h.T, rcond=None)  # (n_fourier, n_l)
    coef, *_ = np.linalg.lstsq(chebyshev_basis(l, length, n_cheb), rows.T, rcond=None)
    return SurfaceBase(length, coef)


@dataclass(frozen=True)
class Thickness:
    """Mean radius along the log, eq. 6: ``a l + b + sum_i alpha_i exp(-(l - (c_i + beta_i))^2 / (2 gamma_i^2))``.

    Attributes
    ----------
    a : float, mm/mm (taper: negative when the log thins towards the top)
    b : float, mm (radius at ``l = 0``)
    centres_mm, alpha_mm, beta_mm, gamma_mm : (k,) float
        Knot-cluster heights ``c_i`` and their bulges' height, shift and width.
    """

    a: float
    b: float
    centres_mm: np.ndarray
    alpha_mm: np.ndarray
    beta_mm: np.ndarray
    gamma_mm: np.ndarray

    def __call__(self, l_mm) -> np.ndarray:
        l = np.asarray(l_mm, dtype=float).reshape(-1, 1)
        c = np.asarray(self.centres_mm, float) + np.asarray(self.beta_mm, float)
        g = np.exp(-((l - c) ** 2) / (2 * np.asarray(self.gamma_mm, float) ** 2))
        return self.a * l[:, 0] + self.b + g @ np.asarray(self.alpha_mm, float)


def fit_thickness(l_mm: ArrayLike, mean_radius_mm: ArrayLike, centres_mm: ArrayLike) -> Thickness:
    """Fit eq. 6 to a mean-radius profile ``mean_radius_mm (k,)`` (mm) at heights
    ``l_mm (k,)`` along the log, given knot-cluster heights ``centres_mm`` (mm).

    Line by linear least squares, then all parameters by ``scipy.optimize.least_squares``
    (bulge widths kept in [5, 500] mm, shifts within +-100 mm).
    """
    l = np.asarray(l_mm, float).reshape(-1)
    y = np.asarray(mean_radius_mm, float).reshape(-1)
    c = np.asarray(centres_mm, float).reshape(-1)
    a, b = np.polyfit(l, y, 1)
    k = len(c)

    def model(z):
        return Thickness(z[0], z[1], c, z[2:2 + k], z[2 + k:2 + 2 * k], z[2 + 2 * k:])(l)

    z0 = np.r_[a, b, np.zeros(k), np.zeros(k), np.full(k, 40.0)]
    lo = np.r_[-np.inf, -np.inf, np.full(k, -np.inf), np.full(k, -100.0), np.full(k, 5.0)]
    hi = np.r_[np.inf, np.inf, np.full(k, np.inf), np.full(k, 100.0), np.full(k, 500.0)]
    r = least_squares(lambda z: model(z) - y, z0, bounds=(lo, hi))
    z = r.x
    return Thickness(float(z[0]), float(z[1]), c, z[2:2 + k], z[2 + k:2 + 2 * k], z[2 + 2 * k:])


# -- surface knots (eq. 7-9) ---------------------------------------------------------------


def dog_sigmas(radius_mm, alpha, m):
    """Widths ``(sigma_narrow, sigma_wide)`` of the DoG whose zero crossing sits at ``radius_mm``.

    Seed 001 eq. 7 ``K = m e^{-x^2/2 s1^2} - e^{-x^2/2 s2^2}`` with ``s2 = alpha s1`` (eq. 8) and
    eq. 9 for ``s1`` is only a bump (positive centre, negative ring) when the *positive* Gaussian
    is the narrow one and ``m > 1``; the printed labels have them the other way round. We keep
    eq. 9 as the width of the wide (depression) Gaussian and ``alpha`` in (0, 1) as the ratio
    narrow / wide, so ``K(radius) = 0`` exactly:
    ``sigma_wide = sqrt(r^2 (1/alpha^2 - 1) / (2 ln m))``, ``sigma_narrow = alpha sigma_wide``.
    """
    alpha = np.asarray(alpha, dtype=float)
    m = np.asarray(m, dtype=float)
    if np.any((alpha <= 0) | (alpha >= 1)) or np.any(m <= 1):
        raise WoodcamError(f"DoG needs alpha in (0, 1) and m > 1; got alpha={alpha!r}, m={m!r}")
    wide = np.sqrt(np.asarray(radius_mm, float) ** 2 * (1 / alpha**2 - 1) / (2 * np.log(m)))
    return alpha * wide, wide


def dog(x_mm, radius_mm, alpha, m) -> np.ndarray:
    """1-D DoG of eq. 7 (with the widths of :func:`dog_sigmas`), ``m - 1`` at 0, 0 at ``radius_mm``."""
    sn, sw = dog_sigmas(radius_mm, alpha, m)
    x = np.asarray(x_mm, float)
    return m * np.exp(-(x**2) / (2 * sn**2)) - np.exp(-(x**2) / (2 * sw**2))


@dataclass(frozen=True)
class SurfaceKnot:
    """A knot bump on the heightmap: 2-D DoG (eq. 7-9) with per-axis radius and width ratio.

    Attributes
    ----------
    l_mm, theta_rad : float
        Centre: where the knot's centre curve meets the surface.
    r_l_mm, r_s_mm : float
        Zero-crossing radii along ``l`` and along the circumference (arc mm): the size of the
        knot's intersection with the surface, from the internal knot model.
    alpha_l, alpha_s : float in (0, 1)
        Narrow / wide width ratios per axis (the "tuple" ``alpha`` of seed 001).
    m : float > 1
        Elevation / depression proportion (eq. 7).
    height_mm : float
        Height of the bump's centre above the base (the DoG is scaled to it; the seed works
        with unit-free heightmaps and leaves this scale implicit).
    """

    l_mm: float
    theta_rad: float
    r_l_mm: float
    r_s_mm: float
    alpha_l: float
    alpha_s: float
    m: float
    height_mm: float

    def evaluate(self, dl_mm, ds_mm) -> np.ndarray:
        """Height (mm) at offsets ``dl_mm`` (along ``l``) and ``ds_mm`` (arc), broadcast."""
        nl, wl = dog_sigmas(self.r_l_mm, self.alpha_l, self.m)
        ns, ws = dog_sigmas(self.r_s_mm, self.alpha_s, self.m)
        dl, ds = np.asarray(dl_mm, float), np.asarray(ds_mm, float)
        k = self.m * np.exp(-0.5 * ((dl / nl) ** 2 + (ds / ns) ** 2)) - np.exp(-0.5 * ((dl / wl) ** 2 + (ds / ws) ** 2))
        return self.height_mm * k / (self.m - 1.0)

    def support_mm(self) -> tuple[float, float]:
        """Half extents (l, arc) in mm beyond which the bump is below 1e-4 of its height."""
        _, wl = dog_sigmas(self.r_l_mm, self.alpha_l, self.m)
        _, ws = dog_sigmas(self.r_s_mm, self.alpha_s, self.m)
        return 4.3 * float(wl), 4.3 * float(ws)


def add_surface_knots(radius_mm, l_mm, theta_rad, knots, arc_radius_mm: float) -> np.ndarray:
    """Heightmap plus the bumps of ``knots`` (each evaluated in its own window), ``(n_l, n_theta)``.

    ``arc_radius_mm`` converts azimuth to arc length (``ds = dtheta * arc_radius_mm``): the
    mean log radius. Azimuth wraps around.
    """
    out = np.array(radius_mm, dtype=float, copy=True)
    l = np.asarray(l_mm, float)
    t = np.asarray(theta_rad, float)
    dl_step = l[1] - l[0]
    dt_step = t[1] - t[0]
    n_t = len(t)
    for k in knots:
        hl, hs = k.support_mm()
        i0 = max(int(np.floor((k.l_mm - hl - l[0]) / dl_step)), 0)
        i1 = min(int(np.ceil((k.l_mm + hl - l[0]) / dl_step)) + 1, len(l))
        if i1 <= i0:
            continue
        half_j = min(int(np.ceil(hs / arc_radius_mm / dt_step)), (n_t - 1) // 2)
        jc = int(np.round(k.theta_rad / dt_step))
        j = np.arange(jc - half_j, jc + half_j + 1) % n_t  # distinct columns: plain += is safe
        dtheta = np.angle(np.exp(1j * (t[j] - k.theta_rad)))
        bump = k.evaluate((l[i0:i1] - k.l_mm)[:, None], (dtheta * arc_radius_mm)[None, :])
        out[i0:i1, j] += bump
    return out


def fit_surface_knot(patch_mm: ArrayLike, dl_mm: ArrayLike, ds_mm: ArrayLike, r_l_mm: float,
                     r_s_mm: float) -> SurfaceKnot:
    """Fit ``alpha_l, alpha_s, m, height`` of one bump to a detail patch (seed 001 §4.3).

    ``patch_mm : (a, b)`` is the heightmap minus its base around the knot, sampled at offsets
    ``dl_mm : (a,)`` and ``ds_mm : (b,)`` from the bump centre; the radii come from the internal
    knot model (``r_l_mm``, ``r_s_mm``: the zero-crossing radii along ``l`` and round the
    circumference, arc mm, as :class:`SurfaceKnot`'s). Minimises the RMSE with
    ``scipy.optimize.least_squares`` (bounded).
    """
    P = np.asarray(patch_mm, float)
    DL, DS = np.asarray(dl_mm, float)[:, None], np.asarray(ds_mm, float)[None, :]

    def res(z):
        return (SurfaceKnot(0, 0, r_l_mm, r_s_mm, z[0], z[1], z[2], z[3]).evaluate(DL, DS) - P).ravel()

    z0 = np.array([0.5, 0.5, 1.5, float(P.max())])
    r = least_squares(res, z0, bounds=([0.05, 0.05, 1.01, -np.inf], [0.95, 0.95, 20.0, np.inf]))
    return SurfaceKnot(0.0, 0.0, r_l_mm, r_s_mm, *map(float, r.x))


# -- grain: Gabor noise ---------------------------------------------------------------------


def gabor_noise(n_l: int, n_theta: int, dl_mm: float, ds_mm: float, rng: np.random.Generator, *,
                wavelength_mm: float = 12.0, elongation: float = 6.0, octaves: int = 3,
                amplitude_mm: float = 0.3) -> np.ndarray:
    """Multi-octave Gabor noise ``(n_l, n_theta)`` mm with ridges along the log (the grain).

    Each octave is Gaussian white noise convolved with a Gabor kernel
    ``exp(-pi (a_l^2 dl^2 + a_s^2 ds^2)) cos(2 pi ds / wavelength)`` (seed 001 §3.4, after
    Lagae et al. 2009): the cosine runs across the grain and the envelope is ``elongation``
    times longer along ``l``. Hand-written because the dense form is one FFT product with the
    kernels' analytic spectra (two Gaussians at ``+-1/wavelength``), much faster than sparse
    convolution and not in scipy. All octaves filter the same white noise (one FFT pair); the
    octaves' filters are each normalised to unit output variance (Parseval), octave ``o`` with
    half the wavelength and weight ``0.5^o``. The azimuth is periodic; along ``l`` the noise is
    computed on a padded grid and cropped so the log's two ends do not correlate. The result
    is scaled to standard deviation ``amplitude_mm``.

    ``n_l`` x ``n_theta`` samples ``dl_mm`` apart along the log and ``ds_mm`` (arc mm) round
    it; ``rng``: the white noise's generator; ``wavelength_mm``: the first octave's wavelength
    across the grain (default 12 mm).
    """
    pad = n_l // 4 + 8
    nl = n_l + 2 * pad
    fl = np.fft.fftfreq(nl, d=dl_mm)[:, None]
    fs = np.fft.rfftfreq(n_theta, d=ds_mm)[None, :]
    weight = np.ones(fs.shape[1])
    weight[1:(n_theta + 1) // 2] = 2.0  # rfft bins standing for two conjugate bins
    filt = np.zeros((nl, fs.shape[1]))
    for o in range(octaves):
        f0 = 2.0**o / wavelength_mm
        a_s = f0 / 1.5          # envelope ~1.5 wavelengths across the grain
        a_l = a_s / elongation  # and `elongation` times that along it
        spec = np.exp(-np.pi * (fl**2 / a_l**2 + (fs - f0) ** 2 / a_s**2))
        spec += np.exp(-np.pi * (fl**2 / a_l**2 + (fs + f0) ** 2 / a_s**2))
        power = float(np.sum(spec**2 * weight))
        if power > 0:
            filt += 0.5**o * spec / np.sqrt(power)
    white = rng.standard_normal((nl, n_theta))
    total = np.fft.irfft2(np.fft.rfft2(white) * filt, s=(nl, n_theta))[pad:pad + n_l]
    sd = total.std()
    return total * (amplitude_mm / sd) if sd > 0 else total
