"""woodcam.fields.rings: ring maps and ring lines of a growth-time image, on analytic rings."""

import numpy as np

from woodcam.fields.rings import MOKUME_RING_SIGMA_MM, iso_lines, ring_lines, ring_map

W_MM = 2.0      # ring width
PX_MM = 0.25    # pixel pitch


def _circles(h=161, w=201):
    r, c = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    return np.hypot(r - 80.0, c - 100.0) * PX_MM / W_MM     # years = radius / ring width


def test_iso_lines_lie_on_the_circles_of_whole_years():
    g = _circles()
    lines = iso_lines(g, first_year=1)
    years = sorted({y for y, _ in lines})
    assert years[0] == 1 and years[-1] == int(np.floor(g.max()))
    for year, xy in lines:
        radius_px = np.hypot(xy[:, 0] - 80.0, xy[:, 1] - 100.0)
        np.testing.assert_allclose(radius_px * PX_MM, year * W_MM, atol=0.02)   # < 0.1 px


def test_ring_lines_are_resampled_in_mm_and_masked():
    g = _circles()
    inside = np.zeros(g.shape, bool)
    inside[:, :100] = True                                   # left half only
    pts, years = ring_lines(g, 0.5, inside=inside, spacing=PX_MM, first_year=1)
    assert len(pts) == len(years) > 100
    np.testing.assert_allclose(np.hypot(pts[:, 0] - 80 * PX_MM, pts[:, 1] - 100 * PX_MM), years * W_MM,
                               atol=0.02)
    assert pts[:, 1].max() <= 100 * PX_MM + 1e-9
    gaps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert np.median(gaps) <= 0.5 + 1e-9                        # a point every 0.5 mm
    empty_pts, empty_years = ring_lines(np.full((5, 5), 0.3), 1.0)
    assert empty_pts.shape == (0, 2) and empty_years.shape == (0,)


def test_ring_map_is_one_on_boundaries_and_falls_with_the_distance():
    g = _circles()
    m = ring_map(g, MOKUME_RING_SIGMA_MM, PX_MM)
    d_mm = np.abs(g - np.round(g)) * W_MM                    # distance to the nearest boundary
    far = (d_mm > 0.3) & (g > 2)
    np.testing.assert_allclose(m[far], np.exp(-(d_mm[far] / MOKUME_RING_SIGMA_MM) ** 2), atol=0.02)
    assert m.dtype == np.float32 and m.max() <= 1.0
    # the same map in pixel units
    np.testing.assert_allclose(ring_map(g, MOKUME_RING_SIGMA_MM / PX_MM), m, atol=1e-6)
