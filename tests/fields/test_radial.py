"""Eq. 7-9 of seed 000 in mm: analytic values, placement, radius functions."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.fields import LogFrame, arf
from woodcam.fields.radial import RadialScalingField, RadiusFunction


def test_constant_radius_gives_circular_rings(rng):
    f = RadialScalingField(LogFrame((10.0, 20.0, 0.0), (0, 0, 1)), ring_width_mm=2.0)
    p = rng.uniform(-50, 50, (1000, 3))
    expected = np.hypot(p[:, 0] - 10, p[:, 1] - 20) / 2.0
    np.testing.assert_allclose(f(p), expected, rtol=1e-12)


def test_pith_axis_any_direction_and_outside_block(rng):
    axis = np.array([1.0, 2.0, -0.5])
    pith = np.array([-300.0, 40.0, 500.0])  # far outside a 100 mm block
    f = RadialScalingField(LogFrame(tuple(pith), tuple(axis)), ring_width_mm=4.0)
    p = rng.uniform(0, 100, (500, 3))
    a = axis / np.linalg.norm(axis)
    d = p - pith
    rho = np.linalg.norm(d - (d @ a)[:, None] * a, axis=1)
    np.testing.assert_allclose(f(p), rho / 4.0, rtol=1e-10)
    # Moving along the axis never changes growth time for a constant radius function.
    np.testing.assert_allclose(f(p + 7.3 * a), f(p), rtol=1e-10)


def test_eq9_blend_between_end_radius_functions():
    r_lo, r_hi = RadiusFunction.constant(0.8), RadiusFunction.constant(1.2)
    f = RadialScalingField(LogFrame((0, 0, 0), (0, 0, 1)), 1.0, r_lo, r_hi, half_length_mm=50.0)
    pts = np.array([[10.0, 0, -50], [10.0, 0, 0], [10.0, 0, 50], [10.0, 0, 80]])
    # r' = 0.8, 1.0, 1.2 and clamped at 1.2 beyond the end.
    np.testing.assert_allclose(f(pts), [10 / 0.8, 10 / 1.0, 10 / 1.2, 10 / 1.2])


def test_phi_measured_from_plus_y():
    """phi is the angle between (0, 1) and (x, y) (eq. 7)."""
    s = np.ones(360)
    s[90] = 2.0  # phi = 90 deg -> the +x direction (atan2(x, y))
    f = RadialScalingField(LogFrame((0, 0, 0), (0, 0, 1), reference=(1, 0, 0)), 1.0,
                           RadiusFunction(s), RadiusFunction(s))
    assert f(np.array([[5.0, 0.0, 0.0]]))[0] == pytest.approx(2.5)
    assert f(np.array([[0.0, 5.0, 0.0]]))[0] == pytest.approx(5.0)


def test_laplacian_smoothing_interpolates_constraints_smoothly(rng):
    c = rng.normal(1.0, 0.1, 15)
    r = RadiusFunction.from_constraints(c, m=360)
    np.testing.assert_allclose(r(2 * np.pi * np.arange(15) / 15), c, atol=1e-9)
    # Smooth: the second difference is small compared with the constraint spread.
    d2 = np.roll(r.samples, -1) - 2 * r.samples + np.roll(r.samples, 1)
    assert np.abs(d2).max() < 0.05 * np.ptp(c)
    # Known answer: the samples minimising the squared second differences through the
    # constraints are the periodic cubic spline through them (differs by 8e-5 of a 0.36 spread)
    from scipy.interpolate import CubicSpline

    at = np.round(np.arange(15) * 360 / 15)
    spline = CubicSpline(np.r_[at, 360], np.r_[c, c[0]], bc_type="periodic")
    np.testing.assert_allclose(r.samples, spline(np.arange(360)), atol=5e-4)
    # Periodic: the value wraps around continuously.
    assert r(np.array([2 * np.pi - 1e-9]))[0] == pytest.approx(r(np.array([0.0]))[0], abs=1e-6)


def test_to_dict_round_trip(rng):
    f = RadialScalingField.random(LogFrame((1, 2, 3), (0.2, 0, 1)), 3.0, rng)
    g = RadialScalingField.from_dict(f.to_dict())
    p = rng.uniform(0, 50, (100, 3))
    np.testing.assert_array_equal(f(p), g(p))
    # every setting, none at its default: the reference direction (phi = 0) and the pith age
    frame = LogFrame((1, 2, 3), (0.2, 0, 1), reference=(0, 1, 0))
    f = RadialScalingField(frame, 2.5, RadiusFunction.random(rng), RadiusFunction.random(rng),
                           half_length_mm=30.0, age_offset_years=4.0)
    g = RadialScalingField.from_dict(f.to_dict())
    assert g.to_dict() == f.to_dict()
    np.testing.assert_array_equal(f(p), g(p))
    assert g.age_offset_years == 4.0 and g.half_length_mm == 30.0
    np.testing.assert_allclose(g.frame.rotation, frame.rotation)


def test_arf_eq6():
    np.testing.assert_allclose(arf([0.0, 0.5, 1.0, 2.75, -0.25]), [0, 0.25, 0, 0.5625, 0.5625])


def test_errors():
    with pytest.raises(WoodcamError, match="ring_width_mm must be a finite number > 0"):
        RadialScalingField(LogFrame(), ring_width_mm=0)
    with pytest.raises(WoodcamError, match="axis must be a non-zero direction"):
        LogFrame((0, 0, 0), (0, 0, 0))
    with pytest.raises(WoodcamError, match=r"points_mm must have shape \(n, 3\)"):
        RadialScalingField(LogFrame())(np.zeros((4, 2)))
