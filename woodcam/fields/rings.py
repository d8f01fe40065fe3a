"""Rings of a growth-time image: the one home of ring maps (and their line width).

A ring boundary is an integer iso-line of the growth time ``g`` (years). A ring map is a
Mokume-style image of those lines, ``exp(-(d / sigma)^2)``, ``d`` the in-image distance to the
nearest boundary. :mod:`woodcam.synth` draws them on synthetic faces and
:mod:`woodcam.appearance.volumes` feeds them to the colour networks; both call
:func:`ring_map`. Face pixel points live in :func:`woodcam.frames.face_pixel_points`.
"""

from __future__ import annotations

import numpy as np

#: Line width (mm) of the Mokume U-Net ring maps as ``sigma`` of ``exp(-(d / sigma)^2)``:
#: their lines are 5.1-5.9 px wide at half maximum on 256 px faces of ~50 mm cubes
#: (measured on H11 and CN03 face E), and FWHM = 1.665 sigma -> sigma ~ 3.2 px ~ 0.62 mm.
MOKUME_RING_SIGMA_MM = 0.62


def ring_map(years_img, sigma: float, spacing: float = 1.0) -> np.ndarray:
    """Ring map of growth-time images ``(..., h, w)`` years: ``exp(-(d / sigma)^2)`` float32.

    ``d = |g - round(g)| / |grad g|`` is the in-image distance to the nearest integer
    iso-line, to first order, in the unit of ``spacing`` (the pixel pitch: 1 for pixels, or mm
    per cell); ``sigma`` is in that unit too (e.g. :data:`MOKUME_RING_SIGMA_MM` with
    ``spacing`` in mm). Values in (0, 1], 1 on a ring boundary.
    """
    g = np.asarray(years_img, np.float64)
    gr, gc = np.gradient(g, spacing, axis=(-2, -1))
    d = np.abs(g - np.round(g)) / np.maximum(np.hypot(gr, gc), 1e-9)
    return np.exp(-((d / sigma) ** 2)).astype(np.float32)
