"""Texture by numbers: training faces for the ring net in a real photo's own texture.

A synthetic face knows its true growth time ``years (h, w)`` at every pixel, hence its ring
phase ``frac(years)`` (0 on the true ring boundary), ring normal and spacing. A real face photo
knows the same three things approximately, from the classical detector
(:func:`woodcam.detect.rings.detect_rings`). :func:`quilt_face` paints the synthetic face with
patches of the real photo whose phase matches, turned to the synthetic normal and scaled to the
synthetic spacing (image analogies / texture by numbers, Hertzmann et al. 2001; patches as in
image quilting, Efros & Freeman 2001). The label stays the synthetic ring boundary.

Phase 0 of a real face (:func:`quilt_source`), two anchors:

- ``"lines"`` (default, the one kept): the classical detector's ring lines (its default rule,
  ``dark-edge``: the end of the dark line on its steeper side), the phase linear between two
  lines along the ring normal (:func:`phase_between_lines`). Each ring's own line is placed on
  its own profile, so the copied edges sit on the label to about a pixel.
- ``"fall"``: the filter's phase (the order map mod 1), shifted per face to the **steepest
  fall** of the mean luminance profile across the ring and reversed where the steepest edge is
  a rise, so the dark side always follows phase 0 (in oak the first earlywood pores start
  abruptly against light latewood; in spruce the dark latewood ends abruptly against
  earlywood, a sharp fall read from outside). The Gabor phase places each ring's edge only to a
  few pixels, and a net trained on it learned a blur (README, "Texture by numbers").

Only numpy/scipy; used by :func:`woodcam.synth.ring_training_faces` (``RingNetSpec.style``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError

#: Phase bins of the luminance profile across a ring (:func:`phase_profile`).
PROFILE_BINS = 32
#: Smoothing (px) of the source phase field before its gradient (normal and spacing) is read.
SOURCE_SMOOTH_PX = 1.5
#: A source pixel is used when its smoothed phasor keeps this much of the length a clean
#: phase ramp of its frequency would keep (the phase is locally coherent) and its spacing lies in
#: :data:`SOURCE_SPACING_PX`.
SOURCE_COHERENCE_MIN = 0.8
SOURCE_SPACING_PX = (4.0, 64.0)
#: Patch side and stride (px) of the quilt; candidates tried per patch (the best phase
#: agreement wins); phase disagreement (cycles) at which a patch pixel's weight falls by e.
QUILT_PATCH_PX = 24
QUILT_STRIDE_PX = 12
QUILT_CANDIDATES = 6
QUILT_PHASE_TOL = 0.08
#: Cost of rescaling a candidate, per unit of ``|ln(source spacing / target spacing)|``, against
#: its phase agreement (in [-1, 1]): real pores keep their size where a source ring fits.
QUILT_SCALE_COST = 0.3
#: A source face is used when at least this share of it has a usable phase (CN03's back face,
#: whose few detected lines leave none between two of them, is not).
SOURCE_MIN_SHARE = 0.05


@dataclass
class QuiltSource:
    """A real face photo prepared as a texture source.

    ``rgb (h, w, 3)`` float32 in [0, 1]; ``phasor (h, w)`` complex64, ``exp(2 pi i phase)`` with
    phase 0 on the ring's steepest luminance fall (module docstring), 0 where unusable;
    ``freq (h, w, 2)`` float32 the phase gradient (row, col) in cycles/px; ``valid (h, w)`` bool;
    ``name``."""

    rgb: np.ndarray
    phasor: np.ndarray
    freq: np.ndarray
    valid: np.ndarray
    name: str = "source"


def phase_profile(values: np.ndarray, phase: np.ndarray, mask: np.ndarray | None = None,
                  bins: int = PROFILE_BINS) -> np.ndarray:
    """``(bins,)`` mean of ``values (h, w)`` per bin of ``phase (h, w)`` (cycles, taken mod 1)
    over ``mask``; an empty bin takes its circular neighbours' mean."""
    m = np.isfinite(phase) & np.isfinite(values) if mask is None else (np.asarray(mask, bool) & np.isfinite(phase))
    k = np.floor(np.mod(phase[m], 1.0) * bins).astype(int) % bins
    s = np.bincount(k, values[m], bins)
    n = np.bincount(k, None, bins)
    prof = np.where(n > 0, s / np.maximum(n, 1), np.nan)
    if np.isnan(prof).any() and np.isfinite(prof).any():
        idx = np.arange(bins)
        good = np.isfinite(prof)
        prof = np.interp(idx, idx[good], prof[good], period=bins)
    return prof


def steepest_fall(profile: np.ndarray) -> tuple[float, float, float]:
    """Of a circular profile ``(bins,)`` lightly smoothed: ``(phase of the steepest fall in
    cycles, that slope, the steepest rise's slope)`` (slopes per bin)."""
    from scipy import ndimage

    p = ndimage.gaussian_filter1d(np.asarray(profile, float), 1.0, mode="wrap")
    d = np.roll(p, -1) - p                       # slope from bin k to k + 1
    k = int(np.argmin(d))
    return (k + 1.0) / len(p), float(d[k]), float(d.max())


def _phase_gradient(phasor: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed ``phasor`` and its phase gradient ``(h, w, 2)`` (cycles/px); the mask's own
    edges only change the phasor's length, not its phase gradient."""
    from scipy import ndimage

    def blur(a, order=(0, 0)):
        return (ndimage.gaussian_filter(a.real, sigma, order=order)
                + 1j * ndimage.gaussian_filter(a.imag, sigma, order=order))

    zs = blur(phasor)
    den = np.maximum(np.abs(zs) ** 2, 1e-12)
    fr = np.imag(np.conj(zs) * blur(phasor, (1, 0))) / den / (2 * np.pi)
    fc = np.imag(np.conj(zs) * blur(phasor, (0, 1))) / den / (2 * np.pi)
    return zs, np.stack([fr, fc], axis=-1).astype(np.float32)


def source_from_phase(photo: np.ndarray, phase: np.ndarray, name: str = "source", shift: bool = True) -> QuiltSource:
    """A :class:`QuiltSource` from a photo ``(h, w, 3)`` uint8 and its ring phase ``(h, w)``
    (cycles, NaN where unknown; any offset and direction: it is normalised here so that 0 sits on
    the steepest luminance fall, module docstring)."""
    from .learned import net_input

    x = net_input(photo)
    ph = np.asarray(phase, np.float64)
    ok = np.isfinite(ph)
    prof = phase_profile(x, ph, ok)
    at, fall, rise = steepest_fall(prof)
    if rise > -fall:                  # the steepest edge is a rise: read the ring the other way
        ph = -ph
        at, fall, rise = steepest_fall(phase_profile(x, ph, ok))
    if shift:
        ph = ph - at
    z = np.where(ok, np.exp(2j * np.pi * np.nan_to_num(ph)), 0).astype(np.complex64)
    zs, freq = _phase_gradient(z, SOURCE_SMOOTH_PX)
    k2 = freq[..., 0] ** 2 + freq[..., 1] ** 2
    lam = 1.0 / np.maximum(np.sqrt(k2), 1e-6)
    # a clean phase ramp of k cycles/px keeps exp(-2 pi^2 sigma^2 k^2) of its length under the
    # Gaussian; what is lost beyond that is incoherence
    coherence = np.abs(zs) * np.exp(np.minimum(2 * np.pi ** 2 * SOURCE_SMOOTH_PX ** 2 * k2, 5.0))
    valid = ok & (coherence >= SOURCE_COHERENCE_MIN) & (lam >= SOURCE_SPACING_PX[0]) & (lam <= SOURCE_SPACING_PX[1])
    rgb = np.asarray(photo, np.float32)[..., :3] / 255.0
    return QuiltSource(rgb, np.where(valid, z, 0).astype(np.complex64), freq, valid, name)


def phase_between_lines(lines: list, normal_rad: np.ndarray, wavelength_px: np.ndarray,
                        max_span: float = 1.6, step_px: float = 0.5) -> np.ndarray:
    """``(h, w)`` ring phase (cycles in [0, 1), NaN where unknown) that is 0 on the ring
    ``lines`` (polylines ``(k, 2)`` row, col) and rises linearly to the next line along the
    local ``normal_rad``: ``b / (b + f)`` with ``b``, ``f`` the distances to the nearest line
    behind and ahead. Unknown where either is not found within ``max_span`` spacings
    (``wavelength_px``) or ``b + f`` exceeds that (a missed ring between)."""
    from scipy import ndimage

    from .rings import lines_mask

    h, w = normal_rad.shape
    on = lines_mask(lines, (h, w))
    hit = (ndimage.distance_transform_edt(~on) <= 0.75).astype(np.float32)
    lam = np.asarray(wavelength_px, float)
    reach = max_span * lam
    n_steps = int(np.ceil(float(np.nanmax(reach)) / step_px))
    r, c = np.mgrid[0:h, 0:w].astype(float)
    nr, nc = np.sin(normal_rad), np.cos(normal_rad)
    dist = []
    for sign in (-1.0, 1.0):
        found = np.full(h * w, np.inf)
        # each step samples only the pixels still looking (sampling the whole image at every step
        # cost twice the time on the Mokume faces), kept compact: not found yet, within reach at
        # the next step (t grows; a NaN reach never finds a line), the ray still in the image (its
        # coordinates move monotonically, so once outside, where the sample is 0, it stays out;
        # a NaN normal's ray counts as outside, as map_coordinates gives it 0 too)
        idx = np.arange(h * w)
        rr, cc, nrr, ncc, rch = r.ravel(), c.ravel(), nr.ravel(), nc.ravel(), reach.ravel()
        for k in range(1, n_steps + 1):
            t = k * step_px
            x, y = rr + sign * t * nrr, cc + sign * t * ncc
            v = ndimage.map_coordinates(hit, [x, y], order=0, mode="constant")
            got = (v > 0) & (t <= rch)
            found[idx[got]] = t
            keep = ~got & ((k + 1) * step_px <= rch) & (x >= 0) & (x <= h - 1) & (y >= 0) & (y <= w - 1)
            if not keep.any():
                break
            idx, rr, cc, nrr, ncc, rch = idx[keep], rr[keep], cc[keep], nrr[keep], ncc[keep], rch[keep]
        dist.append(found.reshape(h, w))
    b, f = dist
    b = np.where(on, 0.0, b)
    with np.errstate(invalid="ignore"):
        phase = b / (b + f)
    bad = ~np.isfinite(b) | ~np.isfinite(f) | (b + f > reach) | (b + f < 2.0)
    bad &= ~on
    return np.where(bad, np.nan, np.mod(phase, 1.0))


def quilt_source(photo: np.ndarray, px_per_mm: float | None = None, name: str = "source",
                 anchor: str = "lines") -> QuiltSource:
    """Prepare a real face photo ``(h, w, 3)`` uint8 as a texture source. ``anchor="lines"``: the
    ring phase is 0 on the classical detector's ring lines (its default rule) and linear between
    them (:func:`phase_between_lines`); ``"fall"``: the detector's order map
    (:attr:`~woodcam.detect.rings.RingDetection.order_map`), shifted to the steepest fall."""
    from .rings import detect_rings

    det = detect_rings(photo, px_per_mm=px_per_mm, name=name)
    if anchor == "fall":
        return source_from_phase(photo, det.order_map, name)
    phase = phase_between_lines([t.points_px for t in det.traces], det.normal_rad, det.wavelength_px)
    return source_from_phase(photo, phase, name, shift=False)


def _sample(img: np.ndarray, r: np.ndarray, c: np.ndarray, mode: str = "constant") -> np.ndarray:
    """Bilinear samples of ``img (h, w[, k])`` at ``r, c`` (same shape); outside: 0
    (``mode="constant"``) or the nearest edge pixel (``"nearest"``)."""
    from scipy import ndimage

    if img.ndim == 2:
        return ndimage.map_coordinates(img, [r.ravel(), c.ravel()], order=1, mode=mode).reshape(r.shape)
    return np.stack([_sample(img[..., k], r, c, mode) for k in range(img.shape[-1])], axis=-1)


def quilt_face(years: np.ndarray, source: QuiltSource, rng: np.random.Generator,
               patch_px: int = QUILT_PATCH_PX, stride_px: int = QUILT_STRIDE_PX,
               candidates: int = QUILT_CANDIDATES) -> tuple[np.ndarray, float]:
    """Paint a face whose true growth time is ``years (h, w)`` with ``source``'s texture.

    Patches of ``patch_px`` every ``stride_px`` (overlapping). For each, ``candidates`` random
    usable source pixels are tried: a candidate is moved along its ring normal to the patch
    centre's phase, and every patch pixel ``u`` is mapped to ``s + dy(u) * lam_s * n_s +
    b(u) * (lam_s / lam_t) * t_s``, where ``dy`` is the growth time from the centre to ``u``
    (so the copied phase follows the synthetic rings across the patch, curvature and all),
    ``b`` the distance along the centre's ring tangent, ``lam`` the spacings, ``n, t`` the
    normal and tangent. The candidate whose copied phase best agrees with ``frac(years)`` wins;
    overlapping patches are blended by a raised-cosine window times their phase agreement
    (disagreement ``QUILT_PHASE_TOL`` cycles: weight / e). Returns ``(rgb (h, w, 3) uint8,
    share of pixels whose best phase agreement is within QUILT_PHASE_TOL)``."""
    from scipy import ndimage

    y = np.asarray(years, np.float64)
    h, w = y.shape
    gr, gc = np.gradient(y)
    gr, gc = ndimage.gaussian_filter(gr, 1.0), ndimage.gaussian_filter(gc, 1.0)
    usable = np.flatnonzero(source.valid.ravel())
    if not len(usable):
        raise WoodcamError(f"quilt_face: texture source {source.name!r} has no usable ring phase (its valid "
                           f"share is 0); pass a source whose valid share is at least SOURCE_MIN_SHARE, as "
                           f"texture_sources keeps")
    hs, ws = source.valid.shape
    src_r, src_c = np.divmod(usable, ws)
    centres_r = np.arange(0, h + stride_px, stride_px, dtype=float)
    centres_c = np.arange(0, w + stride_px, stride_px, dtype=float)
    cr, cc = [a.ravel() for a in np.meshgrid(centres_r, centres_c, indexing="ij")]
    m = len(cr)
    off = np.arange(patch_px) - patch_px // 2          # whole pixels: patches land on the grid
    dr, dc = np.meshgrid(off, off, indexing="ij")
    win = (np.cos(np.pi * (dr + 0.5) / (patch_px + 1)) * np.cos(np.pi * (dc + 0.5) / (patch_px + 1))) ** 2
    ur = np.clip(cr[:, None, None] + dr, 0, h - 1).astype(int)                   # (m, p, p)
    uc = np.clip(cc[:, None, None] + dc, 0, w - 1).astype(int)
    inside = ((cr[:, None, None] + dr >= 0) & (cr[:, None, None] + dr <= h - 1)
              & (cc[:, None, None] + dc >= 0) & (cc[:, None, None] + dc <= w - 1))
    ci, cj = np.clip(np.round(cr), 0, h - 1).astype(int), np.clip(np.round(cc), 0, w - 1).astype(int)
    y_c = y[ci, cj]
    kt = np.stack([gr[ci, cj], gc[ci, cj]], axis=1)                              # cycles/px
    lam_t = 1.0 / np.maximum(np.hypot(kt[:, 0], kt[:, 1]), 1e-6)
    nt = kt * lam_t[:, None]
    tt = np.stack([-nt[:, 1], nt[:, 0]], axis=1)
    dy = y[ur, uc] - y_c[:, None, None]                                          # (m, p, p)
    bt = (ur - cr[:, None, None]) * tt[:, 0, None, None] + (uc - cc[:, None, None]) * tt[:, 1, None, None]
    target = np.exp(2j * np.pi * y[ur, uc])

    best_score = np.full(m, -np.inf)
    best = None
    for _ in range(candidates):
        pick = rng.integers(0, len(usable), m)
        sr, sc = src_r[pick].astype(float), src_c[pick].astype(float)
        ks = source.freq[src_r[pick], src_c[pick]].astype(float)
        lam_s = 1.0 / np.maximum(np.hypot(ks[:, 0], ks[:, 1]), 1e-6)
        ns = ks * lam_s[:, None]
        ts = np.stack([-ns[:, 1], ns[:, 0]], axis=1)
        # move the candidate along its normal to the centre's phase
        phi_s = np.angle(source.phasor[src_r[pick], src_c[pick]]) / (2 * np.pi)
        shift = np.mod(y_c - phi_s + 0.5, 1.0) - 0.5
        sr, sc = sr + shift * lam_s * ns[:, 0], sc + shift * lam_s * ns[:, 1]
        scale = lam_s / lam_t
        qr = (sr[:, None, None] + dy * lam_s[:, None, None] * ns[:, 0, None, None]
              + bt * scale[:, None, None] * ts[:, 0, None, None])
        qc = (sc[:, None, None] + dy * lam_s[:, None, None] * ns[:, 1, None, None]
              + bt * scale[:, None, None] * ts[:, 1, None, None])
        zq = _sample(source.phasor.real, qr, qc) + 1j * _sample(source.phasor.imag, qr, qc)
        agree = np.real(zq * np.conj(target))              # cos of the phase error times |zq|
        score = ((agree * win * inside).sum(axis=(1, 2)) / np.maximum((win * inside).sum(axis=(1, 2)), 1e-9)
                 - QUILT_SCALE_COST * np.abs(np.log(scale)))
        better = score > best_score
        if best is None:
            best = [qr, qc, agree]
        else:
            for k, a in enumerate((qr, qc, agree)):
                best[k][better] = a[better]
        best_score = np.where(better, score, best_score)
    qr, qc, agree = best
    # phase error (cycles) from the agreement cos(2 pi e)
    err = np.arccos(np.clip(agree, -1.0, 1.0)) / (2 * np.pi)
    wgt = win[None] * inside * np.exp(-(err / QUILT_PHASE_TOL) ** 2) + 1e-6 * win[None] * inside
    rgb = _sample(source.rgb, qr, qc, "nearest")                                            # (m, p, p, 3)
    # the overlapping patches summed per pixel: bincount adds in the same order as np.add.at,
    # ten times faster (the same sums to the bit)
    at = np.broadcast_to(ur * w + uc, wgt.shape).ravel()
    acc = np.stack([np.bincount(at, (rgb[..., c] * wgt).ravel(), h * w) for c in range(3)], axis=-1)
    tot = np.bincount(at, wgt.ravel(), h * w)
    good = np.zeros((h, w))
    np.maximum.at(good, (ur, uc), (err <= QUILT_PHASE_TOL) * inside)
    out = (acc / np.maximum(tot, 1e-12)[:, None]).reshape(h, w, 3)
    return np.clip(out * 255 + 0.5, 0, 255).astype(np.uint8), float(good.mean())
