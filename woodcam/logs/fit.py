"""Fitting the log model of seed 001 to data (§4.2-4.3).

* :func:`fit_knot`: the 9-parameter knot model (:mod:`.knot`) to points on a knot's surface,
  given in log-centric ``(theta_rad, l_mm, rho_mm)``: a least-squares initialisation of the
  trajectory and radius curves from per-``rho`` slices, then Levenberg-Marquardt
  (``scipy.optimize.least_squares(method="lm")``) on all nine parameters, minimising the
  point-to-surface distances of :meth:`Knot.surface_residuals`. The bounded parameters are
  optimised in unconstrained coordinates (log for lengths and ovality, logit for the ratios),
  so the fitted knot always satisfies the model's constraints.
* :func:`fit_gran_knots`: the same on the CT-measured spruce log of ``shared/data/trees``
  (Larsson et al. 2022), whose knots are described by curves; we sample points on each knot's
  surface from that description (:func:`sample_gran_knot_points`) and fit.

Centreline and surface fits live with their models (:func:`woodcam.logs.centreline.fit_centreline`,
:func:`woodcam.logs.surface.fit_surface_base`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from ..errors import WoodcamError
from .knot import MAX_INCLINE, Knot, KnotShape, to_slr
from .._types import ArrayLike, PathLike

_LOGIT_CLIP = 30.0  # only guards exp() overflow; sigmoid(30) is 1 to double precision
_INIT_LOGIT = 1.5  # start LM with ratios in [0.18, 0.82], where the sigmoid still has slope


def _logit(p):
    p = np.clip(np.asarray(p, float), 1e-6, 1 - 1e-6)
    return np.log(p / (1 - p))


def _sigmoid(z):
    return 1.0 / (1.0 + np.exp(-np.clip(z, -_LOGIT_CLIP, _LOGIT_CLIP)))


def params_to_unconstrained(params: KnotShape) -> np.ndarray:
    """(9,) unconstrained vector: ``s0, l0, log gamma, log rho_max, logit phi0, logit phi1,
    log r_max, logit psi0, logit psi1`` (the coordinates generation and fitting work in)."""
    p = params
    return np.array([p.s0_mm, p.l0_mm, np.log(p.gamma), np.log(p.rho_max_mm), _logit(p.phi0),
                     _logit(p.phi1), np.log(p.r_max_mm), _logit(p.psi0), _logit(p.psi1)])


def unconstrained_to_params(z) -> KnotShape:
    """Inverse of :func:`params_to_unconstrained`; any finite ``z : (9,)`` gives a valid knot."""
    z = np.asarray(z, dtype=float)
    return KnotShape(float(z[0]), float(z[1]), float(np.exp(np.clip(z[2], -5, 5))),
                      float(np.exp(np.clip(z[3], -10, 10))), float(_sigmoid(z[4])), float(_sigmoid(z[5])),
                      float(np.exp(np.clip(z[6], -10, 10))), float(_sigmoid(z[7])), float(_sigmoid(z[8])))


@dataclass(frozen=True)
class KnotFit:
    """Result of :func:`fit_knot`.

    Attributes
    ----------
    knot : Knot
        The fitted knot (``theta_mean_rad`` = circular mean azimuth of the points).
    rmse_mm : float
        Root mean square point-to-surface distance after Levenberg-Marquardt.
    init_rmse_mm : float
        The same for the least-squares initialisation.
    n_points : int
    success : bool
        ``least_squares``'s convergence flag.
    """

    knot: Knot
    rmse_mm: float
    init_rmse_mm: float
    n_points: int
    success: bool


def _slices(slr: np.ndarray, n_slices: int):
    order = np.argsort(slr[:, 2])
    groups = np.array_split(order, n_slices)
    cen = np.array([slr[g].mean(0) for g in groups])
    sd = np.array([slr[g].std(0) for g in groups])
    return cen, sd


def _init_params(slr: np.ndarray) -> np.ndarray:
    """Least-squares initialisation (seed 001 §4.2): trajectory, then radius, from slices."""
    n_slices = int(np.clip(len(slr) // 40, 4, 24))
    cen, sd = _slices(slr, n_slices)
    s0 = float(slr[:, 0].mean())
    rho_c, l_c = cen[:, 2], cen[:, 1]
    rho_top = float(max(rho_c.max(), 1.0))
    half = rho_c >= np.median(rho_c)
    m = np.polyfit(rho_c[half], l_c[half], 1)[0] if half.sum() >= 2 else 0.0
    phi1 = float(np.clip((np.arctan(m) / MAX_INCLINE + 1) / 2, 0.02, 0.98))

    def traj_res(z):
        k = Knot(unconstrained_to_params(np.r_[s0, z[0], 0.0, z[1], z[2], z[3], 0.0, 0.0, 0.0]))
        return k.height(rho_c) - l_c

    # a nearly straight knot leaves rho_max free: keep it inside the sampled range
    lo = np.array([-np.inf, np.log(max(0.05 * rho_top, 0.5)), -4.0, -4.0])
    hi = np.array([np.inf, np.log(rho_top), 4.0, 4.0])
    best = None
    for frac in (0.1, 0.35, 0.95):
        z0 = np.array([l_c[0] - m * rho_c[0], np.log(frac * rho_top), 0.0, _logit(phi1)])
        r = least_squares(traj_res, np.clip(z0, lo + 1e-9, hi - 1e-9), method="trf", bounds=(lo, hi))
        if best is None or r.cost < best.cost:
            best = r
    l0, lrm, lp0, lp1 = best.x
    traj = Knot(unconstrained_to_params([s0, l0, 0.0, lrm, lp0, lp1, 0.0, 0.0, 0.0]))
    r_slice = np.sqrt(2.0) * sd[:, 0]
    c_slice = traj.arc_length(rho_c)
    norm = np.sqrt(1 + traj.height_slope(rho_c) ** 2)
    gamma = float(np.clip(np.median(sd[:, 1] / np.maximum(sd[:, 0], 1e-6) / norm), 0.3, 3.0))
    rmax0 = float(np.interp(np.exp(lrm), rho_c, r_slice))

    def rad_res(z):
        p = unconstrained_to_params([s0, l0, 0.0, lrm, lp0, lp1, z[0], z[1], z[2]])
        return Knot(p).radius_at_length(c_slice) - r_slice

    r = least_squares(rad_res, np.array([np.log(max(rmax0, 0.1)), 0.0, 0.0]), method="trf")
    return np.r_[s0, l0, np.log(gamma), lrm, lp0, lp1, r.x]


def fit_knot(points_lcs: ArrayLike, *, theta_mean_rad: float | None = None, max_nfev: int = 400) -> KnotFit:
    """Fit the 9-parameter knot model to knot surface points (seed 001 §4.2).

    Parameters
    ----------
    points_lcs : (n, 3) float
        Points on the knot surface in log-centric ``(theta_rad, l_mm, rho_mm)``, n >= 20.
    theta_mean_rad : float, optional
        Reference azimuth of the arc coordinate; default the circular mean of the points.
    max_nfev : int
        Cap on residual evaluations of the Levenberg-Marquardt refinement.
    """
    pts = np.asarray(points_lcs, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 20:
        raise WoodcamError(
            f"points_lcs must have shape (n >= 20, 3) as (theta_rad, l_mm, rho_mm); got {pts.shape}; "
            "sample more points on the knot")
    slr, theta_mean = to_slr(pts, theta_mean_rad)

    def res(z):
        return Knot(unconstrained_to_params(z), theta_mean).surface_residuals(slr)

    z0 = _init_params(slr)
    for i in (4, 5, 7, 8):  # logit coordinates
        z0[i] = np.clip(z0[i], -_INIT_LOGIT, _INIT_LOGIT)
    r0 = res(z0)
    sol = least_squares(res, z0, method="lm", max_nfev=max_nfev, x_scale="jac")
    knot = Knot(unconstrained_to_params(sol.x), theta_mean)
    return KnotFit(knot, float(np.sqrt(np.mean(sol.fun**2))), float(np.sqrt(np.mean(r0**2))),
                   len(pts), bool(sol.success))


# -- the CT-measured spruce log of shared/data/trees ------------------------------------------

#: Columns of a knot row in ``Gran_1_knots.json`` (see shared/data/README.md).
GRAN_COLUMNS = ("A", "B", "z0", "D", "E", "w0", "G", "r_end", "r_death")


def _load_gran_knots(path) -> np.ndarray:
    """Read ``Gran_1_knots.json``: ``(n, 9)`` float rows ``[A, B, z0, D, E, w0, G, r_end, r_death]``."""
    p = Path(path)
    if not p.is_file():
        raise WoodcamError(f"path must be an existing Gran_*_knots.json file; got {str(p)!r}")
    a = np.asarray(json.loads(p.read_text()), dtype=float)
    if a.ndim != 2 or a.shape[1] != 9:
        raise WoodcamError(f"{p.name} must hold rows of 9 numbers {GRAN_COLUMNS}; got shape {a.shape}")
    return a


def gran_knot_diameter(row, r_mm) -> np.ndarray:
    """Knot diameter (mm) of a ``Gran_1`` knot row at distance ``r_mm : (n,)`` from the pith.

    The same model as :meth:`woodcam.fields.skeleton.BranchStrand.from_model`: ``d = A r^(1 + B)``,
    the form whose knot sizes agree best with the bark bumps where knots exit the measured
    log (see ``docs/knots.md``). Clipped below at 0.5 mm.
    """
    r = np.maximum(np.asarray(r_mm, dtype=float), 1e-9)
    return np.maximum(row[0] * r ** (1.0 + row[1]), 0.5)


def sample_gran_knot_points(row, *, n_along: int = 24, n_around: int = 12,
                            r_start_mm: float = 1.0, spacing_power: float = 1.5) -> np.ndarray:
    """Points on one ``Gran_1`` knot's surface, ``(n_along * n_around, 3)`` as ``(theta, l, rho)``.

    Centre curve (data README): height ``z0 + D sqrt(r) + E r`` and azimuth ``w0 + G ln r`` at
    distance ``r`` from the pith, for ``r`` in ``[r_start_mm, r_end]``; circular cross-sections
    of diameter :func:`gran_knot_diameter` perpendicular to the 3-D curve. Coordinates are
    relative to the pith, so they are log-centric directly (``l`` = height).

    Sections are spaced as ``u ** spacing_power`` (``u`` uniform in [0, 1]): denser near the
    pith. With uniform spacing from 5 mm the fit often replaced the first millimetres by a
    steep spurious rise, putting the knot origin ``l0`` 20-30 mm below ``z0`` at a slightly
    lower RMSE; starting at 1 mm with power 1.5 pins ``l0`` within 1 mm of ``z0``.
    """
    A, B, z0, D, E, w0, G, r_end, _ = np.asarray(row, dtype=float)
    u = np.linspace(0.0, 1.0, n_along) ** spacing_power  # denser near the pith, where l0 is pinned
    r = (r_start_mm + (max(r_end, r_start_mm + 1.0) - r_start_mm) * u)[:, None]
    w = w0 + G * np.log(r)
    z = z0 + D * np.sqrt(r) + E * r
    c = np.concatenate([r * np.cos(w), r * np.sin(w), z], axis=1)
    t = np.concatenate([np.cos(w) - r * np.sin(w) * G / r, np.sin(w) + r * np.cos(w) * G / r,
                        D / (2 * np.sqrt(r)) + E], axis=1)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    n1 = np.cross(t, [0.0, 0.0, 1.0])
    n1 /= np.linalg.norm(n1, axis=1, keepdims=True)
    n2 = np.cross(t, n1)
    rad = 0.5 * gran_knot_diameter(row, r[:, 0])[:, None, None]
    phi = np.linspace(0, 2 * np.pi, n_around, endpoint=False)[None, :, None]
    pts = c[:, None, :] + rad * (np.cos(phi) * n1[:, None, :] + np.sin(phi) * n2[:, None, :])
    pts = pts.reshape(-1, 3)
    return np.stack([np.arctan2(pts[:, 1], pts[:, 0]), pts[:, 2], np.hypot(pts[:, 0], pts[:, 1])], axis=1)


@dataclass(frozen=True)
class GranFitTable:
    """Per-knot fits of a ``Gran_*`` log: ``fits[i]`` for data row ``rows[i]``."""

    rows: np.ndarray
    fits: tuple[KnotFit, ...]

    @property
    def rmse_mm(self) -> np.ndarray:
        """(n,) per-knot RMSE (mm)."""
        return np.array([f.rmse_mm for f in self.fits])

    def summary(self) -> dict:
        """Mean and SD of the per-knot RMSE, like seed 001 Table 1."""
        e = self.rmse_mm
        return {"knots": len(e), "rmse_mean_mm": float(e.mean()),
                "rmse_sd_mm": float(e.std(ddof=1)) if len(e) > 1 else 0.0,
                "rmse_median_mm": float(np.median(e)), "rmse_max_mm": float(e.max())}


def fit_gran_knots(knots_json: PathLike, *, indices: ArrayLike | None = None, n_along: int = 24,
                   n_around: int = 12) -> GranFitTable:
    """Fit the knot model to the knots of a ``Gran_*_knots.json`` log (see module docstring).

    ``knots_json``: the ``Gran_*_knots.json`` file (rows of 9 numbers). ``indices`` selects rows
    (default all). Each knot's sampled points (``n_along`` x ``n_around`` on its surface,
    :func:`sample_gran_knot_points`) are fitted independently.
    """
    data = _load_gran_knots(knots_json)
    idx = np.arange(len(data)) if indices is None else np.asarray(indices, dtype=int)
    fits = tuple(fit_knot(sample_gran_knot_points(data[i], n_along=n_along, n_around=n_around)) for i in idx)
    return GranFitTable(data[idx], fits)
