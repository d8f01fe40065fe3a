"""Throughput of the knotted-log field (benchmarks: run with ``-m bench -s``).

Reports points/s for the real 108-knot log against the stem field alone (same points, same
run) and how the cost grows with the number of knots. Ratios, not timed asserts: the CPU cost
of the knotted field over the stem's is asserted below :data:`MAX_KNOTS_OVER_STEM` and
:data:`MAX_SCALING_OVER_STEM` (CPU, not wall: the machine is shared).
"""

import time

import numpy as np
import pytest

from woodcam.fields.knots import KnottedLogField, available_backends
from woodcam.fields.skeleton import BranchStrand, simple_log

pytestmark = pytest.mark.bench

#: Bars on CPU(real 108-knot log) / CPU(stem alone), same points, per backend. No target is
#: stated: measured 6.2-6.7 (numpy) and 3.8-5.2 (numba) in four runs on the shared 2-core
#: machine at load ~5-8 (Dec 2026), times a 1.5x margin, so a knot evaluation markedly slower
#: than today (e.g. the spatial culling off, every knot tested at every point) fails.
MAX_KNOTS_OVER_STEM = {"numpy": 10.0, "numba": 7.8}
#: Bars on the same ratio for 108 real knots and 432 dense synthetic ones (the scaling test's
#: points): measured numpy 7.3-8.4 and 22.5-25.1, numba 4.3-4.7 and 11.6-13.4 (four runs),
#: times 1.5.
MAX_SCALING_OVER_STEM = {"numpy": {108: 12.6, 432: 38.0}, "numba": {108: 6.8, 432: 20.0}}


def _rate(f, p, repeat=3, cpu=False):
    """Points/s: best wall-clock of ``repeat`` runs, or with ``cpu=True`` points per CPU-second
    times 2 (what 2 uncontended cores give: the machine is shared, wall-clock under-reports)."""
    f(p[:1000])                                   # compile / warm up
    best = np.inf
    for _ in range(repeat):
        t = time.process_time() if cpu else time.perf_counter()
        f(p)
        dt = (time.process_time() - t) / 2 if cpu else time.perf_counter() - t
        best = min(best, dt)
    return len(p) / best


def _points(n, seed=0):
    rng = np.random.default_rng(seed)
    # a 100 mm block through the knottiest part of the log and a whole-log scatter
    block = rng.uniform([-20.0, 20.0, 3550.0], [80.0, 120.0, 3650.0], (n // 2, 3))
    rr = 135.0 * np.sqrt(rng.uniform(0, 1, n - n // 2))
    th = rng.uniform(0, 2 * np.pi, n - n // 2)
    whole = np.stack([rr * np.cos(th), rr * np.sin(th), rng.uniform(0, 3990, n - n // 2)], 1)
    return np.concatenate([block, whole])


@pytest.mark.parametrize("backend", available_backends())
def test_throughput_real_log(gran1, backend):
    n = 1_000_000 if backend == "numba" else 200_000
    p = _points(n)
    fs = KnottedLogField(gran1.with_knots([]), backend=backend)
    ff = KnottedLogField(gran1, backend=backend)
    stem, full = _rate(fs, p), _rate(ff, p)
    stem_cpu, full_cpu = _rate(fs, p, cpu=True), _rate(ff, p, cpu=True)
    print(f"\n[{backend}] real log, 108 knots: {full / 1e6:.2f} M points/s wall-clock "
          f"({full_cpu / 1e6:.2f} M points/s per 2 CPU-seconds); stem alone {stem / 1e6:.2f} "
          f"({stem_cpu / 1e6:.2f}); knots cost {stem / full:.1f}x the stem wall, "
          f"{stem_cpu / full_cpu:.1f}x CPU (bar {MAX_KNOTS_OVER_STEM[backend]})")
    assert stem_cpu / full_cpu < MAX_KNOTS_OVER_STEM[backend], (
        f"[{backend}] the 108-knot log costs {stem_cpu / full_cpu:.1f}x the stem's CPU time; bar "
        f"{MAX_KNOTS_OVER_STEM[backend]} (measured 3.8-6.7, times 1.5)")


@pytest.mark.parametrize("backend", available_backends())
def test_scaling_with_number_of_knots(gran1, backend):
    n = 400_000 if backend == "numba" else 100_000
    p = _points(n, seed=1)
    base = _rate(KnottedLogField(gran1.with_knots([]), backend=backend), p, cpu=True)
    rows = []
    for m in (0, 13, 27, 54, 108):
        knots = gran1.knots[::max(1, 108 // m)][:m] if m else []
        rows.append((m, _rate(KnottedLogField(gran1.with_knots(knots), backend=backend), p,
                              cpu=True)))
    # a dense synthetic log: 4 x the real knot density (432 knots on 4 m) -> per-point cost
    # follows the knots near a point, not the total
    rng = np.random.default_rng(2)
    dense = [BranchStrand.from_model(0.2, -0.05, z, 0.1, -0.2, w, 0.01, 130.0, 90.0)
             for z, w in zip(rng.uniform(0, 3990, 432), rng.uniform(0, 2 * np.pi, 432))]
    rows.append((432, _rate(KnottedLogField(simple_log(3990, 135, dense), backend=backend), p,
                            cpu=True)))
    print(f"\n[{backend}] knots -> M points/s per 2 CPU-seconds (stem alone {base / 1e6:.2f}):")
    for m, r in rows:
        print(f"  {m:4d} knots: {r / 1e6:6.2f} M points/s  ({base / r:4.1f}x stem cost)")
    bars = MAX_SCALING_OVER_STEM[backend]
    print(f"  bars: {bars}")
    for m, r in rows:
        if m in bars:
            assert base / r < bars[m], (
                f"[{backend}] {m} knots cost {base / r:.1f}x the stem's CPU time; bar {bars[m]} "
                "(measured in four runs, times 1.5)")
