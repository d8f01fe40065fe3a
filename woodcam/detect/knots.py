"""Knots on one face photo: the dark, compact, roughly elliptic region where the stem's rings are
disturbed (the branch's end grain, cut across).

Data forms: ``photo (h, w, 3) uint8``; the result is ``mask (h, w) bool``, True on a knot, as
:attr:`woodcam.block.Face.extras` ``["knot_mask"]`` (the fitter leaves pixels near it out).

Method: the luminance smoothed over :data:`KNOT_SMOOTH_MM` (wider than latewood lines, so the
knot is one blob) is compared with the face's median; pixels darker by
:data:`KNOT_DARKNESS_MAD` robust deviations (median absolute deviation of the smoothed face) form
candidate regions; an accepted region's edge is where the smoothed luminance is halfway between
its dark core (10th percentile) and the face's median. A region is a knot when it is large
(:data:`KNOT_MIN_DIAMETER_MM`), compact (its fitted ellipse's axis ratio at most
:data:`KNOT_MAX_AXIS_RATIO`: latewood bands and dark streaks are long and thin), and the rings are
disturbed in it: the ring normals found by the ring detector point every way there (the knot's own
rings circle round its centre), so the resultant length of their doubled angles is below
:data:`KNOT_MAX_ORIENTATION_ORDER`; a dark stain or heartwood patch that the stem's rings run
straight through keeps it near 1.
"""

from __future__ import annotations

import numpy as np

#: Smoothing (mm) of the luminance before looking for dark regions: 0.8 mm is wider than
#: latewood lines (2-3 px on 256 px faces of a 50 mm cube, 0.4-0.6 mm).
KNOT_SMOOTH_MM = 0.8
#: A knot is darker than the face's median by this many median absolute deviations.
KNOT_DARKNESS_MAD = 2.0
#: Smallest knot diameter (mm) reported: pin knots below it do not bend the rings measurably.
KNOT_MIN_DIAMETER_MM = 4.0
#: Largest axis ratio of a knot's ellipse; branch wood cut along its length is a spike knot,
#: and elongated dark regions are usually latewood bands or stains.
KNOT_MAX_AXIS_RATIO = 4.0
#: Largest resultant length |mean exp(2 i normal)| of the ring normals inside a knot region:
#: midway between rings running every way (0) and straight rings (1).
KNOT_MAX_ORIENTATION_ORDER = 0.5


def detect_knots(photo: np.ndarray, px_per_mm: float, normal_rad: np.ndarray | None = None) -> np.ndarray:
    """``(h, w)`` bool mask of the knots on ``photo`` (module docstring).

    Parameters
    ----------
    photo : (h, w, 3) uint8 RGB.
    px_per_mm : image density.
    normal_rad : (h, w) float, optional
        The ring detector's local ring normals (:attr:`RingDetection.normal_rad`); when given, a
        region must also disturb the rings (module docstring) to count.
    """
    from scipy import ndimage
    from skimage import measure

    from .rings import luminance

    lum = ndimage.gaussian_filter(luminance(photo).astype(float), KNOT_SMOOTH_MM * px_per_mm)
    med = float(np.median(lum))
    mad = float(np.median(np.abs(lum - med))) + 1e-3
    dark = lum < med - KNOT_DARKNESS_MAD * mad
    dark = ndimage.binary_fill_holes(ndimage.binary_opening(dark, iterations=2))
    lab, n = ndimage.label(dark)
    mask = np.zeros(dark.shape, bool)
    if n == 0:
        return mask
    min_area = np.pi / 4 * (KNOT_MIN_DIAMETER_MM * px_per_mm) ** 2
    doubled = None if normal_rad is None else np.exp(2j * np.asarray(normal_rad, float))
    for reg in measure.regionprops(lab):
        if reg.area < min_area:
            continue
        if reg.axis_minor_length <= 0 or reg.axis_major_length / reg.axis_minor_length > KNOT_MAX_AXIS_RATIO:
            continue
        region = lab == reg.label
        if doubled is not None and abs(doubled[region].mean()) > KNOT_MAX_ORIENTATION_ORDER:
            continue
        # the knot's edge: halfway between its dark core and the face (the blur widens the
        # candidate region, whose threshold sits near the face's median)
        core = float(np.percentile(lum[region], 10))
        edge = ndimage.binary_fill_holes(region & (lum < 0.5 * (core + med)))
        mask |= edge if edge.any() else region
    return mask
