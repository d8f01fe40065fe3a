"""Solid value noise: range, lattice values, smoothness, determinism."""

import numpy as np

from woodcam.appearance.noise import _PX, _PY, _PZ, TABLE, value_noise


def test_range_and_lattice_values(rng):
    q = rng.uniform(-50, 50, (100_000, 3))
    v = value_noise(q)
    assert v.dtype == np.float32 and v.min() >= -1 and v.max() <= 1 and v.std() > 0.2
    # At lattice points the noise is the hashed table value itself.
    i = rng.integers(-20, 20, (100, 3))
    h = (i[:, 0] * _PX) ^ (i[:, 1] * _PY) ^ (i[:, 2] * _PZ)
    np.testing.assert_array_equal(value_noise(i.astype(float)), TABLE[h & (len(TABLE) - 1)])


def test_continuous_across_cells(rng):
    q = rng.uniform(-5, 5, (10_000, 3))
    d = np.abs(value_noise(q) - value_noise(q + 1e-4)).max()
    assert d < 1e-3  # smoothstep weights: Lipschitz ~ 1.5 * 2 per unit per axis


def test_smooth_across_cell_faces(rng):
    """Smoothstep weights make the noise C1: on a lattice face its slope across the face is
    zero from both sides (trilinear weights leave a kink of order one there)."""
    h = 1e-3
    for k in range(3):
        q = rng.uniform(-5, 5, (2000, 3))
        q[:, k] = rng.integers(-5, 5, len(q))             # on a face normal to axis k
        step = np.eye(3)[k] * h
        right = (value_noise(q + step) - value_noise(q)) / h
        left = (value_noise(q) - value_noise(q - step)) / h
        assert np.abs(right).max() < 0.05 and np.abs(left).max() < 0.05, k
        # off the faces the slope is of order one: the check above is not vacuous
        mid = q + np.eye(3)[k] * 0.5
        assert np.abs((value_noise(mid + step) - value_noise(mid)) / h).mean() > 0.2, k


def test_seed_changes_noise_and_is_deterministic(rng):
    q = rng.uniform(-5, 5, (1000, 3))
    np.testing.assert_array_equal(value_noise(q, 3), value_noise(q, 3))
    assert np.abs(value_noise(q, 3) - value_noise(q, 4)).mean() > 0.1
