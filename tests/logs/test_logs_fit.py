"""Fitting the knot model (seed 001 §4.2): synthetic recovery and the real spruce log."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.logs.fit import (
    _load_gran_knots,
    fit_gran_knots,
    fit_knot,
    gran_knot_diameter,
    params_to_unconstrained,
    sample_gran_knot_points,
    unconstrained_to_params,
)
from woodcam.logs.knot import Knot, KnotShape

# Knots whose tube never bends more sharply than its own radius (there the points of a
# cross-section fall inside the knot and cannot all be surface points).
TRUE_KNOTS = [
    (KnotShape(0.0, -50.0, 0.8, 25.0, 0.3, 0.35, 6.0, 0.7, 0.3), 1.0),
    (KnotShape(0.0, 300.0, 1.0, 90.0, 0.8, 0.6, 15.0, 0.2, 0.8), -2.5),
    (KnotShape(0.0, 1200.0, 1.25, 60.0, 0.45, 0.7, 10.0, 0.5, 0.5), 3.0),
]

#: Recovery tolerances from noise-free points: lengths in mm, ratios absolute. psi0 (the radius
#: curve's start slope) only shapes the first millimetres of a thin knot, hence its looser bar.
TOL = {"s0_mm": 0.05, "l0_mm": 0.3, "gamma": 0.01, "rho_max_mm": 1.0, "phi0": 0.02, "phi1": 0.005,
       "r_max_mm": 0.1, "psi0": 0.05, "psi1": 0.02}


@pytest.mark.parametrize("params,theta", TRUE_KNOTS)
def test_fit_recovers_noise_free_synthetic_knots(params, theta):
    k = Knot(params, theta)
    pts = k.surface_points(np.linspace(3.0, 120.0, 30), 16)
    fit = fit_knot(pts)
    assert fit.knot.theta_mean_rad == pytest.approx(theta, abs=1e-9)  # s0 = 0: symmetric points
    assert fit.rmse_mm < 0.01 and fit.rmse_mm < fit.init_rmse_mm
    got, want = fit.knot.params, params
    for name, tol in TOL.items():
        assert abs(getattr(got, name) - getattr(want, name)) <= tol, name


def test_fit_recovers_an_offset_knot_given_its_reference_azimuth():
    params = KnotShape(3.0, 40.0, 1.1, 50.0, 0.5, 0.65, 8.0, 0.5, 0.5)
    pts = Knot(params, 0.7).surface_points(np.linspace(3.0, 110.0, 30), 16)
    fit = fit_knot(pts, theta_mean_rad=0.7)
    assert fit.rmse_mm < 0.01
    np.testing.assert_allclose(fit.knot.params.to_array(), params.to_array(), atol=0.3)
    assert abs(fit.knot.params.s0_mm - 3.0) < 0.05


def test_fit_with_noise_has_rmse_near_the_noise():
    params, theta = TRUE_KNOTS[2]
    pts = Knot(params, theta).surface_points(np.linspace(3.0, 120.0, 30), 16)
    rng = np.random.default_rng(0)
    noisy = pts + np.c_[np.zeros(len(pts)), rng.normal(0, 0.5, (len(pts), 2))]
    fit = fit_knot(noisy)
    # residuals are distances to the surface: about the noise's SD (0.5 mm) in the normal direction
    assert 0.3 < fit.rmse_mm < 0.7
    assert abs(fit.knot.params.r_max_mm - params.r_max_mm) < 0.5


def test_unconstrained_round_trip_and_any_vector_is_a_valid_knot():
    p = TRUE_KNOTS[1][0]
    np.testing.assert_allclose(unconstrained_to_params(params_to_unconstrained(p)).to_array(), p.to_array(), rtol=1e-9)
    q = unconstrained_to_params(np.array([0, 0, -50, 50, -100, 100, 3, 40, -40]))
    assert 0 <= q.phi0 <= 1 and q.gamma > 0


def test_fit_refuses_too_few_points():
    with pytest.raises(WoodcamError, match="n >= 20"):
        fit_knot(np.zeros((5, 3)))


# -- the CT-measured spruce log (shared data) ------------------------------------------------

#: RMSE bar on the real log. Seed 001 reports 4.75 mm mean over 102 Scots pine knots measured
#: on CT voxels; our points are sampled from Gran_1's smooth knot description (no voxel noise),
#: so the bar is set lower; the full-log figure is in the slow test below.
REAL_MEAN_RMSE_MM = 2.0


def test_gran_knot_rows_load_and_sample(gran_knots_json):
    rows = _load_gran_knots(gran_knots_json)
    assert rows.shape == (108, 9)
    pts = sample_gran_knot_points(rows[7], n_along=10, n_around=8)
    assert pts.shape == (80, 3)
    # the sampled points sit one knot radius from the described centre curve
    A, B, z0, D, E, w0, G, r_end, _ = rows[7]
    assert np.all(pts[:, 2] > 0) and pts[:, 2].max() <= r_end + gran_knot_diameter(rows[7], r_end) / 2 + 1e-6


def test_fit_real_log_subset(gran_knots_json):
    """Four knots spread along the log (the full table is the slow test below)."""
    table = fit_gran_knots(gran_knots_json, indices=[0, 27, 54, 81])
    s = table.summary()
    assert s["knots"] == 4
    assert s["rmse_mean_mm"] < REAL_MEAN_RMSE_MM
    assert all(f.rmse_mm < f.init_rmse_mm + 1e-9 for f in table.fits)


@pytest.mark.slow
def test_fit_real_log_all_knots(gran_knots_json):
    table = fit_gran_knots(gran_knots_json)
    s = table.summary()
    print("Gran_1 knot fit:", s)
    assert s["knots"] == 108 and s["rmse_mean_mm"] < REAL_MEAN_RMSE_MM
