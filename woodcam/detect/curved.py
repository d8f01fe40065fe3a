"""The curved Gabor filter of the ring detector: a Gabor across the ring, a Gaussian along its curve.

Data forms (one face image, ``(row, col)`` pixels as in :mod:`woodcam.detect.rings`):
``x : (h, w) float32`` the flattened, contrast-normalised luminance; ``normal_rad : (h, w)`` the
local ring normal (radians, ``atan2(d row, d col)``, sign consistent over the face);
``wavelength_px : (h, w)`` the local ring spacing (px).

The response at pixel ``p`` (Gottschlich 2012's curved Gabor filter, which Nindel et al. 2023
use on wood; seed 000 sec. 5.1 names automatic ring extraction as future work) is

    z(p) = sum_s G_along(s) q(c_p(s)) / sum_s G_along(s),
    q(y) = 2 sum_u g(u) exp(-2 pi i u) x(y + u lam(y) n(y)),

with ``c_p(s)`` the ring curve through ``p`` (the streamline of the ring tangent field, arc
length ``s``), ``G_along`` a Gaussian of std :data:`ALONG_WAVELENGTHS` local spacings (at most
:data:`ALONG_MAX_PX`), and ``q`` a one-dimensional complex Gabor across the ring at each point's
own normal and spacing (orientation and frequency adapted; ``g`` a Gaussian of std
:data:`ACROSS_WAVELENGTHS` spacings, ``u`` in spacings). ``q`` is analytic along the normal:
its phase is 0 on a bright line and pi on a dark one, and it is the same along a ring, so the
sum along the curve is coherent on a ring while pores, ray flecks and noise, which do not follow
the rings, average out over a long stretch, without the blur a straight kernel of that length
gives a curved ring.
"""

from __future__ import annotations

import numba
import numpy as np

#: Std of the Gaussian along the ring curve, in local ring spacings (pores and ray flecks are far
#: shorter), and its cap (px; the cost grows with it). On the synthetic development seeds 0-3 the
#: length hardly matters: 1.5 spacings (cap 24 px) vs 1.0 (cap 16 px), dark-edge rule, F within
#: 2 px plain 0.930 / 0.929, realistic 0.747 / 0.745; the shorter is cheaper.
ALONG_WAVELENGTHS = 1.0
ALONG_MAX_PX = 16.0
#: Std of the Gaussian across the ring, in local ring spacings: 0.5 passes about one octave of
#: frequency round the local one and leaks exp(-2 pi^2 0.5^2) = 0.7 % of the mean.
ACROSS_WAVELENGTHS = 0.5
#: Samples per ring spacing across the ring.
ACROSS_SAMPLES_PER_WAVELENGTH = 8
#: Least orientation coherence at a streamline point for its tangent to steer the streamline
#: (the detector's ring-evidence gate, ``rings.COHERENCE_MIN``); below it the step goes on straight.
MIN_COHERENCE = 0.35
#: Streamline step (px; 2 px keeps a curve of 60 px radius within 0.2 px of the circle over
#: +-30 px, ``tests/detect/test_detect_curved.py``) and reach (in stds of the Gaussian along
#: the ring).
STEP_PX = 2.0
REACH_SIGMAS = 3.0


def across_gabor(x: np.ndarray, normal_rad: np.ndarray, wavelength_px: np.ndarray) -> np.ndarray:
    """``q (h, w) complex64`` (module docstring): the 1-D complex Gabor across the ring at every
    pixel, at its own normal and spacing, sampled by bilinear interpolation (reflecting borders)."""
    import cv2

    h, w = x.shape
    k = ACROSS_WAVELENGTHS
    u = np.arange(-3 * k, 3 * k + 1e-9, 1.0 / ACROSS_SAMPLES_PER_WAVELENGTH)
    g = np.exp(-0.5 * (u / k) ** 2)
    g /= g.sum()
    rr, cc = np.meshgrid(np.arange(h, dtype=np.float32), np.arange(w, dtype=np.float32), indexing="ij")
    nr = (np.sin(normal_rad) * wavelength_px).astype(np.float32)
    nc = (np.cos(normal_rad) * wavelength_px).astype(np.float32)
    xs = np.ascontiguousarray(x, np.float32)
    acc = np.zeros((h, w), np.complex64)
    for ui, gi in zip(u, g):
        v = cv2.remap(xs, cc + float(ui) * nc, rr + float(ui) * nr, cv2.INTER_LINEAR,
                      borderMode=cv2.BORDER_REFLECT)
        acc += np.complex64(2.0 * gi * np.exp(-2j * np.pi * ui)) * v
    return acc


@numba.njit(nogil=True, fastmath=True, cache=True, parallel=True)
def _streamline_kernel(stack, n_fields, normal, ratio, n_steps, step, min_coh, out):  # pragma: no cover
    """``out (h, w, n_fields)``: the Gaussian-weighted sums along the streamlines, ``stack (h, w,
    n_fields + 2)`` the fields and the normal's doubled angle (cos, sin); ``ratio (h, w)`` is
    ``exp(-step^2 / (2 sigma^2))``, so the weight at step k, ``ratio^(k^2)``, is a running product."""
    h, w = normal.shape
    nch = n_fields + 2
    for i in numba.prange(h):
        val = np.empty(nch, np.float32)
        for j in range(w):
            # the centre's own weight: its reliability (squared coherence, 1 without)
            wsum = stack[i, j, n_fields] ** 2 + stack[i, j, n_fields + 1] ** 2 + 1e-6
            for f in range(n_fields):
                out[i, j, f] = wsum * stack[i, j, f]
            a = normal[i, j]
            q = ratio[i, j]
            for sign in (1.0, -1.0):
                r, c = float(i), float(j)
                dr, dc = sign * np.cos(a), -sign * np.sin(a)     # tangent = normal turned
                wk, qk = 1.0, q                                  # weight ratio^(k^2), factor ratio^(2k-1)
                for _ in range(n_steps):
                    r += step * dr
                    c += step * dc
                    if r < 0 or r > h - 1 or c < 0 or c > w - 1:
                        break
                    wk *= qk
                    qk *= q * q
                    if wk < 1e-3:
                        break
                    # bilinear sample of every channel at (r, c)
                    r0 = min(int(r), h - 2)
                    c0 = min(int(c), w - 2)
                    fr, fc = r - r0, c - c0
                    w00, w01 = (1 - fr) * (1 - fc), (1 - fr) * fc
                    w10, w11 = fr * (1 - fc), fr * fc
                    for ch in range(nch):
                        val[ch] = (w00 * stack[r0, c0, ch] + w01 * stack[r0, c0 + 1, ch]
                                   + w10 * stack[r0 + 1, c0, ch] + w11 * stack[r0 + 1, c0 + 1, ch])
                    # the sample's weight: the Gaussian times its reliability, the squared
                    # length of the (coherence-scaled) doubled-angle vector there
                    c2, s2 = val[n_fields], val[n_fields + 1]
                    nrm2 = c2 * c2 + s2 * s2
                    for f in range(n_fields):
                        out[i, j, f] += wk * nrm2 * val[f]
                    wsum += wk * nrm2
                    # the tangent from the doubled angle (cos 2a, sin 2a) read here, turned to
                    # continue the step: a tangent has no sign, its doubled angle varies smoothly
                    nrm = np.sqrt(nrm2)
                    if nrm < min_coh:
                        continue                                 # no trusted direction here: go on
                    c2 /= nrm
                    tr = np.sqrt(max(0.5 * (1 + c2), 0.0))
                    tc = -np.sqrt(max(0.5 * (1 - c2), 0.0)) * (1.0 if s2 >= 0 else -1.0)
                    if tr * dr + tc * dc < 0:
                        tr, tc = -tr, -tc
                    dr, dc = tr, tc
            for f in range(n_fields):
                out[i, j, f] /= wsum


def streamline_average(fields: np.ndarray, normal_rad: np.ndarray, sigma_px: np.ndarray,
                       step_px: float = STEP_PX, coherence: np.ndarray | None = None) -> np.ndarray:
    """``(c, h, w)`` float32: ``fields (c, h, w)`` averaged along the ring curve through every
    pixel with Gaussian weights ``exp(-s^2 / (2 sigma^2))`` of the arc length ``s`` (``sigma_px
    (h, w)``, the centre pixel's; out to :data:`REACH_SIGMAS` of it), times the squared
    ``coherence (h, w)`` at each point where given.

    The curve is the streamline of the ring tangent field (``normal_rad`` turned by 90 degrees),
    traced by Euler steps of ``step_px`` both ways from each pixel, the tangent read by bilinear
    interpolation of its doubled angle and turned to continue the previous step; it stops at the
    border. Hand-written (numba): no library traces streamlines of a sign-free orientation field
    from every pixel."""
    c, h, w = fields.shape
    coh = np.ones(normal_rad.shape, np.float32) if coherence is None else np.asarray(coherence, np.float32)
    stack = np.ascontiguousarray(np.dstack([*np.asarray(fields, np.float32), coh * np.cos(2 * normal_rad),
                                            coh * np.sin(2 * normal_rad)]).astype(np.float32))
    sigma = np.maximum(np.asarray(sigma_px, np.float32), 1e-3)
    ratio = np.exp(-0.5 * (step_px / sigma) ** 2).astype(np.float64)
    n_steps = int(np.ceil(REACH_SIGMAS * float(sigma.max()) / step_px))
    out = np.empty((h, w, c), np.float32)
    _streamline_kernel(stack, c, np.ascontiguousarray(normal_rad, np.float32), ratio, n_steps,
                       float(step_px), MIN_COHERENCE if coherence is not None else 1e-9, out)
    return np.moveaxis(out, -1, 0)


def curved_gabor(x: np.ndarray, normal_rad: np.ndarray, wavelength_px: np.ndarray,
                 coherence: np.ndarray | None = None) -> np.ndarray:
    """``z (h, w) complex64``, the curved Gabor response (module docstring): phase pi on the
    dark line of each ring, 0 on the bright one.

    ``coherence (h, w)`` in [0, 1], optional: the orientation coherence; each point along a curve
    then counts with its squared coherence and steers the curve only where it is at least
    :data:`MIN_COHERENCE`. The across responses are averaged as unit phasors (their phase
    only), so one strong speck on the curve cannot outvote the ring; the magnitude of ``z`` is
    then the phase agreement along the curve (1: all agree), not the ring's contrast."""
    q = across_gabor(x, normal_rad, wavelength_px)
    q = q / (np.abs(q) + 1e-6)
    sigma = np.clip(ALONG_WAVELENGTHS * wavelength_px, 1.0, ALONG_MAX_PX)
    s = streamline_average(np.stack([q.real, q.imag]), normal_rad, sigma, coherence=coherence)
    return (s[0] + 1j * s[1]).astype(np.complex64)
