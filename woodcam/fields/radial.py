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

from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError
from ..tolerances import MIN_RADIUS_SCALE
from .base import LogFrame, check_points

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class RadiusFunction:
    """Smooth periodic radius scaling ``r(phi)``, stored as samples on a uniform periodic grid.

    Attributes
    ----------
    samples : (m,) float
        ``r`` at ``phi = 2 pi i / m``, ``i = 0 .. m-1``; evaluated by periodic linear
        interpolation (m = 360 makes the interpolation error negligible next to the smoothing).
    """

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
            raise WoodcamError(f"values must be positive finite radius scalings; got {values!r}")
        idx = np.unique(np.round(np.arange(len(c)) * m / len(c)).astype(int) % m)
        if len(idx) != len(c):
            raise WoodcamError(f"m={m} samples cannot hold {len(c)} distinct constraints; raise m")
        # Periodic second-difference operator L (m x m); solve min |L r|^2 s.t. r[idx] = c by
        # eliminating the constrained unknowns: L[:, free] r_free = -L[:, idx] c.
        eye = np.eye(m)
        lap = np.roll(eye, -1, axis=1) - 2 * eye + np.roll(eye, 1, axis=1)
        free = np.setdiff1d(np.arange(m), idx)
        r = np.empty(m)
        r[idx] = c
        if len(free):
            r[free] = np.linalg.lstsq(lap[:, free], -lap[:, idx] @ c, rcond=None)[0]
        return cls(r)

    @classmethod
    def random(cls, rng: np.random.Generator, n_constraints: int = 15, sigma: float = 0.1,
               m: int = 360) -> "RadiusFunction":
        """Random radius function: constraints from ``N(1, sigma)`` (seed 000: N_c=15, sigma=0.1)."""
        vals = np.clip(rng.normal(1.0, sigma, n_constraints), 0.5, 1.5)
        return cls.from_constraints(vals, m)

    def __call__(self, phi) -> np.ndarray:
        """Evaluate at angles ``phi`` (radians, any shape)."""
        s = self.samples
        m = len(s)
        t = np.mod(np.asarray(phi, dtype=float), _TWO_PI) * (m / _TWO_PI)
        i0 = np.floor(t).astype(np.int64)
        f = t - i0
        i0 %= m
        return s[i0] * (1.0 - f) + s[(i0 + 1) % m] * f


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

    frame: LogFrame
    ring_width_mm: float = 3.0
    r_minus: RadiusFunction = RadiusFunction.constant()
    r_plus: RadiusFunction = RadiusFunction.constant()
    half_length_mm: float = 100.0
    age_offset_years: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.ring_width_mm) and self.ring_width_mm > 0):
            raise WoodcamError(f"ring_width_mm must be > 0 mm; got {self.ring_width_mm!r}")
        if not (np.isfinite(self.half_length_mm) and self.half_length_mm > 0):
            raise WoodcamError(f"half_length_mm must be > 0 mm; got {self.half_length_mm!r}")

    @property
    def axis(self) -> np.ndarray:
        """Pith direction in the block frame, (3,) unit."""
        return self.frame.rotation[2]

    def radius_scale(self, phi, zeta) -> np.ndarray:
        """``r'(phi, zeta)`` of eq. 9, ``zeta`` clamped to [-1, 1]."""
        w = (np.clip(zeta, -1.0, 1.0) + 1.0) * 0.5
        r = (1.0 - w) * self.r_minus(phi) + w * self.r_plus(phi)
        return np.maximum(r, MIN_RADIUS_SCALE)

    def __call__(self, points_mm) -> np.ndarray:
        """Growth time ``years : (n,)`` at ``points_mm : (n, 3)`` (block frame, mm)."""
        q = self.frame.to_log(check_points(points_mm))
        x, y, z = q[:, 0], q[:, 1], q[:, 2]
        rho = np.hypot(x, y)
        phi = np.arctan2(x, y)  # angle from (0, 1) to (x, y), eq. 7
        r = self.radius_scale(phi, z / self.half_length_mm)
        return self.age_offset_years + rho / (self.ring_width_mm * r)

    def grain_direction(self, points_mm) -> np.ndarray:
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
