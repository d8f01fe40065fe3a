"""Benchmark: the whole neural appearance stage of one block at 128^3, and its colour lookup.

Run with ``pytest -m bench -s tests/bench/test_appearance_neural_bench.py``. Reports wall and
CPU seconds of training the three networks and translating the volume (target: <= 60 s per
block on 2 cores, seed 000: ~48 min on a GPU), as a ratio against a baseline measured in the
same run: fitting the colour-map appearance of the same block. Lookup throughput is reported
against the colour map's.
"""

import time

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance, Wood
from woodcam.appearance.neural import fit_neural_appearance
from woodcam.fields.builtin import builtin_block
from woodcam.synth import synth_block

pytestmark = pytest.mark.bench


def _timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w, time.process_time() - c


@pytest.mark.parametrize("quality", ["draft", "normal"])
def test_neural_stage_time_per_block(quality):
    b = builtin_block("flat-sawn")
    block = synth_block(b.field, b.size_mm, face_px=256, seed=0)
    app, wall, cpu = _timed(lambda: fit_neural_appearance(block, b.field, resolution=128, quality=quality,
                                                          cache_dir=False, progress=False))
    cm, cm_wall, _ = _timed(lambda: ColorMapAppearance.fit_to_block(block, b.field))
    m = app.meta
    print(f"\nneural appearance ({quality}, 128^3 over {b.size_mm} mm): {wall:.1f} s wall, "
          f"{cpu:.1f} s CPU (train {m['train_s']:.1f} s: {m['net_train_s']}, apply {m['apply_s']:.1f} s, "
          f"sub-cell detail {m['detail_s']:.1f} s); "
          f"colour-map fit {cm_wall:.2f} s; ratio {wall / cm_wall:.0f}x")
    rng = np.random.default_rng(0)
    n = 1_000_000
    p = rng.uniform(0, 1, (n, 3)) * np.asarray(b.size_mm)
    normals = rng.normal(size=p.shape)
    _, t_neural, _ = _timed(lambda: Wood(b.field, app).color(p, normals))
    _, t_cm, _ = _timed(lambda: Wood(b.field, cm).color(p, normals))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    _, t_plain, _ = _timed(lambda: app.color(None, p, normals))   # trilinear only, no detail
    print(f"lookup of 1M texels: neural {t_neural:.2f} s (without sub-cell detail {t_plain:.2f} s), "
          f"colour map {t_cm:.2f} s (ratio {t_neural / t_cm:.2f})")
    assert app.volumes.volumes.shape[1:4] == (128, 102, 64)
