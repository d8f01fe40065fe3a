"""The knotted-log growth field (seed 003): smooth minimum, stem, alive and dead knots."""

import numpy as np
import pytest
from scipy import ndimage

from woodcam.errors import WoodcamError
from woodcam.fields.knots import (
    KnotParams,
    KnottedLogField,
    PlacedField,
    available_backends,
    place_block_in_log,
    power_smooth_min,
    smoothing_amount,
)
from woodcam.fields.skeleton import BranchStrand, simple_log
from woodcam.logs import render as lr

BACKENDS = available_backends()


def _knot(z0=300.0, r_death=150.0, az=0.0, r_end=100.0):
    # horizontal, untwisted knot; diameter 0.25 r (radius 12.5 % of the pith distance)
    return BranchStrand.from_model(0.25, 0.0, z0, 0.0, 0.0, az, 0.0, r_end, r_death)


# -- smooth minimum -------------------------------------------------------------------------

def test_power_smooth_min_is_the_seed_formula_and_bounded():
    rng = np.random.default_rng(1)
    a, b = rng.uniform(0.1, 50, (2, 1000))
    for k in (1.5, 3.0, 5.0):
        ref = (a ** k * b ** k / (a ** k + b ** k)) ** (1 / k)          # eq. 2 as written
        s = power_smooth_min(a, b, k)
        assert np.allclose(s, ref, rtol=1e-12)
        m = np.minimum(a, b)
        assert np.all(s <= m + 1e-12)                                  # never above the min
        assert np.all(s >= m * 2 ** (-1 / k) - 1e-12)                   # |delta| <= (1-2^-1/k) m
        d = smoothing_amount(a, b, k)
        assert np.all(d <= 0) and np.all(-d <= m * (1 - 2 ** (-1 / k)) + 1e-12)


def test_power_smooth_min_is_continuous():
    # 1-Lipschitz in each argument: a step h changes it by at most h
    a = np.linspace(0.0, 20.0, 200001)
    for k in (1.5, 5.0):
        s = power_smooth_min(a, 10.0, k)
        assert np.max(np.abs(np.diff(s))) <= (a[1] - a[0]) * (1 + 1e-9)


# -- stem --------------------------------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_log_without_knots_is_the_stem_field_exactly(backend):
    f = KnottedLogField(simple_log(), ring_width_mm=2.5, backend=backend)
    rng = np.random.default_rng(2)
    p = rng.uniform([-120, -120, -5], [120, 120, 605], (5000, 3))
    expected = np.hypot(p[:, 0], p[:, 1]) / 2.5          # straight round log: d / ring width
    assert np.allclose(f(p), expected, rtol=0, atol=1e-12)
    if backend == "numpy":
        assert np.array_equal(f(p), f.stem_years(p))
    else:   # the compiled kernel rounds sqrt(x^2 + y^2) differently from numpy's hypot
        assert np.allclose(f(p), f.stem_years(p), rtol=1e-15, atol=0)
    feats = f.knot_features(p)
    assert all(np.all(v == 0) for v in feats.values())


def test_real_log_without_knots_is_its_stem_field(gran1):
    f = KnottedLogField(gran1.with_knots([]), backend="numpy")
    rng = np.random.default_rng(3)
    p = rng.uniform([-140, -140, 0], [140, 140, 3990], (4000, 3))
    assert np.array_equal(f(p), f.stem_years(p))


def test_stem_rings_follow_the_measured_outline(gran1):
    # on the outer surface the ring count equals mean radius / ring width at every azimuth
    f = KnottedLogField(gran1.with_knots([]), ring_width_mm=2.0, surface_smoothing=(1, 1))
    z = np.full(360, 2005.0)
    az = np.radians(np.arange(360))
    c = gran1.pith_at(z)
    rad = gran1.radius_at(z, az)
    p = np.stack([c[:, 0] + rad * np.cos(az), c[:, 1] + rad * np.sin(az), z], 1)
    y = f(p)
    # 1e-3 years: the speed ratio R / mean R is interpolated between rows of different means
    assert np.ptp(y) < 1e-3
    assert y[0] == pytest.approx(rad.mean() / 2.0, rel=1e-3)


# -- knots ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_far_knots_add_exactly_nothing(backend):
    near, far = _knot(300.0), _knot(2500.0, az=2.0)
    f1 = KnottedLogField(simple_log(3000, knots=[near]), backend=backend)
    f2 = KnottedLogField(simple_log(3000, knots=[near, far]), backend=backend)
    f0 = KnottedLogField(simple_log(3000), backend=backend)
    rng = np.random.default_rng(4)
    p = rng.uniform([-100, -100, 200], [100, 100, 400], (3000, 3))
    assert np.array_equal(f1(p), f2(p))
    q = rng.uniform([-100, -100, 1000], [100, 100, 1500], (3000, 3))   # between the knots
    assert np.array_equal(f2(q), f0(q))


def test_knot_centre_is_young_wood_and_its_size_is_the_data_diameter():
    f = KnottedLogField(simple_log(knots=[_knot()]), ring_width_mm=2.0)
    # on the knot axis at 60 mm from the pith: knot wood, growth time ~0 (the branch's pith)
    o = f.evaluate([[60.0, 0.0, 300.0]])
    assert o["knot"][0] > 0.95 and o["years"][0] < 0.5
    # across the knot (tangential line) the knot feature spans about the diameter (15 mm)
    y = np.linspace(-20, 20, 4001)
    o = f.evaluate(np.stack([np.full_like(y, 60.0), y, np.full_like(y, 300.0)], 1))
    width = np.ptp(y[o["knot"] > 0.2])
    assert width == pytest.approx(15.0, rel=0.15)
    assert o["knot"][0] < 0.01 and o["knot"][-1] < 0.01


def test_rings_continuous_across_an_alive_knot_and_broken_at_a_dead_knot_outline():
    zz = np.linspace(280.0, 320.0, 40001)                    # 0.001 mm steps across the knot
    line = np.stack([np.full_like(zz, 70.0), np.zeros_like(zz), zz], 1)
    alive = KnottedLogField(simple_log(knots=[_knot(r_death=150.0)]), ring_width_mm=2.0)
    dead = KnottedLogField(simple_log(knots=[_knot(r_death=40.0)]), ring_width_mm=2.0)
    ya = alive(line)
    od = dead.evaluate(line)
    # alive: no jump anywhere (largest step 0.004 years per micrometre, at the knot's axis);
    # over any 0.05 mm (a fine texel) less than half a year
    assert np.max(np.abs(np.diff(ya))) < 0.02
    assert np.max(np.abs(ya[50:] - ya[:-50])) < 0.5
    # dead: the rings break at the bark ring: several years within 0.05 mm, only under the
    # outline (the change is a step narrower than the outline, not a smooth bend)
    change = np.abs(od["years"][50:] - od["years"][:-50])
    breaks = np.nonzero(change > 3.0)[0] + 25
    assert len(breaks) >= 2
    outl = zz[od["outline"] > 0]
    assert len(outl) > 0
    for j in breaks:
        assert np.min(np.abs(outl - zz[j])) < 0.05
    # the outline sits at the knot radius at death: 0.125 * 40 = 5 mm (+- noise 8 %)
    assert np.max(np.abs(outl - 300.0)) == pytest.approx(5.0, abs=0.8)
    # inside the loose knot: dead wood
    assert od["dead"][20000] > 0.9 and alive.knot_features(line)["dead"].max() == 0


def test_dead_knot_field_is_continuous_away_from_its_outline():
    """The seed's shader switches to the dead form abruptly where smin > t_death, which also
    breaks rings on a ring-parallel surface all around the knot; the blend over
    death_band_mm removes those breaks (checked by refining: a true jump stays a jump)."""
    dead = KnottedLogField(simple_log(knots=[_knot(r_death=40.0, r_end=140.0)]))
    x = np.linspace(30.0, 90.0, 60001)                   # radial line beside the knot
    for y0, z0 in ((14.0, 300.0), (0.0, 318.0), (25.0, 290.0)):
        line = np.stack([x, np.full_like(x, y0), np.full_like(x, z0)], 1)
        o = dead.evaluate(line)
        assert o["outline"].max() == 0
        assert np.max(np.abs(np.diff(o["years"]))) < 0.005    # years per micrometre


def test_dead_knot_smoothing_changes_sign_after_death():
    # right after death the knot pulls the rings (delta < 0), far after death it pushes
    # them (inverted smoothing, seed Sec. 4.2.2); compare with the alive knot field
    k_alive, k_dead = _knot(r_death=150.0, r_end=140.0), _knot(r_death=40.0, r_end=140.0)
    fa = KnottedLogField(simple_log(knots=[k_alive]), params=KnotParams(knot_noise=0))
    fd = KnottedLogField(simple_log(knots=[k_dead]), params=KnotParams(knot_noise=0))
    f0 = KnottedLogField(simple_log())
    near_after = np.array([[45.0, 0.0, 300.0 + 12.0]])     # just past death, beside the knot
    far_after = np.array([[95.0, 12.0, 300.0]])            # long after death, at its side
    assert fa(near_after)[0] < f0(near_after)[0]
    assert fd(near_after)[0] < f0(near_after)[0]
    assert fd(far_after)[0] > f0(far_after)[0]             # inverted: rings bulge away
    assert fa(far_after)[0] < f0(far_after)[0]


def test_knot_noise_zero_gives_a_round_knot():
    """``knot_noise`` is the irregularity of the knot's radius round its axis: without it the
    knot's width is the same across every diameter (within the stem's own curvature), with
    the default 8 % it is not."""
    s = np.linspace(-15, 15, 3001)
    widths = {}
    for noise in (0.0, 0.08):
        f = KnottedLogField(simple_log(knots=[_knot()]), params=KnotParams(knot_noise=noise))
        w = []
        for b in np.radians(np.arange(0, 180, 15)):       # diameters round the knot axis at r = 60
            line = np.stack([np.full_like(s, 60.0), s * np.cos(b), 300 + s * np.sin(b)], 1)
            w.append(np.ptp(s[f.knot_features(line)["knot"] > 0.5]))
        widths[noise] = np.array(w)
    assert np.ptp(widths[0.0]) < 0.15, widths[0.0]            # 0.06 mm
    # Known answer along the log (beta = 90 deg, d_s = 60 mm throughout): the weight
    # 1 / (1 + (1.2 t_b - t_s) / L)^14 (L = 100 mm) is 1/2 where t_b = (t_s + (2^(1/14) - 1) L) / 1.2,
    # and t_b = |P - S_b| / rho with rho = 0.125 (the knot's radius over its pith distance).
    half = 0.125 * (60.0 + (2 ** (1 / 14) - 1) * 100.0) / 1.2
    assert widths[0.0][6] == pytest.approx(2 * half, abs=0.02)    # 13.56 mm
    assert np.ptp(widths[0.08]) > 0.3, widths[0.08]           # 0.64 mm


@pytest.mark.parametrize("outline_mm", [0.5, 2.0])
def test_dead_knot_outline_is_outline_mm_thick(outline_mm):
    """The bark ring of a dead knot is ``outline_mm`` thick across the knot (measured along the
    log through the knot's axis: 0.13-0.2 mm more, the step where the rings break)."""
    zz = np.linspace(280.0, 320.0, 40001)
    line = np.stack([np.full_like(zz, 70.0), np.zeros_like(zz), zz], 1)
    f = KnottedLogField(simple_log(knots=[_knot(r_death=40.0)]), params=KnotParams(outline_mm=outline_mm))
    on = f.evaluate(line)["outline"] > 0
    for side in (zz > 300, zz < 300):
        assert np.ptp(zz[on & side]) == pytest.approx(outline_mm, abs=0.25)


def test_butterfly_weakens_the_inversion_above_and_below_a_dead_knot():
    """``butterfly``: f = 1 + (f - 1)(1 - butterfly sin^2 beta), beta from the tangential
    direction. At the knot's side (beta = 0) it changes nothing; above it (beta = 90 deg) the
    rings bulge as at the side with butterfly 0 and are pulled in, not inverted, with 1."""
    f0 = KnottedLogField(simple_log())
    side, above = np.array([[95.0, 12.0, 300.0]]), np.array([[95.0, 0.0, 312.0]])
    bulge = {}
    for b in (0.0, 0.5, 1.0):
        fd = KnottedLogField(simple_log(knots=[_knot(r_death=40.0, r_end=140.0)]),
                             params=KnotParams(knot_noise=0, butterfly=b))
        bulge[b] = (fd(side)[0] - f0(side)[0], fd(above)[0] - f0(above)[0])
    assert bulge[0.0][0] > 0.1 and bulge[0.0][0] == bulge[0.5][0] == bulge[1.0][0]
    assert bulge[0.0][1] == pytest.approx(bulge[0.0][0], rel=0.05)
    assert bulge[1.0][1] < bulge[0.5][1] < 0.0


@pytest.mark.skipif(len(BACKENDS) < 2, reason="numba is not installed")
def test_backends_agree(gran1):
    rng = np.random.default_rng(5)
    p = rng.uniform([-145, -145, -10], [145, 145, 4000], (20000, 3))
    a = KnottedLogField(gran1, backend="numpy").evaluate(p, directions=True)
    b = KnottedLogField(gran1, backend="numba").evaluate(p, directions=True)
    for k in a:
        assert np.allclose(a[k], b[k], rtol=0, atol=1e-9), k


def test_grain_direction_follows_stem_and_knot_axis():
    f = KnottedLogField(simple_log(knots=[_knot()]))
    d = f.grain_direction([[60.0, 0.0, 300.0], [-60.0, 0.0, 100.0]])
    assert np.allclose(d[0], [1, 0, 0], atol=0.05)    # inside the horizontal knot: radial
    assert np.allclose(d[1], [0, 0, 1], atol=1e-9)    # plain stem wood: along the pith
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)


def test_real_log_knots_sit_where_the_data_says(gran1):
    """Tangential sections at 60 mm from the pith: each knot's blob is centred on the data's
    knot axis point and is as wide as the data's diameter model."""
    f = KnottedLogField(gran1)
    checked = 0
    for i in range(0, 108, 6):
        k = gran1.knots[i]
        r = 60.0
        p = gran1.knot_point(i, [r])[0]
        c = gran1.pith_at([p[2]])[0]
        az = np.arctan2(p[1] - c[1], p[0] - c[0])
        s = lr.tangential_board(gran1, p[2], az, r, length_mm=60, width_mm=60, px_per_mm=4)
        P = s.points()
        kn = f.knot_features(P.reshape(-1, 3))["knot"].reshape(P.shape[:2])
        lab, _ = ndimage.label(kn > 0.2)
        centre = lab[120, 120]
        if k.r_end_mm < r:                 # overgrown before 60 mm: no knot there
            assert centre == 0
            continue
        assert centre > 0, i
        cy, cx = ndimage.center_of_mass(lab == centre)
        assert np.hypot(cx - 119.5, cy - 119.5) / 4 < 1.0, i           # mm
        diam = 2 * np.sqrt((lab == centre).sum() / 16 / np.pi)
        expect = k.diameter_at([min(r, k.r_death_mm)])[0]
        assert diam == pytest.approx(expect, rel=0.2, abs=1.0), i
        checked += 1
    assert checked >= 12


# -- placement and shading ---------------------------------------------------------------------

def test_placed_field_maps_block_points_into_the_log():
    f = KnottedLogField(simple_log(knots=[_knot()]))
    # block X along log -y, Y along log +x, Z along log +z; block origin at log (40, 30, 250)
    R = np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1.0]])
    pf = place_block_in_log(f, (40.0, 30.0, 250.0), R)
    pb = np.array([[30.0, 20.0, 50.0], [5.0, 5.0, 5.0]])
    pl = np.array([[60.0, 0.0, 300.0], [45.0, 25.0, 255.0]])
    assert np.allclose(pf.to_log(pb), pl)
    assert np.array_equal(pf(pb), f(pl))
    assert np.allclose(pf.grain_direction(pb)[0], R.T @ f.grain_direction(pl)[0])
    with pytest.raises(WoodcamError, match="rotation"):
        PlacedField(f, (0, 0, 0), np.diag([1.0, 1.0, -1.0]))


def test_placed_field_from_log_frame():
    from woodcam.fields.base import LogFrame

    f = KnottedLogField(simple_log())
    frame = LogFrame(pith_point_mm=(50.0, -80.0, 0.0), axis=(0, 0, 1), reference=(1, 0, 0))
    pf = PlacedField.from_log_frame(f, frame)
    p = np.array([[50.0, 20.0, 30.0]])                   # 100 mm from the pith
    assert pf(p)[0] == pytest.approx(100.0 / 2.0)


@pytest.mark.parametrize("name, value, rule", [
    ("k_stem", "1", r"in \[0\.1, 64\]; got '1'"),
    ("k_knot", None, r"in \[0\.1, 64\]; got None"),
    ("death_band_mm", 1 + 1j, r"> 0; got \(1\+1j\)"),
    ("range_d0_mm", [1], r">= 0; got \[1\]"),
    ("knot_noise", "abc", r"in \[0, 1\]; got 'abc'; the default is 0\.08"),
    ("outline_mm", float("nan"), ">= 0; got nan; the default is 1"),
    ("range_d1_mm", float("inf"), ">= 0; got inf"),
    ("k_transition_mm", 0, "> 0; got 0; the default is 30"),
    ("death_f_min", "x", r"; got 'x'; the default is -1\.5"),
    ("knot_edge_sharpness", True, "> 0; got True"),
])
def test_every_knot_param_is_a_number_in_its_range(name, value, rule):
    """A string, None, a complex number or a list for k_stem, k_knot, death_band_mm, butterfly,
    outline_mm or a range was a bare TypeError of a comparison; the other eight parameters were
    kept as given ('abc', NaN, True) until a field was evaluated, NaN passed 'outline_mm < 0' and
    inf the range check."""
    with pytest.raises(WoodcamError, match=rf"KnotParams\.{name} must be a finite number.*{rule}"):
        KnotParams(**{name: value})


def test_params_are_checked():
    with pytest.raises(WoodcamError, match="k_knot"):
        KnotParams(k_knot=0.0)
    with pytest.raises(WoodcamError, match=r"butterfly must be a finite number in \[0, 1\]"):
        KnotParams(butterfly=2.0)
    with pytest.raises(WoodcamError, match="ring_width_mm"):
        KnottedLogField(simple_log(), ring_width_mm=0)
    with pytest.raises(WoodcamError, match="backend"):
        KnottedLogField(simple_log(), backend="gpu")


@pytest.mark.parametrize("backend", BACKENDS)
def test_irregular_pith_samples(backend):
    from woodcam.fields.skeleton import LogSkeleton

    z = np.array([0.0, 5.0, 20.0, 60.0, 100.0])
    xy = np.stack([0.1 * z, np.zeros_like(z)], 1)          # a leaning, straight pith
    log = LogSkeleton(z, xy, np.full((5, 8), 80.0))
    f = KnottedLogField(log, ring_width_mm=2.0, backend=backend)
    rng = np.random.default_rng(6)
    p = rng.uniform([-60, -60, 0], [60, 60, 100], (2000, 3))
    expected = np.hypot(p[:, 0] - 0.1 * p[:, 2], p[:, 1]) / 2.0
    assert np.allclose(f(p), expected, atol=1e-9)
