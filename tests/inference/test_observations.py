"""Ring-map observations: one-pixel ring lines, blobs dropped, touching rings kept apart."""

import numpy as np

from woodcam.block import Block, Face
from woodcam.frames import FACES
from woodcam.inference.observations import gather_observations

RING_COLS = (20, 50, 80, 110, 118, 170)


def _map() -> np.ndarray:
    """200 x 200 px (0.25 mm) front-face ring map: six vertical rings 4 px wide at
    :data:`RING_COLS`, a 40 px blob over rings 50 and 80 (where a U-Net is unsure, as on H11's
    face A) and a 3 px bridge where rings 110 and 118 (2 mm apart) touch."""
    m = np.zeros((200, 200), np.float32)
    for c in RING_COLS:
        m[:, c - 2:c + 2] = 1.0
    m[150:190, 42:88] = 1.0      # blob spanning two rings
    m[49:52, 110:119] = 1.0      # bridge joining two close rings
    return m


def test_ring_map_groups_are_one_ring_each():
    block = Block((50.0, 50.0, 50.0), {"front": Face("front", (200, 200), ring_map=_map())})
    obs = gather_observations(block)
    assert set(np.unique(obs.face)) == {FACES.index("front")}
    col = obs.points_mm[:, 0] / 0.25  # front face: block x = column * pixel
    for g in range(obs.n_groups):
        c = col[obs.group == g]
        # a group is one ring: all its points on one ring line (old blob components took in
        # the blob and the bridge, so two rings were one group, one year, to the fit)
        assert np.ptp(c) < 3.0, (g, c.min(), c.max())
        assert np.min(np.abs(np.subtract.outer(RING_COLS, np.median(c)))) < 1.5
    # the rings are lines thinned to one pixel, sampled about every 0.25 mm along them
    assert np.all(np.min(np.abs(np.subtract.outer(col, RING_COLS)), axis=1) <= 1.5)
    per_mm = len(obs.points_mm) / (len(RING_COLS) * 50.0)
    assert 2.5 < per_mm < 4.5, per_mm
    # every ring is still seen (the blob's rows are dropped, the rest of rings 50 and 80 kept)
    seen = {c for c in RING_COLS if np.any(np.abs(col - c) <= 1.5)}
    assert seen == set(RING_COLS)
