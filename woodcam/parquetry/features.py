"""Feature maps of seed 002 (Iseringhausen et al., "Computational Parquetry"), sec. 3.2.

Images here are ``(h, w, 3)`` float32 RGB in [0, 1] or ``(h, w)`` float32 grey, row 0 at the
top. A feature map is ``(h, w, 2)`` float32: channel 0 the weighted intensity, channel 1 the
weighted Sobel edge magnitude (eq. 1). Rotations are in degrees, counter-clockwise as seen on
the image (OpenCV's convention), about the image centre, on a canvas grown to hold the whole
rotated image; pixels outside the source are zero and flagged invalid in the returned mask.
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError
from ..tolerances import PARQUETRY_GREY_LEVEL_TOL

#: Rec. 601 luma weights: the intensity filter F_intens of eq. 1 (the paper's code uses
#: OpenCV's grey conversion, which is the same).
_LUMA = np.array([0.299, 0.587, 0.114], np.float32)

#: Sobel responses of a [0, 1] image lie in [0, 4 * sqrt(2)]; dividing by this brings the edge
#: channel to roughly the intensity's range so that w_intens and w_edge mean what they say.
_SOBEL_NORM = 4.0


def intensity(rgb) -> np.ndarray:
    """Grey intensity ``(h, w)`` float32 in [0, 1] of ``rgb (h, w, 3)`` (or grey passed through)."""
    a = np.asarray(rgb, np.float32)
    if a.ndim == 2:
        return a
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise WoodcamError(f"image must be (h, w) grey or (h, w, 3) RGB; got shape {a.shape}")
    return a[..., :3] @ _LUMA


def edge(grey) -> np.ndarray:
    """Sobel gradient magnitude ``(h, w)`` float32 of a grey image, scaled to about [0, 1]."""
    import cv2

    g = np.asarray(grey, np.float32)
    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=3, borderType=cv2.BORDER_REPLICATE)
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=3, borderType=cv2.BORDER_REPLICATE)
    return np.sqrt(gx * gx + gy * gy) / _SOBEL_NORM


def features(grey, w_intens: float, w_edge: float) -> np.ndarray:
    """Eq. 1: ``F(I) = (w_intens F_intens(I), w_edge F_edge(I))`` as ``(h, w, 2)`` float32."""
    g = np.asarray(grey, np.float32)
    return np.stack([w_intens * g, w_edge * edge(g)], axis=-1).astype(np.float32)


def match_histogram(target_grey, source_values, w_hist: float) -> np.ndarray:
    """Eq. 2: the target intensity blended with its CDF-matched version, ``(h, w)`` float32.

    ``F'_intens(I_T) = (1 - w_hist) F_intens(I_T) + w_hist F_equalize(I_T, I_S)``, where
    ``F_equalize`` maps each target grey level through the target's CDF and the inverse CDF of
    ``source_values`` (all usable veneer pixels, any shape), as in the paper's CDF matching.
    """
    t = np.asarray(target_grey, np.float32)
    s = np.sort(np.asarray(source_values, np.float32).ravel())
    if s.size == 0:
        raise WoodcamError("histogram matching needs at least one usable veneer pixel; got none")
    flat = t.ravel()
    order = np.argsort(flat, kind="stable")
    # Equal grey levels share one quantile (their mean rank), so flat areas stay flat; levels
    # within PARQUETRY_GREY_LEVEL_TOL of the one before are equal (a resampled flat area is a
    # few float32 ulps apart, and ranked apart it became a grid pattern of a fifth of the wood's
    # histogram). Sorted levels that many ranks run in one level: its mean rank is the middle.
    level = np.concatenate([[0], np.cumsum(np.diff(flat[order]) > PARQUETRY_GREY_LEVEL_TOL)])
    count = np.bincount(level)
    first = np.concatenate([[0], np.cumsum(count)[:-1]])
    inv = np.empty_like(level)
    inv[order] = level
    q = (first[inv] + (count[inv] - 1) / 2.0 + 0.5) / flat.size
    eq = np.interp(q, (np.arange(s.size) + 0.5) / s.size, s).astype(np.float32)
    return ((1.0 - w_hist) * flat + w_hist * eq).reshape(t.shape).astype(np.float32)


def rotation_matrix(shape_hw, angle_deg: float) -> tuple[np.ndarray, tuple[int, int]]:
    """Affine ``(2, 3)`` from source pixel (x, y) to the rotated canvas, and the canvas (h, w).

    The canvas is the bounding box of the rotated image (rounded up), centred on it. Pixel
    coordinates are OpenCV's: x = column, y = row, pixel centres at integers.
    """
    import cv2

    h, w = shape_hw
    m = cv2.getRotationMatrix2D(((w - 1) / 2.0, (h - 1) / 2.0), float(angle_deg), 1.0)
    c, s = abs(m[0, 0]), abs(m[0, 1])
    nw = int(np.ceil(w * c + h * s - 1e-9))
    nh = int(np.ceil(w * s + h * c - 1e-9))
    m[0, 2] += (nw - 1) / 2.0 - (w - 1) / 2.0
    m[1, 2] += (nh - 1) / 2.0 - (h - 1) / 2.0
    return m, (nh, nw)


def rotate(image, mask, angle_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rotate ``image (h, w[, c])`` and its usable mask ``(h, w) bool`` by ``angle_deg``.

    Returns ``(rotated (H, W[, c]) float32, rotated_mask (H, W) bool, affine (2, 3))``. The
    rotated mask is True only where the whole bilinear footprint lies in usable wood, so no
    matched pixel ever borrows colour from outside the sheet.
    """
    import cv2

    img = np.asarray(image, np.float32)
    m, (nh, nw) = rotation_matrix(img.shape[:2], angle_deg)
    if angle_deg % 360.0 == 0.0:
        return img.copy(), np.asarray(mask, bool).copy(), m
    out = cv2.warpAffine(img, m, (nw, nh), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    mk = cv2.warpAffine(np.asarray(mask, np.float32), m, (nw, nh), flags=cv2.INTER_LINEAR,
                        borderMode=cv2.BORDER_CONSTANT)
    return out, mk > 1.0 - 1e-4, m
