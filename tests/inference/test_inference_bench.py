"""Benchmark: seed 000's Table 1 on 8 synthetic eq. 7-9 blocks, RBF baseline vs our radial fit.

Run: ``WOODCAM_BENCH_OUT=/tmp/bench python -m pytest tests/inference/test_inference_bench.py -m bench -s``
(the table and cut-plane images go to that folder, else to pytest's tmp_path).
50 mm cubes, rings 2-5 mm, seven interior cut planes each; full = six faces, partial = front,
top, left (half the surface, meeting at a corner); clean traces, and realistic ones (0.3 mm
jitter, 20 % of ~10 mm ring segments missing, 3 traces per block mislabelled by +-1 year).
"""

import os
from pathlib import Path

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam._cli_fit import PARTIAL_FACES
from woodcam.inference import benchmark

N_BLOCKS = 8
TARGETS = {  # (face set, traces): (matched 1 mm, matched 2 mm) the issue asks of our method
    ("full", "clean"): (97.0, 99.5),
    ("partial", "clean"): (90.0, 97.0),
    ("full", "realistic"): (92.0, 98.0),
}


@pytest.mark.bench
@pytest.mark.slow
@pytest.mark.parametrize("traces", ["clean", "realistic"])
def test_table1_benchmark(traces, tmp_path):
    out = Path(os.environ.get("WOODCAM_BENCH_OUT", tmp_path)) / traces
    kw = {} if traces == "clean" else dict(jitter_mm=0.3, missing=0.2, n_mislabelled=3)
    blocks = []
    for i in range(N_BLOCKS):
        rng = np.random.default_rng(100 + i)
        b = make_block(random_field(rng), rng=rng, **kw)
        b.name = f"eq79-{i}"
        blocks.append(b)
    res = benchmark(blocks, ("rbf", "radial"), {"full": None, "partial": list(PARTIAL_FACES)},
                    out_dir=out, progress=print)
    print(f"\n## {traces} traces\n\n" + res["table"])
    for label in ("full", "partial"):
        mean = res[label][-1]
        for col in ("matched_1", "matched_2", "unmatched_1", "unmatched_2"):
            assert mean["radial"][col] >= mean["rbf"][col], (label, col)
        bar = TARGETS.get((label, traces))
        if bar:
            assert mean["radial"]["matched_1"] >= bar[0], (label, traces)
            assert mean["radial"]["matched_2"] >= bar[1], (label, traces)
