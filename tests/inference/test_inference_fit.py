"""Fitting growth fields to synthetic eq. 7-9 blocks (seed 000) with known truth."""

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.block import Block, Face, RingTrace
from woodcam.errors import WoodcamError
from woodcam.fields import GridField
from woodcam.inference import (
    DEFAULT_PLANES, bake, evaluate_fit, fit_block, gather_observations,
)
from woodcam.inference.radial import RadialField, fit_radial, number_rings
from woodcam.inference.rbf import fit_rbf

# Accuracy bars for one clean block, all six faces, on three cut planes at 0.2 mm pixels.
# The benchmark (8 blocks x 7 planes) measures 99.9 % / 100 %; 97 / 99.5 % is the target.
FULL_BAR_1MM, FULL_BAR_2MM = 97.0, 99.5
PLANES = DEFAULT_PLANES[:2] + DEFAULT_PLANES[-1:]


@pytest.fixture(scope="module")
def field():
    return random_field(np.random.default_rng(101))


@pytest.fixture(scope="module")
def labelled_fit(field):
    block = make_block(field, px_per_mm=4, rng=np.random.default_rng(0))
    return block, fit_block(block, "radial")


def _interior(n=3000, seed=0):
    return np.random.default_rng(seed).uniform(2, 48, (n, 3))


def test_radial_recovers_eq79_field(field, labelled_fit):
    block, fit = labelled_fit
    assert isinstance(fit, GridField)
    summary, scores = evaluate_fit(field, fit, block.size_mm, planes=PLANES, pixel_mm=0.2)
    assert summary["matched_1"] >= FULL_BAR_1MM
    assert summary["matched_2"] >= FULL_BAR_2MM
    assert summary["coverage_1"] >= FULL_BAR_1MM  # it draws the true rings, not just a few
    # growth time itself: within 0.1 year at 99 % of interior points
    err = np.abs(fit(_interior()) - field(_interior()))
    assert np.percentile(err, 99) < 0.1


def test_unlabelled_traces_give_the_same_rings_up_to_age_offset(field, labelled_fit):
    block = make_block(field, px_per_mm=4, rng=np.random.default_rng(0), labelled=False)
    unl = fit_block(block, "radial")
    diff = unl(_interior()) - labelled_fit[1](_interior())
    offset = np.round(np.median(diff))
    assert np.percentile(np.abs(diff - offset), 99) < 0.1


def test_ring_maps_give_the_same_rings_up_to_age_offset(field, labelled_fit):
    block = make_block(field, px_per_mm=4, rng=np.random.default_rng(0), labelled=False,
                       traces=False, ring_map=True)
    assert all(f.ring_map is not None and not f.traces for f in block.faces.values())
    unl = fit_block(block, "radial")
    diff = unl(_interior()) - labelled_fit[1](_interior())
    offset = np.round(np.median(diff))
    assert np.percentile(np.abs(diff - offset), 99) < 0.1


def test_mislabelled_and_noisy_traces_are_tolerated(field):
    rng = np.random.default_rng(3)
    block = make_block(field, px_per_mm=4, rng=rng, jitter_mm=0.3, missing=0.2, n_mislabelled=3)
    fit = fit_block(block, "radial")
    err = np.abs(fit(_interior()) - field(_interior()))
    assert np.percentile(err, 95) < 0.2


def test_rbf_baseline_interpolates_labelled_points(field, labelled_fit):
    block = labelled_fit[0]
    raw = fit_block(block, "rbf", baked=False)
    obs = gather_observations(block)
    i = np.arange(0, len(obs.points_mm), 97)
    # thin-plate interpolation passes through its (subsampled) data; nearby points within 0.05 y
    assert np.median(np.abs(raw(obs.points_mm[i]) - obs.years[i])) < 0.05
    unl = make_block(field, px_per_mm=2, labelled=False)
    with pytest.raises(WoodcamError, match="needs year-labelled traces"):
        fit_rbf(gather_observations(unl))
    # fit_block numbers unlabelled rings with the radial fit first: same rings as the truth
    summary, _ = evaluate_fit(field, fit_block(unl, "rbf"), unl.size_mm, planes=PLANES, pixel_mm=0.2)
    assert summary["unmatched_2"] >= 90


def test_partial_annotation_uses_only_the_given_faces(field):
    block = make_block(field, px_per_mm=3, rng=np.random.default_rng(0))
    obs = gather_observations(block, ["front", "B", "left"])
    assert set(np.unique(obs.face)) == {0, 1, 2}  # front, top, left in FACES order
    fit = fit_block(block, "radial", faces=["front", "top", "left"])
    err = np.abs(fit(_interior()) - field(_interior()))
    # three faces leave the far side to extrapolation: 0.3 year is ~1.3 mm on its 4.4 mm rings
    assert np.percentile(err, 90) < 0.3


def test_number_rings_picks_the_fundamental_not_a_harmonic():
    rng = np.random.default_rng(0)
    levels = 3.0 * rng.integers(0, 12, 40) + 0.7 + rng.normal(0, 0.05, 40)
    # a spacing estimate 30 % off still brackets the true 1/3 ring per unit, and 2/3 (every
    # ring on an even year) aligns just as well: the smallest k must win.
    for spacing in (2.3, 3.0, 4.0):
        k, a = number_rings(levels, np.ones(40), spacing)
        assert k == pytest.approx(1 / 3, rel=0.01)
        years = k * levels + a
        assert np.max(np.abs(years - np.round(years))) < 0.05


def test_bad_inputs_give_clear_errors(field):
    empty = Block((50, 50, 50), {"front": Face("front", (100, 100))})
    with pytest.raises(WoodcamError, match="no ring traces or ring-map rings"):
        fit_block(empty, "radial")
    one = make_block(field, px_per_mm=2, faces=("front", "top"))
    with pytest.raises(WoodcamError, match="face must be one of"):
        fit_block(one, "radial", faces=["front", "side"])
    with pytest.raises(WoodcamError, match=r"faces \['left'\] are not on block"):
        fit_block(one, "radial", faces=["left"])
    with pytest.raises(WoodcamError, match="method must be one of evidence, rbf, radial"):
        fit_block(one, "magic")
    for seed in (-1, 1.5, True):
        with pytest.raises(WoodcamError, match="seed must be an integer >= 0"):
            fit_block(one, "evidence", seed=seed)
    squashed = Block((50, 50, 50), {"front": Face("front", (100, 50), traces=[
        RingTrace(np.array([[10.0, 5.0], [90.0, 40.0]]), 3)])})
    with pytest.raises(WoodcamError, match="not square; check size_mm"):
        fit_block(squashed, "radial")
    rings = make_block(field, px_per_mm=2, labelled=False, faces=("front",))
    rings.faces["front"].traces = rings.faces["front"].traces[:1]
    with pytest.raises(WoodcamError, match="at least two rings on one face"):
        fit_block(rings, "radial")


def test_baked_field_round_trip(tmp_path, field):
    baked = bake(field, (50, 50, 50))
    p = _interior(2000)
    # cubic splines on a 1 mm grid: away from the pith cone the growth time is reproduced
    assert np.percentile(np.abs(baked(p) - field(p)), 95) < 0.01
    path = baked.save(tmp_path / "f.npz")
    again = GridField.load(path)
    assert np.array_equal(again(p), baked(p))
    (tmp_path / "bad.npz").write_bytes(b"nope")
    with pytest.raises(WoodcamError, match="not a woodcam grid field"):
        GridField.load(tmp_path / "bad.npz")


def test_radial_field_state_round_trip(labelled_fit):
    import json

    from woodcam.inference import RadialField, fit_radial

    obs = gather_observations(labelled_fit[0])
    f = fit_radial(obs, labelled_fit[0].size_mm)
    g = RadialField.from_dict(json.loads(json.dumps(f.to_dict())))
    p = _interior(500)
    assert np.array_equal(g(p), f(p))


class _WidthHistoryField:
    """An eq. 7-9 field whose years are warped by a growth history: every year a different ring
    width, the same all around the stem (h(t) = t + 0.3 sin(1.3 t), monotone)."""

    def __init__(self, base):
        self.base = base

    def __call__(self, points_mm):
        t = self.base(points_mm)
        return t + 0.3 * np.sin(1.3 * t)


def test_growth_history_follows_year_to_year_ring_widths(field):
    truth = _WidthHistoryField(field)
    block = make_block(truth, px_per_mm=4, rng=np.random.default_rng(0))
    obs = gather_observations(block)
    p = _interior()
    with_h = fit_radial(obs, block.size_mm)
    without = fit_radial(obs, block.size_mm, history=False)
    err_h = np.percentile(np.abs(with_h(p) - truth(p)), 90)
    err_0 = np.percentile(np.abs(without(p) - truth(p)), 90)
    # The warp is in the model: 90 % of interior points within 0.12 year (measured 0.05-0.10 on
    # three fields); the plain radial model cannot follow the widths (measured 0.32-0.54 year).
    assert err_h < 0.12 and err_0 > 2 * err_h, (err_h, err_0)
    assert np.all(np.diff(with_h.history_levels) > 0)
    # the history survives the JSON state
    again = RadialField.from_dict(with_h.to_dict())
    assert np.allclose(again(p), with_h(p))
