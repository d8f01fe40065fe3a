"""Fitting the generic neural growth field to traced rings (eq. 5 of seed 000)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from woodcam.errors import WoodcamError  # noqa: E402
from woodcam.fields.base import LogFrame  # noqa: E402
from woodcam.fields.grid import GridField  # noqa: E402
from woodcam.fields.neural import MODELS_DIR, SPEC_NAME, WEIGHTS_NAME, load_model  # noqa: E402
from woodcam.fields.radial import RadialScalingField, RadiusFunction  # noqa: E402
from woodcam.inference.neural import fit_neural, fit_neural_details  # noqa: E402
from woodcam.synth import synth_block  # noqa: E402


@pytest.fixture(autouse=True, scope="module")
def _packaged_model_present():
    """The neural GTF model is committed with the package (pyproject package-data "models/*"):
    a missing file is a broken package, asserted here, not a model still to be trained (this
    module skipped, and the suite passed, without it)."""
    for name in (WEIGHTS_NAME, SPEC_NAME):
        assert (MODELS_DIR / name).is_file(), (
            f"{MODELS_DIR / name} is missing: it is committed with the package; restore it from git "
            "(git checkout woodcam/models)")


SIZE = (50.0, 40.0, 30.0)


@pytest.fixture(scope="module")
def model():
    return load_model()


def _interior(size, n=12):
    return np.stack(np.meshgrid(*[np.linspace(0, s, n) for s in size], indexing="ij"), -1).reshape(-1, 3)


def _angle_deg(a, b):
    return np.degrees(np.arccos(min(1.0, abs(float(np.dot(a, b))))))


@pytest.fixture(scope="module")
def boxed_heart():
    """Pith through the block, tilted 6 degrees, rings 3 mm, 3 years at the pith (eq. 7-9)."""
    rng = np.random.default_rng(7)
    f = RadialScalingField(LogFrame((22.0, 17.0, 0.0), (0.1, 0.05, 1.0)), 3.0,
                           RadiusFunction.random(rng), RadiusFunction.random(rng), 100.0, 3.0)
    return synth_block(f, SIZE, face_px=128, seed=1)


@pytest.fixture(scope="module")
def flat_sawn():
    """Pith 45 mm below the block bottom, along X, rings 4 mm, 5 years at the pith."""
    rng = np.random.default_rng(11)
    f = RadialScalingField(LogFrame((25.0, 15.0, -45.0), (1.0, 0.08, 0.1)), 4.0,
                           RadiusFunction.random(rng), RadiusFunction.random(rng), 150.0, 5.0)
    return synth_block(f, SIZE, face_px=128, seed=2)


def test_fit_boxed_heart_recovers_rings_axis_and_age(model, boxed_heart):
    fit = fit_neural_details(boxed_heart, model=model, steps=150)
    truth = boxed_heart.true_field
    p = _interior(SIZE)
    err = np.abs(fit.grid(p) - truth(p))
    # bar: interior growth time within a fifth of a ring on average, 95 % within half a ring
    assert err.mean() < 0.2, err.mean()
    assert np.mean(err < 0.5) > 0.95
    assert fit.field.age_offset == 3.0  # eq. 5's integer age offset a
    assert _angle_deg(fit.field.axis, truth.axis) < 5.0
    # the refinement improves on the grid search (c = 0)
    assert fit.loss_years < 0.5 * fit.grid_loss_years
    assert isinstance(fit.grid, GridField)
    assert _angle_deg(fit.grid.axis, truth.axis) < 5.0


def test_fit_flat_sawn_recovers_rings(model, flat_sawn):
    grid = fit_neural(flat_sawn, model=model, steps=150)
    truth = flat_sawn.true_field
    p = _interior(SIZE)
    err = np.abs(grid(p) - truth(p))
    assert err.mean() < 0.3, err.mean()
    assert np.mean(err < 0.5) > 0.85
    # bake covers the block with the default spacing (longest side / 48)
    assert np.all(np.asarray(grid.origin_mm) < 0)
    assert grid.spacing_mm == pytest.approx((50 / 48,) * 3)


def test_fit_ignores_unlabelled_traces_and_is_deterministic(model, boxed_heart):
    faces = {k: dataclasses.replace(f, traces=[dataclasses.replace(t, year=None) for t in f.traces])
             if k in ("left", "right") else f for k, f in boxed_heart.faces.items()}
    blk = dataclasses.replace(boxed_heart, faces=faces)
    a = fit_neural_details(blk, model=model, steps=5)
    b = fit_neural_details(blk, model=model, steps=5)
    pts, yrs = blk.trace_points_mm()
    assert a.n_points == int(np.isfinite(yrs).sum()) < len(yrs)
    np.testing.assert_array_equal(a.grid.years, b.grid.years)


def test_fit_rejects_bad_inputs(model, boxed_heart):
    f = RadialScalingField(LogFrame((10.0, 10.0, 0.0), (0, 0, 1)), 3.0)
    # ring maps but no traces: labels="years" insists on labelled traces
    no_traces = synth_block(f, (20.0, 20.0, 20.0), face_px=32, trace_faces=[])
    with pytest.raises(WoodcamError, match="labels='years' needs year-labelled ring traces"):
        fit_neural(no_traces, model=model, labels="years")
    unlabelled = synth_block(f, (20.0, 20.0, 20.0), face_px=32, unlabelled_fraction=1.0)
    with pytest.raises(WoodcamError, match="labels='years' needs year-labelled ring traces"):
        fit_neural(unlabelled, model=model, labels="years")
    # no rings at all: no traces, no ring maps / ring maps without a ring pixel
    bare = synth_block(f, (20.0, 20.0, 20.0), face_px=32, trace_faces=[], ring_map_faces=[])
    with pytest.raises(WoodcamError, match="no ring traces or ring-map rings"):
        fit_neural(bare, model=model)
    dark = dataclasses.replace(no_traces, faces={k: dataclasses.replace(v, ring_map=np.zeros_like(v.ring_map))
                                                 for k, v in no_traces.faces.items()})
    with pytest.raises(WoodcamError, match="no ring traces or ring-map rings"):
        fit_neural(dark, model=model)
    # a single unlabelled ring cannot be numbered
    one = synth_block(RadialScalingField(LogFrame((10.0, 10.0, 0.0), (0, 0, 1)), 8.0),
                      (20.0, 20.0, 20.0), face_px=32, faces=["top"], ring_map_faces=[],
                      unlabelled_fraction=1.0)
    assert len(one.faces["top"].traces) == 1
    with pytest.raises(WoodcamError, match="at least two rings"):
        fit_neural(one, model=model)
    with pytest.raises(WoodcamError, match="steps must be an integer >= 0"):
        fit_neural(boxed_heart, model=model, steps=-1)
    with pytest.raises(WoodcamError, match="year_free_steps must be an integer >= 0"):
        fit_neural(boxed_heart, model=model, year_free_steps=1.5)
    with pytest.raises(WoodcamError, match="labels must be one of auto, years, none"):
        fit_neural(boxed_heart, model=model, labels="yes")
    with pytest.raises(WoodcamError, match="start must be one of grid, radial"):
        fit_neural(boxed_heart, model=model, start="best")
    with pytest.raises(WoodcamError, match="model must be None"):
        fit_neural(boxed_heart, model=42)


# -- unlabelled rings: numbering + year-free refinement ----------------------------------------

@pytest.fixture(scope="module")
def eq79_maps():
    """An eq. 7-9 block (rings ~5 mm, pith ~10 deg off the Z axis), 3 px/mm: labelled traces,
    and the same block with only ring maps (no traces, no years)."""
    from _eq79_blocks import make_block, random_field
    from woodcam.block import Face

    rng = np.random.default_rng(100)
    truth = random_field(rng)
    blk = make_block(truth, px_per_mm=3.0, rng=rng, ring_map=True)
    maps = dataclasses.replace(blk, faces={k: Face(k, f.shape, ring_map=f.ring_map)
                                           for k, f in blk.faces.items()})
    return truth, blk, maps


@pytest.fixture(scope="module")
def eq79_fits(model, eq79_maps):
    truth, blk, maps = eq79_maps
    return (fit_neural_details(blk, model=model, steps=150),
            fit_neural_details(maps, model=model, steps=150))


def _ring_density(field, truth, size, n=2000, h=0.05):
    """Median ratio of |grad years| of ``field`` to ``truth`` at interior points: 1 = same ring
    width, 2 = a field stretched to twice as many rings."""
    p = np.random.default_rng(3).uniform(0.1, 0.9, (n, 3)) * np.asarray(size)
    e = np.eye(3) * h

    def grad(f):
        return np.linalg.norm(np.stack([(f(p + e[i]) - f(p - e[i])) / (2 * h) for i in range(3)], 1), axis=1)
    return float(np.median(grad(field) / grad(truth)))


def test_unlabelled_ring_maps_give_the_rings_of_labelled_traces(eq79_maps, eq79_fits):
    from woodcam.inference.evaluate import DEFAULT_PLANES, evaluate_fits

    truth, blk, maps = eq79_maps
    lab, unl = eq79_fits
    assert lab.mode == "years" and unl.mode == "year-free"
    assert unl.n_points > 1000 and len(unl.gap_points_mm) > 100
    # bar: the unlabelled fit's ring lines lie within 1 mm of the labelled fit's (any year:
    # rings agree up to the age offset) at >= 95 % of their points, and of the truth's likewise
    res = evaluate_fits(truth, {"lab": lab.grid, "unl": unl.grid}, blk.size_mm,
                        planes=DEFAULT_PLANES[:4], pixel_mm=0.2)
    assert res["lab"][0]["unmatched_1"] > 95.0
    assert res["unl"][0]["unmatched_1"] > 95.0, res["unl"][0]
    vs_lab = evaluate_fits(lab.grid, {"unl": unl.grid}, blk.size_mm, planes=DEFAULT_PLANES[:4],
                           pixel_mm=0.2)["unl"][0]
    assert vs_lab["unmatched_1"] > 95.0, vs_lab
    # the year-free step keeps the rings on the ring pixels (mean distance to an integer, years)
    assert unl.loss_years < 0.05
    assert unl.loss_years <= unl.labelled_loss_years + 0.005


def test_unlabelled_fit_keeps_the_ring_width(eq79_maps, eq79_fits):
    """Guard against the degenerate scale: the fitted ring density is the truth's within 5 %."""
    truth, blk, _ = eq79_maps
    _, unl = eq79_fits
    assert _ring_density(unl.field, truth, blk.size_mm) == pytest.approx(1.0, abs=0.05)


def test_gap_term_rejects_the_stretched_field(model, eq79_maps, eq79_fits):
    """A field with twice the ring density (every ring on an even integer) fits the ring pixels
    as well as the right one; only the gap term tells them apart, and only with it does the
    refinement leave the stretched field."""
    from woodcam.inference.neural import _refine_year_free, year_free_loss

    truth, blk, _ = eq79_maps
    _, unl = eq79_fits
    net, spec = model
    start = unl.field
    stretched = dataclasses.replace(start, scale=2 * start.scale, age_offset=2 * start.age_offset)
    ring, gap = unl.ring_points_mm, unl.gap_points_mm
    r1, g1 = year_free_loss(start, ring, gap)
    r2, g2 = year_free_loss(stretched, ring, gap)
    assert r2 < 0.05 and r1 < 0.05          # both put the ring pixels on integers
    assert g1 < 0.02 and g2 > 0.3            # the stretched one puts the gap points there too
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # as fit_neural does; two threads on a busy machine were 15x slower
    try:
        ring_only = _refine_year_free(torch, net, spec, stretched, ring, gap, 40,
                                      np.random.default_rng(0), w_gap=0.0, w_scale=0.0)
        guarded = _refine_year_free(torch, net, spec, stretched, ring, gap, 40,
                                    np.random.default_rng(0), w_gap=1.0, w_scale=0.0)
    finally:
        torch.set_num_threads(threads)
    assert _ring_density(ring_only, truth, blk.size_mm) == pytest.approx(2.0, abs=0.05)
    assert _ring_density(guarded, truth, blk.size_mm) < 1.9


def test_fit_block_neural_uses_ring_maps_without_years(eq79_maps):
    """``fit_block(block, "neural")`` on a ring-map-only block (the Mokume input)."""
    from woodcam.inference import fit_block

    truth, _, maps = eq79_maps
    field = fit_block(maps, "neural", faces=["top", "front", "right"])
    assert isinstance(field, GridField)
    p = np.random.default_rng(1).uniform(5, 45, (4000, 3))
    d = field(p) - truth(p)
    # rings up to the age offset: the difference is near one integer everywhere
    off = np.round(np.median(d))
    assert np.mean(np.abs(d - off) < 0.5) > 0.9


@pytest.mark.slow
@pytest.mark.parametrize("pattern", ["flat-sawn", "quarter-sawn", "rift", "pith-inside"])
def test_fit_analytic_log_blocks(model, pattern):
    """Blocks cut from eccentric, lobed analytic logs whose ring width drifts with radius (not
    in the eq. 7-9 family the model was trained on): a ring-accurate fit on average."""
    from woodcam.synth import cut_block, random_log_placement

    size = (80.0, 50.0, 30.0)
    errs = []
    for seed in (0, 1):
        log, place = random_log_placement(np.random.default_rng(1000 + seed), pattern, size)
        truth = cut_block(log, size, **place)
        grid = fit_neural(synth_block(truth, size, face_px=256, seed=seed), model=model)
        p = _interior(size, 16)
        errs.append(np.abs(grid(p) - truth(p)))
    err = np.concatenate(errs)
    assert err.mean() < 0.4, err.mean()
    assert np.mean(err < 0.5) > 0.7


def test_fit_block_dispatches_to_the_neural_fitter():
    """``fit_block(block, "neural")`` is the seed's eq. 5 fit, baked to a grid."""
    from woodcam.fields import GridField, LogFrame, RadialScalingField
    from woodcam.inference import fit_block
    from woodcam.synth import synth_block

    truth = RadialScalingField(LogFrame((25.0, 25.0, 0.0), (0.05, 0.0, 1.0)), 3.0)
    block = synth_block(truth, (50, 50, 50), face_px=96, seed=0)
    field = fit_block(block, "neural")
    assert isinstance(field, GridField)
    p = np.random.default_rng(1).uniform(5, 45, (4000, 3))
    assert np.mean(np.abs(field(p) - truth(p))) < 0.3  # years, the bar of the pith-inside test


@pytest.mark.slow
def test_radial_start_rescues_a_grid_search_miss(model):
    """eq. 7-9 block 101 of the benchmark set: no grid direction is near enough to its pith for
    the labelled fit to recover (unmatched 1 mm ~36 %, measured); the radial fitter's pith line
    as an extra grid candidate (``start="radial"``) gives ring-accurate lines."""
    from _eq79_blocks import make_block, random_field
    from woodcam.inference.evaluate import DEFAULT_PLANES, evaluate_fit

    rng = np.random.default_rng(101)
    truth = random_field(rng)
    blk = make_block(truth, px_per_mm=3.0, rng=rng)
    grid = fit_neural(blk, model=model, start="radial")
    summary, _ = evaluate_fit(truth, grid, blk.size_mm, planes=DEFAULT_PLANES[:4], pixel_mm=0.2)
    assert summary["matched_1"] > 95.0, summary
