"""The small learned ring detector: spec round trip, a tiny training run, the committed weights."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from woodcam.detect.learned import MODELS_DIR, SPEC_NAME, WEIGHTS_NAME, RingNetSpec
from woodcam.errors import WoodcamError

pytest.importorskip("torch", reason="the learned ring detector needs torch (pip install 'woodcam[learn]')")


def test_spec_round_trip_and_unknown_keys(tmp_path):
    spec = RingNetSpec(seed=3, steps=7)
    spec.save(tmp_path / "s.json")
    assert RingNetSpec.load(tmp_path / "s.json") == spec
    (tmp_path / "bad.json").write_text('{"seed": 1, "depth": 9}')
    with pytest.raises(WoodcamError, match="unknown keys"):
        RingNetSpec.load(tmp_path / "bad.json")


@pytest.mark.slow
def test_tiny_training_run_is_reproducible(tmp_path):
    from woodcam.detect.learned import ring_probability, train_ring_net
    from woodcam.synth import ring_training_faces

    spec = replace(RingNetSpec(), n_blocks=1, face_px=64, crop_px=32, batch=2, steps=3, log_every=1, width=4)
    x, y = ring_training_faces(spec)
    assert x.shape == y.shape == (6, 64, 64) and 0 < y.mean() < 0.5
    r1 = train_ring_net(spec, x, y, tmp_path / "a", progress=False)
    r2 = train_ring_net(spec, x, y, tmp_path / "b", progress=False)
    assert r1["steps"] == 3 and r1["final_loss"] == pytest.approx(r2["final_loss"], rel=1e-5)
    for name in (SPEC_NAME, WEIGHTS_NAME, "rings_train_log.csv"):
        assert (tmp_path / "a" / name).is_file()
    p = ring_probability(np.full((40, 44, 3), 128, np.uint8), models_dir=tmp_path / "a")
    assert p.shape == (40, 44) and np.all((p >= 0) & (p <= 1))


def test_committed_weights_are_small_and_find_lines():
    from woodcam.detect import ridge_scores
    from woodcam.detect.learned import detect_rings_learned

    from .test_detect_rings import _line_face

    path = MODELS_DIR / WEIGHTS_NAME
    if not path.is_file():
        pytest.skip("no committed ring net (woodcam train rings --out woodcam/models)")
    assert path.stat().st_size <= 2_000_000
    photo, truth = _line_face(spacing=16.0, width=2.5)
    det = detect_rings_learned(photo)
    assert ridge_scores(det.points_px, truth, thresholds=(3.0,)).f[3.0] >= 0.8


def test_missing_weights_are_named(tmp_path):
    from woodcam.detect.learned import load_ring_net

    with pytest.raises(WoodcamError, match="woodcam train rings"):
        load_ring_net(tmp_path)


@pytest.mark.slow
def test_committed_net_on_heldout_synthetic_faces():
    """Measured (README): F within 2 px 0.99 on the 48 faces of seeds 1000-1007."""
    from woodcam.detect.evaluate import EVAL_SEEDS, score_synthetic, summary
    from woodcam.detect.learned import detect_rings_learned
    from woodcam.synth import ring_eval_faces

    if not (MODELS_DIR / WEIGHTS_NAME).is_file():
        pytest.skip("no committed ring net (woodcam train rings --out woodcam/models)")
    faces = [f for s in EVAL_SEEDS[:2] for f in ring_eval_faces(s)]
    s = summary(score_synthetic(faces, detector=lambda p, ppm: detect_rings_learned(p, px_per_mm=ppm)))
    assert s["F@2"] >= 0.95 and s["chance F@2"] < 0.2, s
