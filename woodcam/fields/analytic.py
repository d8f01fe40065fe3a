"""A knot-free analytic log in its own frame: eccentric, lobed rings of slowly varying width.

The log frame has ``z`` on the pith (mm). :func:`woodcam.synth.cut_block` places such a field in
a block; any other log-frame field (e.g. ``KnottedLogField``) works there too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError
from .base import check_points


@dataclass(frozen=True)
class AnalyticLogField:
    """A knot-free log in its own frame (mm; ``z`` on the pith), as a growth-time field.

    Rings are slightly eccentric, slightly lobed and have a ring width that varies slowly with
    the distance from the pith::

        r_eff = r (1 - e cos(theta - theta_e)) (1 + a cos(k theta + phi))
        w(r)  = w0 (1 + s r_eff)                      ring width (mm) at radius r_eff
        years = ln(1 + s r_eff) / (w0 s)   (= r_eff / w0 when s = 0)

    so ``d years / d r_eff = 1 / w(r_eff)``. Years are 0 on the pith.

    Parameters
    ----------
    ring_width_mm : float
        ``w0``, ring width at the pith (mm).
    width_slope_per_mm : float
        ``s``: relative change of ring width per mm of radius; ``1 + s r`` is clamped at 0.05
        for negative ``s`` far from the pith.
    eccentricity, eccentric_azimuth_deg : float
        ``e`` in [0, 0.5): rings are wider towards ``theta_e``.
    lobe_amplitude, lobes, lobe_phase_deg : float, int, float
        ``a``, ``k``, ``phi``: non-circular rings.
    """

    ring_width_mm: float = 3.0
    width_slope_per_mm: float = 0.0
    eccentricity: float = 0.0
    eccentric_azimuth_deg: float = 0.0
    lobe_amplitude: float = 0.0
    lobes: int = 3
    lobe_phase_deg: float = 0.0

    #: Fibre direction in the log frame (straight stem).
    axis = (0.0, 0.0, 1.0)

    def __post_init__(self):
        if not self.ring_width_mm > 0:
            raise WoodcamError(f"ring_width_mm must be > 0 mm; got {self.ring_width_mm!r}")
        if not 0 <= self.eccentricity < 0.5:
            raise WoodcamError(f"eccentricity must be in [0, 0.5); got {self.eccentricity!r}")
        if not 0 <= self.lobe_amplitude < 0.5:
            raise WoodcamError(f"lobe_amplitude must be in [0, 0.5); got {self.lobe_amplitude!r}")

    def __call__(self, points_log_mm) -> np.ndarray:
        """Growth time ``(n,)`` in years at log-frame points ``(n, 3)`` mm."""
        p = check_points(points_log_mm, "points_log_mm", frame="log")
        x, y = p[:, 0], p[:, 1]
        r = np.hypot(x, y)
        th = np.arctan2(y, x)
        r_eff = r * (1.0 - self.eccentricity * np.cos(th - math.radians(self.eccentric_azimuth_deg)))
        r_eff *= 1.0 + self.lobe_amplitude * np.cos(self.lobes * th + math.radians(self.lobe_phase_deg))
        s = self.width_slope_per_mm
        if abs(s) < 1e-12:
            return r_eff / self.ring_width_mm
        return np.log(np.maximum(1.0 + s * r_eff, 0.05)) / (self.ring_width_mm * s)

    def ring_width_at(self, radius_mm: float) -> float:
        """Ring width (mm) at ``radius_mm`` from the pith (ignoring eccentricity and lobes)."""
        return self.ring_width_mm * max(1.0 + self.width_slope_per_mm * radius_mm, 0.05)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    @classmethod
    def from_dict(cls, d: dict) -> AnalyticLogField:
        return cls(**d)
