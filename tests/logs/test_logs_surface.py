"""Centreline and surface models of seed 001 §3.3-3.4 and their fits (§4.3)."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.logs.centreline import Centreline, fit_centreline
from woodcam.logs.surface import (SurfaceBase, SurfaceKnot, Thickness, add_surface_knots, dog, fit_surface_base,
                                  fit_surface_knot, fit_thickness, fourier_basis, gabor_noise, heightmap_axes)


def test_centreline_fit_recovers_generated_coefficients():
    rng = np.random.default_rng(0)
    true = Centreline(4000.0, rng.normal(0, 8, 4), rng.normal(0, 8, 4), (180.0, 170.0))
    l = np.linspace(0, 4000, 400)
    fit = fit_centreline(l, true.xy(l), 4, 4000.0)
    np.testing.assert_allclose(fit.coef_x, true.coef_x, atol=1e-9)
    np.testing.assert_allclose(fit.coef_y, true.coef_y, atol=1e-9)
    np.testing.assert_allclose(fit.offset_xy, true.offset_xy, atol=1e-9)


def test_centreline_log_centric_round_trip():
    c = Centreline(1000.0, np.array([5.0, -2.0]), np.array([1.0, 3.0]))
    lcs = np.array([[0.3, 100.0, 50.0], [-2.0, 900.0, 120.0]])
    np.testing.assert_allclose(c.to_log_centric(c.to_log_frame(lcs)), lcs, atol=1e-12)


def test_centreline_fit_refuses_too_many_coefficients():
    with pytest.raises(WoodcamError, match="n_coef must lie in"):
        fit_centreline([0, 1, 2], np.zeros((3, 2)), 5)


def test_fourier_basis_is_orthogonal_on_a_full_turn():
    t = 2 * np.pi * np.arange(360) / 360
    F = fourier_basis(t, 10)
    G = F.T @ F / 360
    np.testing.assert_allclose(G, np.diag([1.0] + [0.5] * 9), atol=1e-12)


def test_surface_base_fit_recovers_generated_coefficients():
    rng = np.random.default_rng(1)
    coef = rng.normal(0, 2, (10, 10))
    coef[0, 0] = 125.0
    true = SurfaceBase(4000.0, coef)
    l, t = heightmap_axes(4000.0, 401, 360)
    fit = fit_surface_base(true.grid(l, t), l, t, n_fourier=10, n_cheb=10, length_mm=4000.0)
    np.testing.assert_allclose(fit.coef, coef, atol=1e-8)
    # with grain noise on top the coefficients still come back to a small fraction of a mm
    noisy = true.grid(l, t) + gabor_noise(401, 360, 10.0, 2 * np.pi * 125 / 360, rng, amplitude_mm=0.3)
    fit = fit_surface_base(noisy, l, t, length_mm=4000.0)
    assert np.abs(fit.coef - coef).max() < 0.05


def test_surface_base_pointwise_matches_grid():
    rng = np.random.default_rng(2)
    b = SurfaceBase(100.0, rng.normal(size=(3, 5)))
    l, t = np.array([0.0, 37.0, 100.0]), np.array([0.0, 1.0, 5.0])
    np.testing.assert_allclose(b.at(l, t), np.diag(b.grid(l, t)), atol=1e-12)


def test_thickness_fit_recovers_eq6_parameters():
    true = Thickness(-0.004, 130.0, np.array([500.0, 1400.0, 2500.0]), np.array([2.0, 1.5, 3.0]),
                     np.array([10.0, -5.0, 0.0]), np.array([40.0, 60.0, 50.0]))
    l = np.linspace(0, 4000, 801)
    fit = fit_thickness(l, true(l), true.centres_mm)
    assert abs(fit.a - true.a) < 1e-6 and abs(fit.b - true.b) < 1e-3
    np.testing.assert_allclose(fit.alpha_mm, true.alpha_mm, atol=1e-3)
    np.testing.assert_allclose(fit.beta_mm, true.beta_mm, atol=0.05)
    np.testing.assert_allclose(fit.gamma_mm, true.gamma_mm, atol=0.05)


@pytest.mark.parametrize("alpha,m", [(0.3, 2.0), (0.5, 1.5), (0.8, 4.0)])
def test_dog_crosses_zero_at_the_knot_radius(alpha, m):
    assert abs(dog(7.0, 7.0, alpha, m)) < 1e-12
    assert dog(0.0, 7.0, alpha, m) == pytest.approx(m - 1)
    assert dog(3.0, 7.0, alpha, m) > 0 > dog(10.0, 7.0, alpha, m)  # bump, then depression ring


def test_dog_refuses_parameters_without_a_bump():
    with pytest.raises(WoodcamError, match="alpha in \\(0, 1\\) and m > 1"):
        dog(1.0, 5.0, 1.2, 2.0)


def test_surface_knot_on_heightmap_has_its_height_and_radii():
    l, t = heightmap_axes(1000.0, 501, 720)
    k = SurfaceKnot(500.0, np.pi, 16.0, 10.0, 0.4, 0.4, 3.0, 2.5)
    hm = add_surface_knots(np.zeros((501, 720)), l, t, [k], arc_radius_mm=100.0)
    assert hm.max() == pytest.approx(2.5, rel=1e-9)
    i, j = np.unravel_index(hm.argmax(), hm.shape)
    assert l[i] == pytest.approx(500.0) and t[j] == pytest.approx(np.pi)
    # zero crossings 16 mm along l and 10 mm of arc across
    assert abs(k.evaluate(16.0, 0.0)) < 1e-12 and abs(k.evaluate(0.0, 10.0)) < 1e-12


def test_surface_knot_wraps_around_the_seam():
    l, t = heightmap_axes(1000.0, 201, 360)
    k = SurfaceKnot(500.0, 0.0, 16.0, 30.0, 0.4, 0.4, 3.0, 2.0)
    hm = add_surface_knots(np.zeros((201, 360)), l, t, [k], arc_radius_mm=100.0)
    np.testing.assert_allclose(hm[100, 1:20], hm[100, -1:-20:-1], atol=1e-12)


def test_fit_surface_knot_recovers_shape_parameters():
    true = SurfaceKnot(0.0, 0.0, 14.0, 9.0, 0.35, 0.45, 2.5, 3.0)
    dl, ds = np.linspace(-60, 60, 121), np.linspace(-40, 40, 81)
    fit = fit_surface_knot(true.evaluate(dl[:, None], ds[None, :]), dl, ds, 14.0, 9.0)
    np.testing.assert_allclose([fit.alpha_l, fit.alpha_s, fit.m, fit.height_mm], [0.35, 0.45, 2.5, 3.0], rtol=1e-4)


def test_gabor_noise_has_its_amplitude_and_runs_along_the_log():
    rng = np.random.default_rng(3)
    n = gabor_noise(400, 360, 5.0, 2.0, rng, amplitude_mm=0.3, wavelength_mm=10.0)
    assert n.shape == (400, 360)
    assert n.std() == pytest.approx(0.3, rel=1e-9)
    assert abs(n.mean()) < 0.05

    def corr(a, b):
        return np.corrcoef(a.ravel(), b.ravel())[0, 1]

    # neighbours 10 mm apart: strongly alike along the grain, not across it
    along = corr(n[:-2], n[2:])
    across = corr(n[:, :-5], n[:, 5:])
    assert along > 0.8 and along - across > 0.5


def test_base_and_centreline_fit_the_real_spruce_log(gran_knots_json):
    """Gran_1 (CT-measured spruce): 10 x 10 base shape and 4-term centreline fits.

    Bars: the heightmap's bumps and bark are not in the base model, so its RMSE stays at a few
    mm (measured 2.4 mm); the pith wanders by a few mm around a 4-term curve (measured 4.1 mm).
    """
    import json

    radii = np.asarray(json.loads((gran_knots_json.parent / "Gran_1_radii.json").read_text()))
    pith = np.asarray(json.loads((gran_knots_json.parent / "Gran_1_pith.json").read_text()))
    l, t = pith[:, 2], np.deg2rad(np.arange(360))
    base = fit_surface_base(radii, l, t, length_mm=3990.0)
    assert np.sqrt(np.mean((radii - base.grid(l, t)) ** 2)) < 3.0
    assert 115 < base.coef[0, 0] < 135  # mean radius
    c = fit_centreline(l, pith[:, :2], 4, 3990.0)
    assert np.sqrt(np.mean(np.sum((c.xy(l) - pith[:, :2]) ** 2, axis=1))) < 5.0
