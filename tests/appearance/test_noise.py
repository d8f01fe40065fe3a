"""Solid value noise: range, lattice values, smoothness, determinism."""

import numpy as np

from woodcam.appearance.noise import _PX, _PY, _PZ, _TABLE, grain_noise, value_noise


def test_range_and_lattice_values(rng):
    q = rng.uniform(-50, 50, (100_000, 3))
    v = value_noise(q)
    assert v.dtype == np.float32 and v.min() >= -1 and v.max() <= 1 and v.std() > 0.2
    # At lattice points the noise is the hashed table value itself.
    i = rng.integers(-20, 20, (100, 3))
    h = (i[:, 0] * _PX) ^ (i[:, 1] * _PY) ^ (i[:, 2] * _PZ)
    np.testing.assert_array_equal(value_noise(i.astype(float)), _TABLE[h & (len(_TABLE) - 1)])


def test_continuous_across_cells(rng):
    q = rng.uniform(-5, 5, (10_000, 3))
    d = np.abs(value_noise(q) - value_noise(q + 1e-4)).max()
    assert d < 1e-3  # smoothstep weights: Lipschitz ~ 1.5 * 2 per unit per axis


def test_seed_changes_noise_and_is_deterministic(rng):
    q = rng.uniform(-5, 5, (1000, 3))
    np.testing.assert_array_equal(value_noise(q, 3), value_noise(q, 3))
    assert np.abs(value_noise(q, 3) - value_noise(q, 4)).mean() > 0.1


def test_grain_noise_stretched_along_grain():
    t = np.linspace(0, 10, 2001)
    g = np.tile([0, 0, 1.0], (len(t), 1))
    along = grain_noise(np.stack([0 * t, 0 * t, t], 1), g, 0.2, 5.0)
    across = grain_noise(np.stack([t, 0 * t, 0 * t], 1), g, 0.2, 5.0)
    assert np.abs(np.diff(across)).mean() > 10 * np.abs(np.diff(along)).mean()
