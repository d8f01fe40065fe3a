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


def _phase_between_lines_whole_image(lines, normal_rad, wavelength_px, max_span=1.6, step_px=0.5):
    """The reference: phase_between_lines as it was, sampling every pixel of the image at every
    step along the normal (the found distances ``b, f``; the phase follows from them)."""
    from scipy import ndimage

    from woodcam.detect.rings import lines_mask

    h, w = normal_rad.shape
    hit = (ndimage.distance_transform_edt(~lines_mask(lines, (h, w))) <= 0.75).astype(np.float32)
    reach = max_span * np.asarray(wavelength_px, float)
    r, c = np.mgrid[0:h, 0:w].astype(float)
    nr, nc = np.sin(normal_rad), np.cos(normal_rad)
    dist = []
    for sign in (-1.0, 1.0):
        found = np.full((h, w), np.inf)
        for k in range(1, int(np.ceil(float(np.nanmax(reach)) / step_px)) + 1):
            t = k * step_px
            v = ndimage.map_coordinates(hit, [r + sign * t * nr, c + sign * t * nc], order=0, mode="constant")
            found[(v > 0) & ~np.isfinite(found) & (t <= reach)] = t
        dist.append(found)
    return dist


def _phase_from(lines, normal_rad, wavelength_px, b, f, max_span=1.6):
    from woodcam.detect.rings import lines_mask

    on = lines_mask(lines, normal_rad.shape)
    b = np.where(on, 0.0, b)
    with np.errstate(invalid="ignore"):
        phase = b / (b + f)
    bad = (~np.isfinite(b) | ~np.isfinite(f) | (b + f > max_span * wavelength_px) | (b + f < 2.0)) & ~on
    return np.where(bad, np.nan, np.mod(phase, 1.0))


def _same_bits(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _check_against_whole_image(lines, normal_rad, wavelength_px, **kw):
    from woodcam.detect.quilt import phase_between_lines

    b, f = _phase_between_lines_whole_image(lines, normal_rad, wavelength_px, **kw)
    expect = _phase_from(lines, normal_rad, wavelength_px, b, f, kw.get("max_span", 1.6))
    got = phase_between_lines(lines, normal_rad, wavelength_px, **kw)
    assert np.isfinite(got).mean() > 0.3 and _same_bits(got, expect)


def test_phase_between_lines_samples_only_the_pixels_still_looking(monkeypatch):
    """phase_between_lines sampled the whole image at every step along the normal; now only the
    pixels that have not found their line, are within reach and whose ray is still inside the
    image: the same bits as the whole-image march (NaN reach and normals, another step too)."""
    from scipy import ndimage

    from woodcam.detect.quilt import phase_between_lines
    from woodcam.detect.rings import detect_rings

    det = detect_rings(_stand_in(1.0, angle_deg=70.0))
    lines = [t.points_px for t in det.traces]
    _check_against_whole_image(lines, det.normal_rad, det.wavelength_px)
    sampled = []
    real = ndimage.map_coordinates
    monkeypatch.setattr(ndimage, "map_coordinates", lambda img, q, **kw: sampled.append(np.size(q[0])) or real(img, q, **kw))
    phase_between_lines(lines, det.normal_rad, det.wavelength_px)
    n_steps = int(np.ceil(1.6 * float(np.nanmax(det.wavelength_px)) / 0.5))
    whole = 2 * n_steps * det.normal_rad.size                # both ways, every pixel, every step
    assert sum(sampled) < 0.5 * whole, (sum(sampled), whole)   # measured 0.27
    monkeypatch.undo()
    lam, nrm = det.wavelength_px.astype(float), det.normal_rad.astype(float)
    lam[:40, :50] = np.nan                                 # no spacing known: never found
    nrm[100:120, 60:90] = np.nan                           # no normal: map_coordinates gives 0
    lam[150:, 150:] *= 0.3                                 # a short reach: stop early
    _check_against_whole_image(lines, nrm, lam, step_px=0.3, max_span=1.4)


def test_phase_between_lines_on_a_real_face_is_the_whole_image_march(shared_data):
    """The same on a real face with the widest spacing of the twelve (reach 230 px, 460 steps)."""
    from PIL import Image

    from woodcam.detect.rings import detect_rings

    photo = np.asarray(Image.open(shared_data / "mokume" / "H11" / "B_col.png").convert("RGB"))
    det = detect_rings(photo)
    _check_against_whole_image([t.points_px for t in det.traces], det.normal_rad, det.wavelength_px)
