"""Scoring the ring detector: synthetic faces with known rings, and real faces against reference maps.

- :func:`synthetic_faces` renders face photos of synthetic blocks (:func:`woodcam.synth.synth_block`,
  random logs and sawing patterns) with the true ring lines known exactly (the integer iso-lines
  of the true field, refined onto them by Newton steps);
- :func:`score_synthetic` runs :func:`~woodcam.detect.rings.detect_rings` on them and scores the
  detected ring lines against the true ones (:mod:`woodcam.detect.score`);
- :func:`score_reference_block` scores every face of a block with ring maps (e.g. a Mokume
  sample, whose U-Net maps are a reference, not truth) beside the chance control.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..frames import FACES
from .rings import BoundaryRule, detect_rings
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


def synthetic_faces(seed: int, face_px: int = 256, size_mm: float = 50.0,
                    ring_width_range_mm=(1.5, 6.0), faces=FACES) -> list[SyntheticFace]:
    """Faces of one synthetic cube of ``size_mm`` drawn from ``np.random.default_rng(seed)``:
    a random eccentric, lobed log and sawing pattern (:func:`woodcam.synth.random_log_placement`),
    photos with camera noise, exposure variation, vignetting and lens blur (synth_block defaults).
    Faces with fewer than two true rings are skipped."""
    from ..synth import PATTERNS, cut_block, random_log_placement, synth_block

    rng = np.random.default_rng(seed)
    pattern = PATTERNS[seed % len(PATTERNS)]
    size = (size_mm,) * 3
    log, placement = random_log_placement(rng, pattern, size, ring_width_range_mm)
    field = cut_block(log, size, **placement)
    block = synth_block(field, size, face_px=face_px, rng=rng, seed=None, faces=faces,
                        ring_map_faces=(), name=f"synthetic-{seed}")
    px_mm = block.meta["px_per_mm"]
    out = []
    for name, f in block.faces.items():
        if len(f.traces) < 2:
            continue
        truth = np.concatenate([_dense(t.points_px) for t in f.traces])
        out.append(SyntheticFace(f.photo, truth, px_mm, f"seed {seed} {pattern} {name}"))
    return out


def _dense(p: np.ndarray, step: float = 0.5) -> np.ndarray:
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


def score_synthetic(seeds=EVAL_SEEDS, face_px: int = 256, rule: BoundaryRule = "dark-centre",
                    detector=None) -> list[FaceResult]:
    """Detect rings on every face of the synthetic cubes of ``seeds``; score against the truth.

    ``detector``: optional callable ``(photo, px_per_mm) -> RingDetection``; default
    :func:`detect_rings` with ``rule``.
    """
    det_fn = detector or (lambda photo, ppm: detect_rings(photo, px_per_mm=ppm, rule=rule))
    results = []
    for seed in seeds:
        for sf in synthetic_faces(seed, face_px):
            t0 = time.perf_counter()
            d = det_fn(sf.photo, sf.px_per_mm)
            dt = time.perf_counter() - t0
            pts = d.points_px
            results.append(FaceResult(sf.label, ridge_scores(pts, sf.truth_px),
                                      ridge_scores(shifted_half_ring(pts, d.normal_rad, d.wavelength_px), sf.truth_px),
                                      dt, d.warnings))
    return results


def score_reference_block(block, rule: BoundaryRule = "dark-centre", detector=None) -> list[FaceResult]:
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
