"""The trainers set torch's threads for their run and put the caller's setting back; they seed
their initial weights without touching the caller's torch random numbers."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")


@pytest.fixture
def three_threads():
    before = torch.get_num_threads()
    torch.set_num_threads(3)
    yield 3
    torch.set_num_threads(before)


def test_train_gtf_restores_the_callers_threads(tmp_path, three_threads):
    """train_gtf(threads=1) left torch on one thread for the rest of the process."""
    from woodcam.fields.neural import GTFSpec, train_gtf

    spec = GTFSpec(n_fields=8, points_per_field=64, latent_dim=4, hidden=16, layers=2, n_harmonics=3,
                   batch_fields=4, batch_points=16, steps=4, checkpoint_every=4, log_every=2)
    train_gtf(spec, tmp_path, progress=False, threads=1)
    assert torch.get_num_threads() == three_threads


def test_train_ring_net_restores_the_callers_threads(tmp_path, three_threads):
    from woodcam.detect.learned import RingNetSpec, train_ring_net

    rng = np.random.default_rng(0)
    x = rng.standard_normal((2, 32, 32)).astype(np.float32)
    y = (rng.uniform(size=(2, 32, 32)) < 0.2).astype(np.float32)
    train_ring_net(RingNetSpec(n_blocks=1, face_px=32, crop_px=16, batch=2, steps=2, width=2), x, y, tmp_path,
                   progress=False)
    assert torch.get_num_threads() == three_threads


def test_train_translation_restores_the_callers_threads(three_threads):
    from dataclasses import replace

    from woodcam.appearance.translation import train_translation, translation_spec

    rng = np.random.default_rng(0)
    pair = (rng.uniform(size=(2, 32, 32)).astype(np.float32), rng.uniform(size=(32, 32, 3)).astype(np.float32),
            np.ones((32, 32), bool))
    train_translation([pair], replace(translation_spec("draft", 1), patch_px=16, patches=8), progress=False,
                      threads=1)
    assert torch.get_num_threads() == three_threads


def _callers_stream_after(run) -> bool:
    """Whether the caller's torch random numbers go on from its own seed across ``run()``."""
    torch.manual_seed(123)
    expected = torch.rand(3)
    torch.manual_seed(123)
    run()
    return torch.equal(torch.rand(3), expected)


def test_trainers_leave_the_callers_torch_random_numbers(tmp_path):
    """train_ring_net and train_translation called torch.manual_seed(spec.seed): after a
    training run the caller's torch.rand gave the spec seed's stream, not its own."""
    from dataclasses import replace

    from woodcam.appearance.translation import train_translation, translation_spec
    from woodcam.detect.learned import RingNetSpec, train_ring_net

    rng = np.random.default_rng(0)
    x = rng.standard_normal((2, 32, 32)).astype(np.float32)
    y = (rng.uniform(size=(2, 32, 32)) < 0.2).astype(np.float32)
    pair = (rng.uniform(size=(2, 32, 32)).astype(np.float32), rng.uniform(size=(32, 32, 3)).astype(np.float32),
            np.ones((32, 32), bool))
    assert _callers_stream_after(lambda: train_ring_net(
        RingNetSpec(n_blocks=1, face_px=32, crop_px=16, batch=2, steps=2, width=2), x, y, tmp_path,
        progress=False))
    assert _callers_stream_after(lambda: train_translation(
        [pair], replace(translation_spec("draft", 1), patch_px=16, patches=8), progress=False, threads=1))
