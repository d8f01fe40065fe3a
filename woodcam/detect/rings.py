"""Annual rings found on one face photo by a weight-free quadrature filter bank.

Data forms (pixels of one face image, ``(row, col)``, pixel centres at integers as in
:mod:`woodcam.block.block`):

- ``photo : (h, w, 3) uint8`` RGB, rectified to the face;
- ``traces : list of RingTrace``, sub-pixel polylines on the detected ring boundaries, unlabelled;
- ``ring_map : (h, w) float32 in [0, 1]``, bright on ring boundaries like the Mokume ``arl`` maps;
- ``normal_rad : (h, w)`` the local ring normal (radians, ``atan2(d row, d col)``), sign
  made consistent over the face (it points the same way as the face's dominant ring normal);
- ``wavelength_px : (h, w)`` the local ring spacing in pixels;
- ``confidence : (h, w)`` in [0, 1]: orientation coherence times relative amplitude.

Method (seed 000 sec. 5.1 names automatic ring extraction as future work; Nindel et al. 2023
use curved Gabor filters: a quadrature filter bank for orientation and spacing, then a curved
Gabor adapted to both):

1. Luminance, flattened (minus a wide Gaussian) and contrast-normalised (divided by the local
   RMS), so exposure gradients and vignetting do not move the rings.
2. A bank of log-Gabor quadrature filters (Field 1987), one-sided in the Fourier plane so each
   response ``z_jk = e + i o`` is analytic: ``G_jk(f, a) = exp(-ln(f / f_j)^2 / (2 ln(s_r)^2))
   exp(-d(a, theta_k)^2 / (2 s_a^2))`` for wavelengths ``1 / f_j`` half an octave apart between
   :data:`WAVELENGTH_RANGE_PX` and orientations ``theta_k`` spanning the half plane centred on the
   face's dominant ring normal (so the odd parts agree in sign across the bank).
3. Adaptation to the local orientation (steering): per scale, the orientations are blended
   with weights ``E_jk^2`` of their locally smoothed energies ``E_jk = G_sigma * |z_jk|^2``. These
   kernels are straight and short along the ring; the bank gives the local ring normal, spacing
   (from the blend's phase gradient), coherence and amplitude.
3b. The curved Gabor (:mod:`woodcam.detect.curved`): with that normal and spacing, a 1-D complex
   Gabor across the ring at every pixel's own orientation and frequency, averaged with a Gaussian
   along the ring's curve (the streamline of the ring tangents through the pixel). Its phase,
   not the bank's, places and orders the rings wherever the two agree within
   :data:`CURVED_AGREE_RAD`; opt-in (``curved=True``; :data:`CURVED_GABOR` says why it is off).
4. Frequency gating: rings are periodic, so their band energy peaks at the ring spacing,
   while pores, fibres, rays, oak figure and lighting are broadband. Each scale is weighted by
   its log spectral prominence over its two neighbours (0 for any power law) times its
   orientation coherence ``|sum_k E_k e^{2 i theta_k}| / sum_k E_k`` (pores are isotropic, rays
   cross the rings). Gates: coherence, relative amplitude against the face's 75th percentile,
   and the amplitude over the flattened photo's local contrast.
5. Ring lines. The band centres (phase pi of the response: ``o = 0`` where ``e < 0``)
   are sub-pixel contours (linear interpolation between pixel centres); the phase unwrapped over
   the evidence region orders them across the face (:attr:`RingDetection.ring_order`). Each
   centre line is then moved, across the ring by at most a third of a spacing, onto the ring
   line of the :data:`BoundaryRule`:

   - ``"dark-edge"`` (default): from the darkest line (below) toward the band's steeper edge
     (voted locally, as for ``"sharp-edge"``), to where the luminance has risen
     :data:`DARK_EDGE_RISE` of the way to that edge's top: the end of the dark line, where the
     ring boundary is. On a narrow line darkest at the boundary (spruce latewood) this stays
     within about a pixel of the darkest line; on a broad dark band with a flat bottom that ends
     in a step (woodcam's plain synthetic latewood) the darkest line is ill-placed (its smoothed
     minimum sits 0.12 ring spacings inside, 1.5-3 px) and this finds the step.
   - ``"dark-line"``: the darkest line of the band, at 1 px scale, averaged along the
     ring. This is where the Mokume U-Net maps (trained on people's annotations of real wood)
     put a ring: the mean luminance profile across their ridges has its minimum on the ridge on
     all 12 faces of CN03 and H11 (spruce: the narrow latewood line; oak: the dark first rows of
     earlywood pores next to the boundary). In softwood latewood density peaks at the ring
     boundary, so this is the boundary to within its 2-4 px width.
   - ``"sharp-edge"``: the steeper of the band's two edges (voted locally, so a pith inside the
     face is handled): the exact ring boundary of woodcam's plain synthetic faces, whose
     latewood ramps over 45 % of a ring and whose darkest line is therefore not the boundary.
   - ``"dark-centre"``: the band centre itself (the filter's phase alone).

6. Ring pieces. A ring broken by pores, a ray fleck, a knot or a jump of its line comes out in
   pieces; the phase links the pieces of one ring (``_ring_ids``: same place in the order, one
   evidence region, a short gap no other ring crosses) and they share ``RingTrace.ring``, so
   the fitter gives them one growth time instead of numbering each as a ring of its own.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._checks import as_floats, check_bool
from .._repr import summary_repr
from ..block.block import RingTrace
from ..errors import WoodcamError

BoundaryRule = Literal["dark-line", "dark-edge", "sharp-edge", "dark-centre"]
BOUNDARY_RULES: tuple[str, ...] = ("dark-line", "dark-edge", "sharp-edge", "dark-centre")
#: The rule the detector uses unless told (module docstring, step 5).
DEFAULT_RULE: BoundaryRule = "dark-edge"

#: Ring spacings (px) the filter bank looks for. 4.5 px is above the pore / fibre texture of the
#: Mokume faces (pores 2-3 px apart on 256 px faces of a 50 mm cube); 64 px is a quarter of such a
#: face, the widest ring whose period still fits a few times across it.
WAVELENGTH_RANGE_PX = (4.5, 128.0)
#: Ring spacings (mm) looked for when the image density is known: 0.88 mm is 4.5 px on the
#: Mokume faces (5.12 px/mm), 25 mm the widest rings of fast-grown softwood.
RING_SPACING_RANGE_MM = (0.88, 25.0)
#: Filter scales per octave of wavelength (half an octave apart: a ring's spectral peak spans
#: about three of them, so its prominence over its neighbours shows), and orientations over
#: the half plane.
SCALES_PER_OCTAVE = 2
N_ORIENTATIONS = 8
#: Angular std of each filter (radians): overlapping neighbours (spacing pi/8 = 0.39).
ANGULAR_SIGMA_RAD = 0.30
#: Radial bandwidth: std of ln(f / f_j), about one octave at half height.
RADIAL_SIGMA_LN = 0.40
#: Energy smoothing (in wavelengths of each filter) before the local choice of filter.
ENERGY_SMOOTH_WAVELENGTHS = 0.8
#: Smoothing (in wavelengths of each scale) of the band energy whose spectral peak picks the
#: ring scale: two ring spacings hold enough periods to show a peak.
PERIOD_SMOOTH_WAVELENGTHS = 2.0
#: Least coherence-weighted peak height (natural log of band energy) for a pixel to count as
#: showing a spectral peak; below it the spectrum's bend picks the scale (``_response``).
PEAK_MIN = 0.02
#: Gates: a pixel is ring evidence when coherence >= COHERENCE_MIN and the blended amplitude is
#: at least AMPLITUDE_MIN of the face's 75th-percentile amplitude.
COHERENCE_MIN = 0.35
AMPLITUDE_MIN = 0.25
#: Fine scale (px) of the luminance on which a ring line is placed: a latewood line is 2-4 px
#: wide on 256 px faces of a 50 mm cube; 1 px keeps it apart from its neighbours.
SNAP_SIGMA_PX = 1.0
#: How far (in local ring spacings, each way) a band centre may move to its ring line.
SNAP_REACH_WAVELENGTHS = 0.33
#: Half length (px) of the stretch along the ring over which the profile across it is averaged
#: (pores and ray flecks are shorter than it; the ring bends little over it).
SNAP_ALONG_PX = 3
#: Vertices (1 px apart) of a trace whose profiles across the ring are averaged before the
#: ring line is placed on them (``_along_traces``).
SNAP_TRACE_VERTICES = 9
#: Faint rings (``_faint_lines``): the scale (px) of the valley detector, and the least valley
#: depth, relative to the median depth on the rings the band centres found.
VALLEY_SIGMA_PX = 1.5
VALLEY_REL = 0.5
#: Largest change (px) of the move between neighbouring vertices (1 px apart) of a trace; a
#: larger one is a jump to another line and the trace is cut there.
SNAP_JUMP_PX = 1.0
#: Median window (vertices) of the moves along a trace: one pore cannot pull a line aside.
SNAP_MEDIAN_VERTICES = 5
#: ``"dark-edge"``: share of the rise from the dark line's minimum to its sharp edge's top at
#: which the dark line ends (``_latewood_end``). On the synthetic development seeds 0-3 (plain /
#: realistic faces, F within 2 px): 0.05 -> 0.84 / 0.73, 0.10 -> 0.93 / 0.75, 0.25 -> 0.97 /
#: 0.76 (the best there), 0.35 -> 0.97 / 0.73. 0.10 is the smallest that meets the 0.90 goal on the
#: plain faces; the larger 0.25 was rejected after seeing it move the lines 1-1.6 px off the
#: Mokume maps' ridges on the real spruce faces (which mark the darkest line): not blind.
DARK_EDGE_RISE = 0.10
#: Reach (in ring spacings) of the local vote between the two edges for ``"sharp-edge"``.
VOTE_SCALE_WAVELENGTHS = 2.0
#: Least local amplitude of the ring component, in units of the photo's local RMS contrast
#: after flattening: white noise reaches 0.04-0.06, the faintest real ring face seen (Mokume
#: CN03 top, oak) 0.13, synthetic faces 0.4-0.55.
SIGNAL_MIN = 0.09
#: Ring pieces shorter than this many local wavelengths are dropped (pores, specks).
MIN_TRACE_WAVELENGTHS = 1.0
#: Longest gap (in local ring spacings) between the ends of two pieces that the phase says are one
#: ring for them to be linked as one ring (``_ring_ids``): a pore cluster, ray fleck or shake
#: breaks a ring over a spacing or two; farther apart, an unwrapping error around a knot could
#: give two rings one order.
LINK_GAP_WAVELENGTHS = 3.0
#: Largest difference (in rings) of two pieces' places in the ring order for them to be one ring:
#: band centres sit on whole numbers (same number or not), faint lines where they lie between.
LINK_ORDER_TOL = 0.25
#: Least number of vertices (1 px apart) of one piece lying beside another (their nearest vertex
#: of it away from its ends) for a link between the two to be refused (``_side_by_side``): 3 px
#: of overlap along the ring, more than the kink of a line cut where it jumped. Added after H11's
#: right face gave one ring id to 9 pieces of 5 rings (DETECT_VERSION 7).
SIDE_BY_SIDE_VERTICES = 3
#: Use the curved Gabor response (:mod:`woodcam.detect.curved`) for the ring phase by default.
#: Off (``woodcam rings detect --curved`` turns it on): it gains 0.01-0.02 F on the synthetic and
#: real faces (README), costs ~1.5x the CPU, and moved the downstream fits both ways (in-sample
#: loss H11 13.1 -> 11.0, CN03 12.5 -> 18.9 points within 2 px, DETECT_VERSION 5). With the fitter of FIT_VERSION 7
#: the radial fit from H11's curved rings counted 2.1-2.8 times the Mokume maps' rings: its
#: numbering took its ring scale from the wrong alignment peak; since every clear peak is tried
#: and the one whose neighbouring rings are one year apart kept (FIT_VERSION 8), it counted
#: 1.05-1.35 times; with speck pieces dropped after the snap (DETECT_VERSION 6) 0.37-0.89
#: (median 0.75, below ``tests/detect/test_detect_downstream.py``'s 0.8), though its in-sample
#: loss is then the lowest measured (H11 6.9 / 9.9, CN03 8.7 / 5.1 within 2 / 5 px).
CURVED_GABOR = False
#: Largest phase difference (radians) between the curved and the bank's straight response at
#: a pixel for the curved one to be used there; elsewhere the bank's is kept. The curved Gabor
#: trusts the orientation field, and a band of noise across the rings turns that field by 20
#: degrees or more over ~50 px round it: there the two disagree, the curves hook, and without
#: this check the pieces of one ring stopped linking (``test_pieces_of_one_ring_share_its_id``:
#: 17 lines -> 51-55 ring ids). Chosen on the development seeds 0-3 (dark-edge, F within 2 px
#: plain / realistic): pi/3 0.923 / 0.723, 0.5 rad 0.906 / 0.718, no check 0.911 / 0.728.
CURVED_AGREE_RAD = float(np.pi / 3)
#: Spacing of trace vertices (px) after resampling the contour lines.
TRACE_STEP_PX = 1.0
#: Share of the face that must be ring evidence; below it the face has "no rings".
MIN_RING_AREA = 0.15
#: Ring-map line width: std (mm) of exp(-(d/sigma)^2), the width of the Mokume U-Net maps.
RING_MAP_SIGMA_MM = 0.62


@dataclass
class RingDetection:
    """What :func:`detect_rings` found on one face (see module docstring for shapes).

    Maps are ``(h, w)``, the face image's pixels (row, column; the face's own image frame,
    :mod:`woodcam.frames`): ``ring_map`` float32 in [0, 1], ``normal_rad`` the ring normal's
    angle (radians), ``wavelength_px`` the ring spacing (pixels), ``confidence`` in [0, 1],
    ``evidence`` bool; ``traces`` polylines in continuous pixel coordinates ``(row, col)``.
    ``rule``: the boundary rule the traces were snapped to (one of :data:`BOUNDARY_RULES`,
    :func:`detect_rings`' ``rule``); ``warnings``: strings naming the face when little or no
    ring evidence was found. ``order_map`` ``(h, w)`` float32 (rings, NaN outside the evidence)
    and ``ring_order`` (one number per trace) order the rings across the face, as commented
    below.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    traces: list[RingTrace]
    ring_map: np.ndarray
    normal_rad: np.ndarray
    wavelength_px: np.ndarray
    confidence: np.ndarray
    evidence: np.ndarray          # (h, w) bool, the gated ring-evidence region
    rule: str
    warnings: list[str] = field(default_factory=list)
    #: (h, w) float32: the response's phase unwrapped over the evidence region, in rings
    #: (cycles), 0 on the first band centre found; NaN outside the evidence. It grows by one
    #: per ring along the face's dominant normal, so it orders the rings across the face.
    order_map: np.ndarray | None = None
    #: Per trace, its ring's place in that order (an integer for a band centre, ``k + 1/2`` for a
    #: faint ring found between two; relative to this face only: the same ring on two faces
    #: gets unrelated numbers, so these are not years). Traces of one ring also share their
    #: ``RingTrace.ring`` id (order within one connected evidence region).
    ring_order: list[float] = field(default_factory=list)

    @property
    def points_px(self) -> np.ndarray:
        """All trace vertices ``(n, 2)`` float (row, col)."""
        if not self.traces:
            return np.zeros((0, 2))
        return np.concatenate([t.points_px for t in self.traces])


def luminance(photo: np.ndarray) -> np.ndarray:
    """``(h, w)`` float32 luminance in [0, 1] of an ``(h, w, 3)`` photo (Rec. 601): uint8, or float
    in [0, 1]; ``(h, w)`` grey the same."""
    a = np.asarray(photo)
    if a.dtype != np.uint8:
        # another integer type (a 16-bit export) or a float photo in 0..255 would be read as if
        # in 0..1, and NaNs reach OpenCV: refused here with what to pass instead
        if not np.issubdtype(a.dtype, np.floating):
            raise WoodcamError(f"photo must be uint8 (0..255) or float (0..1); got dtype {a.dtype}; convert "
                               "it with woodcam._readers.photo_rgb8 (16-bit exports are scaled to 8 bits)")
        if a.size and not (np.all(np.isfinite(a)) and -1e-3 <= float(a.min()) and float(a.max()) <= 1.0 + 1e-3):
            raise WoodcamError(f"a float photo must hold finite values in [0, 1]; got range "
                               f"[{np.nanmin(a) if np.isfinite(a).any() else 'nan'}, "
                               f"{np.nanmax(a) if np.isfinite(a).any() else 'nan'}] with "
                               f"{int(np.sum(~np.isfinite(a)))} non-finite; divide by 255 or pass uint8")
    if a.ndim == 2:
        return a.astype(np.float32) / (255.0 if a.dtype == np.uint8 else 1.0)
    if a.ndim != 3 or a.shape[2] != 3:  # a 4- or 5-channel array was read by its first three without a word
        raise WoodcamError(f"photo must be (h, w, 3) RGB or (h, w) grey; got shape {a.shape}; pass its RGB "
                           "channels (photo[..., :3] where the first three are red, green, blue)")
    scale = 255.0 if a.dtype == np.uint8 else 1.0
    return (a.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)) / scale


#: Gaussians wider than this (sigma, px) run through the FFT (:func:`_gaussian_reflect`): the
#: direct 1-D passes cost (8 sigma + 1) taps a pixel, the FFT a few log n. Crossover measured
#: on 256^2 and 1000x700 images at sigma 12-20 px.
FFT_GAUSSIAN_SIGMA_PX = 16.0


def _gaussian_reflect(img: np.ndarray, sigma: float) -> np.ndarray:
    """``scipy.ndimage.gaussian_filter(img, sigma, mode="reflect")`` of a 2-D ``img`` (float32 in,
    float32 out), through the FFT when ``sigma`` exceeds :data:`FFT_GAUSSIAN_SIGMA_PX` (other
    dtypes, and narrower sigmas, by scipy itself).

    The detector's widest blurs (the illumination flattening at sigma up to half the face, the
    edge vote at two ring spacings) took 40-45 % of a face's time: 0.2 s of 0.45 s on a 256^2
    face, 1.4 s of 3 s on a 500^2 one, in 1025- and 2001-tap passes. Reflected, each line is
    periodic with period 2n (``abc|cba``), so a pass is a circular convolution of that period with
    the truncated kernel (``truncate=4``, normalised, as scipy builds it) folded into it. Each pass
    is computed in float64 and stored as float32, as scipy's are, so the result is scipy's: equal
    bit for bit on the 12 Mokume faces, synthetic faces and random images tried (DETECT_VERSION
    unchanged)."""
    from scipy import ndimage

    out = np.asarray(img)
    if sigma <= FFT_GAUSSIAN_SIGMA_PX or out.dtype != np.float32 or out.ndim != 2:
        return ndimage.gaussian_filter(out, sigma, mode="reflect")
    radius = int(4.0 * float(sigma) + 0.5)
    k = np.arange(-radius, radius + 1)
    weights = np.exp(-0.5 / float(sigma) ** 2 * k.astype(np.float64) ** 2)
    weights /= weights.sum()
    for axis in (0, 1):  # scipy's order: the float32 rounding between passes is the same
        n = out.shape[axis]
        folded = np.zeros(2 * n)
        np.add.at(folded, k % (2 * n), weights)
        line = np.concatenate([out, np.flip(out, axis)], axis=axis).astype(np.float64)
        spec = np.fft.rfft(line, axis=axis) * np.expand_dims(np.fft.rfft(folded), 1 - axis)
        out = np.take(np.fft.irfft(spec, n=2 * n, axis=axis), np.arange(n), axis=axis).astype(np.float32)
    return out


def _normalise(lum: np.ndarray, sigma: float) -> np.ndarray:
    """Flatten the illumination (a fitted quadratic surface, then a Gaussian of ``sigma`` px) and
    divide by the local RMS contrast (Gaussian, ``sigma`` px). The quadratic takes out lighting
    gradients and vignetting, which the Gaussian alone leaves as ramps along the borders."""

    h, w = lum.shape
    rr, cc = np.meshgrid(np.linspace(-1, 1, h), np.linspace(-1, 1, w), indexing="ij")
    basis = np.stack([np.ones_like(rr), rr, cc, rr * rr, rr * cc, cc * cc], axis=-1).reshape(-1, 6)
    coef = np.linalg.lstsq(basis[::7], lum.reshape(-1)[::7], rcond=None)[0]
    lum = lum - (basis @ coef).reshape(h, w).astype(np.float32)
    x = lum - _gaussian_reflect(lum, sigma)
    rms = np.sqrt(_gaussian_reflect(x * x, sigma))
    return x / (rms + 1e-3 + 0.05 * float(np.median(rms)))


def dominant_normal(lum: np.ndarray) -> float:
    """Angle (radians, ``atan2(d row, d col)``) of the face's dominant ring normal: the main axis of
    the summed structure tensor of the luminance (gradient at 1.5 px)."""
    from scipy import ndimage

    gr = ndimage.gaussian_filter(lum, 1.5, order=(1, 0))
    gc = ndimage.gaussian_filter(lum, 1.5, order=(0, 1))
    jrr, jcc, jrc = float((gr * gr).sum()), float((gc * gc).sum()), float((gr * gc).sum())
    return 0.5 * float(np.arctan2(2 * jrc, jcc - jrr))


def _bank(shape, theta0: float, wavelengths, n_orient: int) -> tuple[np.ndarray, Iterator[np.ndarray]]:
    """The orientations ``(n_orient,)`` (radians, spanning ``theta0 +- pi/2``) and, one scale at a
    time as the iterator is advanced, the frequency responses ``(n_orient, h, w)`` float32 of
    that scale's one-sided log-Gabor filters: the whole bank at once (8 scales x 8 orientations
    of a 600 x 400 face: 120 MB of float64 and its float32 copy) was a face's largest allocation."""
    h, w = shape
    fr = np.fft.fftfreq(h)[:, None]
    fc = np.fft.fftfreq(w)[None, :]
    f = np.hypot(fr, fc)
    ang = np.arctan2(fr, fc)
    f[0, 0] = 1.0  # the DC term is removed below
    thetas = theta0 + (np.arange(n_orient) + 0.5) / n_orient * np.pi - np.pi / 2
    d = np.angle(np.exp(1j * (ang[None] - thetas[:, None, None])))     # wrapped to (-pi, pi]
    angular = np.exp(-d ** 2 / (2 * ANGULAR_SIGMA_RAD ** 2))
    # one-sided (analytic): a filter passes frequencies within pi/2 of its orientation only
    angular[np.abs(d) > np.pi / 2] = 0.0

    def scales() -> Iterator[np.ndarray]:
        for lam in np.asarray(wavelengths, float):
            radial = np.exp(-np.log(f * lam) ** 2 / (2 * RADIAL_SIGMA_LN ** 2))
            radial[0, 0] = 0.0
            yield (radial[None] * angular).astype(np.float32)

    return thetas, scales()


def _blur(img: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur (reflecting borders) of a float32 ``(h, w)`` image; wide blurs run on an
    image shrunk by up to 4x (area averaging) and are enlarged back: the result is smooth on
    that scale anyway, and OpenCV's cost grows with the kernel."""
    import cv2

    h, w = img.shape
    f = int(min(4, max(1, sigma // 3)))
    if f == 1:
        return cv2.GaussianBlur(img, (0, 0), sigma, borderType=cv2.BORDER_REFLECT)
    small = cv2.resize(img, (max(1, w // f), max(1, h // f)), interpolation=cv2.INTER_AREA)
    small = cv2.GaussianBlur(small, (0, 0), sigma / f, borderType=cv2.BORDER_REFLECT)
    return cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)


def _response(x: np.ndarray, wavelengths, n_orient: int):
    """Blended analytic response ``z (h, w) complex64``, local wavelength (px), normal angle,
    coherence, and the blend's local amplitude in units of ``x``.

    Per scale ``j``: the orientations are blended with weights ``E_jk^2`` (the steered response
    of that scale), and the scale's band energy ``S_j`` is smoothed over
    :data:`PERIOD_SMOOTH_WAVELENGTHS` of its own spacing. Frequency gating: rings are periodic,
    so their band energy peaks at the ring spacing, while pores, fibres, rays, figure and
    lighting are broadband (power falling or rising smoothly with scale). A scale's weight is
    its log spectral peak height ``P_j = min(ln S_j - ln S_{j-1}, ln S_j - ln S_{j+1})`` (0 unless
    a local maximum; the end scales cannot show one; where no scale peaks, the bend
    ``ln S_j - (ln S_{j-1} + ln S_{j+1}) / 2``, 0 for a power law) times its orientation
    coherence, squared. Scales blend with those weights, each normalised by its
    local band amplitude ``sqrt(S_j)``."""
    from scipy import fft

    h, w = x.shape
    n_scales = len(wavelengths)
    theta0 = dominant_normal(x)
    thetas, bank = _bank(x.shape, theta0, wavelengths, n_orient)
    spec = fft.fft2(x.astype(np.float32), workers=-1)
    rot = np.exp(2j * thetas).astype(np.complex64)[:, None, None]
    band = np.zeros((n_scales, h, w), np.float32)        # S_j
    coh = np.zeros((n_scales, h, w), np.float32)
    zj = np.zeros((n_scales, h, w), np.complex64)
    amp = np.zeros((n_scales, h, w), np.float32)
    orient = np.zeros((h, w), np.complex64)               # doubled-angle normal, all scales
    for j, (lam, filters) in enumerate(zip(wavelengths, bank)):
        # (K, h, w) analytic responses of this scale (2x: the one-sided spectrum)
        z = fft.ifft2(2.0 * spec[None] * filters, axes=(-2, -1), workers=-1).astype(np.complex64)
        energy = z.real ** 2 + z.imag ** 2
        for k in range(n_orient):
            energy[k] = _blur(energy[k], ENERGY_SMOOTH_WAVELENGTHS * float(lam))
        esum = energy.sum(axis=0) + 1e-20
        d = (energy * rot).sum(axis=0) / esum
        coh[j] = np.abs(d)
        # the orientation is read from every scale (whitened, coherence-weighted), not only
        # the ring scale: inside a knot the finer scales see its own rings circle round
        orient += (esum / float(esum.mean())) * coh[j] * d
        wgt = energy * energy
        wsum = wgt.sum(axis=0) + 1e-20
        zj[j] = (wgt * z).sum(axis=0) / wsum
        amp[j] = np.sqrt((wgt * energy).sum(axis=0) / wsum)
        band[j] = _blur(esum, PERIOD_SMOOTH_WAVELENGTHS * float(lam))
    log_band = np.log(band + 1e-20)
    prominence = np.zeros_like(band)
    # a peak: the scale's band energy above both neighbours' (by the smaller margin); where no
    # scale shows one (a knot's tangle, too few periods), the bend (concavity) of the log
    # spectrum instead, so such regions keep a response rather than none
    peak = np.clip(np.minimum(log_band[1:-1] - log_band[:-2], log_band[1:-1] - log_band[2:]), 0.0, None)
    bend = np.clip(log_band[1:-1] - 0.5 * (log_band[:-2] + log_band[2:]), 0.0, None)
    has_peak = (peak * coh[1:-1]).max(axis=0) > PEAK_MIN
    prominence[1:-1] = np.where(has_peak[None], peak, bend)
    wgt = (prominence * coh) ** 2
    total = wgt.sum(axis=0) + 1e-20
    zb = (wgt * zj / np.sqrt(band + 1e-20)).sum(axis=0) / total
    lam_px = np.exp((wgt * np.log(np.asarray(wavelengths, np.float32))[:, None, None]).sum(axis=0) / total)
    amp_raw = (wgt * amp).sum(axis=0) / total
    coherence = (wgt * coh).sum(axis=0) / total
    lam_px = _instantaneous_wavelength(zb, lam_px, wavelengths)
    normal = 0.5 * np.angle(orient * np.exp(-2j * theta0)) + theta0   # within theta0 +- pi/2
    return (zb.astype(np.complex64), lam_px.astype(np.float32), normal.astype(np.float32),
            coherence.astype(np.float32), amp_raw.astype(np.float32))


def _ring_order(z: np.ndarray, evidence: np.ndarray, polys: list) -> tuple[np.ndarray, list[float]]:
    """The order map (``RingDetection.order_map``) and each band-centre polyline's place in it
    (an integer, NaN for a polyline off the evidence region).

    The phase of the analytic response rises by 2 pi per ring along the filters' common
    direction; unwrapped over the evidence region (skimage's reliability-sorted unwrapping,
    Herraez et al. 2002) it numbers the rings consistently across the face wherever the region
    is connected. Band centres sit at phase pi (mod 2 pi), so a polyline's order is the
    median of ``(phase - pi) / 2 pi`` on it, rounded."""
    from skimage.restoration import unwrap_phase

    h, w = z.shape
    order = np.full((h, w), np.nan, np.float32)
    if not evidence.any():
        return order, [0] * len(polys)
    wrapped = np.ma.masked_array(np.angle(z), mask=~evidence)
    un = np.asarray(unwrap_phase(wrapped).filled(np.nan), np.float64)
    cycles = (un - np.pi) / (2 * np.pi)
    out = [_piece_order(cycles, p) for p in polys]
    base = np.nanmin(out) if np.isfinite(out).any() else 0.0
    base = np.floor(base + 0.5)
    order[evidence] = (cycles[evidence] - base).astype(np.float32)
    return order, [float(np.round(o - base)) if np.isfinite(o) else np.nan for o in out]


def _piece_order(order_map: np.ndarray, q: np.ndarray) -> float:
    """Median of the order map on a polyline ``q (k, 2)``: its place in the ring order, read
    where it lies (NaN off the evidence region)."""
    h, w = order_map.shape
    v = order_map[np.clip(np.round(q[:, 0]).astype(int), 0, h - 1), np.clip(np.round(q[:, 1]).astype(int), 0, w - 1)]
    return float(np.nanmedian(v)) if np.isfinite(v).any() else np.nan


def _ring_ids(polys: list, order: list[float], evidence: np.ndarray, order_map: np.ndarray,
              lam: np.ndarray, n_centre: int) -> list[int | None]:
    """Per piece, the face-local id of the ring it belongs to (:attr:`RingTrace.ring`).

    ``order``: per piece its place in the ring order (the band centre's integer for a piece of
    one, where it lies in the order map for a faint line; NaN for none). The first
    ``n_centre`` pieces come from band centres, the rest are faint lines; a faint line is
    linked to faint lines only (it lies off every band centre's line by construction).

    Why: a ring broken by a pore band, a ray fleck or a jump of the line is still one growth
    time; handed to the fitter as separate pieces, each gets a level of its own, and on Mokume
    CN03 (oak) the pieces were then numbered as extra rings. Two pieces are linked when the
    phase says they are one ring: places in the ring order within :data:`LINK_ORDER_TOL` of
    each other, in one connected evidence region (the phase is unwrapped per region), an end of
    one within :data:`LINK_GAP_WAVELENGTHS` ring spacings of the nearest end of the other, and the
    unwrapped order along the straight gap between those ends within half a ring of theirs (no
    other ring crosses it), and the two not running beside each other (``_side_by_side``: the
    unwrapped phase can give neighbouring rings one order where a ring is faint or missing).
    Only nearby pieces: around a knot or a fork the unwrapped phase can give two far-apart rings
    the same order. Linked pieces (transitively) share an id; a piece
    with no order (off the evidence) gets None.
    """
    from scipy import ndimage
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(polys)
    if not n:
        return []
    h, w = evidence.shape
    lab, _ = ndimage.label(evidence)

    def pix(q):
        return (np.clip(np.round(q[:, 0]).astype(int), 0, h - 1), np.clip(np.round(q[:, 1]).astype(int), 0, w - 1))

    region = np.zeros(n, int)
    for i, q in enumerate(polys):
        r = lab[pix(q)]
        r = r[r > 0]
        region[i] = np.bincount(r).argmax() if len(r) and np.isfinite(order[i]) else 0
    o = np.asarray(order, float)
    faint = np.arange(n) >= n_centre
    ends = np.concatenate([np.stack([q[0], q[-1]]) for q in polys])          # (2n, 2): piece e // 2
    piece = np.arange(2 * n) // 2
    reach = LINK_GAP_WAVELENGTHS * lam[pix(ends)]
    # candidate end pairs within the largest reach (a k-d tree: faces may hold thousands of pieces)
    pairs = cKDTree(ends).query_pairs(float(reach.max()), output_type="ndarray")
    ea, eb = pairs[:, 0], pairs[:, 1]
    pa, pb = piece[ea], piece[eb]
    gap = np.linalg.norm(ends[ea] - ends[eb], axis=1)
    # per pair of pieces only their nearest ends: that gap is where one would continue into
    # the other, so the test is made there; if the phase says another ring crosses it, other
    # end pairs do not make them one ring (allowing any pair flipped H11's fit from 5-15 rings
    # a face to 1-5)
    first = np.lexsort((gap, np.maximum(pa, pb), np.minimum(pa, pb)))
    key = np.minimum(pa, pb)[first] * (n + 1) + np.maximum(pa, pb)[first]
    nearest = np.zeros(len(gap), bool)
    nearest[first[np.diff(key, prepend=-1) != 0]] = True   # keys >= 0; also right with no pair
    ok = (nearest & (pa != pb) & (region[pa] == region[pb]) & (region[pa] > 0) & (faint[pa] == faint[pb])
          & (np.abs(o[pa] - o[pb]) <= LINK_ORDER_TOL) & (gap <= np.minimum(reach[ea], reach[eb])))
    t = np.linspace(0.0, 1.0, 9)[:, None]
    rows, cols = [], []
    for e, f in zip(ea[ok], eb[ok]):         # few candidates: a short loop
        v = order_map[pix(ends[e] + t * (ends[f] - ends[e]))]
        v = v[np.isfinite(v)]
        if len(v) and np.max(np.abs(v - (o[piece[e]] + o[piece[f]]) / 2)) > 0.5:
            continue
        if _side_by_side(polys[piece[e]], polys[piece[f]]):
            continue
        rows.append(piece[e])
        cols.append(piece[f])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    has = region > 0
    ids = {c: m for m, c in enumerate(sorted({int(comp[k]) for k in range(n) if has[k]}))}
    return [int(ids[int(comp[k])]) if has[k] else None for k in range(n)]


def _side_by_side(p: np.ndarray, q: np.ndarray) -> bool:
    """True when polylines ``p (k, 2)`` and ``q (l, 2)`` (row, col; vertices ~1 px apart) run
    beside each other: at least :data:`SIDE_BY_SIDE_VERTICES` vertices of one have their nearest
    vertex of the other away from its ends (two vertices in from each). Pieces of one ring
    follow each other along it, so each one's nearest vertices of the other are at its end; a
    ring never runs beside itself, so two such pieces are two rings whatever the phase says."""
    from scipy.spatial import cKDTree

    for a, b in ((p, q), (q, p)):
        if len(a) < 5:
            continue
        i = cKDTree(a).query(b)[1]
        if np.count_nonzero((i >= 2) & (i <= len(a) - 3)) >= SIDE_BY_SIDE_VERTICES:
            return True
    return False


def _instantaneous_wavelength(z: np.ndarray, lam_scale: np.ndarray, wavelengths) -> np.ndarray:
    """``(h, w)`` local ring spacing (px) from the blended response's phase gradient,
    ``2 pi / |grad phase|`` with ``grad phase = Im(conj(z) grad z) / |z|^2`` (the instantaneous
    frequency), averaged with weights ``|z|^2`` over about one spacing; the scale blend's
    spacing ``lam_scale`` where the response is too weak. Finer than the bank's half-octave
    steps, whose weighted mean is pulled toward whichever neighbour of the true spacing has
    the larger weight."""
    gz_r, gz_c = np.gradient(z)
    mag2 = (z.real ** 2 + z.imag ** 2).astype(np.float32)
    fr = np.imag(np.conj(z) * gz_r).astype(np.float32)
    fc = np.imag(np.conj(z) * gz_c).astype(np.float32)
    sig = float(np.median(lam_scale))
    den = _blur(mag2, sig) + 1e-12
    freq = np.hypot(_blur(fr, sig), _blur(fc, sig)) / den                # rad / px
    lam = 2 * np.pi / np.maximum(freq, 1e-6)
    weak = den < 0.05 * float(np.median(den))
    lam = np.where(weak, lam_scale, lam)
    return np.clip(lam, float(wavelengths[0]), float(wavelengths[-1])).astype(np.float32)


def _contour_runs(values: np.ndarray, keep: np.ndarray, min_len_px: np.ndarray) -> list[np.ndarray]:
    """Polylines ``(k, 2)`` (row, col) of the zero contour of ``values``, cut where ``keep`` (h, w)
    bool is False, resampled every :data:`TRACE_STEP_PX`; pieces shorter than ``min_len_px``
    (an (h, w) map read at each piece's middle) are dropped."""
    import contourpy

    h, w = values.shape
    gen = contourpy.contour_generator(z=values.astype(np.float64), line_type="Separate")
    out = []
    for line in gen.lines(0.0):
        if len(line) < 2:
            continue
        p = _resample_polyline(line[:, ::-1], TRACE_STEP_PX)              # (x, y) -> (row, col)
        r = np.clip(np.round(p[:, 0]).astype(int), 0, h - 1)
        c = np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)
        ok = keep[r, c]
        if not ok.any():
            continue
        # runs of consecutive kept vertices
        edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(np.int8), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            piece = p[a:b]
            if len(piece) < 2:
                continue
            mid = piece[len(piece) // 2]
            length = (len(piece) - 1) * TRACE_STEP_PX
            if length >= min_len_px[int(np.clip(round(mid[0]), 0, h - 1)), int(np.clip(round(mid[1]), 0, w - 1))]:
                out.append(piece)
    return out


def _resample_polyline(p: np.ndarray, step: float) -> np.ndarray:
    """Points every ``step`` along a polyline ``(k, 2)`` (ends kept), by interpolation."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return p[:1]
    t = np.linspace(0.0, s[-1], max(2, int(np.ceil(s[-1] / step)) + 1))
    return np.stack([np.interp(t, s, p[:, 0]), np.interp(t, s, p[:, 1])], axis=1)


def _profiles(img: np.ndarray, points: np.ndarray, n_rc: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """``(n, m)`` values of ``img (h, w)`` at ``points (n, 2) + offsets (n, m) * n_rc (n, 2)``
    (bilinear), each averaged over +-:data:`SNAP_ALONG_PX` along the ring (the normal turned)."""
    from scipy import ndimage

    acc = np.zeros(offsets.shape, np.float64)
    for u in range(-SNAP_ALONG_PX, SNAP_ALONG_PX + 1):
        q0 = points[:, :1] + offsets * n_rc[:, :1] - u * n_rc[:, 1:]
        q1 = points[:, 1:] + offsets * n_rc[:, 1:] + u * n_rc[:, :1]
        acc += ndimage.map_coordinates(img, [q0.ravel(), q1.ravel()], order=1, mode="nearest").reshape(offsets.shape)
    return acc / (2 * SNAP_ALONG_PX + 1)


def _faint_lines(lum: np.ndarray, polys: list, normal: np.ndarray, lam: np.ndarray,
                 evidence: np.ndarray, min_len: np.ndarray) -> list:
    """Dark lines the band centres missed: a ring fainter than its neighbours (the spectral
    peak may then sit at two ring spacings, one band centre per pair). Valleys of the
    luminance across the ring (second derivative along the normal, ``n^T H n`` at
    :data:`VALLEY_SIGMA_PX`, > 0 on a dark line) at least :data:`VALLEY_REL` as deep as the
    median on the lines already found, in the evidence region, farther than a quarter spacing
    from every found line: the sub-pixel zero contour of the valley's derivative along the
    normal (its crest), as for the band centres."""
    from scipy import ndimage

    rel = VALLEY_REL
    h, w = lum.shape
    sg = VALLEY_SIGMA_PX
    n_r, n_c = np.sin(normal), np.cos(normal)
    hrr = ndimage.gaussian_filter(lum, sg, order=(2, 0))
    hcc = ndimage.gaussian_filter(lum, sg, order=(0, 2))
    hrc = ndimage.gaussian_filter(lum, sg, order=(1, 1))
    depth = n_r * n_r * hrr + 2 * n_r * n_c * hrc + n_c * n_c * hcc          # > 0 in a valley
    gr, gc = np.gradient(depth)
    crest = gr * n_r + gc * n_c                                               # 0 on the crest
    p = np.concatenate(polys)
    r = np.clip(np.round(p[:, 0]).astype(int), 0, h - 1)
    c = np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)
    found = float(np.median(_sample(depth, p)))
    if not found > 0:
        return []
    on = np.zeros((h, w), bool)
    on[r, c] = True
    far = ndimage.distance_transform_edt(~on) > np.maximum(0.25 * lam, 2.0)
    keep = evidence & far & (depth >= rel * found)
    return _contour_runs(crest, keep, min_len)


def _along_traces(prof: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """``prof (n, m)`` averaged over :data:`SNAP_TRACE_VERTICES` consecutive vertices of the same
    trace (``owner (n,)``, vertices 1 px apart, traces contiguous): a ring line is continuous,
    so one trace's moves come from the profile of a stretch of it, not of one vertex."""
    from scipy import ndimage

    win = SNAP_TRACE_VERTICES
    if win <= 1:
        return prof
    out = np.empty_like(prof)
    cuts = np.flatnonzero(np.diff(owner)) + 1
    for a, b in zip(np.concatenate([[0], cuts]), np.concatenate([cuts, [len(owner)]])):
        out[a:b] = ndimage.uniform_filter1d(prof[a:b], min(win, b - a), axis=0, mode="nearest")
    return out


def _parabolic(values: np.ndarray, i: np.ndarray) -> np.ndarray:
    """Sub-sample position ``i + d`` of the extreme of ``values (n, m)`` at indices ``i (n,)``."""
    rows = np.arange(len(values))
    i = np.clip(i, 1, values.shape[1] - 2)
    y0, y1, y2 = values[rows, i - 1], values[rows, i], values[rows, i + 1]
    den = y0 - 2 * y1 + y2
    safe = np.where(np.abs(den) > 1e-12, den, 1.0)
    return i + np.clip(np.where(np.abs(den) > 1e-12, 0.5 * (y0 - y2) / safe, 0.0), -1.0, 1.0)


def _vote(steep_f: np.ndarray, steep_r: np.ndarray, r: np.ndarray, c: np.ndarray, lam: np.ndarray,
          shape: tuple[int, int]) -> np.ndarray:
    """Per trace vertex (pixel ``r, c``), True where the band's rising edge (out of the dark band,
    along the normal) is the steeper: the mean steepness of each edge (``steep_f``, ``steep_r``
    (n,)) over :data:`VOTE_SCALE_WAVELENGTHS` ring spacings round it. Which edge is sharp can
    change within a face (the pith inside it, a knot), so the vote is local, not per face."""

    sigma = VOTE_SCALE_WAVELENGTHS * float(np.median(lam[r, c]))
    count = np.zeros(shape, np.float32)
    np.add.at(count, (r, c), 1.0)
    count = _gaussian_reflect(count, sigma) + 1e-6
    votes = []
    for vals in (steep_f, steep_r):
        acc = np.zeros(shape, np.float32)
        np.add.at(acc, (r, c), vals.astype(np.float32))
        votes.append((_gaussian_reflect(acc, sigma) / count)[r, c])
    return votes[1] >= votes[0]


def _latewood_end(prof: np.ndarray, pos: np.ndarray, rising: np.ndarray) -> np.ndarray:
    """``"dark-edge"``: from the darkest line ``pos (n,)`` (sub-sample index into ``prof (n, m)``,
    the luminance across the ring) toward the band's sharp edge (``rising (n,)`` bool: the edge
    at larger indices), to the first sample where the luminance has risen
    :data:`DARK_EDGE_RISE` of the way from the minimum to the edge's top (linear interpolation
    between samples): the end of the dark line, where the ring boundary is. Where the darkest
    line is the boundary (narrow softwood latewood) this is within a pixel of it; on a broad
    dark band ending in a step it is the step, not the band's middle."""
    n, m = prof.shape
    rows = np.arange(n)
    # mirror the rows whose sharp edge is at smaller indices, so the walk always goes up
    q = np.where(rising[:, None], prof, prof[:, ::-1])
    start = np.where(rising, pos, m - 1 - pos)
    i0 = np.clip(np.floor(start).astype(int), 0, m - 1)
    idx = np.arange(m)[None, :]
    after = idx > i0[:, None]
    lo = q[rows, i0]
    top = np.where(after, q, -np.inf).max(axis=1)
    level = lo + DARK_EDGE_RISE * (top - lo)
    above = after & (q >= level[:, None])
    j = np.where(above.any(axis=1), np.argmax(above, axis=1), i0)
    qa, qb = q[rows, np.maximum(j - 1, 0)], q[rows, j]
    frac = np.clip((level - qa) / np.where(qb - qa > 1e-12, qb - qa, 1.0), 0.0, 1.0)
    end = np.where(j > i0, np.maximum(j - 1 + frac, start), start)
    return np.where(rising, end, m - 1 - end)


def _snap(lum: np.ndarray, polys: list, normal: np.ndarray, lam: np.ndarray, rule: str) -> tuple[list, list[int]]:
    """Move band-centre polylines (the fundamental's phase pi) onto the ring line of ``rule``;
    returns the moved pieces and, per piece, the index of the polyline it came from (a polyline
    cut at a jump gives several).

    ``"dark-line"``: the darkest line of the band (the minimum across the ring of the luminance
    at :data:`SNAP_SIGMA_PX`, averaged along it); ``"sharp-edge"``: the steeper of the band's two
    edges (extremes of the derivative across the ring), voted locally; ``"dark-edge"``: from the
    darkest line toward the voted sharp edge, to the end of the dark line (``_latewood_end``). Moves are looked for
    within :data:`SNAP_REACH_WAVELENGTHS` of a spacing, refined by a parabola through the
    extreme and median-filtered along each trace."""
    from scipy import ndimage

    if not polys:
        return polys, []
    h, w = lum.shape
    p = np.concatenate(polys)
    owner = np.repeat(np.arange(len(polys)), [len(q) for q in polys])
    r = np.clip(np.round(p[:, 0]).astype(int), 0, h - 1)
    c = np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)
    n_rc = np.stack([np.sin(normal[r, c]), np.cos(normal[r, c])], axis=1)
    t = np.linspace(-SNAP_REACH_WAVELENGTHS, SNAP_REACH_WAVELENGTHS, 41)
    offsets = t[None, :] * lam[r, c][:, None]
    step = offsets[:, 1] - offsets[:, 0]
    mid = (len(t) - 1) // 2
    if rule in ("dark-line", "dark-edge"):
        prof = _along_traces(_profiles(ndimage.gaussian_filter(lum, SNAP_SIGMA_PX), p, n_rc, offsets), owner)
        i_min = np.argmin(prof, axis=1)
        pos = _parabolic(prof, i_min)
    if rule != "dark-line":
        gr = ndimage.gaussian_filter(lum, SNAP_SIGMA_PX, order=(1, 0))
        gc = ndimage.gaussian_filter(lum, SNAP_SIGMA_PX, order=(0, 1))
        g = _along_traces(_profiles(gr, p, n_rc, offsets) * n_rc[:, :1]
                          + _profiles(gc, p, n_rc, offsets) * n_rc[:, 1:], owner)
        falling = np.where(np.arange(len(t)) <= mid, -g, -np.inf)      # into the band
        rising = np.where(np.arange(len(t)) >= mid, g, -np.inf)        # out of it
        i_f, i_r = np.argmax(falling, axis=1), np.argmax(rising, axis=1)
        rows = np.arange(len(p))
        rising_wins = _vote(falling[rows, i_f], rising[rows, i_r], r, c, lam, (h, w))
        if rule == "sharp-edge":
            pos = np.where(rising_wins, _parabolic(g, i_r), _parabolic(-g, i_f))
        else:
            pos = _latewood_end(prof, pos, rising_wins)
    move = (pos - (len(t) - 1) / 2) * step
    out, src = [], []
    for k, q in enumerate(polys):
        mk = move[owner == k]
        if len(mk) >= SNAP_MEDIAN_VERTICES:
            mk = ndimage.median_filter(mk, SNAP_MEDIAN_VERTICES, mode="nearest")
        moved = q + mk[:, None] * n_rc[owner == k]
        # where the line jumps to another dark line (two within reach), cut it there: the jump
        # itself would be a piece of "ring" running across the rings
        cuts = np.flatnonzero(np.abs(np.diff(mk)) > SNAP_JUMP_PX) + 1
        lam_k = lam[r[owner == k], c[owner == k]]
        for piece, lam_p in zip(np.split(moved, cuts), np.split(lam_k, cuts)):
            # the cuts make new pieces: they obey the least length the contour runs did
            # (MIN_TRACE_WAVELENGTHS), else a band snapped to pore streaks leaves specks
            if len(piece) >= 3 and (np.sum(np.hypot(*np.diff(piece, axis=0).T))
                                    >= MIN_TRACE_WAVELENGTHS * float(np.median(lam_p))):
                out.append(piece)
                src.append(k)
    return out, src


def _sample(img: np.ndarray, p: np.ndarray) -> np.ndarray:
    from scipy import ndimage

    return ndimage.map_coordinates(img, p.T, order=1, mode="nearest")


def lines_mask(lines, shape) -> np.ndarray:
    """``(h, w)`` bool: the pixels of the polylines ``lines`` (each ``(k, 2)`` row, col px),
    rasterised every half pixel along them (rounded, clipped to the image)."""
    h, w = shape
    on = np.zeros(shape, bool)
    for q in lines:
        p = _resample_polyline(np.asarray(q, float), 0.5)
        on[np.clip(np.round(p[:, 0]).astype(int), 0, h - 1), np.clip(np.round(p[:, 1]).astype(int), 0, w - 1)] = True
    return on


def ring_map_from_traces(traces, shape, sigma_px: float) -> np.ndarray:
    """``(h, w)`` float32 map ``exp(-(d / sigma_px)^2)`` of the distance ``d`` (px) to the traces
    (rasterised every half pixel along them, :func:`lines_mask`)."""
    from scipy import ndimage

    on = lines_mask([t.points_px for t in traces], shape)
    if not on.any():
        return np.zeros(shape, np.float32)
    d = ndimage.distance_transform_edt(~on)
    return np.exp(-(d / max(sigma_px, 1e-6)) ** 2).astype(np.float32)


def detect_rings(photo: np.ndarray, *, px_per_mm: float | None = None, rule: BoundaryRule = DEFAULT_RULE,
                 wavelength_range_px: tuple[float, float] | None = None,
                 name: str = "face", curved: bool | None = None) -> RingDetection:
    """Find the annual-ring boundaries on one face photo (module docstring: the method).

    Parameters
    ----------
    photo : (h, w, 3) uint8 RGB (or (h, w) grey), rectified to the face.
    px_per_mm : float, optional
        Image density; sets the ring map's line width (:data:`RING_MAP_SIGMA_MM`). Default: a
        256 px face of a 50 mm cube (5.12 px/mm), as the Mokume samples.
    rule : one of :data:`BOUNDARY_RULES` (default :data:`DEFAULT_RULE`, "dark-edge")
        Which phase extreme is the ring boundary (module docstring, step 5).
    wavelength_range_px : (min, max), optional
        Ring spacings the bank covers, px. Default :data:`RING_SPACING_RANGE_MM` at
        ``px_per_mm`` (never below 4.5 px, the pore scale), or :data:`WAVELENGTH_RANGE_PX`.
    name : str
        The face's name, used in warnings.
    curved : bool, optional
        Place and order the rings by the curved Gabor's phase (module docstring, step 3b);
        default :data:`CURVED_GABOR` (off).

    Returns
    -------
    RingDetection
        ``warnings`` names the face when little or no ring evidence was found.

    Raises
    ------
    WoodcamError
        For a photo too small to hold a ring (< 16 px a side), or a bad ``rule``.
    """
    if not isinstance(name, str):  # it names the face in every message and warning
        raise WoodcamError(f"name must be the face's name (str), e.g. 'front'; got {name!r} "
                           f"({type(name).__name__})")
    if rule not in BOUNDARY_RULES:
        raise WoodcamError(f"rule must be one of {', '.join(BOUNDARY_RULES)}; got {rule!r}")
    if curved is not None:
        curved = check_bool(curved, "curved", fix="pass True, False or None (the default, CURVED_GABOR)")
    lum = luminance(photo)
    h, w = lum.shape
    if min(h, w) < 16:
        raise WoodcamError(f"photo of face {name!r} is {h}x{w} px; ring detection needs at least 16x16 px")
    if px_per_mm is not None and not (isinstance(px_per_mm, (int, float, np.number))
                                      and 0 < px_per_mm <= 1000):  # 1e6 blurred for ever (sigma 1e6 px)
        raise WoodcamError(f"px_per_mm of face {name!r} must be a number in (0, 1000] px/mm; got {px_per_mm!r}")
    if wavelength_range_px is None:
        wavelength_range_px = WAVELENGTH_RANGE_PX if not px_per_mm else (
            max(WAVELENGTH_RANGE_PX[0], RING_SPACING_RANGE_MM[0] * px_per_mm), RING_SPACING_RANGE_MM[1] * px_per_mm)
    wl = as_floats(wavelength_range_px)  # 5 was a TypeError of tuple(), ('a', 'b') one of '<='
    if wl is None or wl.shape != (2,):
        raise WoodcamError(f"wavelength_range_px must be (min, max) px; got {wavelength_range_px!r}")
    lo, hi = float(wl[0]), float(wl[1])
    if not 2.0 <= lo < hi:
        raise WoodcamError(f"wavelength_range_px must be (min, max) with 2 <= min < max; got {wavelength_range_px!r}")
    if lo > 0.5 * max(h, w):
        raise WoodcamError(f"photo of face {name!r} is {h}x{w} px: too small to hold a ring of {lo:.3g} px or "
                           f"more (the shortest ring spacing at {px_per_mm} px/mm); check px_per_mm")
    hi = max(min(hi, 0.5 * max(h, w)), 1.5 * lo)
    n_scales = max(3, int(np.round(np.log2(hi / lo) * SCALES_PER_OCTAVE)) + 1)
    wavelengths = lo * 2.0 ** (np.arange(n_scales) / SCALES_PER_OCTAVE)
    x = _normalise(lum, sigma=hi)
    z, lam, normal, coherence, amp_x = _response(x, wavelengths, N_ORIENTATIONS)
    # the gates use the bank's amplitude; the curved response gives the phase only (gating on
    # its amplitude too cut the evidence at a band of noise across the rings, 0.99 -> 0.87 of
    # the face in tests/detect/test_detect_rings.py, which split one ring into unlinked pieces)
    amp = np.abs(z)
    if CURVED_GABOR if curved is None else curved:
        from .curved import curved_gabor

        zc = curved_gabor(x, normal, lam, coherence)
        # where the two disagree the orientation field is not to be trusted (CURVED_AGREE_RAD);
        # the curved phase with the bank's amplitude elsewhere
        if CURVED_AGREE_RAD < np.pi:
            agree = np.abs(np.angle(zc * np.conj(z))) <= CURVED_AGREE_RAD
            z = np.where(agree, zc * (np.abs(z) / (np.abs(zc) + 1e-6)), z).astype(np.complex64)
        else:
            z = zc
    ref = float(np.percentile(amp, 75)) + 1e-9
    rel_amp = np.clip(amp / ref, 0.0, 1.0)
    confidence = (coherence * rel_amp).astype(np.float32)
    evidence = (coherence >= COHERENCE_MIN) & (rel_amp >= AMPLITUDE_MIN) & (amp_x >= SIGNAL_MIN)
    warnings: list[str] = []
    min_len = MIN_TRACE_WAVELENGTHS * lam
    even, odd = z.real, z.imag
    # band centres: phase pi of the blended response (odd part 0 where the even part is < 0)
    polys = _contour_runs(odd, evidence & (even < 0), min_len)
    order_map, centre_order = _ring_order(z, evidence, polys)
    src = list(range(len(polys)))
    if rule != "dark-centre":
        polys, src = _snap(lum, polys, normal, lam, rule)
    ring_order = [float(centre_order[k]) for k in src]
    if rule in ("dark-line", "dark-edge") and polys and VALLEY_REL > 0:
        faint = _faint_lines(lum, polys, normal, lam, evidence, min_len)
        polys = polys + faint
        # a faint ring lies between two band centres: linked by where it lies in the order,
        # reported as k + 1/2
        faint_at = [_piece_order(order_map, q) for q in faint]
        ring_order += [float(np.floor(o)) + 0.5 for o in faint_at]
    else:
        faint_at = []
    n_centre = len(polys) - len(faint_at)
    ring_ids = _ring_ids(polys, ring_order[:n_centre] + faint_at, evidence, order_map, lam, n_centre)
    ring_order = [o if np.isfinite(o) else 0.0 for o in ring_order]
    traces = [RingTrace(p, ring=k) for p, k in zip(polys, ring_ids)]
    share = float(evidence.mean())
    if share < MIN_RING_AREA or not traces:
        warnings.append(
            f"face {name!r}: little ring evidence ({100 * share:.0f} % of the face, {len(traces)} ring "
            f"pieces); the photo may be blank, over-exposed, out of focus or show no rings: check it "
            f"with 'woodcam rings show' and trace the rings by hand (SVG) if needed")
    sigma_px = RING_MAP_SIGMA_MM * (px_per_mm if px_per_mm else 256 / 50.0)
    ring_map = ring_map_from_traces(traces, (h, w), sigma_px)
    return RingDetection(traces, ring_map, normal, lam, confidence, evidence, rule, warnings,
                         order_map, ring_order)
