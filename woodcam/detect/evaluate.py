"""Scoring the ring detector: synthetic faces with known rings, and real faces against reference maps.

- :func:`score_synthetic` runs :func:`~woodcam.detect.rings.detect_rings` on faces with known
  rings (:class:`SyntheticFace`, rendered by :func:`woodcam.synth.ring_eval_faces` from synthetic
  blocks: the true ring lines are the integer iso-lines of the true field) and scores the
  detected ring lines against the true ones (:mod:`woodcam.detect.score`);
- :func:`score_reference_block` scores every face of a block with ring maps (e.g. a Mokume
  sample, whose U-Net maps are a reference, not truth) beside the chance control.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .rings import DEFAULT_RULE, BoundaryRule, detect_rings
from .score import (
    SCORE_THRESHOLDS_PX,
    RidgeScore,
    reference_ridge,
    ridge_scores,
    shifted_half_ring,
)

#: Seeds of the synthetic evaluation faces. The detector's constants were set by looking at
#: other seeds (0-9) and the real faces; these are never used for that.
EVAL_SEEDS = tuple(range(1000, 1008))


@dataclass
class SyntheticFace:
    """One rendered face: ``photo (h, w, 3) uint8``, true ring points ``truth_px (n, 2)`` (row, col)
    every <= 1 px along the true ring lines, ``px_per_mm``, and where it came from."""

    photo: np.ndarray
    truth_px: np.ndarray
    px_per_mm: float
    label: str


def dense_polyline(p: np.ndarray, step: float = 0.5) -> np.ndarray:
    """Points every ``step`` px along a polyline ``(k, 2)`` (row, col), ends kept."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], max(2, int(np.ceil(s[-1] / step)) + 1))
    return np.stack([np.interp(t, s, p[:, 0]), np.interp(t, s, p[:, 1])], axis=1)


@dataclass
class FaceResult:
    label: str
    score: RidgeScore
    chance: RidgeScore
    seconds: float
    warnings: list


def _mean(results, key: str, k: float) -> float:
    return float(np.mean([getattr(getattr(r, key.split(".")[0]), key.split(".")[1])[k] for r in results]))


def summary(results: list[FaceResult], thresholds=SCORE_THRESHOLDS_PX) -> dict:
    """Mean precision / recall / F per threshold, and the chance control's mean F."""
    out = {}
    for k in thresholds:
        out[f"P@{k:g}"] = _mean(results, "score.precision", k)
        out[f"R@{k:g}"] = _mean(results, "score.recall", k)
        out[f"F@{k:g}"] = _mean(results, "score.f", k)
        out[f"chance F@{k:g}"] = _mean(results, "chance.f", k)
    out["seconds"] = float(np.mean([r.seconds for r in results]))
    return out


def score_synthetic(faces: list[SyntheticFace], rule: BoundaryRule = DEFAULT_RULE,
                    detector=None) -> list[FaceResult]:
    """Detect rings on synthetic ``faces`` (e.g. :func:`woodcam.synth.ring_eval_faces` of
    :data:`EVAL_SEEDS`); score against their true ring lines.

    ``detector``: optional callable ``(photo, px_per_mm) -> RingDetection``; default
    :func:`detect_rings` with ``rule``.
    """
    det_fn = detector or (lambda photo, ppm: detect_rings(photo, px_per_mm=ppm, rule=rule))
    results = []
    for sf in faces:
        t0 = time.perf_counter()
        d = det_fn(sf.photo, sf.px_per_mm)
        dt = time.perf_counter() - t0
        pts = d.points_px
        results.append(FaceResult(sf.label, ridge_scores(pts, sf.truth_px),
                                  ridge_scores(shifted_half_ring(pts, d.normal_rad, d.wavelength_px), sf.truth_px),
                                  dt, d.warnings))
    return results


def score_reference_block(block, rule: BoundaryRule = DEFAULT_RULE, detector=None) -> list[FaceResult]:
    """Detect rings on each face of ``block`` that has a photo and a ring map; score against the
    map's ridge (knot masks, grown by the fitter's margin, are left out of both)."""
    from scipy import ndimage

    from ..tolerances import KNOT_MASK_MARGIN_MM

    det_fn = detector or (lambda photo, ppm: detect_rings(photo, px_per_mm=ppm, rule=rule))
    results = []
    for name, f in block.faces.items():
        if f.photo is None or f.ring_map is None:
            continue
        px_mm = min(block.face_pixel_size_mm(name))
        excl = None
        mask = f.extras.get("knot_mask")
        if mask is not None and np.any(mask):
            excl = ndimage.distance_transform_edt(~np.asarray(mask, bool)) * px_mm <= KNOT_MASK_MARGIN_MM
        t0 = time.perf_counter()
        d = det_fn(f.photo, 1.0 / px_mm)
        dt = time.perf_counter() - t0
        ref = reference_ridge(f.ring_map, exclude=excl)
        pts = d.points_px
        if excl is not None and len(pts):
            h, w = f.shape
            keep = ~excl[np.clip(np.round(pts[:, 0]).astype(int), 0, h - 1),
                         np.clip(np.round(pts[:, 1]).astype(int), 0, w - 1)]
            pts = pts[keep]
        results.append(FaceResult(f"{block.name} {name}", ridge_scores(pts, ref),
                                  ridge_scores(shifted_half_ring(pts, d.normal_rad, d.wavelength_px), ref),
                                  dt, d.warnings))
    return results


def results_table(results: list[FaceResult], thresholds=SCORE_THRESHOLDS_PX) -> str:
    """Markdown: one row per face (P / R / F per threshold, chance F, seconds) and the mean."""
    ks = [f"{k:g}" for k in thresholds]
    head = (["face"] + [f"{m} ≤{k} px" for k in ks for m in ("P", "R", "F")]
            + [f"chance F ≤{k} px" for k in ks] + ["s"])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in results:
        cells = [r.label]
        for k in thresholds:
            cells += [f"{r.score.precision[k]:.2f}", f"{r.score.recall[k]:.2f}", f"{r.score.f[k]:.2f}"]
        cells += [f"{r.chance.f[k]:.2f}" for k in thresholds] + [f"{r.seconds:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    s = summary(results, thresholds)
    cells = ["**mean**"]
    for k in ks:
        cells += [f"{s[f'P@{k}']:.2f}", f"{s[f'R@{k}']:.2f}", f"**{s[f'F@{k}']:.2f}**"]
    cells += [f"{s[f'chance F@{k}']:.2f}" for k in ks] + [f"{s['seconds']:.2f}"]
    lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
