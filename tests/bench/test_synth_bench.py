"""Benchmark: time to synthesise one block with six 512^2 faces (target < 5 s).

Run with ``pytest -m bench -s``. Reported as wall and CPU seconds, and as a ratio against a
baseline measured in the same run: evaluating the growth field at the 6 x 512^2 pixel centres,
the least any renderer must do. On a shared, oversubscribed machine the CPU time is the
figure to compare with the target; the CPU ratio is asserted (:data:`MAX_SYNTH_OVER_FIELD`),
not a time.
"""

import time

import pytest

from woodcam.fields import evaluate
from woodcam.frames import FACES, face_pixel_points
from woodcam.synth import AnalyticLogField, cut_block, synth_block

pytestmark = pytest.mark.bench

SIZE = (50.0, 50.0, 50.0)

#: Bar on CPU(synth_block) / CPU(field at the 6 x 512^2 pixel centres). The target, < 5 s, is
#: ~50x the baseline's ~0.10 CPU-s, too loose to notice a block twice as slow; so the bar is
#: the measured ratio, 7.0-7.7 in four runs on the shared 2-core machine at load ~4-5
#: (Dec 2026; synth_block 0.69-0.77 CPU-s), times a 1.5x margin. Under it the block stays
#: far inside the target.
MAX_SYNTH_OVER_FIELD = 11.5


def _best(fn, repeats=2):
    fn()  # warm-up: imports, caches
    walls, cpus = [], []
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    # each best on its own: a min over (wall, cpu) pairs took the CPU of the fastest-wall run
    return min(walls), min(cpus)


def test_synth_block_six_512_faces():
    field = cut_block(AnalyticLogField(3.0, 0.001, 0.1, lobe_amplitude=0.02), SIZE, "rift")
    full = _best(lambda: synth_block(field, SIZE, face_px=512))
    base = _best(lambda: [evaluate(field, face_pixel_points(n, (512, 512), SIZE).reshape(-1, 3)) for n in FACES])
    print(f"\nsynth_block 6 x 512^2: wall {full[0]:.2f} s, cpu {full[1]:.2f} s (target < 5 s); "
          f"field-evaluation baseline wall {base[0]:.2f} s, cpu {base[1]:.2f} s; "
          f"ratio (cpu) {full[1] / base[1]:.1f} (bar {MAX_SYNTH_OVER_FIELD})")
    assert full[1] / base[1] < MAX_SYNTH_OVER_FIELD, (
        f"synth_block costs {full[1] / base[1]:.1f}x the CPU time of evaluating the field at its "
        f"pixels; bar {MAX_SYNTH_OVER_FIELD} (measured 7.0-7.7, times 1.5)")
