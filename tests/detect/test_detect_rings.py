"""The classical ring detector on analytic faces, synthetic faces with known rings, and real faces."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from woodcam.detect import detect_rings, reference_ridge, ridge_scores
from woodcam.detect.evaluate import (
    EVAL_SEEDS,
    score_reference_block,
    score_synthetic,
    summary,
)
from woodcam.detect.score import shifted_half_ring
from woodcam.errors import WoodcamError


def _mokume(sample: str) -> Path:
    root = Path(os.environ.get("WOODCAM_SHARED_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
    folder = root / "mokume" / sample
    if not folder.is_dir():
        pytest.skip(f"Mokume sample {sample} not found under {root} (set WOODCAM_SHARED_DATA)")
    return folder


def _faces(seeds):
    from woodcam.synth import ring_eval_faces

    return [f for s in seeds for f in ring_eval_faces(s)]


def _line_face(spacing=14.0, angle_deg=20.0, n=192, seed=0, width=1.8, contrast=0.25):
    """Dark Gaussian lines every ``spacing`` px across the normal at ``angle_deg``; returns the
    photo and the exact line positions sampled densely, (m, 2) (row, col)."""
    rng = np.random.default_rng(seed)
    a = np.radians(angle_deg)
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    s = rr * np.sin(a) + cc * np.cos(a)                       # coordinate along the normal
    d = (s - spacing * np.round(s / spacing))                 # signed distance to the nearest line
    lum = 0.7 - contrast * np.exp(-(d / width) ** 2) + 0.02 * rng.standard_normal((n, n))
    photo = np.clip(np.repeat(lum[..., None], 3, axis=2) * 255, 0, 255).astype(np.uint8)
    truth = np.argwhere(np.abs(d) < 0.5).astype(float)
    return photo, truth


def test_parallel_lines_found_within_a_pixel():
    photo, truth = _line_face()
    det = detect_rings(photo, rule="dark-centre")
    sc = ridge_scores(det.points_px, truth, thresholds=(1.0, 2.0))
    assert sc.f[1.0] >= 0.9 and sc.f[2.0] >= 0.95, sc
    # the chance control (half a ring off) is far below
    ch = ridge_scores(shifted_half_ring(det.points_px, det.normal_rad, det.wavelength_px), truth, thresholds=(2.0,))
    assert ch.f[2.0] < 0.2
    # local spacing and orientation recovered away from the border
    inner = (slice(40, -40), slice(40, -40))
    assert np.median(det.wavelength_px[inner]) == pytest.approx(14.0, rel=0.1)
    n = det.normal_rad[inner]
    assert np.degrees(np.abs(np.angle(np.exp(2j * (n - np.radians(20.0)))))).mean() / 2 < 3.0
    assert not det.warnings


def test_dark_line_rule_sits_on_the_lines_and_rings_are_ordered():
    photo, truth = _line_face()
    det = detect_rings(photo, rule="dark-line")
    sc = ridge_scores(det.points_px, truth, thresholds=(1.0, 2.0))
    assert sc.f[1.0] >= 0.9 and sc.f[2.0] >= 0.95, sc
    # the unwrapped phase numbers the lines in order along the normal, one apart
    a = np.radians(20.0)
    along = [float(np.mean(t.points_px[:, 0] * np.sin(a) + t.points_px[:, 1] * np.cos(a)))
             for t in det.traces]
    order = np.array(det.ring_order)[np.argsort(along)]
    assert len(order) >= 10 and np.all(np.diff(order) == 1), order
    assert np.nanmax(det.order_map) - np.nanmin(det.order_map) == pytest.approx(len(order), abs=1.5)


def test_pieces_of_one_ring_share_its_id():
    """Lines broken by a 10 px band of pore-like noise across them: the detector finds each line
    in pieces, and the phase links the pieces of one line (one RingTrace.ring id, one growth
    time for the fitter) and keeps the lines apart (without the link each piece was a ring of
    its own to the fitter, and on Mokume CN03 the pieces were numbered as extra rings)."""
    photo, _ = _line_face()
    n, a, spacing = photo.shape[0], np.radians(20.0), 14.0
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    along = -rr * np.cos(a) + cc * np.sin(a)
    gap = np.abs(along - np.median(along)) < 5.0
    noise = 150 + 60 * np.random.default_rng(1).standard_normal(int(gap.sum()))
    photo[gap] = np.clip(noise, 0, 255).astype(np.uint8)[:, None]
    det = detect_rings(photo)
    line = [int(np.round(np.mean(t.points_px @ [np.sin(a), np.cos(a)]) / spacing)) for t in det.traces]
    ids = [t.ring for t in det.traces]
    assert None not in ids
    assert len(det.traces) >= len(set(line)) + 10          # broken: more pieces than lines
    by_id = {k: {ln for ln, i in zip(line, ids) if i == k} for k in set(ids)}
    by_line = {ln: {i for ln2, i in zip(line, ids) if ln2 == ln} for ln in set(line)}
    assert all(len(v) == 1 for v in by_id.values()), by_id       # an id is one line
    assert all(len(v) == 1 for v in by_line.values()), by_line   # a line is one id
    assert len(set(ids)) == len(set(line)) >= 12


def test_ring_links_need_one_order_one_region_and_a_short_gap():
    """``_ring_ids`` on a known order map (vertical rings 14 px apart, order = col / 14): pieces
    are one ring only with the same place in the order, in one evidence region, across a gap of
    at most LINK_GAP_WAVELENGTHS spacings; faint lines (after the band centres) link only to
    faint lines at the same place, not to any between the same two band centres."""
    from woodcam.detect.rings import LINK_GAP_WAVELENGTHS, _ring_ids

    n, lam = 400, 14.0
    order_map = np.tile(np.arange(n, dtype=np.float32) / lam, (n, 1))
    evidence = np.ones((n, n), bool)
    evidence[165:175] = False                         # two regions: rows < 165 and > 175

    def piece(col, r0, r1):
        return np.stack([np.arange(r0, r1, dtype=float), np.full(r1 - r0, float(col))], axis=1)

    far = int(220 + LINK_GAP_WAVELENGTHS * lam + 20)
    polys = [piece(28, 0, 40), piece(28, 60, 100),    # A, B: one ring across a 20 px gap
             piece(28, 130, 160),                     # H: and on across 30 px
             piece(42, 0, 40),                        # D: the next ring
             piece(28, 180, 220),                     # I: past the evidence gap, 20 px from H
             piece(28, far, far + 30),                # C: I's order and region, too far
             piece(33, 0, 40), piece(38, 45, 80),     # faint E, F: between rings 2 and 3, apart
             piece(33, 50, 90)]                       # faint G: E's line
    order = [2.0, 2.0, 2.0, 3.0, 2.0, 2.0, 33 / lam, 38 / lam, 33 / lam]
    ids = _ring_ids(polys, order, evidence, order_map, np.full((n, n), lam, np.float32), n_centre=6)
    a, b, h, d, i, c, e, f, g = ids
    assert a == b == h and e == g and None not in ids
    assert len({a, c, d, i, e, f}) == 6


def test_pieces_beside_each_other_are_not_one_ring():
    """A ring never runs beside itself: two pieces the order map calls one ring (a faint ring
    between them skipped by the phase, as on H11's right face, where one id covered 9 pieces of 5
    rings) are refused when they lie side by side, 8 px apart across the ring and overlapping
    30 px along it; the pieces of one ring that follow each other along it are still linked,
    also when the next piece starts off by a pixel (a line cut where it jumped)."""
    from woodcam.detect.rings import _ring_ids

    n, lam = 200, 14.0
    order_map = np.zeros((n, n), np.float32)          # one order everywhere: the phase skipped
    evidence = np.ones((n, n), bool)

    def piece(col, r0, r1):
        return np.stack([np.arange(r0, r1, dtype=float), np.full(r1 - r0, float(col))], axis=1)

    polys = [piece(50, 10, 60), piece(58, 30, 90),   # A, B: beside each other, overlapping
             piece(100, 10, 60), piece(101, 62, 110)]  # C, D: end to end, D a pixel aside
    ids = _ring_ids(polys, [0.0] * 4, evidence, order_map, np.full((n, n), lam, np.float32), n_centre=4)
    a, b, c, d = ids
    assert c == d and a != b, ids


def test_dark_line_and_sharp_edge_rules_on_a_skewed_band():
    """A dark band that darkens slowly and ends sharply (plain synthetic latewood): the
    sharp-edge rule finds the step, the dark-line rule the darkest line just before it."""
    n, spacing = 192, 20.0
    rr, cc = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    frac = np.mod(cc / spacing, 1.0)
    dark = np.clip((frac - 0.5) / 0.5, 0, 1) ** 2            # ramps up, drops at frac = 1
    lum = 0.8 - 0.35 * dark + 0.01 * np.random.default_rng(1).standard_normal((n, n))
    from scipy import ndimage

    lum = ndimage.gaussian_filter(lum, 0.6)
    photo = np.clip(np.repeat(lum[..., None], 3, axis=2) * 255, 0, 255).astype(np.uint8)
    steps = np.array([[r, c] for c in np.arange(spacing, n, spacing) - 0.5 for r in range(n)], float)
    edge = detect_rings(photo, rule="sharp-edge")
    assert ridge_scores(edge.points_px, steps, thresholds=(1.0,)).f[1.0] >= 0.9
    line = detect_rings(photo, rule="dark-line")
    off = np.abs(line.points_px[:, 1][:, None] - steps[:: n, 1][None]).min(axis=1)
    assert np.median(off) <= 2.0 and np.median(off) >= 0.3     # just before the step, not on it
    centre = detect_rings(photo, rule="dark-centre")
    off_c = np.abs(centre.points_px[:, 1][:, None] - steps[:: n, 1][None]).min(axis=1)
    assert np.median(off_c) > np.median(off) + 0.3               # the band centre is further in


def test_blank_and_noise_faces_warn_and_find_little():
    rng = np.random.default_rng(3)
    blank = np.full((128, 128, 3), 180, np.uint8)
    det = detect_rings(blank, name="top")
    assert not det.traces and det.warnings and "'top'" in det.warnings[0]
    assert not det.ring_map.any()
    # isotropic pores (dark dots) and white noise: no coherent rings
    pores = np.full((160, 160), 0.7)
    idx = rng.integers(0, 160, size=(600, 2))
    pores[idx[:, 0], idx[:, 1]] = 0.3
    pores += 0.03 * rng.standard_normal(pores.shape)
    photo = np.clip(np.repeat(pores[..., None], 3, axis=2) * 255, 0, 255).astype(np.uint8)
    det = detect_rings(photo, name="left")
    assert det.warnings and "'left'" in det.warnings[0]
    assert det.evidence.mean() < 0.15


def test_bad_arguments_are_refused():
    with pytest.raises(WoodcamError, match="rule must be one of"):
        detect_rings(np.zeros((64, 64, 3), np.uint8), rule="middle")
    with pytest.raises(WoodcamError, match="at least 16x16"):
        detect_rings(np.zeros((8, 8, 3), np.uint8))
    with pytest.raises(WoodcamError, match="photo must be"):
        detect_rings(np.zeros((64, 64, 2), np.uint8))


@pytest.mark.parametrize("channels", [4, 5])
def test_a_photo_of_other_than_three_channels_or_a_non_str_name_is_refused(channels):
    """A 5-channel array was read by its first three channels, and name=3 taken, without a word."""
    with pytest.raises(WoodcamError, match=rf"photo must be \(h, w, 3\) RGB .*got shape \(64, 64, {channels}\).*"
                       r"photo\[\.\.\., :3\]"):
        detect_rings(np.zeros((64, 64, channels), np.uint8))
    with pytest.raises(WoodcamError, match=r"name must be the face's name \(str\).*got 3 \(int\)"):
        detect_rings(np.zeros((64, 64, 3), np.uint8), name=3)


def test_scores_are_exact_on_a_known_case():
    ref = np.array([[10, c] for c in range(20)])
    det = np.array([[11.0, c] for c in range(10)] + [[30.0, c] for c in range(10)])   # half right
    sc = ridge_scores(det, ref, thresholds=(2.0,))
    # precision: the 10 points on row 11; recall: ref columns 0..10 (col 10 is 1 px from (11, 9),
    # col 11 is sqrt(5) px away)
    assert sc.precision[2.0] == 0.5 and sc.recall[2.0] == 0.55
    assert sc.f[2.0] == pytest.approx(2 * 0.5 * 0.55 / 1.05)
    assert ridge_scores(np.zeros((0, 2)), ref).f[2.0] == 0.0
    ring_map = np.zeros((40, 40), np.float32)
    ring_map[9:12, 5:30] = 1.0
    ridge = reference_ridge(ring_map)
    assert np.all(np.abs(ridge[:, 0] - 10) <= 1) and 20 <= len(ridge) <= 25   # skeleton ends may bend


#: Bars on the held-out synthetic seeds (the default: dark-edge rule, straight bank); the goal is
#: 0.90 within 2 px. Plain faces, seeds 1000-1007 (README): F within 2 / 5 px 0.915 / 0.945.
SYNTH_BAR_F2_ALL = 0.90
SYNTH_BAR_F2_FIRST = 0.80
#: Realistic faces (seeds 1000-1003, sharp-edge): F within 5 px 0.72.
REALISTIC_BAR_F5 = 0.66


def test_synthetic_faces_first_heldout_seed():
    res = score_synthetic(_faces(EVAL_SEEDS[:1]))
    s = summary(res)
    assert len(res) >= 4
    assert s["F@2"] >= SYNTH_BAR_F2_FIRST, s
    assert s["chance F@2"] < 0.2


def test_a_face_of_one_ring_piece_is_detected_without_a_scale():
    """detect_rings without px_per_mm on a face whose rings came out as one piece (seed 1000's
    plain back face) raised IndexError where the pieces' end pairs are matched: with no pair, the
    'first of each pair' mask had one entry for none. It finds the piece, as with the face's scale."""
    from woodcam.synth import ring_eval_faces

    (face,) = [f for f in ring_eval_faces(1000) if f.label == "seed 1000 flat-sawn plain back"]
    det = detect_rings(face.photo)
    assert len(det.traces) == 1 and det.warnings == []
    (res,) = score_synthetic([face], detector=lambda photo, ppm: detect_rings(photo))
    assert res.score.f[5.0] > 0.65, res.score.f


@pytest.mark.slow
def test_synthetic_faces_all_heldout_seeds():
    faces = _faces(EVAL_SEEDS)
    s = summary(score_synthetic(faces))                       # the default rule, dark-edge
    assert s["F@2"] >= SYNTH_BAR_F2_ALL and s["F@5"] >= 0.90, s
    e = summary(score_synthetic(faces, rule="sharp-edge"))
    assert e["F@2"] >= SYNTH_BAR_F2_ALL, e
    # the darkest line sits inside the plain faces' flat latewood plateau, before the boundary:
    # within 5 px but not 2 px (README: 0.358 / 0.894)
    d = summary(score_synthetic(faces, rule="dark-line"))
    assert d["F@5"] >= 0.85 and d["F@2"] < 0.6, d


@pytest.mark.slow
def test_realistic_synthetic_faces_all_heldout_seeds():
    """Narrow softwood latewood and ring-porous oak with rays and figure (README figures:
    seeds 1000-1003, sharp-edge F within 2 / 5 px 0.63 / 0.72, chance 0.08 / 0.43)."""
    from woodcam.synth import ring_eval_faces

    faces = [f for s in EVAL_SEEDS[:4] for f in ring_eval_faces(s, style="realistic")]
    s = summary(score_synthetic(faces, rule="sharp-edge"))
    assert s["F@5"] >= REALISTIC_BAR_F5 and s["F@2"] > 2 * s["chance F@2"], s


#: Real faces against the Mokume U-Net maps (a reference, not truth), the default detector.
#: Measured (README): H11 mean F 0.59 / 0.71 within 2 / 5 px (chance 0.10 / 0.23), CN03 0.28 /
#: 0.63 (chance 0.01 / 0.05; 0.29 / 0.67 before speck pieces were dropped after the snap, which
#: cost CN03 recall near the ridges and gained the fits: README); the bars sit below (CN03's 5 px
#: bar, set when it measured 0.67, is now just met and was not lowered).
H11_BAR = {2.0: 0.50, 5.0: 0.63}
CN03_BAR = {2.0: 0.25, 5.0: 0.63}


def test_h11_faces_against_the_mokume_maps():
    from woodcam.block.io import read_mokume

    res = score_reference_block(read_mokume(_mokume("H11")))
    s = summary(res)
    assert len(res) == 6
    assert s["F@2"] >= H11_BAR[2.0] and s["F@5"] >= H11_BAR[5.0], s
    assert s["F@2"] > 3 * s["chance F@2"]


@pytest.mark.slow
def test_cn03_faces_against_the_mokume_maps():
    from woodcam.block.io import read_mokume

    s = summary(score_reference_block(read_mokume(_mokume("CN03"))))
    assert s["F@2"] >= CN03_BAR[2.0] and s["F@5"] >= CN03_BAR[5.0], s
    assert s["F@2"] > 2 * s["chance F@2"]


def test_realistic_softwood_faces_are_darkest_on_their_ring_boundary():
    """The realistic generator's claim: narrow softwood latewood is darkest at the ring boundary
    (the true line, within 1 px), as on the real spruce faces (a latewood band widened to half
    a ring and darkening early fails this)."""
    from scipy import ndimage

    from woodcam.detect.rings import luminance
    from woodcam.synth import ring_eval_faces

    def darkest_offset(face):
        det = detect_rings(face.photo, px_per_mm=face.px_per_mm, rule="dark-centre")
        p = face.truth_px[::3]
        r = np.clip(np.round(p[:, 0]).astype(int), 0, face.photo.shape[0] - 1)
        c = np.clip(np.round(p[:, 1]).astype(int), 0, face.photo.shape[1] - 1)
        n = np.stack([np.sin(det.normal_rad[r, c]), np.cos(det.normal_rad[r, c])], axis=1)
        t = np.arange(-6, 7)
        q = p[:, None, :] + t[None, :, None] * n[:, None, :]
        lum = ndimage.gaussian_filter(luminance(face.photo), 1.0)
        prof = ndimage.map_coordinates(lum, [q[..., 0].ravel(), q[..., 1].ravel()], order=1).reshape(len(p), -1)
        return abs(t[np.argmin(prof.mean(axis=0))])

    real = ring_eval_faces(2, style="realistic", faces=("front", "top"))     # even seed: softwood
    assert all("realistic" in f.label for f in real)
    assert max(darkest_offset(f) for f in real) <= 1
    with pytest.raises(WoodcamError, match="style must be"):
        ring_eval_faces(2, style="photo")


def test_no_speck_pieces_after_the_snap():
    """Snapping a band centre to its line cuts it where the line jumps (SNAP_JUMP_PX); the cut
    pieces obey the least length the contour runs do (MIN_TRACE_WAVELENGTHS ring spacings).
    CN03's back face (oak, tangential: pore streaks across wide bands) is the case: without the
    check half its traced length was in pieces under 0.2 spacings, strung along pore streaks, and
    the fit from CN03's detected rings lost 19.6 points within 5 px in-sample (7.8 with it)."""
    from woodcam.block.io import read_mokume
    from woodcam.detect.rings import MIN_TRACE_WAVELENGTHS

    face = read_mokume(_mokume("CN03")).faces["back"]
    det = detect_rings(face.photo, px_per_mm=256 / 50)
    h, w = det.wavelength_px.shape
    short = []
    for t in det.traces:
        p = t.points_px
        length = float(np.sum(np.hypot(*np.diff(p, axis=0).T)))
        r = np.clip(np.round(p[:, 0]).astype(int), 0, h - 1)
        c = np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)
        # the detector reads the spacing before the snap moved the vertices (a few px): 0.8
        if length < 0.8 * MIN_TRACE_WAVELENGTHS * float(np.median(det.wavelength_px[r, c])):
            short.append(round(length, 1))
    assert det.traces and not short, short


@pytest.mark.parametrize("photo, match", [
    (np.full((64, 64, 3), np.nan), "finite values in \\[0, 1\\].*12288 non-finite"),
    (np.full((64, 64, 3), 200.0), "finite values in \\[0, 1\\]; got range \\[200.0, 200.0\\]"),
    (np.full((64, 64, 3), 40000, np.uint16), "uint8 \\(0..255\\) or float \\(0..1\\); got dtype uint16"),
])
def test_a_photo_the_detector_would_misread_is_refused(photo, match):
    """A 16-bit photo or a float one in 0..255 was read as if in 0..1 (all white), and NaNs
    reached OpenCV's own assertion."""
    with pytest.raises(WoodcamError, match=match):
        detect_rings(photo, px_per_mm=5.0)


def test_the_filter_bank_is_built_a_scale_at_a_time():
    """The log-Gabor bank of every scale and orientation was built at once in float64 and copied
    to float32 (8 x 8 x 600 x 400: 120 MB and 60 MB more): a 0.3 MP face's detection peaked at
    1.3 kB a pixel (311 MB). Now each scale's filters are made as the scale is used: the same
    numbers, and the peak under 0.95 kB a pixel (0.85)."""
    import tracemalloc

    from woodcam.detect import rings

    shape, wavelengths, theta0 = (40, 60), [4.0, 6.5, 11.0], 0.3
    thetas, scales = rings._bank(shape, theta0, wavelengths, 8)
    got = np.stack(list(scales))
    # the whole bank at once, as it was built
    fr, fc = np.fft.fftfreq(shape[0])[:, None], np.fft.fftfreq(shape[1])[None, :]
    f, ang = np.hypot(fr, fc), np.arctan2(fr, fc)
    f[0, 0] = 1.0
    radial = np.exp(-np.log(f[None] * np.asarray(wavelengths)[:, None, None]) ** 2 / (2 * rings.RADIAL_SIGMA_LN ** 2))
    radial[:, 0, 0] = 0.0
    d = np.angle(np.exp(1j * (ang[None] - thetas[:, None, None])))
    angular = np.exp(-d ** 2 / (2 * rings.ANGULAR_SIGMA_RAD ** 2))
    angular[np.abs(d) > np.pi / 2] = 0.0
    assert got.dtype == np.float32 and np.array_equal(got, (radial[:, None] * angular[None]).astype(np.float32))
    photo, _ = _line_face(n=480)
    detect_rings(photo[:64, :64])  # the modules' first use is no face's
    tracemalloc.start()
    try:
        detect_rings(photo)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 950 * photo.shape[0] * photo.shape[1], f"{peak / photo.shape[0] / photo.shape[1]:.0f} B a pixel"


@pytest.mark.parametrize("shape, sigma", [((64, 48), 17.0), ((256, 256), 128.0), ((37, 500), 250.0),
                                          ((300, 200), 60.0), ((20, 30), 40.0), ((64, 48), 3.0)])
def test_the_wide_gaussians_are_scipys_bit_for_bit(shape, sigma):
    """The detector's widest blurs run through the FFT (_gaussian_reflect); each must equal
    scipy.ndimage.gaussian_filter(mode="reflect") to the last bit, so detections, their caches
    and DETECT_VERSION are unchanged: kernels longer than the image (reflected again and again),
    non-square images, and the narrow ones scipy still does."""
    from scipy import ndimage

    from woodcam.detect import rings

    x = np.random.default_rng(7).normal(size=shape).astype(np.float32) ** 2  # x * x in _normalise
    got = rings._gaussian_reflect(x, sigma)
    assert got.dtype == np.float32 and np.array_equal(got, ndimage.gaussian_filter(x, sigma, mode="reflect"))


def test_no_wide_gaussian_is_filtered_tap_by_tap(monkeypatch):
    """A 256^2 face spent 0.2 s of its 0.45 s in scipy's direct Gaussian passes of sigma 128 px
    (1025 taps, the illumination flattening) and 50 px (the edge vote), a 500^2 face 1.4 s of
    3 s (2001 taps); through the FFT they take 0.02 s and 0.12 s. No Gaussian wider than
    FFT_GAUSSIAN_SIGMA_PX reaches scipy's direct filter now."""
    from scipy import ndimage

    from woodcam.detect import rings

    photo, _ = _line_face(n=256)
    real, sigmas = ndimage.gaussian_filter, []
    monkeypatch.setattr(ndimage, "gaussian_filter",
                        lambda a, sigma, *args, **kw: sigmas.append(float(np.max(sigma))) or real(a, sigma, *args, **kw))
    found = detect_rings(photo)
    assert found.traces and sigmas and max(sigmas) <= rings.FFT_GAUSSIAN_SIGMA_PX, sigmas
