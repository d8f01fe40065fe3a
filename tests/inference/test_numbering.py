"""Numbering unlabelled rings by a pith basin that counts them consistently (issue 12: the
bistable real-block fits, where a wrong axis basin numbered H11's rings 2-3 years apart or
merged neighbours into one year)."""

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.inference import gather_observations
from woodcam.inference.observations import RingObservations
from woodcam.inference.radial import (RadialField, _by_numbering, _initial_numbering,
                                      step_consistency)


@pytest.fixture(scope="module")
def truth_and_obs():
    field = random_field(np.random.default_rng(101))
    block = make_block(field, px_per_mm=4, rng=np.random.default_rng(0), labelled=False,
                       traces=False, ring_map=True)
    return field, gather_observations(block)


def _numbered(obs, years_per_point):
    return RingObservations(obs.points_mm, np.asarray(years_per_point, float), obs.group, obs.face)


def test_step_consistency_counts_neighbour_rings_one_year_apart(truth_and_obs):
    field, obs = truth_and_obs
    true_years = np.round(field(obs.points_mm))  # ring maps are the integer iso-lines
    assert step_consistency(_numbered(obs, true_years)) > 0.9
    # rings counted twice (a numbering from a wrong, steep axis): no neighbour one year apart
    assert step_consistency(_numbered(obs, 2 * true_years)) < 0.05
    # neighbours merged pairwise into one year: about half the steps are 0
    assert step_consistency(_numbered(obs, np.floor(true_years / 2))) < 0.65


def test_a_planted_wrong_basin_loses_the_numbering(truth_and_obs):
    """The lowest-cost basin is planted wrong (a pith axis across the true one): its numbering
    of the ring maps is inconsistent on the faces, so the consistent basin numbers the rings."""
    field, obs = truth_and_obs
    # the true field as a basin's shape fit, whose levels are in mm (rho * s with s ~ 1 ring/mm)
    good = (lambda p: field(p) * field.w, None, None)
    d = np.cross(field.axis, [0.3, 0.5, 0.8])
    wrong = RadialField(np.array([25.0, 25.0, 25.0]), d / np.linalg.norm(d), 43.3, 2, 1,
                        np.zeros(10), 0.0)
    wrong.coef[0] = 1.0  # rings per mm: concentric about the wrong axis
    assert step_consistency(_initial_numbering(obs, wrong)[0]) < 0.6
    order, num = _by_numbering(obs, [(wrong, None, None), good])
    assert order[0] is good
    # the chosen basin's numbering comes back with it (not computed twice)
    assert np.array_equal(num[0].years, _initial_numbering(obs, good[0])[0].years)
    # a consistent lowest-cost basin keeps its place (the in-sample cost breaks near-ties)
    assert _by_numbering(obs, [good, (wrong, None, None)])[0][0] is good


def test_a_wrong_ring_scale_is_replaced_by_a_consistent_one(truth_and_obs, monkeypatch):
    """The alignment's ring scale is planted wrong (twice the rings: every other integer a
    ring that is not there); the other alignment peaks are tried and the one numbering
    neighbouring rings one year apart wins."""
    import woodcam.inference.radial as radial

    field, obs = truth_and_obs
    shape = lambda p: field(p) * field.w  # noqa: E731  (levels in mm, as a basin's shape fit)
    right, k, _, _ = _initial_numbering(obs, shape)
    assert step_consistency(right) > 0.9
    honest = radial.number_rings
    monkeypatch.setattr(radial, "number_rings", lambda *a: (2 * honest(*a)[0], honest(*a)[1]))
    num, k2, _, _ = _initial_numbering(obs, shape)
    assert abs(k2 - k) < 0.05 * k
    assert step_consistency(num) > 0.9
    # and with no other peak to try, the planted scale would have stood
    monkeypatch.setattr(radial, "_alignment_peaks", lambda *a: [])
    assert step_consistency(_initial_numbering(obs, shape)[0]) < 0.1


@pytest.mark.slow
def test_h11_folds_number_neighbouring_rings_one_year_apart(shared_data):
    """H11 from its ring maps, the right face held out: the lowest-cost pith basin merged
    neighbouring rings into one year (93 % of steps 0, the fold's rings numbered 0-4 across a
    face showing 10), and every hypothesis was fitted to those numbers. The numbering now
    comes from a basin whose neighbouring rings are one year apart."""
    from woodcam.block.io import read_mokume
    from woodcam.inference.radial import fit_radial_hypotheses

    b = read_mokume(shared_data / "mokume" / "H11")
    obs = gather_observations(b, [f for f in b.faces if f != "right"])
    _, numbered = fit_radial_hypotheses(obs, b.size_mm)
    assert step_consistency(numbered) > 0.5
    spans = [np.ptp(numbered.years[numbered.face == f]) for f in np.unique(numbered.face)]
    assert min(spans) >= 3 and np.median(spans) >= 6, spans  # the maps show 4-14 rings a face


def test_a_pith_search_that_finds_no_consistent_numbering_is_repeated_on_other_subsets(truth_and_obs, monkeypatch):
    """The search's point subset of one seed finds only a wrong basin (planted: its numbering
    has fewer than NUMBERING_MIN_STEP of the neighbouring rings one year apart); the search is
    repeated with the next seed and the consistent basin found there numbers the rings. A
    search that finds a consistent basin is not repeated."""
    import woodcam.inference.radial as radial
    from woodcam.tolerances import NUMBERING_MIN_STEP

    field, obs = truth_and_obs
    good = (lambda p: field(p) * field.w, None, None)
    good[0].pith_mm, good[0].axis = np.full(3, 25.0), np.asarray(field.axis)  # what a basin carries
    d = np.cross(field.axis, [1.0, 1.0, 0.0])  # across the true axis: 0.09 of the steps one year
    wrong = RadialField(np.array([25.0, 25.0, 25.0]), d / np.linalg.norm(d), 43.3, 2, 1, np.zeros(10), 0.0)
    wrong.coef[0] = 1.0
    assert step_consistency(_initial_numbering(obs, wrong)[0]) < NUMBERING_MIN_STEP
    calls = []

    def search(obs_, size, K, M, ridge, seed=0, n_basins=0, workers=1, **kw):
        calls.append(seed)
        return [(wrong, None, None)] if seed == 7 else [good]

    monkeypatch.setattr(radial, "fit_axis_and_shape", search)
    order, num = radial._numbered_basins(obs, (50.0, 50.0, 50.0), 12, 1, 1e-8, 7, 3)
    assert calls == [7, 8] and order[0] is good and step_consistency(num[0]) > 0.9
    calls.clear()
    assert radial._numbered_basins(obs, (50.0, 50.0, 50.0), 12, 1, 1e-8, 8, 3)[0][0] is good and calls == [8]
    # without the repeated search the wrong basin would have numbered the rings
    monkeypatch.setattr(radial, "NUMBERING_RESEARCHES", 0)
    calls.clear()
    order, _ = radial._numbered_basins(obs, (50.0, 50.0, 50.0), 12, 1, 1e-8, 7, 3)
    assert calls == [7] and [f[0] for f in order] == [wrong]


@pytest.mark.slow
def test_h11_numbering_does_not_hang_on_one_unlucky_subset(shared_data):
    """H11 from all six ring maps with the evidence seed 2: its pith search's point subset found
    one basin, numbering 0.28 of the neighbouring rings one year apart (seeds 0, 1, 3-5:
    0.67-0.73), and the evidence fit on those numbers reproduced 14 % of the maps' own ridge
    pixels within 2 px (other seeds 75-77 %). The search is repeated on other subsets."""
    from woodcam.block.io import read_mokume
    from woodcam.inference.radial import fit_radial_hypotheses

    b = read_mokume(shared_data / "mokume" / "H11")
    _, numbered = fit_radial_hypotheses(gather_observations(b), b.size_mm, seed=2)
    assert step_consistency(numbered) > 0.6
