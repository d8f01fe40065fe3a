"""Ring-map observations: one-pixel ring lines, blobs dropped, touching rings kept apart."""

import numpy as np

from woodcam.block import Block, Face, RingTrace
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


def test_unlabelled_pieces_of_one_ring_are_one_group():
    """Traces sharing a ``ring`` id on a face (the detector's pieces of one ring) are one group,
    so the fitter gives them one growth time; other traces, labelled ones and the same id on
    another face stay apart."""
    col = np.linspace(0, 40, 41)

    def piece(row, c0, c1, year=None, ring=None):
        c = col[(col >= c0) & (col <= c1)]
        return RingTrace(np.stack([np.full(len(c), float(row)), c], axis=1), year, ring)

    front = Face("front", (200, 200), traces=[piece(10, 0, 15, ring=0), piece(10, 25, 40, ring=0),
                                              piece(30, 0, 40, ring=1), piece(50, 0, 40)])
    top = Face("top", (200, 200), traces=[piece(10, 0, 40, ring=0), piece(30, 0, 40, ring=0)])
    obs = gather_observations(Block((50.0, 50.0, 50.0), {"front": front, "top": top}))
    fr = obs.face == FACES.index("front")
    rows = np.round(50.0 - obs.points_mm[fr, 2] / 0.25 - 0.5)       # front: block z = (h - row) * px
    groups = {int(r): set(obs.group[fr][rows == r]) for r in np.unique(rows)}
    assert [len(g) for g in groups.values()] == [1, 1, 1]           # each ring one group
    assert len(set().union(*groups.values())) == 3                  # three rings, three groups
    assert len(np.unique(obs.group[~fr])) == 1                      # id 0 on top: its own group
    assert not set(obs.group[~fr]) & set(obs.group[fr])


def test_a_few_year_labels_do_not_throw_the_other_rings_away():
    """One data-year on one stroke kept only that stroke (97 of 4664 points: a field of one
    year), without a word; now the labels are dropped when they are few, kept when they are
    most, and either is said."""
    import pytest

    from woodcam.errors import WoodcamWarning

    traces = [RingTrace(np.array([[r, 2.0], [r, 60.0]]), 5 if r == 10 else None) for r in (10, 20, 30, 40)]
    block = Block((50, 50, 50), faces={"top": Face("top", (64, 64), traces=traces)})
    with pytest.warns(WoodcamWarning, match="25 % of the ring points carry a year label .*the labels are ignored"):
        obs = gather_observations(block)
    assert len(np.unique(obs.group)) == 4 and not np.isfinite(obs.years).any()
    traces = [RingTrace(t.points_px, None if i == 0 else 5 + i) for i, t in enumerate(traces)]
    block = Block((50, 50, 50), faces={"top": Face("top", (64, 64), traces=traces)})
    with pytest.warns(WoodcamWarning, match="75 % .*only the labelled ones are fitted"):
        obs = gather_observations(block)
    assert sorted(np.unique(obs.years)) == [6.0, 7.0, 8.0]


def test_a_face_asked_for_without_rings_is_named():
    """'fit --faces top,front' with no rings on top fitted front alone without a word."""
    import pytest

    from woodcam.errors import WoodcamWarning

    traces = [RingTrace(np.array([[r, 2.0], [r, 60.0]]), None, k) for k, r in enumerate((10, 20, 30))]
    block = Block((50, 50, 50), faces={"top": Face("top", (64, 64)),
                                       "front": Face("front", (64, 64), traces=traces)})
    with pytest.warns(WoodcamWarning, match="face 'top' of block .* has no traced rings and no ring map: it is not used"):
        obs = gather_observations(block, faces=["top", "front"])
    assert set(np.unique(obs.face)) == {FACES.index("front")}
