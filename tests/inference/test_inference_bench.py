"""Benchmark: seed 000's Table 1 on synthetic blocks, RBF baseline vs the seed's neural fit vs ours.

Run: ``WOODCAM_BENCH_OUT=/tmp/bench python -m pytest tests/inference/test_inference_bench.py -m bench -s``
(the tables and cut-plane images go to that folder, else to pytest's tmp_path).
50 mm cubes, seven interior cut planes each; full = six faces, partial = front, top, left (half
the surface, meeting at a corner). Three kinds of block, 8 each:

- clean: eq. 7-9 fields (rings 2-5 mm), every ring traced exactly;
- realistic: the same fields, 0.3 mm jitter, 20 % of ~10 mm ring segments missing, 3 traces per
  block mislabelled by +-1 year;
- knotted: cut from logs of the log generator (seed 001) through the knot field (seed 003),
  rings 2-5 mm, the block's front face through a knot; clean traces of every ring, knot rings
  included, and each face's knots marked (``extras["knot_mask"]``, as on Mokume's H11), which
  the fits leave out with a 3 mm margin. The cut planes score every true ring line, knot rings
  included.
"""

import os
from pathlib import Path

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.cli.fit import PARTIAL_FACES
from woodcam.inference import benchmark

N_BLOCKS = 8
METHODS = ("rbf", "neural", "radial")
TARGETS = {  # (face set, kind): (matched 1 mm, matched 2 mm) the issue asks of our method
    ("full", "clean"): (97.0, 99.5),
    ("partial", "clean"): (90.0, 97.0),
    ("full", "realistic"): (92.0, 98.0),
    ("full", "knotted"): (80.0, 93.0),
}


def knotted_block(i: int, size_mm=(50.0, 50.0, 50.0)):
    """Block ``i`` of the knotted set: a generated log, a knot chosen at random among those that
    reach past the block's depth, the block's front face cut through it (seed 003's setting)."""
    from woodcam.fields import block_at_knot, place_block_in_log
    from woodcam.synth import knotted_log_field

    rng = np.random.default_rng(200 + i)
    log_field = knotted_log_field(rng, (2.0, 5.0), length_mm=1200.0)
    log = log_field.log
    long_enough = [k for k, kn in enumerate(log.knots)
                   if kn.r_end_mm > size_mm[1] + 15.0 and 150.0 < kn.z0_mm < 1050.0]
    k = int(rng.choice(long_enough))
    field = place_block_in_log(log_field, *block_at_knot(log, k, size_mm))
    return make_block(field, size_mm, rng=rng, knot_masks=True)


def _blocks(kind: str):
    blocks = []
    for i in range(N_BLOCKS):
        if kind == "knotted":
            b = knotted_block(i)
        else:
            rng = np.random.default_rng(100 + i)
            kw = {} if kind == "clean" else dict(jitter_mm=0.3, missing=0.2, n_mislabelled=3)
            b = make_block(random_field(rng), rng=rng, **kw)
        b.name = f"{kind}-{i}"
        blocks.append(b)
    return blocks


@pytest.mark.bench
@pytest.mark.slow
@pytest.mark.parametrize("kind", ["clean", "realistic", pytest.param("knotted", marks=pytest.mark.xfail(
    strict=True, reason="issue 5's knotted goal is not met: a knot bends the rings across the whole "
    "knot-centred block, which the straight-pith radial model cannot follow; RBF wins there "
    "(measured 68.5/79.2 % vs radial 31.2/47.1 %, six faces)"))])
def test_table1_benchmark(kind, tmp_path):
    out = Path(os.environ.get("WOODCAM_BENCH_OUT", tmp_path)) / kind
    res = benchmark(_blocks(kind), METHODS, {"full": None, "partial": list(PARTIAL_FACES)},
                    out_dir=out, progress=print)
    print(f"\n## {kind} blocks\n\n" + res["table"])
    for label in ("full", "partial"):
        mean = res[label][-1]
        for col in ("matched_1", "matched_2", "unmatched_1", "unmatched_2"):
            assert mean["radial"][col] >= mean["rbf"][col], (label, col)
        bar = TARGETS.get((label, kind))
        if bar:
            assert mean["radial"]["matched_1"] >= bar[0], (label, kind)
            assert mean["radial"]["matched_2"] >= bar[1], (label, kind)
