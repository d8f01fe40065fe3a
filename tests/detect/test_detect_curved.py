"""The curved Gabor filter (woodcam.detect.curved) and the dark-edge ring rule, on analytic faces."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.detect import detect_rings, ridge_scores
from woodcam.detect.curved import across_gabor, curved_gabor, streamline_average


def _circles(n=160, centre=(-20.0, 80.0)):
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    rad = np.hypot(rr - centre[0], cc - centre[1])
    normal = np.arctan2(rr - centre[0], cc - centre[1]).astype(np.float32)
    inner = (rad > 40) & (rr > 5) & (rr < n - 5) & (cc > 5) & (cc < n - 5)
    return rr, cc, rad, normal, inner


def test_streamline_average_follows_the_ring_curve():
    """Averaging the radius along circles about the centre returns the radius itself (the curve
    through each pixel is its circle); a straight average along the tangent, as a straight kernel
    sees it, runs outward and is off by sigma^2 / (2 r) (0.47 px mean here)."""
    rr, cc, rad, normal, inner = _circles()
    sigma = np.full(rad.shape, 10.0, np.float32)
    out = streamline_average(rad[None].astype(np.float32), normal, sigma)[0]
    err = np.abs(out - rad)[inner]
    assert err.mean() < 0.12 and err.max() < 0.3, (err.mean(), err.max())
    # a constant is kept everywhere, the border included (the weights are normalised)
    const = streamline_average(np.full((1, *rad.shape), 3.0, np.float32), normal, sigma)[0]
    assert np.allclose(const, 3.0, atol=1e-4)
    # the straight control, for scale
    s = np.arange(-30, 31)[:, None, None]
    wts = np.exp(-0.5 * (s / 10.0) ** 2)
    straight = (wts * np.hypot(rr + s * np.cos(normal) + 20.0, cc - s * np.sin(normal) - 80.0)).sum(0) / wts.sum()
    assert np.abs(straight - rad)[inner].mean() > 3 * err.mean()


def test_curved_gabor_phase_is_pi_on_the_dark_line_at_the_local_spacing():
    """Curved rings whose spacing grows from 8 to 20 px across the face (a chirp): with the true
    normal and spacing, the response's phase is 2 pi times the ring coordinate (0 on the bright
    line, pi on the dark one) everywhere inside, and its amplitude is about the pattern's."""
    rr, cc, rad, normal, inner = _circles(n=192, centre=(-30.0, 96.0))
    lam = (8.0 + 12.0 * (rad - rad.min()) / (rad.max() - rad.min())).astype(np.float32)
    # ring coordinate u with du/dr = 1 / lam(r): integrate numerically along r
    r_grid = np.linspace(rad.min(), rad.max(), 4000)
    lam_r = 8.0 + 12.0 * (r_grid - rad.min()) / (rad.max() - rad.min())
    u_r = np.concatenate([[0.0], np.cumsum(np.diff(r_grid) / lam_r[1:])])
    u = np.interp(rad, r_grid, u_r)
    x = np.cos(2 * np.pi * u).astype(np.float32)
    z = curved_gabor(x, normal, lam)
    err = np.angle(z * np.exp(-2j * np.pi * u))
    keep = inner & (rad > 50)
    assert np.abs(err[keep]).mean() < 0.15, np.abs(err[keep]).mean()
    assert np.median(np.abs(z[keep])) == pytest.approx(1.0, abs=0.15)
    # frequency adapted: the Gabor across the ring passes the whole pattern's amplitude at every
    # spacing (one tuned to the median spacing passes a few per cent at 8 and 20 px)
    q = np.abs(across_gabor(x, normal, lam))[keep]
    assert np.percentile(q, 5) > 0.8 and np.median(q) == pytest.approx(1.0, abs=0.1), (np.percentile(q, 5), np.median(q))


def test_detect_rings_with_the_curved_gabor_finds_curved_rings():
    """``detect_rings(curved=True)`` on noisy rings round a centre above the face: the band
    centres lie on the true dark lines, as with the straight bank."""
    n, lam = 192, 12.0
    rng = np.random.default_rng(0)
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    rad = np.hypot(rr + 40, cc - n / 2)
    d = rad - lam * (np.floor(rad / lam) + 0.5)
    lum = 0.6 - 0.2 * np.exp(-(d / 1.8) ** 2) + 0.1 * rng.standard_normal((n, n))
    photo = np.clip(np.repeat(lum[..., None], 3, 2) * 255, 0, 255).astype(np.uint8)
    truth = np.argwhere(np.abs(d) < 0.5).astype(float)
    det = detect_rings(photo, rule="dark-centre", curved=True)
    assert ridge_scores(det.points_px, truth, thresholds=(2.0,)).f[2.0] >= 0.95


def _band_face(dark, n=192, spacing=20.0, seed=1):
    """A photo whose luminance across vertical rings (spacing px) follows ``dark(frac)`` in
    [0, 1] (1 darkest), ring boundaries at ``frac = 1`` (col = k spacing - 0.5)."""
    from scipy import ndimage

    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    frac = np.mod((cc + 0.5) / spacing, 1.0)
    lum = 0.8 - 0.35 * dark(frac) + 0.01 * np.random.default_rng(seed).standard_normal((n, n))
    lum = ndimage.gaussian_filter(lum, 0.6)
    photo = np.clip(np.repeat(lum[..., None], 3, axis=2) * 255, 0, 255).astype(np.uint8)
    steps = np.arange(spacing, n, spacing) - 0.5
    return photo, steps


def _offsets(det, steps):
    return np.abs(det.points_px[:, 1][:, None] - steps[None]).min(axis=1)


def test_dark_edge_rule_finds_the_end_of_a_flat_dark_band():
    """Plain synthetic latewood: a ramp, then a flat dark plateau over the last 20 % of the ring,
    then the step to earlywood (the ring boundary). The darkest line's smoothed minimum sits
    inside the plateau (2.7 px off the step); the dark-edge rule (the default) walks toward its
    end, to where the luminance has risen a tenth of the way (1.4 px off: within the 2 px goal)."""
    photo, steps = _band_face(lambda f: np.clip((f - 0.4) / 0.4, 0, 1))
    edge = detect_rings(photo)
    assert edge.rule == "dark-edge"
    off = _offsets(edge, steps)
    assert np.median(off) <= 1.6, np.median(off)
    truth = np.array([[r, c] for c in steps for r in range(192)], float)
    assert ridge_scores(edge.points_px, truth, thresholds=(2.0,)).f[2.0] >= 0.9
    line = detect_rings(photo, rule="dark-line")
    assert np.median(_offsets(line, steps)) >= np.median(off) + 1.0


def test_dark_edge_rule_stays_on_a_narrow_line_darkest_at_the_boundary():
    """Spruce-like latewood: a narrow line (15 % of the ring) darkening up to the boundary and
    ending there: the darkest line is the boundary and dark-edge stays on it (within 1 px)."""
    photo, steps = _band_face(lambda f: np.clip((f - 0.85) / 0.15, 0, 1) ** 1.5)
    line = detect_rings(photo, rule="dark-line")
    edge = detect_rings(photo, rule="dark-edge")
    assert np.median(_offsets(line, steps)) <= 1.0
    assert np.median(_offsets(edge, steps)) <= 1.0
    # and it moved toward the boundary, not away (the sharp side won the vote)
    assert np.median(_offsets(edge, steps)) <= np.median(_offsets(line, steps)) + 0.1
