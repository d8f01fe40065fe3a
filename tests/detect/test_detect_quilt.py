"""Texture by numbers (woodcam.detect.quilt): a real face's rings copied onto a synthetic face's
true rings, the ring boundary onto the boundary."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.detect.quilt import phase_profile, quilt_face, quilt_source, steepest_fall


def _ring_profile(phi: np.ndarray) -> np.ndarray:
    """An asymmetric ring in [0, 1] by its phase (cycles): a steep fall at phase 0 into a dark
    band, then a slow rise back to light over the rest of the ring."""
    f = np.mod(phi, 1.0)
    return np.where(f < 0.08, 0.8 - 0.5 * f / 0.08, 0.3 + 0.5 * (f - 0.08) / 0.92)


def _stand_in(direction: float, seed=0, n=192, spacing=13.0, angle_deg=25.0):
    """A 'real' face with straight rings whose phase is known (``direction`` +1 or -1: the
    ring's steep fall faces one way or the other across the face), plus speckle."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:n, 0:n].astype(float)
    a = np.radians(angle_deg)
    phi = (r * np.sin(a) + c * np.cos(a)) / spacing + 0.37
    lum = _ring_profile(direction * phi) + 0.04 * rng.standard_normal((n, n))
    photo = np.clip(np.stack([lum * 0.95, lum * 0.8, lum * 0.6], -1) * 255, 0, 255).astype(np.uint8)
    return photo


@pytest.mark.parametrize("direction", [1.0, -1.0])
@pytest.mark.parametrize("anchor", ["lines", "fall"])
def test_quilted_face_puts_the_source_ring_boundary_on_the_true_one(direction, anchor):
    """Either way round, the copied ring lies on the target's rings with its own profile:
    ``"fall"`` puts the source's steepest fall on the true ring line, ``"lines"`` the classical
    detector's ring line (the end of the dark band, within a pixel of its darkest line)."""
    photo = _stand_in(direction)
    src = quilt_source(photo, anchor=anchor)
    assert src.valid.mean() > 0.5
    # the target: curved rings of another spacing and orientation (growth time in years)
    r, c = np.mgrid[0:128, 0:160].astype(float)
    years = np.hypot(r - 260.0, c + 40.0) / 9.0
    img, share = quilt_face(years, src, np.random.default_rng(1))
    assert img.shape == (128, 160, 3) and img.dtype == np.uint8 and share > 0.9
    lum = img.astype(float).mean(-1) / 255
    prof = phase_profile(lum, years)
    truth = _ring_profile((np.arange(32) + 0.5) / 32)
    best = max(range(-6, 7), key=lambda k: np.corrcoef(np.roll(truth, k), prof)[0, 1])
    assert np.corrcoef(np.roll(truth, best), prof)[0, 1] > 0.9, prof
    at, fall, rise = steepest_fall(prof)
    assert -fall > 2 * rise, (at, fall, rise)
    if anchor == "fall":
        assert min(at, 1 - at) <= 1.5 / 32 and abs(best) <= 1, (at, best)
    else:   # the darkest bin (0.08 of a ring after the fall, 2.6 bins) on the line
        assert min(np.argmin(prof), 32 - np.argmin(prof)) <= 1 and -4 <= best <= -2, (np.argmin(prof), best)


def test_a_source_without_usable_phase_is_refused_with_the_fix():
    """A source with no usable ring phase raised a bare ValueError: now the project's error,
    naming the source and the fix."""
    import dataclasses

    from woodcam.errors import WoodcamError

    photo = _stand_in(1.0)
    src = quilt_source(photo)
    empty = dataclasses.replace(src, valid=np.zeros_like(src.valid))
    years = np.add.outer(np.arange(64.0), np.zeros(64)) / 13.0
    with pytest.raises(WoodcamError, match="no usable ring phase.*SOURCE_MIN_SHARE"):
        quilt_face(years, empty, np.random.default_rng(0))
