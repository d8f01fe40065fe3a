"""Generated logs (seed 001 §4): reproducibility, model constraints, knots vs surface."""

import time

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.logs.generate import CompoundGaussian, generate_log, group_whorls, knot_stats_from_fits
from woodcam.logs.knot import radius_coefficients, trajectory_coefficients


@pytest.fixture(scope="module")
def log():
    return generate_log(11, length_mm=2000.0)


def test_same_seed_gives_the_identical_log_and_another_seed_a_different_one():
    a = generate_log(5, length_mm=1000.0)
    b = generate_log(5, length_mm=1000.0)
    c = generate_log(6, length_mm=1000.0)
    np.testing.assert_array_equal(a.heightmap_mm, b.heightmap_mm)
    assert [k.knot for k in a.knots] == [k.knot for k in b.knots]
    assert a.heightmap_mm.shape == c.heightmap_mm.shape
    assert np.abs(a.heightmap_mm - c.heightmap_mm).mean() > 1.0
    assert [k.knot for k in a.knots] != [k.knot for k in c.knots]


def test_generated_knots_satisfy_the_model_constraints(log):
    assert len(log.knots) > 20
    for gk in log.knots:
        p = gk.knot.params
        a_l, E_l, L_l = trajectory_coefficients(p.rho_max_mm, p.phi0, p.phi1)
        assert a_l >= 0 and E_l >= 2
        a_r, E_r, L_r = radius_coefficients(p.r_max_mm, p.psi0, p.psi1, gk.knot.c_max_mm())
        assert a_r >= -1e-9 and E_r >= 2 and L_r >= 0
        rho = np.linspace(0, gk.end_mm, 400)
        slope = gk.knot.height_slope(rho)
        assert np.all(np.diff(slope) <= 1e-9), "trajectory must be concave"
        assert np.all(np.diff(gk.radius(rho)) >= -1e-9), "knots do not thin out"
        assert 0 < gk.death_mm <= gk.end_mm


def test_knots_that_reach_the_surface_end_on_it(log):
    reach = [k for k in log.knots if k.reaches_surface]
    assert reach
    end = np.array([k.end_mm for k in reach])
    l = np.array([k.height(np.array([k.end_mm]))[0] for k in reach])
    t = np.array([k.azimuth(np.array([k.end_mm]))[0] for k in reach])
    np.testing.assert_allclose(log.base_radius(l, t), end, atol=0.05)
    for k in (k for k in log.knots if not k.reaches_surface):  # overgrown: ends inside
        l, t = k.height(np.array([k.end_mm])), k.azimuth(np.array([k.end_mm]))
        assert k.end_mm < log.base_radius(l, t)[0] - 1.0


def test_knot_description_in_the_log_frame(log):
    gk = log.knots[0]
    # at the pith the knot centre is on the centreline, at its start height
    c0 = gk.centerline(np.array([0.0]))[0]
    np.testing.assert_allclose(c0, log.centreline_points(np.array([gk.start_height_mm]))[0], atol=1e-9)
    # at distance rho it is rho away from the centreline at its own height
    rho = np.array([30.0, 60.0])
    c = gk.centerline(rho)
    axis = log.centreline_points(c[:, 2])
    np.testing.assert_allclose(np.hypot(*(c - axis)[:, :2].T), rho, rtol=1e-12)
    np.testing.assert_allclose(gk.vertical_radius(rho), gk.knot.params.gamma * gk.radius(rho))


def test_outer_radius_interpolates_the_heightmap(log):
    l_ax, t_ax = log.axes
    np.testing.assert_allclose(log.outer_radius(l_ax[[3, 50]], t_ax[[7, 359]]), log.heightmap_mm[[3, 50], [7, 359]])
    # the azimuth wraps: halfway between the last column and the first
    mid = log.outer_radius(l_ax[[10]], np.array([t_ax[-1] + np.pi / 360]))
    assert mid[0] == pytest.approx(0.5 * (log.heightmap_mm[10, -1] + log.heightmap_mm[10, 0]))
    with pytest.raises(WoodcamError, match="detail must be 'full' or 'base'"):
        log.outer_radius([0.0], [0.0], detail="smooth")


def test_knots_in_a_whorl_are_alike_and_whorls_differ():
    logs = [generate_log(s, length_mm=4000.0, heightmap_shape=(50, 32)) for s in range(3)]
    within, between = [], []
    for g in logs:
        w = np.array([k.whorl for k in g.knots])
        x = np.log([k.knot.params.r_max_mm for k in g.knots])
        means = [x[w == i].mean() for i in np.unique(w) if (w == i).sum() >= 2]
        within += [x[w == i].var() for i in np.unique(w) if (w == i).sum() >= 2]
        between.append(np.var(means))
    assert np.mean(within) < np.mean(between)


def test_compound_gaussian_levels_have_their_spread():
    cg = CompoundGaussian(np.zeros(2), np.array([0.0, 0.0]), np.array([2.0, 0.0]), np.array([0.1, 1.0]),
                          np.eye(2), sd_knot_logsd=0.0)
    rng = np.random.default_rng(0)
    mu, sig = cg.sample_log(rng)
    np.testing.assert_array_equal(mu, 0.0)
    whorls = np.array([cg.sample_whorl(rng, mu) for _ in range(4000)])
    assert whorls[:, 0].std() == pytest.approx(2.0, rel=0.05) and np.all(whorls[:, 1] == 0)
    knots = cg.sample_knots(rng, np.array([5.0, 5.0]), sig, 4000)
    np.testing.assert_allclose(knots.std(0), [0.1, 1.0], rtol=0.05)


def test_knot_stats_from_fits_recovers_within_and_between_spread():
    rng = np.random.default_rng(1)
    base = np.array([0.0, 0.0, 1.0, 30.0, 0.5, 0.4, 9.0, 0.5, 0.5])
    rows, whorls = [], []
    for w in range(300):
        shift = rng.normal(0, 0.4)   # whorl-to-whorl SD of log r_max
        for _ in range(4):
            p = base.copy()
            p[6] = 9.0 * np.exp(shift + rng.normal(0, 0.1))  # within-whorl SD 0.1
            rows.append(p)
            whorls.append(w)
    cg = knot_stats_from_fits(np.array(rows), np.array(whorls))
    assert cg.sd_knot[5] == pytest.approx(0.1, rel=0.1)
    assert cg.sd_whorl[5] == pytest.approx(0.4, rel=0.1)


def test_group_whorls_splits_at_gaps():
    np.testing.assert_array_equal(group_whorls([350, 10, 341, 30, 600]), [1, 0, 1, 0, 2])


def test_bad_length_is_refused():
    with pytest.raises(WoodcamError, match="length_mm must be a number > 100"):
        generate_log(0, length_mm=10.0)


@pytest.mark.bench
def test_bench_generate_4m_log(benchmark):
    """Generation of a 4 m log with ~100 knots (target < 2 s), reported beside a baseline.

    Baseline: one forward+inverse FFT of the same 801 x 360 heightmap, the cheapest thing the
    generator must do anyway; the ratio is the figure to compare across machines. The CPU
    ratio (best of three each, the machine is shared) is asserted below
    :data:`MAX_GENERATE_OVER_FFT`.
    """
    heightmap = np.random.default_rng(0).standard_normal((801, 360))

    def fft():
        np.fft.irfft2(np.fft.rfft2(heightmap), s=(801, 360))

    def cpu_best(fn, repeats=3):
        fn()  # warm-up
        best = np.inf
        for _ in range(repeats):
            c = time.process_time()
            fn()
            best = min(best, time.process_time() - c)
        return best

    t0 = time.perf_counter()
    for _ in range(5):
        fft()
    base = (time.perf_counter() - t0) / 5
    log = benchmark(generate_log, 3)
    benchmark.extra_info["n_knots"] = len(log.knots)
    benchmark.extra_info["baseline_fft_s"] = base
    benchmark.extra_info["ratio_to_baseline"] = benchmark.stats.stats.mean / base
    assert 60 <= len(log.knots) <= 160
    # Both sides allocate multi-MB arrays, which glibc maps fresh (page faults) until a larger
    # mapped block has been freed: the FFT took 0.008 CPU-s in a fresh process and 0.0045 after
    # other tests. Freeing a 16 MB block first measures both in that steady state.
    np.ones(2_000_000).sum()
    gen_cpu, fft_cpu = cpu_best(lambda: generate_log(3)), cpu_best(fft, 5)
    ratio = gen_cpu / fft_cpu
    print(f"\ngenerate_log 4 m: {gen_cpu:.3f} CPU-s, FFT baseline {fft_cpu:.4f} CPU-s, ratio (CPU) "
          f"{ratio:.1f} (bar {MAX_GENERATE_OVER_FFT})")
    assert ratio < MAX_GENERATE_OVER_FFT, (
        f"generate_log costs {ratio:.1f}x the CPU time of the heightmap's FFT; bar "
        f"{MAX_GENERATE_OVER_FFT} (measured 16.3-17.7, times 1.5)")


#: Bar on CPU(generate_log, 4 m) / CPU(one rfft2 + irfft2 of its 801 x 360 heightmap). The
#: target (< 2 s) is ~400x the FFT's ~0.005 CPU-s, too loose to notice a generator twice as slow;
#: measured 16.3-17.7 in five runs on the shared 2-core machine (Dec 2026), times a 1.5x margin.
MAX_GENERATE_OVER_FFT = 26.5
