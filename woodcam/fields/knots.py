"""Knotted-log growth field: stem and branch strand time fields joined by smooth minima.

Implements the knot model of seed 003 (Wood Knot Editor, after Larsson et al. 2022, "Procedural
Texturing of Solid Wood with Knots") as a growth-time field over a :class:`~.skeleton.LogSkeleton`.

Frames and units. :class:`KnottedLogField` is evaluated in the LOG frame of
:mod:`woodcam.fields.skeleton` (mm; ``z`` along the log). Wrap it with :class:`PlacedField`
(or :func:`place_block_in_log`) to use it in a block frame. Output is growth time in years,
0 on the pith, growing outward; ``ring_width_mm`` converts the model's radial "time" to years.

The model, section by section of the seed (its ``t`` values are lengths here, "mm of stem
radius", so that all constants have physical units; ``years = t / ring_width_mm``):

1. Strand time fields ``t = dist(S, P) / v(S, beta)`` (seed eq. 1) with pseudo-nearest points:
   stem: the pith point at the same height, ``t_s = d_s / v_s`` with the relative speed
   ``v_s = R(z, omega) / mean_omega R(z)`` (the smoothed outer radius over its mean: rings follow
   the measured outline). Knot ``i``: the branch point at the same pith distance
   ``r = min(d_s, r_end)``, ``t_b = |P - S_b| / (rho(r) v_s)`` with ``rho = (diameter/2) / r``,
   so the surface ``t_b = t_s`` has the measured knot diameter.
2. Joining: power smooth minimum ``smin(a, b, k) = (a^k b^k / (a^k + b^k))^(1/k)`` (eq. 2),
   amount of smoothing ``delta = smin - min`` (eq. 3), adaptive
   ``k = (k_knot - k_stem)/2 * tD / (c + |tD|) + (k_knot + k_stem)/2`` with
   ``tD = t_s - t_b`` (Sec. 4.2.1). After death (where ``smin > t_death``) the knot stops
   thickening (``t_b += t_s - t_death``), ``k`` rises with the time since death and ``delta`` is
   scaled by ``f(t_since_death, beta)`` that turns negative (inverted smoothing, Sec. 4.2.2) and
   varies with the orientation ``beta`` around the knot axis (butterfly). Unlike the seed's
   shader, the dead form is blended in over ``death_band_mm`` of ``smin - t_death``: the
   field then stays continuous on the ring-parallel surface where the switch happens away from
   the knot, and still breaks (a step far narrower than the outline) at the knot's bark ring,
   where the time since death is large. Many knots:
   ``min(t_s, t_b1..t_bn) + sum_i delta_i'`` (eq. 6), with each knot's delta faded to 0 over
   its distance range and inside other knots, as the seed's reference shader does.
3. Knot features for rendering (Sec. 4.3): ``knot`` (darkening weight, 0..1), ``dead``
   (inside a dead knot), ``outline`` (the dead knot's bark ring, where the field jumps).

Performance: points are sorted by height and evaluated in chunks; each chunk only visits the
knots whose influence region (distance range ``range_d1_mm + range_k1 * d_s`` around the strand,
outside which a knot's contribution is exactly zero) can reach the chunk's height span, so the
cost grows with the knots near a point, not with all knots of the log.
"""

from __future__ import annotations

import numbers
from dataclasses import asdict, dataclass, replace
from typing import Literal

import numpy as np

from .._checks import check_bool, check_number
from .._repr import attrs_repr
from .._types import ArrayLike
from ..errors import WoodcamError
from .base import check_points
from .skeleton import LogSkeleton

Backend = Literal["auto", "numpy", "numba"]
BACKENDS = ("numpy", "numba")


def available_backends() -> tuple[str, ...]:
    """The evaluation backends usable here (numba only when it imports)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return ("numpy",)
    return BACKENDS


def _pick_backend(backend: str) -> str:
    if backend == "auto":
        return available_backends()[-1]
    if backend not in BACKENDS:
        raise WoodcamError(f"backend must be one of 'auto', 'numpy', 'numba'; got {backend!r}")
    if backend not in available_backends():
        raise WoodcamError("backend 'numba' needs the numba package, which is not installed; "
                           "pip install numba, or use backend='numpy'")
    return backend


#: Division guard (mm) for time values: a point exactly on the pith or on a knot axis has 0.
_T_EPS = 1e-9


@dataclass(frozen=True)
class KnotParams:
    """Parameters of the knot model (defaults: the seed's shader). How knots are coloured is
    :class:`woodcam.appearance.knots.KnotShading`.

    The seed's shader works in times normalised by the log's minimum radius (~100 mm for its
    log); its constants are given here in mm of stem radius (shader value x 100 mm).

    Parameters
    ----------
    k_stem, k_knot : float
        Smoothness exponents of the power smooth minimum outside (low: wide distortion) and
        inside (high: crisp knot edge) a knot (seed "smoothness k", Sec. 4.2.1).
    k_transition_mm : float
        Half-width ``c`` of the blend between the two k targets over ``t_s - t_b``.
    death_k_rate_per_mm : float
        Growth of k per mm of stem radius after death (crisper knot edge, shader ``f4``).
    death_f_min, death_f_max : float
        Range of the dead-knot smoothing factor ``f`` (shader ``f1``, ``f2``): it starts at 1 at
        death and tends to ``death_f_min`` (< 0: inverted smoothing) far after death.
    death_f_length_mm : float
        Stem radius after death over which ``f`` flips (shader ``1/f3``).
    death_band_mm : float
        Width (in ``smin - t_death``, mm of stem radius) over which the dead form blends in;
        the seed switches abruptly, which also breaks rings far from the knot.
    butterfly : float
        0..1, how much weaker the inversion is above/below the knot than at its sides
        (``f = 1 + (f - 1)(1 - butterfly sin^2 beta)``, beta from the tangential direction).
    range_d0_mm, range_k0, range_d1_mm, range_k1 : float
        A knot acts on points within ``range_d1_mm + range_k1 d_s`` of its strand point; its
        smoothing fades out from ``range_d0_mm + range_k0 d_s`` to there.
    knot_noise : float
        Relative amplitude of the knot-radius irregularity around the knot axis.
    outline_mm : float
        Thickness of the dark outline (bark ring) of dead knots, mm across the knot.
    knot_edge_sharpness : float
        Exponent ``m`` of the knot darkening weight ``1 / (1 + x)^m`` (shader: 14).
    """

    k_stem: float = 1.5
    k_knot: float = 5.0
    k_transition_mm: float = 30.0
    death_k_rate_per_mm: float = 0.05
    death_f_min: float = -1.5
    death_f_max: float = 0.2
    death_f_length_mm: float = 12.5
    death_band_mm: float = 0.5
    butterfly: float = 0.5
    range_d0_mm: float = 10.0
    range_k0: float = 0.8
    range_d1_mm: float = 20.0
    range_k1: float = 1.0
    knot_noise: float = 0.08
    outline_mm: float = 1.0
    knot_edge_sharpness: float = 14.0

    def __post_init__(self):
        # Each a finite number in its range, checked by check_number: a string, None or a complex
        # number was a bare TypeError of the comparisons below, and the eight fields they did not
        # compare were kept as given ('abc', NaN, a list) until the field was evaluated; NaN
        # passed 'outline_mm < 0' and inf the range checks.
        for name, lo, hi, lo_open in (("k_stem", 0.1, 64, False), ("k_knot", 0.1, 64, False),
                                      ("k_transition_mm", 0, None, True), ("death_k_rate_per_mm", 0, None, False),
                                      ("death_f_min", None, None, False), ("death_f_max", None, None, False),
                                      ("death_f_length_mm", 0, None, True), ("death_band_mm", 0, None, True),
                                      ("butterfly", 0, 1, False), ("range_d0_mm", 0, None, False),
                                      ("range_k0", 0, None, False), ("range_d1_mm", 0, None, False),
                                      ("range_k1", 0, None, False), ("knot_noise", 0, 1, False),
                                      ("outline_mm", 0, None, False), ("knot_edge_sharpness", 0, None, True)):
            default = self.__dataclass_fields__[name].default
            check_number(getattr(self, name), f"KnotParams.{name}", lo=lo, hi=hi, lo_open=lo_open,
                         fix=f"the default is {default:g}")
        if not (self.range_d1_mm > self.range_d0_mm >= 0 and self.range_k1 >= self.range_k0 >= 0):
            raise WoodcamError("KnotParams ranges need range_d1_mm > range_d0_mm >= 0 and "
                               f"range_k1 >= range_k0 >= 0; got d0={self.range_d0_mm}, "
                               f"d1={self.range_d1_mm}, k0={self.range_k0}, k1={self.range_k1}")


# ---------------------------------------------------------------------------------------------
# smooth minimum (seed eqs. 2, 3)

def power_smooth_min(a, b, k):
    """Power smooth minimum ``(a^k b^k / (a^k + b^k))^(1/k)`` of seed eq. 2, elementwise.

    ``a, b >= 0`` (broadcast); ``k > 0``. Evaluated as ``m (1 + (m/M)^k)^(-1/k)`` with
    ``m = min(a, b)``, ``M = max(a, b)``, which equals eq. 2, never overflows, and shows the
    bounds ``2^(-1/k) m <= smin <= m``.
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    m = np.minimum(a, b)
    M = np.maximum(np.maximum(a, b), _T_EPS)
    q = np.maximum(m, 0.0) / M
    with np.errstate(divide="ignore"):
        lq = np.log(q)
    return m * np.exp(-np.log1p(np.exp(k * lq)) / k)


def smoothing_amount(a, b, k):
    """Amount of smoothing ``delta = smin(a, b, k) - min(a, b)`` (seed eq. 3), ``<= 0``."""
    return power_smooth_min(a, b, k) - np.minimum(a, b)


def _smooth_delta(ts, tb, k):
    """``delta`` of eq. 3 for (K, m) arrays, in place-friendly form."""
    mn = np.minimum(ts, tb)
    mx = np.maximum(np.maximum(ts, tb), _T_EPS)
    with np.errstate(divide="ignore"):
        lq = np.log(mn / mx)
    return mn * np.expm1(-np.log1p(np.exp(k * lq)) / k), mn


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _bilinear_periodic(table, iz, tz, az):
    """Sample ``table (h, a)`` between rows ``iz``, ``iz + 1`` (weight ``tz``) at azimuths
    ``az`` (radians, periodic over the ``a`` columns)."""
    h, a = table.shape
    fa = np.mod(az, 2 * np.pi) * (a / (2 * np.pi))
    ia = fa.astype(np.int64)
    ta = fa - ia
    ia %= a
    ia1 = (ia + 1) % a
    r0 = table[iz, ia] * (1 - ta) + table[iz, ia1] * ta
    r1 = table[iz + 1, ia] * (1 - ta) + table[iz + 1, ia1] * ta
    return r0 * (1 - tz) + r1 * tz


# ---------------------------------------------------------------------------------------------

class KnottedLogField:
    """Growth-time field of a knotted log, evaluated in the log frame (module docstring).

    Parameters
    ----------
    log : Log
        Pith, outer surface and knots (mm).
    ring_width_mm : float
        Mean ring width (mm/year) of the stem: ``years = t / ring_width_mm``.
    params : KnotParams
        Model and rendering parameters.
    surface_smoothing : (int, int)
        Box filter (rows = pith samples, columns = azimuth samples) applied to the measured
        radii before they set the growth speed, as the seed's map maker does (11 x 5), so
        local bumps of the bark do not imprint on every ring.
    table_samples : int >= 2
        Radii (from the pith to past the outermost knot end or the bark) at which each knot's
        axis is tabulated for the lookup (default 128; spacing ``r_top / (table_samples - 1)``).
    chunk : int or None
        numpy backend: points per height-sorted chunk (default 2048); it holds about
        ``chunk x knots-per-chunk x 40`` floats.
    backend : "auto", "numpy" or "numba"
        ``numpy``: dense (knots x points) arrays per chunk, no extra dependency. ``numba``: the
        same formulas compiled, one pass per point that skips out-of-range knots early (about
        20x faster); ``auto`` takes numba when it is installed. Both give the same values.

    Calling it: ``field(points_log_mm (n, 3)) -> years (n,)``.
    """

    def __init__(self, log: LogSkeleton, ring_width_mm: float = 2.0, params: KnotParams | None = None,
                 *, surface_smoothing: tuple[int, int] = (11, 5), chunk: int | None = None,
                 table_samples: int = 128, backend: Backend = "auto"):
        if not isinstance(log, LogSkeleton):
            raise WoodcamError(f"log must be a woodcam.fields.skeleton.LogSkeleton; got "
                               f"{type(log).__name__}; read one with read_log or read_gran1")
        # '2' was a TypeError of '>', table_samples=0 and 1 numpy's empty-min ValueError and a
        # ZeroDivisionError, surface_smoothing=(0, -1) and chunk=0 were quietly made something else
        ring_width_mm = check_number(ring_width_mm, "ring_width_mm", lo=0, lo_open=True,
                                     fix="mm/year; spruce is about 2")
        table_samples = int(check_number(table_samples, "table_samples", lo=2, integer=True,
                                         fix="radii sampled along each knot, e.g. 128"))
        if chunk is not None:
            chunk = int(check_number(chunk, "chunk", lo=1, integer=True, fix="points per chunk, e.g. 2048, or None"))
        sm = surface_smoothing if isinstance(surface_smoothing, (tuple, list)) else ()
        if len(sm) != 2 or not all(isinstance(v, numbers.Integral) and not isinstance(v, bool) and v >= 1 for v in sm):
            raise WoodcamError(f"surface_smoothing must be two window sizes >= 1 (heights, azimuths); got "
                               f"{surface_smoothing!r}; e.g. (11, 5), or (1, 1) for none")
        self.log = log
        self.ring_width_mm = float(ring_width_mm)
        if params is not None and not isinstance(params, KnotParams):  # a dict was an AttributeError at the first call
            raise WoodcamError(f"params must be a KnotParams or None; got {type(params).__name__}; pass "
                               "KnotParams(...) or replace(KnotParams(), name=value)")
        self.params = params if params is not None else KnotParams()
        self.backend = _pick_backend(backend)
        self.chunk = int(chunk or 2048)
        self.axis = (0.0, 0.0, 1.0)
        from scipy.ndimage import uniform_filter

        # stem: relative growth speed per (height, azimuth)
        rs = uniform_filter(log.radii_mm, size=surface_smoothing, mode=("nearest", "wrap"))
        speed = rs / rs.mean(axis=1, keepdims=True)
        # stem tables on a regular height grid (the data's finest spacing), so both backends
        # find a height by index arithmetic
        zs = log.pith_z_mm
        dzmin = float(np.min(np.diff(zs)))
        nz = int(np.ceil((zs[-1] - zs[0]) / dzmin - 1e-9)) + 1
        self._z = zs[0] + dzmin * np.arange(max(nz, 2))  # may end past zs[-1]: np.interp clamps
        self._zg0, self._inv_dz = float(zs[0]), 1.0 / dzmin
        self._pxy = np.stack([np.interp(self._z, zs, log.pith_xy_mm[:, 0]),
                              np.interp(self._z, zs, log.pith_xy_mm[:, 1])], axis=1)
        self._speed = np.stack([np.interp(self._z, zs, speed[:, j])
                                for j in range(speed.shape[1])], axis=1)
        self._pith_slope = np.stack([np.gradient(self._pxy[:, 0], self._z),
                                     np.gradient(self._pxy[:, 1], self._z)], axis=1)
        self._build_knot_tables(table_samples)

    def __repr__(self) -> str:  # arrays as shapes: a notebook shows one line
        return attrs_repr(self, ('log', 'ring_width_mm', 'backend'))

    def _build_knot_tables(self, nr: int):
        kn = self.log.knots
        self.n_knots = len(kn)
        r_top = max([k.r_mm[-1] for k in kn] + [self.log.r_max_mm, 1.0])
        self._r_top = float(r_top)
        self._nr = nr
        self._dr = r_top / (nr - 1)
        r = np.linspace(0.0, r_top, nr)
        K = len(kn)
        Z = np.zeros((K, nr))
        W = np.zeros((K, nr))
        RHO = np.zeros((K, nr))
        self._r_end = np.zeros(K)
        self._r_death = np.zeros(K)
        self._zlo = np.zeros(K)
        self._zhi = np.zeros(K)
        for i, k in enumerate(kn):
            z, w = k.axis_at(r)
            Z[i], W[i] = z, w
            RHO[i] = np.maximum(k.diameter_at(r) * 0.5, 0.05) / np.maximum(r, 1.0)
            self._r_end[i] = min(k.r_end_mm, r_top)
            self._r_death[i] = k.r_death_mm
            m = r <= k.r_end_mm + self._dr
            self._zlo[i], self._zhi[i] = z[m].min(), z[m].max()
        # flat tables with one padding column so index i0 + 1 is always valid
        pad = lambda A: np.concatenate([A, A[:, -1:]], axis=1).ravel()  # noqa: E731
        self._Zf, self._Wf, self._RHOf = pad(Z), pad(W), pad(RHO)
        # cos/sin of the azimuth tabulated too (linear interpolation of them is within 1e-4
        # of the exact unit vector at 128 samples; saves two trig calls per point and knot)
        self._CWf, self._SWf = pad(np.cos(W)), pad(np.sin(W))
        rng = np.random.default_rng(12345)
        ph = rng.uniform(0, 2 * np.pi, size=(K, 3))
        self._phase = np.concatenate([np.cos(ph), np.sin(ph)], axis=1)  # (K, 6): cos, sin

    # -- public API ----------------------------------------------------------------------------

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        """Growth time ``years (n,)`` at log-frame points ``points_mm (n, 3)``."""
        return self.evaluate(points_mm)["years"]

    def stem_years(self, points_mm: ArrayLike) -> np.ndarray:
        """The stem field alone (no knots): ``years (n,)`` at log-frame points (seed eq. 1)."""
        p = check_points(points_mm, frame="log")
        _, _, ds, _, sp = self._stem(p)
        return ds / sp / self.ring_width_mm

    def ring_width_at(self, radius_mm: float) -> float:
        """Ring width (mm) at ``radius_mm`` from the pith, averaged around the log: the stem's
        rings are evenly spaced (``ring_width_mm`` at every radius; around the log they follow
        the outline's relative radius, and knots bend them locally), as
        :meth:`AnalyticLogField.ring_width_at <woodcam.fields.analytic.AnalyticLogField.ring_width_at>`
        ignores eccentricity and lobes."""
        return self.ring_width_mm

    def knot_features(self, points_mm: ArrayLike) -> dict:
        """``{"knot", "dead", "outline"}``, each ``(n,)`` in 0..1, at log-frame points."""
        out = self.evaluate(points_mm)
        return {k: out[k] for k in ("knot", "dead", "outline")}

    def grain_direction(self, points_mm: ArrayLike) -> np.ndarray:
        """Unit fibre directions ``(n, 3)`` (log frame): the pith tangent outside knots, the
        knot axis inside, blended by the knot weight."""
        return self.evaluate(points_mm, directions=True)["direction"]

    def evaluate(self, points_mm: ArrayLike, *, directions: bool = False) -> dict:
        """Everything at once for log-frame points ``(n, 3)``.

        Returns ``years``, ``knot``, ``dead``, ``outline`` (each ``(n,)``) and, with
        ``directions=True``, ``direction (n, 3)``.
        """
        p = check_points(points_mm, frame="log")
        directions = check_bool(directions, "directions")
        n = len(p)
        if self.backend == "numba" and n:
            return self._evaluate_numba(p, directions)
        order = np.argsort(p[:, 2], kind="stable")
        ps = p[order]
        keys = ["years", "knot", "dead", "outline"]
        res = {k: np.empty(n) for k in keys}
        if directions:
            res["direction"] = np.empty((n, 3))
        for s in range(0, n, self.chunk):
            pc = ps[s:s + self.chunk]
            t, kn, dd, ol, best, rb = self._eval_chunk(pc)
            sl = slice(s, s + self.chunk)
            res["years"][sl] = t / self.ring_width_mm
            res["knot"][sl], res["dead"][sl], res["outline"][sl] = kn, dd, ol
            if directions:
                res["direction"][sl] = self._directions(pc[:, 2], best, rb, kn)
        out = {}
        for k, v in res.items():
            o = np.empty_like(v)
            o[order] = v
            out[k] = o
        return out

    def _evaluate_numba(self, p, directions):
        from ._knots_numba import eval_points

        P = self.params
        n = len(p)
        # conservative bound of the pith distance of every point -> knot reach per height bin
        pr = float(np.max(np.hypot(self._pxy[:, 0], self._pxy[:, 1])))
        ds_max = float(np.sqrt(np.max(p[:, 0] ** 2 + p[:, 1] ** 2))) + pr
        bw = 20.0
        z0 = float(min(self._z[0], p[:, 2].min()))
        nb = max(1, int(np.ceil((max(self._z[-1], p[:, 2].max()) - z0) / bw)))
        lo = z0 + bw * np.arange(nb)
        reach = P.range_d1_mm + P.range_k1 * ds_max
        hit = (self._zhi[None, :] + reach >= lo[:, None]) & \
            (self._zlo[None, :] - reach <= lo[:, None] + bw)
        bin_ptr = np.concatenate([[0], np.cumsum(hit.sum(axis=1))]).astype(np.int64)
        bin_knots = np.nonzero(hit)[1].astype(np.int64)
        prm = np.array([P.k_stem, P.k_knot, P.k_transition_mm, P.death_k_rate_per_mm,
                        P.death_f_min, P.death_f_max, P.death_f_length_mm, P.butterfly,
                        P.range_d0_mm, P.range_k0, P.range_d1_mm, P.range_k1, P.knot_noise,
                        P.outline_mm, P.knot_edge_sharpness, P.death_band_mm])
        out = np.empty((5, n))
        best = np.empty(n, np.int64)
        eval_points(np.ascontiguousarray(p), self._zg0, self._inv_dz, self._pxy, self._speed,
                    z0, 1.0 / bw, bin_ptr, bin_knots, self._r_end, self._r_death, self._Zf,
                    self._CWf, self._SWf, self._RHOf, self._nr + 1, 1.0 / self._dr, self._phase,
                    prm, out,
                    best)
        res = {"years": out[0] / self.ring_width_mm, "knot": out[1], "dead": out[2],
               "outline": out[3]}
        if directions:
            res["direction"] = self._directions(p[:, 2], best, out[4], out[1])
        return res

    def knots_near(self, z_lo: float, z_hi: float, d_max: float) -> np.ndarray:
        """Indices of the knots whose influence region can reach heights ``[z_lo, z_hi]`` at
        pith distances ``<= d_max`` (the spatial culling test, exact: farther knots add 0)."""
        reach = self.params.range_d1_mm + self.params.range_k1 * d_max
        return np.nonzero((self._zhi + reach >= z_lo) & (self._zlo - reach <= z_hi))[0]

    # -- internals -----------------------------------------------------------------------------

    def _stem(self, p):
        z = p[:, 2]
        nz = len(self._z)
        fz = np.clip((z - self._zg0) * self._inv_dz, 0.0, nz - 1.0)
        iz = np.minimum(fz.astype(np.int64), nz - 2)
        tz = fz - iz
        px = self._pxy[iz, 0] + (self._pxy[iz + 1, 0] - self._pxy[iz, 0]) * tz
        py = self._pxy[iz, 1] + (self._pxy[iz + 1, 1] - self._pxy[iz, 1]) * tz
        dx = p[:, 0] - px
        dy = p[:, 1] - py
        ds = np.hypot(dx, dy)
        om = np.arctan2(dy, dx)
        sp = _bilinear_periodic(self._speed, iz, tz, om)
        return dx, dy, ds, om, sp

    def _eval_chunk(self, p):
        P = self.params
        dx, dy, ds, om, sp = self._stem(p)
        z = p[:, 2]
        ts = ds / sp
        m = len(p)
        kidx = self.knots_near(z.min(), z.max(), ds.max()) if self.n_knots else np.zeros(0, int)
        if len(kidx) == 0:
            zero = np.zeros(m)
            return ts, zero, zero, zero, np.full(m, -1), zero
        # --- pseudo-nearest branch points S_b at r = min(d_s, r_end) (seed Sec. 4.1)
        r = np.minimum(ds[None, :], self._r_end[kidx, None])            # (K, m)
        fi = r * (1.0 / self._dr)
        i0 = fi.astype(np.int64)
        f = fi - i0
        flat = i0 + (kidx * (self._nr + 1))[:, None]
        Zf, Rf = self._Zf, self._RHOf
        zb = Zf[flat] + (Zf[flat + 1] - Zf[flat]) * f
        rho = Rf[flat] + (Rf[flat + 1] - Rf[flat]) * f
        CWf, SWf = self._CWf, self._SWf
        cw = CWf[flat] + (CWf[flat + 1] - CWf[flat]) * f
        sw = SWf[flat] + (SWf[flat + 1] - SWf[flat]) * f
        bx = dx - r * cw
        by = dy - r * sw
        bz = z - zb
        db = np.sqrt(bx * bx + by * by + bz * bz)
        range1 = P.range_d1_mm + P.range_k1 * ds
        range0 = P.range_d0_mm + P.range_k0 * ds
        inr = db < range1
        # orientation beta around the knot axis: 0 = tangential, pi/2 = up (shader convention)
        tang = by * cw - bx * sw
        inv = 1.0 / np.maximum(np.hypot(tang, bz), _T_EPS)
        cb, sb = tang * inv, bz * inv
        if P.knot_noise:
            ph = self._phase[kidx]
            c2, s2 = cb * cb - sb * sb, 2 * cb * sb
            c3 = c2 * cb - s2 * sb
            s3 = s2 * cb + c2 * sb
            ce, se = np.cos(0.05 * ds), np.sin(0.05 * ds)    # phase drift along the knot
            cp3 = ph[:, 2:3] * ce - ph[:, 5:6] * se
            sp3 = ph[:, 5:6] * ce + ph[:, 2:3] * se
            noise = (0.5 * (cb * ph[:, 0:1] + sb * ph[:, 3:4])
                     + 0.3 * (c2 * ph[:, 1:2] + s2 * ph[:, 4:5])
                     + 0.2 * (c3 * cp3 + s3 * sp3))
            rho = rho * (1.0 + P.knot_noise * noise)
        vb = rho * sp
        tb = db / vb                                                      # seed eq. 1, knot
        # --- adaptive k and smooth minimum (Sec. 4.2.1, eqs. 2-3)
        tD = ts - tb
        kk = (0.5 * (P.k_knot - P.k_stem)) * tD / (P.k_transition_mm + np.abs(tD)) \
            + 0.5 * (P.k_knot + P.k_stem)
        delta, mn = _smooth_delta(ts, tb, kk)
        sm = mn + delta
        # --- dead knots (Sec. 4.2.2, eq. 5)
        Td = self._r_death[kidx, None] / sp                               # (K, m)
        # the seed switches to the dead form where smin > t_death; blending it in over
        # death_band_mm keeps the field continuous where that switch happens far from the
        # knot (a ring-parallel surface), while at the knot's bark ring the time since death is
        # large and the blend is a step narrower than the outline: the rings break there.
        wd = np.where(inr, _smoothstep((sm - Td) * (1.0 / P.death_band_mm)), 0.0)
        dead = wd > 0.0
        ta = np.where(dead, ts - Td, 0.0)
        tb2 = tb + wd * ta
        if dead.any():
            d2, _ = _smooth_delta(ts, tb + ta, kk + P.death_k_rate_per_mm * ta)
            td2 = ta * (1.0 / P.death_f_length_mm) - 1.0
            fr = P.death_f_max - P.death_f_min
            fac = 1.0 - 0.5 * fr * td2 / (0.3 + np.abs(td2)) + P.death_f_min + 0.5 * fr
            fac = 1.0 + (fac - 1.0) * (1.0 - P.butterfly * sb * sb)
            delta = np.where(dead, (1.0 - wd) * delta + wd * fac * d2, delta)
        # --- distance range of each knot: fade delta, drop the knot outside
        prog = np.clip((db - range0) / (range1 - range0), 0.0, 1.0)
        delta = np.where(inr, delta * (1.0 - prog), 0.0)
        tb2 = np.where(inr, tb2, np.inf)
        # --- join all knots (eq. 6), a knot does not smooth another knot's interior
        tbm = np.min(tb2, axis=0)
        with np.errstate(divide="ignore"):
            inv2 = np.sum(1.0 / np.maximum(tb2, _T_EPS) ** 2, axis=0)
            tb_soft = np.where(inv2 > 0, 1.0 / np.sqrt(inv2), np.inf)
        w = _smoothstep(np.where(ts > 0, (ts - tb_soft) / np.maximum(ts, _T_EPS), 0.0))
        t = np.minimum(ts, tbm) + (1.0 - w) * delta.sum(axis=0)
        # --- features (Sec. 4.3)
        L = 100.0  # the shader's time unit in mm of stem radius
        x = np.clip((1.2 * tb_soft - ts) / L, 0.001, 1.0)
        knot = 1.0 / (x + 1.0) ** P.knot_edge_sharpness
        knot = np.where(np.isfinite(tb_soft), knot, 0.0)
        inside_dead = inr & (tb < Td) & (ts > Td)
        deadf = np.max(np.where(inside_dead, np.clip(6.0 * (ts - Td) / L, 0.0, 1.0), 0.0), axis=0)
        gap = (Td - sm) * vb                                              # mm across the knot
        # the bark ring: just inside the knot's size at death, up to where the field jumps
        outl = inr & (wd < 1.0) & ((tb - Td) * vb < P.outline_mm) & \
            (self._r_death[kidx, None] < self._r_end[kidx, None])
        outline = np.max(outl & (gap <= P.outline_mm), axis=0).astype(float)
        j = np.argmin(tb2, axis=0)
        cols = np.arange(m)
        best = np.where(np.isfinite(tbm), kidx[j], -1)
        return t, knot, deadf * knot, outline, best, r[j, cols]

    def _directions(self, z, best, rbest, knot):
        """Fibre directions ``(n, 3)``: pith tangent blended into the nearest knot's axis
        tangent ``dS_b/dr`` by the knot weight."""
        stem = self._stem_dir(z)
        has = best >= 0
        if not has.any():
            return stem
        kb = np.where(has, best, 0)
        fi = rbest * (1.0 / self._dr)
        i0 = np.minimum(fi.astype(np.int64), self._nr - 1)
        fl = i0 + kb * (self._nr + 1)
        Zf, Wf = self._Zf, self._Wf
        dzdr = (Zf[fl + 1] - Zf[fl]) / self._dr
        dwdr = (Wf[fl + 1] - Wf[fl]) / self._dr
        wj = Wf[fl] + (Wf[fl + 1] - Wf[fl]) * (fi - i0)
        kd = np.stack([np.cos(wj) - rbest * np.sin(wj) * dwdr,
                       np.sin(wj) + rbest * np.cos(wj) * dwdr, dzdr], axis=1)
        kd /= np.linalg.norm(kd, axis=1, keepdims=True)
        wgt = np.where(has, knot, 0.0)[:, None]
        d = (1 - wgt) * stem + wgt * kd
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def _stem_dir(self, z):
        sx = np.interp(z, self._z, self._pith_slope[:, 0])
        sy = np.interp(z, self._z, self._pith_slope[:, 1])
        d = np.stack([sx, sy, np.ones_like(z)], axis=1)
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def with_params(self, **changes) -> "KnottedLogField":
        """A copy with some :class:`KnotParams` changed (e.g. ``k_stem=2.0``)."""
        return KnottedLogField(self.log, self.ring_width_mm, replace(self.params, **changes),
                               chunk=self.chunk, backend=self.backend)

    def to_dict(self) -> dict:
        """JSON-serialisable description (the log in its file format, ring width, parameters)."""
        return {"log": self.log.to_json(), "ring_width_mm": float(self.ring_width_mm),
                "params": asdict(self.params)}

    @classmethod
    def from_dict(cls, d: dict) -> "KnottedLogField":
        # Files written before knot shading moved to appearance/knots.py carry its two settings.
        params = {k: v for k, v in d["params"].items() if k not in _MOVED_TO_SHADING}
        return cls(LogSkeleton.from_json(d["log"]), d["ring_width_mm"], KnotParams(**params))


#: Former KnotParams settings now in :class:`woodcam.appearance.knots.KnotShading`.
_MOVED_TO_SHADING = ("alive_darkening", "dead_darkening")


from .placement import PlacedField, place_block_in_log  # noqa: E402,F401  (re-exported)


def block_at_knot(log: LogSkeleton, knot_index: int, size_mm: ArrayLike, *,
                  front_r_mm: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Placement ``(origin_mm, rotation)`` of a ``W x D x H`` block whose front face (Y = 0)
    is a tangential face of ``log`` cut through knot ``knot_index``; ``size_mm`` is that
    ``(W, D, H)`` in mm.

    The block's Z runs along the log, its Y points from the front face toward the pith, its X
    is tangential; the front face lies ``front_r_mm`` from the pith (default: where the knot
    is 10 mm short of its end or the outer radius) and is centred on the knot's crossing.
    Feed the result to :func:`place_block_in_log`.
    """
    W, D, H = (float(v) for v in size_mm)
    k = log.knots[knot_index]
    if front_r_mm is None:
        front_r_mm = max(min(k.r_end_mm, log.r_min_mm) - 10.0, D + 5.0)
    p = log.knot_point(knot_index, [front_r_mm])[0]
    c = log.pith_at([p[2]])[0]
    n = np.array([p[0] - c[0], p[1] - c[1], 0.0])
    n /= np.linalg.norm(n)
    ez = np.array([0.0, 0.0, 1.0])
    t = np.cross(-n, ez)
    R = np.stack([t, -n, ez], axis=1)          # columns: block X, Y, Z in the log frame
    centre_front = np.array([c[0], c[1], p[2]]) + front_r_mm * n
    origin = centre_front - R @ np.array([W / 2, 0.0, H / 2])
    return origin, R


def share_outside_log(log, origin, rotation, size_mm, *, samples: int = 9) -> float:
    """Share in [0, 1] of a ``W x D x H`` block placed at ``(origin, rotation)`` in ``log``
    (:func:`block_at_knot`) that lies outside the log: past its bark (:meth:`LogSkeleton.radius_at`)
    or beyond its ends, measured on a ``samples``-cubed grid of points through the block. The
    field there is extrapolated, wood no log holds."""
    axes = [np.linspace(0.0, float(s), samples) for s in size_mm]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    p = np.asarray(origin, float) + grid @ np.asarray(rotation, float).T
    z0, z1 = float(log.pith_z_mm[0]), float(log.pith_z_mm[-1])
    d = p[:, :2] - log.pith_at(p[:, 2])
    r = np.hypot(d[:, 0], d[:, 1])
    bark = log.radius_at(np.clip(p[:, 2], z0, z1), np.arctan2(d[:, 1], d[:, 0]))
    return float(np.mean((r > bark) | (p[:, 2] < z0) | (p[:, 2] > z1)))


