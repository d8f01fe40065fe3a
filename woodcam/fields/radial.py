"""The seed's radial-scaling growth fields (eq. 7-9 of seed 000), placed rigidly in a block.

In the log frame (``z`` on the pith, see :class:`~woodcam.fields.base.LogFrame`) the field is

    years = age_offset + rho / (ring_width_mm * r'(phi, zeta))                    (eq. 8)
    r'(phi, zeta) = (1 - (zeta + 1) / 2) r_-1(phi) + (zeta + 1) / 2 r_1(phi)      (eq. 9)

with ``rho = sqrt(x^2 + y^2)``, ``phi`` the angle from ``(0, 1)`` to ``(x, y)`` (eq. 7) and
``zeta = z / half_length_mm`` in ``[-1, 1]`` (clamped beyond the ends, so the blend never
extrapolates). ``r_-1`` and ``r_1`` are smooth periodic radius-scaling functions, 1 on average:
a value 1.1 means rings 10 % wider in that direction. Growth time is 0 on the pith and grows
outward by one year every ``ring_width_mm * r'`` mm.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numba
import numpy as np

from .._checks import check_number, received
from .._repr import summary_repr
from .._types import ArrayLike
from ..errors import WoodcamError
from ..tolerances import MIN_RADIUS_SCALE
from .base import LogFrame, check_points

_TWO_PI = 2.0 * np.pi


@functools.lru_cache(maxsize=8)
def laplacian_smoother(n_constraints: int, m: int = 360) -> np.ndarray:
    """``(m, n_constraints)`` linear map from constraint values to radius samples.

    The samples minimise the squared periodic discrete Laplacian
    ``sum (r[i-1] - 2 r[i] + r[i+1])^2`` subject to ``r(2 pi i / N_c) = values[i]`` exactly
    (Laplacian smoothing of §3.2.5 of seed 000). The solution is linear in the constraint
    values, so it is solved once per ``(N_c, m)`` and applied with a matrix product. Constraint
    angles are rounded to the nearest of the ``m`` samples.
    """
    idx = np.round(np.arange(n_constraints) * m / n_constraints).astype(int) % m
    if len(np.unique(idx)) != n_constraints:
        raise WoodcamError(f"m={m} samples cannot hold {n_constraints} distinct constraints; raise m")
    eye = np.eye(m)
    lap = np.roll(eye, -1, axis=1) - 2 * eye + np.roll(eye, 1, axis=1)
    free = np.setdiff1d(np.arange(m), idx)
    a = np.zeros((m, n_constraints))
    a[idx, np.arange(n_constraints)] = 1.0
    if len(free):
        from .._threads import one_blas_thread

        with one_blas_thread():  # a small system: threads only spin (woodcam._threads)
            a[free] = -np.linalg.lstsq(lap[:, free], lap[:, idx], rcond=None)[0]
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class RadiusFunction:
    """Smooth periodic radius scaling ``r(phi)``, stored as samples on a uniform periodic grid.

    Attributes
    ----------
    samples : (m,) float
        ``r`` at ``phi = 2 pi i / m``, ``i = 0 .. m-1``; evaluated by periodic linear
        interpolation (m = 360 makes the interpolation error negligible next to the smoothing).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    samples: np.ndarray

    @classmethod
    def constant(cls, value: float = 1.0, m: int = 360) -> "RadiusFunction":
        return cls(np.full(m, float(value)))

    @classmethod
    def from_constraints(cls, values, m: int = 360) -> "RadiusFunction":
        """Laplacian smoothing through ``N_c`` equally spaced constraints (§3.2.5 of seed 000).

        The samples minimise the squared discrete Laplacian ``sum (r[i-1] - 2 r[i] + r[i+1])^2``
        around the circle subject to ``r(2 pi i / N_c) = values[i]`` exactly, which gives a
        smooth (C1, spline-like) periodic curve through the constraints. The constraint angles
        are rounded to the nearest of the ``m`` samples.
        """
        c = np.asarray(values, dtype=float).ravel()
        if len(c) < 1 or np.any(~np.isfinite(c)) or np.any(c <= 0):
            raise WoodcamError(f"values must be positive finite radius scalings; got {received(values)}")
        return cls(laplacian_smoother(len(c), m) @ c)

    @classmethod
    def random(cls, rng: np.random.Generator, n_constraints: int = 15, sigma: float = 0.1,
               m: int = 360) -> "RadiusFunction":
        """Random radius function: constraints from ``N(1, sigma)`` (seed 000: N_c=15, sigma=0.1)."""
        vals = np.clip(rng.normal(1.0, sigma, n_constraints), 0.5, 1.5)
        return cls.from_constraints(vals, m)

    def __call__(self, phi: ArrayLike) -> np.ndarray:
        """Evaluate at angles ``phi`` (radians, any shape)."""
        s = self.samples
        m = len(s)
        t = np.mod(np.asarray(phi, dtype=float), _TWO_PI) * (m / _TWO_PI)
        i0 = np.floor(t).astype(np.int64)
        f = t - i0
        i0 %= m
        return s[i0] * (1.0 - f) + s[(i0 + 1) % m] * f


def random_log_frame(rng: np.random.Generator, size_mm: ArrayLike = (50.0, 50.0, 50.0)) -> LogFrame:
    """A pith axis for the eq. 7-9 benchmark family of seed 000: tilted <= 20 degrees from a
    random block axis, passing 0-60 mm from the centre of a block of ``size_mm`` (so often
    outside it). Draws from ``rng`` in a fixed order (benchmarks and tests rely on it)."""
    size = np.asarray(size_mm, float)
    base = np.eye(3)[rng.integers(3)]
    tilt = np.deg2rad(rng.uniform(0, 20))
    perp = np.cross(base, rng.normal(size=3))
    perp /= np.linalg.norm(perp)
    axis = np.cos(tilt) * base + np.sin(tilt) * perp
    off = np.cross(axis, rng.normal(size=3))
    off /= np.linalg.norm(off)
    pith = size / 2 + off * rng.uniform(0, 60) + axis * rng.uniform(-20, 20)
    return LogFrame(tuple(pith), tuple(axis))


@dataclass(frozen=True)
class RadialScalingField:
    """Growth-time field of eq. 7-9 of seed 000, in mm and years, placed by a rigid transform.

    Parameters
    ----------
    frame : LogFrame
        Where the pith axis sits in the block frame (any point, any direction; the pith may lie
        outside the block).
    ring_width_mm : float
        Mean ring width (mm per year) where ``r' = 1``.
    r_minus, r_plus : RadiusFunction
        Radius scaling at log-frame ``z = -half_length_mm`` and ``z = +half_length_mm``.
    half_length_mm : float
        Half the axial length over which the two radius functions are blended.
    age_offset_years : float
        Growth time at the pith (0 for a real pith).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    frame: LogFrame
    ring_width_mm: float = 3.0
    r_minus: RadiusFunction = RadiusFunction.constant()
    r_plus: RadiusFunction = RadiusFunction.constant()
    half_length_mm: float = 100.0
    age_offset_years: float = 0.0

    def __post_init__(self):
        # the frame and radius functions are read only at the first call: None was an
        # AttributeError there, a plain array for r_minus one too ('has no attribute samples')
        if not isinstance(self.frame, LogFrame):
            raise WoodcamError(f"frame must be a woodcam.fields.LogFrame; got {type(self.frame).__name__}; "
                               "pass e.g. LogFrame(pith_point_mm=(50, -30, 0), axis=(0, 0, 1))")
        for name in ("r_minus", "r_plus"):
            if not isinstance(getattr(self, name), RadiusFunction):
                raise WoodcamError(f"{name} must be a RadiusFunction; got {type(getattr(self, name)).__name__}; "
                                   f"pass RadiusFunction(samples) or RadiusFunction.constant()")
        # '3' was a TypeError of np.isfinite; a NaN age offset made every year NaN, silently
        check_number(self.ring_width_mm, "ring_width_mm", lo=0, lo_open=True, fix="mm per year, e.g. 3.0")
        check_number(self.half_length_mm, "half_length_mm", lo=0, lo_open=True, fix="mm, e.g. 100.0")
        check_number(self.age_offset_years, "age_offset_years", fix="growth years at the pith, 0 for a real pith")

    @property
    def axis(self) -> np.ndarray:
        """Pith direction in the block frame, (3,) unit."""
        return self.frame.rotation[2]

    def radius_scale(self, phi: ArrayLike, zeta: ArrayLike) -> np.ndarray:
        """``r'(phi, zeta)`` of eq. 9, ``zeta`` clamped to [-1, 1]."""
        w = (np.clip(zeta, -1.0, 1.0) + 1.0) * 0.5
        r = (1.0 - w) * self.r_minus(phi) + w * self.r_plus(phi)
        return np.maximum(r, MIN_RADIUS_SCALE)

    def __call__(self, points_mm: ArrayLike) -> np.ndarray:
        """Growth time ``years : (n,)`` at ``points_mm : (n, 3)`` (block frame, mm)."""
        p = np.ascontiguousarray(check_points(points_mm))
        f = self.frame
        return _radial_kernel(p, np.asarray(f.pith_point_mm, float), f.rotation,
                              self.r_minus.samples, self.r_plus.samples, float(self.half_length_mm),
                              float(self.ring_width_mm), float(self.age_offset_years),
                              MIN_RADIUS_SCALE)

    def grain_direction(self, points_mm: ArrayLike) -> np.ndarray:
        """Fibres run along the straight pith: the axis at every point, (n, 3)."""
        return np.broadcast_to(self.axis, check_points(points_mm).shape)

    def to_dict(self) -> dict:
        """JSON-serialisable description; :meth:`from_dict` restores it exactly."""
        f = self.frame
        return {
            "type": "radial",
            "pith_point_mm": list(map(float, f.pith_point_mm)),
            "axis": list(map(float, f.axis)),
            "reference": None if f.reference is None else list(map(float, f.reference)),
            "ring_width_mm": float(self.ring_width_mm),
            "r_minus": self.r_minus.samples.tolist(),
            "r_plus": self.r_plus.samples.tolist(),
            "half_length_mm": float(self.half_length_mm),
            "age_offset_years": float(self.age_offset_years),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "RadialScalingField":
        frame = LogFrame(tuple(d["pith_point_mm"]), tuple(d["axis"]),
                         None if d.get("reference") is None else tuple(d["reference"]))
        return cls(frame, d["ring_width_mm"], RadiusFunction(np.asarray(d["r_minus"])),
                   RadiusFunction(np.asarray(d["r_plus"])), d["half_length_mm"],
                   d.get("age_offset_years", 0.0))

    @classmethod
    def random(cls, frame: LogFrame, ring_width_mm: float, rng: np.random.Generator, *,
               sigma: float = 0.1, half_length_mm: float = 100.0) -> "RadialScalingField":
        """A random member of the family (the training distribution of §3.2.5 of seed 000)."""
        return cls(frame, ring_width_mm, RadiusFunction.random(rng, sigma=sigma),
                   RadiusFunction.random(rng, sigma=sigma), half_length_mm)


@numba.njit(nogil=True, fastmath=True, cache=True)
def _radial_kernel(p, origin, rot, r_minus, r_plus, half_length, ring_width, age_offset,
                   min_scale):  # pragma: no cover - compiled
    """Eq. 7-9 per point in one compiled pass (numpy needed ~15 array temporaries a call and
    was the bottleneck of colour lookup). Same maths as :meth:`RadialScalingField.radius_scale`."""
    n = p.shape[0]
    m = r_minus.shape[0]
    out = np.empty(n)
    two_pi = 2.0 * np.pi
    for i in range(n):
        dx, dy, dz = p[i, 0] - origin[0], p[i, 1] - origin[1], p[i, 2] - origin[2]
        x = rot[0, 0] * dx + rot[0, 1] * dy + rot[0, 2] * dz
        y = rot[1, 0] * dx + rot[1, 1] * dy + rot[1, 2] * dz
        z = rot[2, 0] * dx + rot[2, 1] * dy + rot[2, 2] * dz
        rho = np.sqrt(x * x + y * y)
        phi = np.arctan2(x, y)  # angle from (0, 1) to (x, y), eq. 7
        t = (phi % two_pi) * (m / two_pi)
        i0 = int(np.floor(t))
        f = t - i0
        i0 = i0 % m
        i1 = (i0 + 1) % m
        rm = r_minus[i0] * (1.0 - f) + r_minus[i1] * f
        rp = r_plus[i0] * (1.0 - f) + r_plus[i1] * f
        w = (min(max(z / half_length, -1.0), 1.0) + 1.0) * 0.5  # eq. 9, clamped at the ends
        r = max((1.0 - w) * rm + w * rp, min_scale)
        out[i] = age_offset + rho / (ring_width * r)
    return out
