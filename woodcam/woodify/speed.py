"""Growth speed of the woodification model (seed 004, sec. 4.2) and the separation of time.

The seed moves every surface point along its normal with speed (eq. 4.1)

    s(t) = c t^(c-1) exp(-t^c)                                    (Weibull density, shape c)

and, with eccentricity (sec. 4.2.1), ``s_e(t, x) = (1 + delta n . up) s(t)``. woodcam adds a
velocity scale ``v`` (mm) and a time scale ``lambda`` (years): a point moves with normal speed

    ds/dt = v / lambda * s(t / lambda) * g(x) * (1 + w(x) . n)

where ``g`` is a speed gain (1 unless brushed, sec. 4.2.2) and ``w = delta * up`` (+ brushed
directions). The time part separates from the space part: with the pseudo-time

    tau(t) = v * W(t / lambda),        W(u) = 1 - exp(-u^c)       (the Weibull CDF)

the front at year ``t`` is the front at ``tau`` of the time-independent problem whose normal
speed is ``F(x, n) = g(x) (1 + w(x) . n)`` (units: mm of pseudo-time per mm). Its arrival time
``T(x)`` (mm) solves the eikonal equation ``g (|grad T| + w . grad T) = 1`` and the growth year
of ``x`` is ``t = lambda * W^-1(T(x) / v)``. A sphere of radius r0 grows to ``r0 + tau(t)``;
with eccentricity its centre moves by ``delta * tau(t)`` along ``up``; it never grows beyond
``r0 + v`` (W < 1): ``v`` is the asymptotic total growth.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._checks import check_vector, real_numbers, received
from ..errors import WoodcamError


def weibull_speed(u: ArrayLike, shape: float = 2.0) -> np.ndarray:
    """Eq. 4.1: ``s(u) = c u^(c-1) exp(-u^c)`` for ``u >= 0`` (dimensionless time), ``c`` the
    Weibull ``shape`` (default 2)."""
    u = np.maximum(np.asarray(u, dtype=float), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = shape * u ** (shape - 1.0) * np.exp(-u ** shape)
    return np.where(u > 0, s, shape if shape == 1.0 else (np.inf if shape < 1 else 0.0))


def weibull_cdf(u: ArrayLike, shape: float = 2.0) -> np.ndarray:
    """``W(u) = 1 - exp(-u^c)`` for ``u >= 0``: the integral of eq. 4.1 from 0 to ``u``; ``c``
    the Weibull ``shape`` (default 2)."""
    u = np.maximum(np.asarray(u, dtype=float), 0.0)
    return -np.expm1(-u ** shape)


def weibull_cdf_inv(q: ArrayLike, shape: float = 2.0) -> np.ndarray:
    """``W^-1(q) = (-ln(1 - q))^(1/c)`` for ``q`` in [0, 1); ``inf`` for ``q >= 1``; ``c`` the
    Weibull ``shape`` (default 2)."""
    q = np.clip(np.asarray(q, dtype=float), 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return (-np.log1p(-q)) ** (1.0 / shape)


@dataclass(frozen=True)
class GrowthSpeed:
    """The growth law: Weibull time part (eq. 4.1) and eccentric direction part (sec. 4.2.1).

    Parameters
    ----------
    velocity_mm : float
        Velocity scale ``v`` (mm): the total growth as ``t -> inf``; after ``t`` years a flat
        surface has moved ``v * W(t / time_scale_years)``.
    time_scale_years : float
        Time scale ``lambda`` (years) of the Weibull law; the growth peaks near
        ``lambda * ((c - 1) / c)^(1/c)`` (0.71 lambda for c = 2).
    shape : float
        Weibull shape ``c > 0`` (seed default 2).
    eccentricity : float
        ``delta`` in ``(-1, 1)``: speed ``(1 + delta n . up)``; positive grows faster on the
        side facing ``up`` (tension wood), negative away from it (compression wood).
    up : (3,) float
        The direction ``y-hat`` of the seed (normalised here); block frame, default +Z.
    """

    velocity_mm: float
    time_scale_years: float
    shape: float = 2.0
    eccentricity: float = 0.0
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        for name in ("velocity_mm", "time_scale_years", "shape", "eccentricity"):  # '1' was np.isfinite's TypeError
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise WoodcamError(f"{name} must be a number; got {v!r}; e.g. GrowthSpeed(velocity_mm=20, "
                                   "time_scale_years=30)")
        if not (np.isfinite(self.velocity_mm) and self.velocity_mm > 0):
            raise WoodcamError(f"velocity_mm must be > 0 (mm of total growth); got {self.velocity_mm!r}")
        if not (np.isfinite(self.time_scale_years) and self.time_scale_years > 0):
            raise WoodcamError(
                f"time_scale_years must be > 0 (years); got {self.time_scale_years!r}")
        if not (np.isfinite(self.shape) and self.shape > 0):
            raise WoodcamError(f"shape (Weibull c) must be > 0; got {self.shape!r}; the seed uses 2")
        if not -1.0 < self.eccentricity < 1.0:
            raise WoodcamError(
                f"eccentricity must lie in (-1, 1) so every normal keeps growing; got "
                f"{self.eccentricity!r}; try 0.3")
        # its own parser (_unit3) read complex numbers with float()'s bare TypeError and a
        # string as numpy's ValueError: the one rule of a direction instead
        up = check_vector(self.up, "up", unit=True, fix="the growth's up direction, e.g. (0, 0, 1)")
        object.__setattr__(self, "up", tuple(float(v) for v in up))

    @property
    def wind(self) -> np.ndarray:
        """``w = delta * up`` (3,): the direction part of the speed ``F = 1 + w . n``."""
        return self.eccentricity * np.asarray(self.up)

    def tau(self, years: ArrayLike) -> np.ndarray:
        """Pseudo-time ``tau = v W(t / lambda)`` (mm) reached at ``years``."""
        t = real_numbers(years, "years")
        return self.velocity_mm * weibull_cdf(t / self.time_scale_years, self.shape)

    def years(self, tau_mm: ArrayLike) -> np.ndarray:
        """Inverse of :meth:`tau`: growth year ``lambda W^-1(T / v)`` of arrival time ``T`` (mm).

        ``T <= 0`` (the input object itself) maps to 0; ``T >= v`` (never reached) to ``inf``.
        """
        q = real_numbers(tau_mm, "tau_mm") / self.velocity_mm
        return self.time_scale_years * weibull_cdf_inv(q, self.shape)

    def speed(self, years: ArrayLike, normals: ArrayLike | None = None) -> np.ndarray:
        """Normal speed ``ds/dt`` (mm/year) at ``years`` for unit ``normals (n, 3)`` (eq. 4.1
        with the eccentric factor); without normals the isotropic speed."""
        lam = self.time_scale_years
        s = self.velocity_mm / lam * weibull_speed(real_numbers(years, "years") / lam, self.shape)
        if normals is None:
            return s
        n = real_numbers(normals, "normals")
        return s * (1.0 + n @ self.wind)

    def to_dict(self) -> dict:
        return {"velocity_mm": self.velocity_mm, "time_scale_years": self.time_scale_years,
                "shape": self.shape, "eccentricity": self.eccentricity, "up": list(self.up)}

    @classmethod
    def from_dict(cls, d: Mapping) -> GrowthSpeed:
        """The speed :meth:`to_dict` wrote. Anything but a dict of its five keys is refused
        (None was a bare "'NoneType' object is not subscriptable", a missing key a bare
        KeyError); each value is checked as the constructor checks it (float() took '20')."""
        keys = ("velocity_mm", "time_scale_years", "shape", "eccentricity", "up")
        if not isinstance(d, Mapping) or any(k not in d for k in keys):
            got = (f"a dict without {', '.join(k for k in keys if k not in d)}" if isinstance(d, Mapping)
                   else received(d))
            raise WoodcamError(f"d must be a growth speed dict with keys {', '.join(keys)} (GrowthSpeed.to_dict()); "
                               f"got {got}; e.g. {cls(20.0, 30.0).to_dict()}")
        return cls(d["velocity_mm"], d["time_scale_years"], d["shape"], d["eccentricity"], d["up"])
