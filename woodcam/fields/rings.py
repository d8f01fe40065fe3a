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


def resample_polyline(p: np.ndarray, step: float) -> np.ndarray:
    """Points every ``step`` along a polyline ``(k, d)`` (ends kept); vectorised by interpolation."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return p[:1]
    t = np.linspace(0.0, s[-1], max(2, int(np.ceil(s[-1] / step)) + 1))
    return np.stack([np.interp(t, s, p[:, i]) for i in range(p.shape[1])], axis=1)


def iso_lines(years_img, *, inside=None, first_year: int | None = None) -> list[tuple[int, np.ndarray]]:
    """The ring boundaries of a growth-time image: its integer iso-lines, by marching squares.

    Parameters
    ----------
    years_img : (h, w) float
        Growth time (years) sampled at pixel centres.
    inside : (h, w) bool, optional
        Pixels to contour (others masked out).
    first_year : int, optional
        Lowest year to draw (e.g. 1: year 0 is the pith itself, not a ring boundary).

    Returns
    -------
    list of (year, points (k, 2) float)
        Each polyline in pixel coordinates ``(row, col)`` (pixel centres at integers), k >= 2;
        lines stay within ``[0, h - 1] x [0, w - 1]``.
    """
    import contourpy  # marching squares: maintained, C++, a core dependency

    g = np.asarray(years_img, float)
    z = g if inside is None else np.ma.masked_array(g, ~np.asarray(inside, bool))
    vals = g if inside is None else g[np.asarray(inside, bool)]
    if vals.size == 0:
        return []
    lo, hi = int(np.ceil(np.nanmin(vals))), int(np.floor(np.nanmax(vals)))
    if first_year is not None:
        lo = max(lo, int(first_year))
    gen = contourpy.contour_generator(z=z, line_type=contourpy.LineType.Separate)
    out = []
    for year in range(lo, hi + 1):
        for xy in gen.lines(year):
            if len(xy) >= 2:
                out.append((year, np.asarray(xy, float)[:, ::-1]))   # contourpy gives (x=col, y=row)
    return out


def ring_lines(years_img, step: float, *, inside=None, spacing: float = 1.0,
               first_year: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` along the integer iso-lines of a growth-time image.

    ``spacing`` is the pixel pitch in the unit of ``step`` (1: pixels; mm per pixel: mm).
    Returns ``points (m, 2)`` as ``(row, col) * spacing`` and ``years (m,)`` int, the year of
    the line each point is on (empty arrays when no line crosses the image).
    """
    pts, yrs = [], []
    for year, line in iso_lines(years_img, inside=inside, first_year=first_year):
        p = resample_polyline(line * spacing, step)
        pts.append(p)
        yrs.append(np.full(len(p), year))
    if not pts:
        return np.empty((0, 2)), np.empty(0, int)
    return np.concatenate(pts), np.concatenate(yrs)
