"""Benchmark: the whole neural appearance stage of one block at 128^3, and its colour lookup.

Run with ``pytest -m bench -s tests/bench/test_appearance_neural_bench.py``. Reports wall and
CPU seconds of training the three networks and translating the volume (target: <= 60 s per
block on 2 cores, seed 000: ~48 min on a GPU), as a ratio against a baseline measured in the
same run: fitting the colour-map appearance of the same block. Lookup throughput is reported
against the colour map's. Both CPU ratios are asserted (:data:`MAX_FIT_OVER_COLORMAP`,
:data:`MAX_LOOKUP_OVER_COLORMAP`); CPU, not wall, because the machine is shared and load
inflates wall time.
"""

import resource
import time

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance, Wood
from woodcam.appearance.neural import fit_neural_appearance
from woodcam.fields.builtin import builtin_block
from woodcam.synth import synth_block

pytestmark = pytest.mark.bench

#: Bars on CPU(neural fit) / CPU(colour-map fit) per quality. The target, <= 60 s per block,
#: is ~3,700x the colour-map fit's ~0.015 CPU-s, too loose to notice a stage twice as slow; so
#: the bar is the measured ratio, 284-318x (draft, 4.6-4.7 CPU-s) and 459-518x (normal,
#: 6.9-8.5 CPU-s) in two to four runs on the shared 2-core machine at load ~5-8 (Dec 2026),
#: times a 1.5x margin. Under it the stage stays far inside the target.
MAX_FIT_OVER_COLORMAP = {"draft": 480, "normal": 780}
#: Bar on CPU(neural lookup of 1M texels) / CPU(colour-map lookup). No target is stated:
#: measured 5.5-7.6 (same runs), times 1.5.
MAX_LOOKUP_OVER_COLORMAP = 11.5


def _cpu_now():
    """CPU seconds so far of this process and its waited-for children."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _timed(fn):
    w, c = time.perf_counter(), _cpu_now()
    out = fn()
    return out, time.perf_counter() - w, _cpu_now() - c


def _best(fn, repeats):
    """``fn()``'s result and its best wall and best CPU seconds of ``repeats`` runs."""
    runs = [_timed(fn) for _ in range(repeats)]
    return runs[0][0], min(r[1] for r in runs), min(r[2] for r in runs)


@pytest.mark.parametrize("quality", ["draft", "normal"])
def test_neural_stage_time_per_block(quality):
    # here, not at import: collecting this file in the default (non-bench) run stays torch-free
    pytest.importorskip("torch", reason="torch (the learn extra) is not installed")
    b = builtin_block("flat-sawn")
    block = synth_block(b.field, b.size_mm, face_px=256, seed=0)
    # warm-up: the first fit in a process also compiles and initialises (numba kernels, torch's
    # first passes), ~2 CPU-s that would count against whichever quality runs first
    fit_neural_appearance(block, b.field, resolution=16, quality=quality, epochs=1, cache_dir=False,
                          progress=False)
    app, wall, cpu = _timed(lambda: fit_neural_appearance(block, b.field, resolution=128, quality=quality,
                                                          cache_dir=False, progress=False))
    # the baseline takes ~0.015 CPU-s: best of five keeps a hiccup out of the ratio
    cm, cm_wall, cm_cpu = _best(lambda: ColorMapAppearance.fit_to_block(block, b.field), 5)
    m = app.meta
    fit_ratio = cpu / cm_cpu
    print(f"\nneural appearance ({quality}, 128^3 over {b.size_mm} mm): {wall:.1f} s wall, "
          f"{cpu:.1f} s CPU (train {m['train_s']:.1f} s: {m['net_train_s']}, apply {m['apply_s']:.1f} s, "
          f"sub-cell detail {m['detail_s']:.1f} s); "
          f"colour-map fit {cm_wall:.3f} s wall, {cm_cpu:.3f} s CPU; ratio (CPU) {fit_ratio:.0f}x "
          f"(bar {MAX_FIT_OVER_COLORMAP[quality]})")
    rng = np.random.default_rng(0)
    n = 1_000_000
    p = rng.uniform(0, 1, (n, 3)) * np.asarray(b.size_mm)
    normals = rng.normal(size=p.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    # warm-up: a process's first lookup pays one-off set-up the colour map's best of two does
    # not (its second run is warm); then the best of two, as the colour map's
    Wood(b.field, app).color(p[:10_000], normals[:10_000])
    _, t_neural, c_neural = _best(lambda: Wood(b.field, app).color(p, normals), 2)
    _, t_cm, c_cm = _best(lambda: Wood(b.field, cm).color(p, normals), 2)
    _, t_plain, c_plain = _best(lambda: app.color(None, p, normals), 1)   # trilinear only, no detail
    look_ratio = c_neural / c_cm
    print(f"lookup of 1M texels: neural {t_neural:.2f} s wall, {c_neural:.2f} s CPU (without "
          f"sub-cell detail {t_plain:.2f} s, {c_plain:.2f} s CPU), colour map {t_cm:.2f} s wall, "
          f"{c_cm:.2f} s CPU (ratio (CPU) {look_ratio:.2f}, bar {MAX_LOOKUP_OVER_COLORMAP})")
    assert app.volumes.volumes.shape[1:4] == (128, 102, 64)
    assert fit_ratio < MAX_FIT_OVER_COLORMAP[quality], (
        f"the neural stage ({quality}) costs {fit_ratio:.0f}x the CPU time of the colour-map fit; "
        f"bar {MAX_FIT_OVER_COLORMAP[quality]} (measured 284-518, times 1.5)")
    assert look_ratio < MAX_LOOKUP_OVER_COLORMAP, (
        f"the neural lookup costs {look_ratio:.2f}x the CPU time of the colour map's; bar "
        f"{MAX_LOOKUP_OVER_COLORMAP} (measured 5.5-7.6, times 1.5)")
