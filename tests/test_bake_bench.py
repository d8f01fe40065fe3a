"""Benchmarks of the bake (``pytest -m bench -s tests/test_bake_bench.py``); no timed asserts
(the bake's CPU ratio to xatlas' charting in the same run is asserted, :data:`MIN_XATLAS_OVER_AUTO`).

Figures printed:
* colour lookup throughput (texels/s) of a real stock's wood (``builtin:flat-sawn``: growth
  field, eq. 10 blend, knots) called as the bake calls it (``wood_colors`` in batches of
  MAX_BATCH_POINTS), and its time ratio to a plain numpy baseline (one ``np.sin`` pass over the
  same (n, 3) points) measured in the same run;
* the bake's own colour step (texel -> 3D point + normal + appearance) in texels/s;
* the bake time per step of a ~20k-triangle carved part at a ~2048^2 atlas.
Targets from the issue: >= 5 M texels/s and <= 3 s for the bake on the 2-core machine.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest
import trimesh

from woodcam.bake import bake

from test_bake import SmoothWood


def _best_of(fn, repeat=3):
    """Best wall time, best CPU time (this process, all threads) and the last result. On the
    shared 2-core machine the CPU time is the steadier figure when other jobs load it."""
    best = np.inf
    best_cpu = np.inf
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        c = time.process_time()
        out = fn()
        best = min(best, time.perf_counter() - t)
        best_cpu = min(best_cpu, time.process_time() - c)
    return best, best_cpu, out


#: Bar on CPU(bake with xatlas' own charts) / CPU(bake with woodcam's projected charts, the
#: default), same part, same run. The target (<= 3 s for the bake) is ~0.8 of the xatlas bake's
#: ~2.3-2.5 CPU-s, too loose to notice a bake twice as slow; so the bar is the measured ratio,
#: 2.52-3.02 in four runs on the shared 2-core machine at load ~5-8 (Dec 2026; the default
#: bake 0.82-0.93 CPU-s), divided by a 1.5x margin. Only a slowdown of the default's own steps
#: (its charts) moves the ratio: one in the steps both share (rasterise, colour, dilate) does not.
MIN_XATLAS_OVER_AUTO = 1.68


def _part_20k():
    """A sphere with three crossing bores: ~20k triangles, curved and carved."""
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=35.0)
    bores = []
    for axis in np.eye(3):
        c = trimesh.creation.cylinder(radius=9.0, height=100.0, sections=64)
        c.apply_transform(trimesh.geometry.align_vectors([0, 0, 1], axis))
        bores.append(c)
    part = trimesh.boolean.difference([sphere, *bores], engine="manifold")
    part.apply_translation([40.0, 40.0, 40.0])
    return part


@pytest.mark.bench
def test_color_lookup_throughput():
    """The lookup the bake's colour step makes (bake's ``paint``: ``wood_colors`` on the stock's
    Wood, batches of MAX_BATCH_POINTS), not a stand-in appearance: it timed SmoothWood, three
    sines, which says nothing of a real wood's cost. Printed as throughput and as a ratio to
    the same run's ``np.sin`` pass, no timed assert (the Wood's own bar, colour over field, is
    tests/bench/test_appearance_bench.py's)."""
    from woodcam.appearance.wood import wood_colors
    from woodcam.stock import open_stock
    from woodcam.tolerances import MAX_BATCH_POINTS

    stock = open_stock("builtin:flat-sawn")
    rng = np.random.default_rng(0)
    n = 2_000_000
    points = rng.random((n, 3)) * np.asarray(stock.size_mm)  # inside the block, as a part's texels
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)

    def lookup():
        rgb = np.empty((n, 3), np.float32)
        for s in range(0, n, MAX_BATCH_POINTS):
            rgb[s:s + MAX_BATCH_POINTS] = wood_colors(stock.wood, points[s:s + MAX_BATCH_POINTS],
                                                      normals[s:s + MAX_BATCH_POINTS])
        return rgb

    lookup()  # warm-up: numba kernels compile on first use
    t_wood, c_wood, rgb = _best_of(lookup)
    t_sin, c_sin, _ = _best_of(lambda: np.sin(points))
    assert rgb.shape == (n, 3) and rgb.min() >= 0.0 and rgb.max() <= 1.0
    # the batches are the one call's answer (the Wood batches the same points itself)
    head = slice(0, 2 * MAX_BATCH_POINTS)
    np.testing.assert_array_equal(rgb[head], stock.wood.color(points[head], normals[head]))
    print(f"\ncolour lookup ({stock.spec} Wood, as the bake calls it): {n / t_wood / 1e6:.2f} M texels/s "
          f"wall, {n / c_wood / 1e6:.2f} M texels/s CPU ({n} texels); np.sin baseline "
          f"{n / t_sin / 1e6:.1f} M points/s wall, {n / c_sin / 1e6:.1f} CPU; "
          f"lookup / baseline time ratio {t_wood / t_sin:.2f} wall, {c_wood / c_sin:.2f} CPU")


def _cpu_with_children() -> float:
    """CPU seconds of this process and its reaped children (the xatlas worker runs in one)."""
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.mark.bench
def test_bake_time_20k_triangles_2048_atlas():
    """Woodcam's projected charts (default) against xatlas' own charting (the bake before issue
    16), same part and run; CPU includes the xatlas worker process."""
    part = _part_20k()
    # density for a ~2048^2 atlas at ~0.5 fill of this part (with 8 px padding)
    tpm = float(np.sqrt(0.5 * 2048**2 / part.area))
    wood = SmoothWood()
    bake(part, wood, texels_per_mm=1.0)  # warm-up (imports, xatlas load, numba cache)
    best = {}
    for _ in range(2):
        for unwrap in ("auto", "xatlas"):
            t = time.perf_counter()
            c = _cpu_with_children()
            with warnings.catch_warnings():  # a slight overshoot rescales; reported below
                warnings.simplefilter("ignore", UserWarning)
                result = bake(part, wood, texels_per_mm=tpm, max_atlas_px=2048, unwrap=unwrap)
            run = (_cpu_with_children() - c, time.perf_counter() - t, result)
            if unwrap not in best or run[0] < best[unwrap][0]:
                best[unwrap] = run
    for unwrap, (cpu, wall, result) in best.items():
        painted = int(result.coverage_mask.sum())
        steps = ", ".join(f"{k} {v:.2f}s" for k, v in result.timings.items())
        print(f"\nbake ({unwrap}): {len(part.faces)} triangles, {result.summary()}, {painted} "
              f"painted texels; best of 2 {cpu:.2f} CPU-s, {wall:.2f} s wall ({steps}); colour "
              f"step {painted / result.timings['color'] / 1e6:.1f} M texels/s wall")
        assert max(result.atlas.shape[:2]) <= 2048
    ratio = best["xatlas"][0] / best["auto"][0]
    print(f"CPU ratio xatlas / auto: {ratio:.2f} (bar > {MIN_XATLAS_OVER_AUTO})")
    assert ratio > MIN_XATLAS_OVER_AUTO, (
        f"the default bake costs 1/{ratio:.2f} of the xatlas bake's CPU time; bar 1/"
        f"{MIN_XATLAS_OVER_AUTO} (measured 1/2.52-1/3.02, with a 1.5x margin)")
