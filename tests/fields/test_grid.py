"""Grid-baked fields: interpolation accuracy, ARF from interpolated growth time, save/load."""

import numpy as np
import pytest

from woodcam._checks import check_rotation
from woodcam.errors import WoodcamError
from woodcam.fields import arf
from woodcam.fields.builtin import BUILTIN_NAMES, builtin_block
from woodcam.fields.grid import GridField
from woodcam.fields.radial import RadiusFunction


def test_cubic_grid_reproduces_quadratic_exactly(rng):
    """A cubic B-spline through nodes reproduces polynomials up to degree 2 away from borders."""
    f = lambda p: 0.01 * p[:, 0] ** 2 + 0.3 * p[:, 1] - 0.02 * p[:, 1] * p[:, 2] + 5
    g = GridField.bake(f, (0, 0, 0), (40, 30, 20), 2.0, margin_nodes=4)
    p = rng.uniform(0, 1, (2000, 3)) * (40, 30, 20)
    np.testing.assert_allclose(g(p), f(p), atol=2e-3)


def test_cubic_grid_reproduces_a_cubic_polynomial_inland(rng):
    """Order 3 tells itself from order 2 here: a cubic B-spline reproduces polynomials up to
    degree 3, a quadratic one only up to degree 2. The spline's border error decays by ~0.27 per
    node inland, so with 14 nodes of margin the box sees ~1e-8 of it: on a cubic polynomial
    (values up to ~700 years) the cubic grid is off by 1.9e-7 years (measured), the bar 2e-6 is
    10x that; an order-2 spline misses by 5.4e-3 (2700x the bar), trilinear by 1.2."""
    f = lambda p: (0.01 * p[:, 0] ** 3 - 0.02 * p[:, 0] * p[:, 1] * p[:, 2]
                   + 0.005 * p[:, 1] ** 2 * p[:, 2] - 0.004 * p[:, 2] ** 3 + 0.3 * p[:, 1] + 5)
    g = GridField.bake(f, (0, 0, 0), (40, 30, 20), 2.0, margin_nodes=14)
    p = rng.uniform(0, 1, (2000, 3)) * (40, 30, 20)
    assert np.abs(g(p) - f(p)).max() < 2e-6


def test_flat_sawn_grid_error_small_against_ring_width(rng):
    """At 2 mm spacing the baked flat-sawn field is within 0.02 years (0.06 mm at 3 mm rings)."""
    b = builtin_block("flat-sawn")
    g = GridField.bake(b.field, (0, 0, 0), b.size_mm, 2.0)
    p = rng.uniform(0, 1, (20000, 3)) * b.size_mm
    assert np.abs(g(p) - b.field(p)).max() < 0.02


def test_arf_from_interpolated_years_keeps_sharp_ring_step():
    """The ARF jumps from ~1 to 0 across a ring boundary even inside one grid cell."""
    f = lambda p: p[:, 0] / 3.0  # rings every 3 mm along X
    g = GridField.bake(f, (0, 0, 0), (30, 4, 4), 4.0)
    x = np.array([[5.99, 2, 2], [6.01, 2, 2]])
    a = arf(g(x))
    assert a[0] > 0.98 and a[1] < 0.02


def test_save_load_round_trip(tmp_path, rng):
    b = builtin_block("quarter-sawn")
    g = GridField.bake(b.field, (0, 0, 0), b.size_mm, 3.0)
    path = g.save(tmp_path / "field")
    assert path.suffix == ".npz"
    h = GridField.load(path)
    p = rng.uniform(0, 1, (100, 3)) * b.size_mm
    np.testing.assert_array_equal(g(p), h(p))
    np.testing.assert_allclose(h.axis, b.field.axis)


def test_save_load_round_trip_keeps_interpolation_layers_and_meta(tmp_path, rng):
    """Everything :meth:`GridField.save` writes comes back: a linear grid stays linear (its
    value between nodes is the trilinear one, not the cubic spline's), layers and meta too."""
    years = rng.uniform(0, 10, (5, 6, 7))
    knot = rng.uniform(0, 1, years.shape)
    g = GridField(years, (1.0, -2.0, 3.0), (2.0, 1.5, 1.0), "linear", axis=(0.0, 1.0, 0.0),
                  layers={"knot": knot}, meta={"method": "rbf", "warnings": ["x"]})
    h = GridField.load(g.save(tmp_path / "g.npz"))
    assert h.interpolation == "linear" and h.meta == g.meta
    assert h.spacing_mm == (2.0, 1.5, 1.0) and h.origin_mm == (1.0, -2.0, 3.0)
    p = np.array([[2.0, -2.0, 3.0]])                    # halfway between nodes (0,0,0) and (1,0,0)
    assert h(p)[0] == pytest.approx((years[0, 0, 0] + years[1, 0, 0]) / 2)
    q = rng.uniform(0, 1, (100, 3)) * (8.0, 7.5, 6.0) + (1.0, -2.0, 3.0)
    np.testing.assert_array_equal(h(q), g(q))
    np.testing.assert_array_equal(h.knot_features(q)["knot"], g.knot_features(q)["knot"])
    assert h.knot_features(p)["knot"][0] == pytest.approx((knot[0, 0, 0] + knot[1, 0, 0]) / 2)


def test_load_garbage(tmp_path):
    bad = tmp_path / "x.npz"
    bad.write_text("not a field")
    # and how to make one (sweep h4: 'woodcam eval rings --truth' of another file said no fix)
    with pytest.raises(WoodcamError, match=r"not a woodcam grid field .*; give a field file as 'woodcam fit BLOCK "
                       r"--out FIELD.npz' writes it \(GridField.save\)$"):
        GridField.load(bad)


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_builtin_blocks_have_many_rings(name, rng):
    b = builtin_block(name)
    p = rng.uniform(0, 1, (20000, 3)) * b.size_mm
    years = b.field(p)
    assert np.all(years >= 0)
    assert np.ptp(years) > 8  # enough rings to read as wood


def test_unknown_builtin():
    with pytest.raises(WoodcamError, match="unknown built-in block 'oak-burl'"):
        builtin_block("oak-burl")


@pytest.mark.parametrize("lo, hi, match", [
    ("a", (1, 1, 1), r"lo_mm must be three finite numbers \(x, y, z\); got 'a'; the box's low corner"),
    ((0, 0, 0), (np.nan, 1, 1), r"hi_mm must be three finite numbers .*got \(nan, 1, 1\)"),
    ((0, 0), (1, 1, 1), r"lo_mm must be three finite numbers"),
    ((0, 0, 5), (1, 1, 1), r"hi_mm must exceed lo_mm on every axis"),
])
def test_bake_refuses_a_box_that_is_not_two_corners(lo, hi, match):
    """'a' was a bare ValueError and a NaN corner a misleading grid-size (MAX_GRID_CELLS) message."""
    with pytest.raises(WoodcamError, match=match):
        GridField.bake(builtin_block("flat-sawn").field, lo, hi, 2.0)


@pytest.mark.parametrize("interpolation", ["cubic", "linear"])
@pytest.mark.parametrize("spacing", [2.0, 1e-14])
def test_a_point_far_outside_the_grid_reads_the_border(interpolation, spacing):
    """'Points beyond the grid clamp to its border', but scipy's map_coordinates turned grid
    coordinates past 2**63 into garbage: a GridField gave ~1e230 years (memory read elsewhere)
    at x = 1e20 mm, a cubic WoodifiedField 0, and its knot layer likewise. Now every point
    reads what a point 1e4 nodes out reads (the border), and nearer ones are untouched. Points
    beyond POINT_BOUND_MM (1e6 mm) are refused at the door (check_points), so 2**63 nodes out
    is reached only on a fine grid: 1e6 mm on a 1e-14 mm grid is 1e20 nodes."""
    import woodcam as w

    years = np.add.outer(np.add.outer(np.arange(4.0), 2 * np.arange(5.0)), 3 * np.arange(6.0))
    g = GridField(years, (0, 0, 0), spacing, interpolation, layers={"knot": years / years.max()})
    wf = w.WoodifiedField(years, (0, 0, 0), spacing, w.GrowthSpeed(10, 1), years_final=1.0,
                          interpolation=interpolation)
    for sign in (1, -1):
        out = sign * 1e4 * spacing
        border = np.array([[out, 1.5, 2.5], [0.5, out, 2.5], [0.5, 1.5, out]]) * np.where(
            np.eye(3, dtype=bool), 1.0, spacing)
        for far in (1e6, 1e5):
            pts = np.where(np.eye(3, dtype=bool), sign * far, border)
            assert np.array_equal(g(pts), g(border))
            assert np.array_equal(g.layer("knot", pts), g.layer("knot", border))
            assert np.array_equal(wf(pts), wf(border))
    assert np.isfinite(g(border)).all() and np.isfinite(wf(border)).all()


@pytest.mark.parametrize("make, match", [
    (lambda: GridField(np.ones((40, 40, 40)) * (1 + 1j), (0, 0, 0), 1.0),
     r"years must be .*; got an array of complex numbers \(dtype complex128, shape \(40, 40, 40\)\); "
     r"pass real numbers \(e\.g\. np\.real\(years\)"),
    (lambda: GridField(np.ones((4, 4, 4)), (0, 0, 0), 1.0, layers={"knot": np.ones((4, 4, 4)) * 1j}),
     r"layer 'knot' must be a finite grid of real numbers .*; got an array of complex numbers "
     r"\(dtype complex128, shape \(4, 4, 4\)\)"),
    (lambda: GridField(np.ones((4, 4, 4)), np.zeros(1000), 1.0),
     r"origin_mm must be three finite numbers .*; got an array of numbers \(dtype float64, shape \(1000,\)\)"),
    (lambda: GridField(np.ones((4, 4, 4)), (0, 0, 0), 1.0, axis=np.zeros((50, 50))),
     r"axis must be three finite numbers .*; got an array of numbers \(dtype float64, shape \(50, 50\)\)"),
    (lambda: check_rotation(np.zeros((100, 3, 3)), "rotation"),
     r"rotation must be a proper 3x3 rotation matrix .*; got an array of numbers \(dtype float64, shape \(100, 3, 3\)\)"),
    (lambda: RadiusFunction.from_constraints(-np.ones(500)),
     r"values must be positive finite radius scalings; got an array of numbers \(dtype float64, shape \(500,\)\)"),
], ids=["complex years", "complex layer", "origin of 1000", "axis 50x50", "rotation of 100", "radius values"])
def test_an_array_argument_refused_is_quoted_briefly(make, match):
    """A refused array was quoted whole (its repr) or as its first 80 characters ("got
    array([[[1.+1.j, 1.+1.j, ..."): now its kind, dtype and shape (_checks.received), and
    complex years are told how to pass real ones."""
    with pytest.raises(WoodcamError, match=match) as err:
        make()
    assert len(str(err.value)) < 300 and "array(" not in str(err.value)


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_a_point_beyond_the_physical_bound_is_refused_not_inf_years(name):
    """A finite point 1e200 mm away overflowed the radius: the analytic blocks answered inf
    years and the knotty one numpy's overflow RuntimeWarning. check_points refuses coordinates
    beyond POINT_BOUND_MM (1e6 mm); points up to it give finite years."""
    from woodcam.tolerances import POINT_BOUND_MM

    field = builtin_block(name).field
    for far in (1e200, 2 * POINT_BOUND_MM, -1e12):
        with pytest.raises(WoodcamError, match=r"points_mm must lie within 1e\+06 mm \(1 km\) of the origin on "
                                               r"each axis; point 1 is \[.*\]; pass block-frame points in mm"):
            field(np.array([[1.0, 2.0, 3.0], [1.0, far, 3.0]]))
    near = 0.999 * POINT_BOUND_MM
    assert np.isfinite(field(np.array([[near, 0, 0], [0, -near, 0], [0, 0, near], [near, near, -near]]))).all()
