"""Log description, the real-log reader and the woodcam log file."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.fields.skeleton import BranchStrand, LogSkeleton, simple_log
from woodcam.logs.io import read_log, write_log


def test_gran1_matches_the_readme_figures(gran1):
    # README: 108 knots, min outer radius 104.06 mm, max 143.375 mm, pith every 10 mm to 3990
    assert len(gran1.knots) == 108
    assert gran1.r_min_mm == pytest.approx(104.06)
    assert gran1.r_max_mm == pytest.approx(143.375)
    assert gran1.length_mm == pytest.approx(3990.0)
    # centred: the pith at mid-length sits on the z axis
    assert np.allclose(gran1.pith_at([gran1.pith_z_mm[200]]), 0.0)


def test_gran1_azimuth_convention_puts_knot_ends_on_the_surface(gran1):
    # knots that reach the bark end where the measured surface is (the reason radii are flipped)
    ends = [(i, k.r_end_mm) for i, k in enumerate(gran1.knots) if k.r_end_mm > 100]
    err = []
    for i, r_end in ends:
        p = gran1.knot_point(i, [r_end])[0]
        c = gran1.pith_at([p[2]])[0]
        az = np.arctan2(p[1] - c[1], p[0] - c[0])
        err.append(r_end - gran1.radius_at([p[2]], [az])[0])
    assert len(ends) == 98
    assert np.median(np.abs(err)) < 2.0   # 1.6 mm; the other conventions give 4.0 and 6.6


def test_gran1_knot_diameters_are_plausible_spruce_knots(gran1):
    r = np.array([10.0, 30.0, 60.0, 100.0])
    d = np.array([k.diameter_at(r) for k in gran1.knots])
    assert np.all(d >= 0)
    assert np.all(np.diff(d, axis=1) >= -1e-9)          # knots thicken outward
    assert 10 < np.median(d[:, 3]) < 30                   # 18 mm at 100 mm from the pith
    assert d.max() < 40


def test_knot_from_model_follows_the_readme_formulas():
    k = BranchStrand.from_model(0.2, -0.05, 500.0, 0.3, -0.1, 1.0, 0.05, 120.0, 80.0)
    r = np.array([1.0, 25.0, 64.0, 100.0])
    z, w = k.axis_at(r)
    assert np.allclose(z, 500 + 0.3 * np.sqrt(r) - 0.1 * r, atol=0.02)
    assert np.allclose(w, 1.0 + 0.05 * np.log(r), atol=3e-3)
    assert np.allclose(k.diameter_at(r[1:]), 0.2 * r[1:] ** 0.95, rtol=2e-3)


def test_log_file_round_trip_is_exact(tmp_path, gran1):
    table_knot = BranchStrand(100.0, 0.5, [0, 50, 100], [0, 5, 12], [0, 0.1, 0.15], [0, 8, 14],
                      90.0, 60.0)
    # the pith samples start off z = 0 and the log has its own name: both must come back
    log = LogSkeleton(gran1.pith_z_mm + 25.0, gran1.pith_xy_mm, gran1.radii_mm,
                      gran1.knots[:5] + (table_knot,), "gran 1 top")
    back = read_log(write_log(log, tmp_path / "log.json"))
    assert back.name == "gran 1 top"
    assert np.array_equal(back.pith_z_mm, log.pith_z_mm)
    assert np.array_equal(back.pith_xy_mm, log.pith_xy_mm)
    assert np.array_equal(back.radii_mm, log.radii_mm)
    assert len(back.knots) == 6
    for a, b in zip(log.knots, back.knots):
        assert np.array_equal(a.r_mm, b.r_mm) and np.array_equal(a.rise_mm, b.rise_mm)
        assert np.array_equal(a.twist_rad, b.twist_rad)
        assert np.array_equal(a.diameter_mm, b.diameter_mm)
        assert (a.z0_mm, a.azimuth0_rad, a.r_end_mm, a.r_death_mm) == \
            (b.z0_mm, b.azimuth0_rad, b.r_end_mm, b.r_death_mm)


def test_bad_inputs_name_the_rule(tmp_path):
    with pytest.raises(WoodcamError, match="does not exist"):
        read_log(tmp_path / "nope.json")
    (tmp_path / "x.json").write_text('{"format": "other"}')
    with pytest.raises(WoodcamError, match="woodcam-log"):
        read_log(tmp_path / "x.json")
    with pytest.raises(WoodcamError, match="start at 0"):
        BranchStrand(0, 0, [1, 2], [0, 0], [0, 0], [0, 1], 10, 5)
    with pytest.raises(WoodcamError, match="radii_mm"):
        LogSkeleton([0, 10], [[0, 0], [0, 0]], [[1.0] * 3, [1.0] * 3])
    with pytest.raises(WoodcamError, match="length_mm"):
        simple_log(-1)


@pytest.mark.parametrize("kw, said", [
    ({"pith_z_mm": "abc"}, "Log.pith_z_mm must be \\(h,\\) heights in mm \\(numbers\\); got 'abc'"),
    ({"pith_xy_mm": "ab"}, "Log.pith_xy_mm must be \\(h, 2\\) pith points in mm \\(numbers\\); got 'ab'"),
    ({"radii_mm": [[1, "a"]]}, "Log.radii_mm must be \\(h, a\\) radii in mm \\(numbers\\); got \\[\\[1, 'a'\\]\\]"),
    ({"knots": 5}, "Log.knots must be a sequence of woodcam.fields.skeleton.BranchStrand; got 5; pass \\(\\)"),
    ({"knots": [1]}, "Log.knots must be a sequence of .*BranchStrand; got \\[1\\]"),
], ids=["z str", "xy str", "radii str", "knots int", "knots of ints"])
def test_a_log_of_what_is_not_numbers_or_knots_is_refused_naming_it(kw, said):
    """A string was numpy's bare ValueError, knots=5 tuple()'s TypeError and
    knots=[1] was taken (an AttributeError in the first knot field)."""
    args = {"pith_z_mm": [0.0, 10.0, 20.0], "pith_xy_mm": np.zeros((3, 2)), "radii_mm": np.ones((3, 8))} | kw
    knots = args.pop("knots", ())
    with pytest.raises(WoodcamError, match=said):
        LogSkeleton(**args, knots=knots)


def test_diameter_model_against_the_bark_bumps(gran1):
    """Where a knot leaves through the bark the measured radius has a bump; its width along
    the azimuth follows the power law ``A r^(1+B)`` better than the quadratic ``A r + B r^2/100``
    (the other reading of the README's "diameter model coefficients"), which gives 64 mm knots
    in a 125 mm-radius log."""
    from scipy.ndimage import median_filter

    ratios_pow, ratios_quad = [], []
    for i, k in enumerate(gran1.knots):
        if k.r_end_mm < 110:
            continue
        p = gran1.knot_point(i, [k.r_end_mm])[0]
        c = gran1.pith_at([p[2]])[0]
        j = int(round(np.degrees(np.arctan2(p[1] - c[1], p[0] - c[0])))) % 360
        iz = int(round(p[2] / 10))
        if not 1 <= iz <= 398:
            continue
        prof = gran1.radii_mm[iz, (j + np.arange(-40, 41)) % 360]
        bump = prof - median_filter(prof, size=41, mode="nearest")
        peak = bump[35:46].max()
        if peak < 0.8:                                  # no clear bump (mm)
            continue
        ic = 35 + int(np.argmax(bump[35:46]))
        lo, hi = ic, ic
        while lo > 0 and bump[lo] > peak / 2:
            lo -= 1
        while hi < 80 and bump[hi] > peak / 2:
            hi += 1
        width = np.radians(hi - lo) * k.r_end_mm
        A, B = k.coefficients["A"], k.coefficients["B"]
        ratios_pow.append(width / (A * k.r_end_mm ** (1 + B)))
        ratios_quad.append(width / (A * k.r_end_mm + B * k.r_end_mm ** 2 / 100))
    assert len(ratios_pow) == 12
    spread_pow, spread_quad = np.std(np.log(ratios_pow)), np.std(np.log(ratios_quad))
    assert spread_pow < 0.75 * spread_quad            # 0.33 vs 0.51


def test_generated_log_converts_itself_to_a_skeleton():
    """GeneratedLog.to_skeleton: the generator's log as the knot field's input."""
    from woodcam.logs import generate_log

    gen = generate_log(5, length_mm=800.0)
    log = gen.to_skeleton(z_step_mm=10.0, azimuths=90)
    assert isinstance(log, LogSkeleton) and log.length_mm == pytest.approx(800.0)
    assert log.radii_mm.shape == (81, 90)
    z = np.array([100.0, 400.0])
    np.testing.assert_allclose(log.pith_at(z), np.asarray(gen.centreline_points(z))[:, :2], atol=1e-9)
    np.testing.assert_allclose(log.radius_at(z, [0.0, 0.0]), gen.outer_radius(z, np.zeros(2)), rtol=1e-9)
    assert len(log.knots) == len(gen.knots) > 0
    k, g = log.knots[0], gen.knots[0]
    rho = np.array([20.0, 0.5 * g.end_mm])
    np.testing.assert_allclose(k.axis_at(rho)[0], g.height(rho), atol=0.5)
    # the round knot of the field has the area of the generator's elliptic one
    np.testing.assert_allclose(k.diameter_at(rho), 2 * g.radius(rho) * np.sqrt(g.knot.params.gamma),
                               rtol=0.02)
    assert (k.r_end_mm, k.r_death_mm) == (float(g.end_mm), float(g.death_mm))
