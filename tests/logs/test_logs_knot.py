"""The knot model of seed 001 §3.2: curves, constraints, surface sampling."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.logs.knot import (
    MAX_INCLINE,
    Knot,
    KnotShape,
    growth_curve,
    growth_curve_slope,
    radius_coefficients,
    to_slr,
    trajectory_coefficients,
)

RATIOS = np.linspace(0.0, 1.0, 6)


def test_growth_curve_reaches_alpha_plus_linear_at_x_max_and_is_linear_after():
    x = np.array([0.0, 40.0, 60.0, 80.0])
    y = growth_curve(x, 40.0, 5.0, 2.0, 0.3)
    assert y[0] == 0.0
    np.testing.assert_allclose(y[1:], 5.0 + 0.3 * x[1:], atol=1e-12)
    np.testing.assert_allclose(growth_curve_slope(x[1:], 40.0, 5.0, 2.0, 0.3), 0.3, atol=1e-12)


def test_growth_curve_slope_matches_finite_differences():
    x = np.linspace(0.5, 39.0, 50)
    h = 1e-6
    fd = (growth_curve(x + h, 40.0, 5.0, 3.0, 0.3) - growth_curve(x - h, 40.0, 5.0, 3.0, 0.3)) / (2 * h)
    np.testing.assert_allclose(growth_curve_slope(x, 40.0, 5.0, 3.0, 0.3), fd, rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("phi0", RATIOS)
@pytest.mark.parametrize("phi1", RATIOS)
def test_trajectory_constraints_hold_for_every_ratio(phi0, phi1):
    """alpha_l >= 0 and the trajectory is concave on [0, 2 rho_max] for all phi in [0, 1]."""
    alpha, E, L = trajectory_coefficients(30.0, phi0, phi1)
    assert alpha >= 0 and E >= 2
    assert abs(np.arctan(L)) <= MAX_INCLINE + 1e-12
    x = np.linspace(0, 60, 2001)
    s = growth_curve_slope(x, 30.0, alpha, E, L)
    assert np.all(np.diff(s) <= 1e-9)  # slope never increases: concave


@pytest.mark.parametrize("psi0", RATIOS)
@pytest.mark.parametrize("psi1", RATIOS)
def test_radius_constraints_hold_for_every_ratio(psi0, psi1):
    alpha, E, L = radius_coefficients(10.0, psi0, psi1, 50.0)
    assert alpha >= -1e-12 and E >= 2 and L >= 0
    c = np.linspace(0, 100, 2001)
    r = growth_curve(c, 50.0, alpha, E, L)
    assert np.all(np.diff(growth_curve_slope(c, 50.0, alpha, E, L)) <= 1e-9)
    assert r[0] == 0 and np.all(np.diff(r) >= -1e-12)
    np.testing.assert_allclose(growth_curve(np.array([50.0]), 50.0, alpha, E, L), 10.0)


def test_knot_radius_equals_r_max_at_rho_max_and_delta_l_is_the_rise():
    p = KnotShape(0.0, 100.0, 1.2, 40.0, 0.6, 0.7, 12.0, 0.4, 0.5)
    k = Knot(p)
    np.testing.assert_allclose(k.radius(np.array([40.0])), 12.0, rtol=1e-9)
    np.testing.assert_allclose(k.height(np.array([40.0])) - 100.0, k.delta_l_mm(), rtol=1e-12)


def test_arc_length_of_a_straight_knot_is_exact():
    # phi0 = 0 (start incline = end incline) and phi1 = 0.75: straight line at 40 degrees
    k = Knot(KnotShape(0.0, 0.0, 1.0, 30.0, 0.0, 0.75, 5.0, 0.5, 0.5))
    slope = np.tan(0.5 * MAX_INCLINE)
    np.testing.assert_allclose(k.arc_length(np.array([50.0])), 50.0 * np.sqrt(1 + slope**2), rtol=1e-9)


def test_surface_points_lie_on_the_surface():
    k = Knot(KnotShape(1.5, 10.0, 1.3, 35.0, 0.5, 0.6, 9.0, 0.3, 0.6), theta_mean_rad=2.0)
    pts = k.surface_points(np.linspace(5, 120, 20), 16)
    slr, _ = to_slr(pts, 2.0)
    assert np.abs(k.surface_residuals(slr)).max() < 1e-4
    # points on a bigger ellipse are outside by the difference in radius along the ray
    k2 = Knot(KnotShape(1.5, 10.0, 1.3, 35.0, 0.5, 0.6, 9.0 * 1.1, 0.3, 0.6), theta_mean_rad=2.0)
    assert np.all(k.surface_residuals(to_slr(k2.surface_points(np.linspace(60, 120, 5), 16), 2.0)[0]) > 0)


def test_to_slr_uses_the_circular_mean_across_the_seam():
    pts = np.array([[np.pi - 0.1, 0.0, 10.0], [-np.pi + 0.1, 0.0, 10.0]])
    slr, tm = to_slr(pts)
    assert abs(abs(tm) - np.pi) < 1e-12
    np.testing.assert_allclose(np.sort(slr[:, 0]), [-1.0, 1.0], atol=1e-9)


def test_invalid_parameters_are_refused():
    with pytest.raises(WoodcamError, match="phi0 is an incline ratio"):
        KnotShape(0, 0, 1, 10, 1.5, 0.5, 3, 0.5, 0.5)
    with pytest.raises(WoodcamError, match="rho_max_mm must be a finite number > 0"):
        KnotShape(0, 0, 1, -10, 0.5, 0.5, 3, 0.5, 0.5)
    with pytest.raises(WoodcamError, match="must have 9 entries"):
        KnotShape.from_array([1, 2, 3])
