"""Agreement of detected ring lines with a reference ring map: precision, recall and F within k px.

The reference is the one-pixel skeleton of the map's bright ring pixels (``>= threshold``);
the detection is its trace vertices ``(n, 2)`` (row, col), at most 1 px apart. Within ``k`` px:

- precision: share of detected points within ``k`` px of a reference ridge pixel;
- recall: share of reference ridge pixels within ``k`` px of a detected point;
- F: their harmonic mean.

The chance control moves every detected point by half its local ring spacing along the local
ring normal: right spacing and direction, rings where none are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from collections.abc import Sequence

#: Reference-map grey level taken as ring (the fitter's RING_MAP_THRESHOLD, 0.5).
REFERENCE_THRESHOLD = 0.5
#: Distances (px) at which agreement is counted: the issue's 2 px and 5 px (~1 mm on a 256 px
#: face of a 50 mm cube).
SCORE_THRESHOLDS_PX = (2.0, 5.0)


def reference_ridge(ring_map: np.ndarray, threshold: float = REFERENCE_THRESHOLD,
                    exclude: np.ndarray | None = None) -> np.ndarray:
    """``(k, 2)`` int (row, col): skeleton of ``ring_map >= threshold`` minus ``exclude`` (h, w) bool."""
    from skimage import morphology

    skel = morphology.skeletonize(np.asarray(ring_map, float) >= threshold)
    if exclude is not None:
        skel &= ~np.asarray(exclude, bool)
    return np.argwhere(skel)


@dataclass
class RidgeScore:
    """Precision / recall / F (fractions in [0, 1]) per threshold ``k`` (px)."""

    precision: dict
    recall: dict
    f: dict
    n_detected: int
    n_reference: int


def ridge_scores(detected_px: np.ndarray, reference_px: np.ndarray,
                 thresholds: Sequence[float] = SCORE_THRESHOLDS_PX) -> RidgeScore:
    """Score detected points ``(n, 2)`` against reference ridge pixels ``(k, 2)`` (module docstring).

    ``detected_px``, ``reference_px``: ``(row, col)`` pixel coordinates of one face image;
    ``thresholds``: the distances (px) a point may lie from the other set and still count
    (default :data:`SCORE_THRESHOLDS_PX`, 2 and 5 px), one precision / recall / F1 each."""
    from scipy.spatial import cKDTree

    det = np.asarray(detected_px, float).reshape(-1, 2)
    ref = np.asarray(reference_px, float).reshape(-1, 2)
    both = len(ref) and len(det)
    d_det = cKDTree(ref).query(det)[0] if both else np.full(len(det), np.inf)
    d_ref = cKDTree(det).query(ref)[0] if both else np.full(len(ref), np.inf)
    p, r, f = {}, {}, {}
    for k in thresholds:
        p[k] = float(np.mean(d_det <= k)) if len(det) else 0.0
        r[k] = float(np.mean(d_ref <= k)) if len(ref) else 0.0
        f[k] = 2 * p[k] * r[k] / (p[k] + r[k]) if p[k] + r[k] > 0 else 0.0
    return RidgeScore(p, r, f, len(det), len(ref))


def shifted_half_ring(points_px: np.ndarray, normal_rad: np.ndarray, wavelength_px: np.ndarray) -> np.ndarray:
    """The chance control: ``points_px (n, 2)`` moved by half the local ring spacing along the
    local ring normal (both ``(h, w)`` maps, read at the nearest pixel)."""
    p = np.asarray(points_px, float).reshape(-1, 2)
    h, w = normal_rad.shape
    r = np.clip(np.round(p[:, 0]).astype(int), 0, h - 1)
    c = np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)
    a, lam = normal_rad[r, c], wavelength_px[r, c]
    return p + 0.5 * lam[:, None] * np.stack([np.sin(a), np.cos(a)], axis=1)
