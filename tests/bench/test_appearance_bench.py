"""Benchmark: colour lookup throughput (texels/s) of the colour-map appearance.

Run with ``make bench`` (or ``pytest -m bench -s``). Reported as points/s and as a ratio
against a baseline measured in the same run: evaluating the growth field alone, which every
appearance must do at least once per texel.
"""

import time

import numpy as np
import pytest

from woodcam.stock import open_stock

pytestmark = pytest.mark.bench


def _rate(fn, n, repeats=3):
    fn()  # warm-up: JIT compile and caches
    best = min(_timed(fn) for _ in range(repeats))
    return n / best


def _timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


@pytest.mark.parametrize("threads", [1, 2])
def test_colour_lookup_throughput(threads):
    stock = open_stock("builtin:flat-sawn")
    rng = np.random.default_rng(0)
    n = 2_000_000
    p = rng.uniform(0, 1, (n, 3)) * stock.size_mm
    normals = rng.normal(size=p.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    stock.wood.threads = threads
    colour = _rate(lambda: stock.wood.color(p, normals), n)
    field = _rate(lambda: stock.wood.field(p), n)
    print(f"\ncolour lookup, {threads} thread(s): {colour / 1e6:.2f} M texels/s; "
          f"field alone {field / 1e6:.2f} M points/s; colour/field ratio {colour / field:.2f}")
    assert colour > 0
