"""Human-like faults of ring annotation: dropped pieces, hand wobble, wrong or missing years."""

from __future__ import annotations

import math

import numpy as np

from ..block import RingTrace
from ..errors import WoodcamError
from .traces import _runs


def _arc_mm(p: np.ndarray, px_mm: tuple[float, float]) -> np.ndarray:
    """Cumulative arc length (mm) along a pixel polyline ``p (k, 2)``."""
    d = np.diff(p, axis=0) * np.asarray(px_mm)
    return np.concatenate([[0.0], np.cumsum(np.hypot(d[:, 0], d[:, 1]))])


def _dropout(traces, px_mm, fraction: float, chunk_mm: float, rng) -> list[RingTrace]:
    """Remove random pieces of ``chunk_mm`` arc length, each with probability ``fraction``."""
    out = []
    for t in traces:
        s = _arc_mm(t.points_px, px_mm)
        chunk = np.floor(s / chunk_mm + rng.uniform()).astype(int)
        keep = rng.uniform(size=chunk.max() + 1) >= fraction
        for a, b in _runs(keep[chunk]):
            if b - a >= 2:
                out.append(RingTrace(t.points_px[a:b], t.year))
    return out


def _jitter(traces, px_mm, sigma_mm: float, corr_mm: float, rng) -> list[RingTrace]:
    """Move every vertex along the trace's normal by Gaussian noise of std ``sigma_mm``.

    The noise is smoothed along the trace with a Gaussian of ``corr_mm`` (a hand wobbles, it
    does not shake) and rescaled so its marginal std stays ``sigma_mm``.
    """
    from scipy.ndimage import gaussian_filter1d

    scale = np.asarray(px_mm)
    out = []
    for t in traces:
        p_mm = t.points_px * scale
        tan = np.gradient(p_mm, axis=0)
        nrm = np.stack([-tan[:, 1], tan[:, 0]], axis=1)
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
        e = rng.standard_normal(len(p_mm))
        if corr_mm > 0 and len(p_mm) > 2:
            step = max(_arc_mm(t.points_px, px_mm)[-1] / (len(p_mm) - 1), 1e-9)
            s = corr_mm / step
            imp = np.zeros(int(8 * s) | 1)
            imp[len(imp) // 2] = 1.0
            kern = gaussian_filter1d(imp, s, mode="constant")
            e = gaussian_filter1d(e, s, mode="reflect") / math.sqrt(max((kern ** 2).sum(), 1e-12))
        out.append(RingTrace((p_mm + (sigma_mm * e)[:, None] * nrm) / scale, t.year))
    return out


def _check_fraction(name: str, value: float) -> float:
    if not 0.0 <= value <= 1.0:
        raise WoodcamError(f"{name} must be a fraction in [0, 1]; got {value!r}")
    return float(value)


def _mislabel(traces, mislabel_fraction: float, unlabelled_fraction: float, rng) -> list[RingTrace]:
    """Shift a fraction of traces' years by +-1 and drop the year of another fraction."""
    u = rng.uniform(size=(len(traces), 2))
    sign = rng.choice([-1, 1], size=len(traces))
    return [RingTrace(t.points_px, None if u[i, 1] < unlabelled_fraction
                      else t.year + int(sign[i]) if u[i, 0] < mislabel_fraction else t.year)
            for i, t in enumerate(traces)]
