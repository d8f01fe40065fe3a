"""Knot masks: an analytic knot (dark disc with its own rings), a dark straight band, H11's knots."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.detect import detect_rings
from woodcam.detect.knots import detect_knots

from .test_detect_rings import _mokume


def _face_with_knot(n=192, centre=(120, 70), radius=30.0, seed=0):
    """Straight rings (dark lines every 12 px) and a dark disc whose own rings circle its centre."""
    rng = np.random.default_rng(seed)
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    d = cc - 12 * np.round(cc / 12)
    lum = 0.75 - 0.2 * np.exp(-(d / 1.6) ** 2)
    rho = np.hypot(rr - centre[0], cc - centre[1])
    inside = rho < radius
    k = rho - 6 * np.round(rho / 6)
    lum = np.where(inside, 0.45 - 0.12 * np.exp(-(k / 1.2) ** 2), lum)
    lum += 0.015 * rng.standard_normal(lum.shape)
    photo = np.clip(np.repeat(lum[..., None], 3, axis=2) * 255, 0, 255).astype(np.uint8)
    return photo, inside


def test_analytic_knot_found_and_straight_dark_band_not():
    photo, truth = _face_with_knot()
    det = detect_rings(photo, px_per_mm=5.0)
    mask = detect_knots(photo, 5.0, det.normal_rad)
    iou = (mask & truth).sum() / (mask | truth).sum()
    assert iou >= 0.7, iou
    # a dark band of the same size that the rings run straight through is no knot
    band = photo.copy()
    band[90:150, :] = (band[90:150, :].astype(float) * 0.6).astype(np.uint8)
    lines, _ = _face_with_knot(radius=0.0)
    lines[90:150, 40:100] = (lines[90:150, 40:100].astype(float) * 0.6).astype(np.uint8)
    det = detect_rings(lines, px_per_mm=5.0)
    assert not detect_knots(lines, 5.0, det.normal_rad).any()


#: H11's knot masks (read_mokume grows the single marked pixel into the photo's dark disc).
#: Measured IoU: left (C) 0.97, back (F) 0.82 (README); the knot thresholds were chosen
#: looking at these two faces, so this checks the code still does what was measured.
H11_KNOT_IOU = 0.7


def test_h11_knot_masks_iou():
    from woodcam.block.io import read_mokume

    b = read_mokume(_mokume("H11"))
    # the two faces whose knot the Mokume data marks; without them the loop below checks nothing
    marked = {name for name, f in b.faces.items() if f.extras.get("knot_mask") is not None}
    assert marked == {"left", "back"}, marked
    for name, f in b.faces.items():
        det = detect_rings(f.photo, px_per_mm=256 / 50)
        mask = detect_knots(f.photo, 256 / 50, det.normal_rad)
        ref = f.extras.get("knot_mask")
        if ref is None:  # no knot marked: none found (measured 0 px on all four faces)
            assert not mask.any(), (name, int(mask.sum()))
            continue
        iou = (mask & ref).sum() / (mask | ref).sum()
        assert iou >= H11_KNOT_IOU, (name, iou)


@pytest.mark.slow
def test_no_knots_on_cn03():
    from woodcam.block.io import read_mokume

    b = read_mokume(_mokume("CN03"))
    for f in b.faces.values():
        det = detect_rings(f.photo, px_per_mm=256 / 50)
        assert not detect_knots(f.photo, 256 / 50, det.normal_rad).any()
