"""Issue 12 part 4: the small-scale residual on top of the smooth stem, kept only where
leave-one-face-out says it predicts (synthetic truth: a round stem with and without a wave)."""

import numpy as np
import pytest

from _eq79_blocks import make_block
from _stems import round_stem
from woodcam.errors import WoodcamError
from woodcam.fields.grid import GridField
from woodcam.fields.residual import FaceResidual, ResidualField
from woodcam.inference import evaluate_fit, gather_observations
from woodcam.inference.evidence import fit_evidence
from woodcam.inference.residual import fit_face_residual

SIZE = (50.0, 50.0, 50.0)
PITH = (-15.0, 20.0)  # outside the block: rings 3 mm apart cross every face


class _Wavy:
    """A stem plus a 3-D wave of ``amp`` years and wavelength ``lam_mm`` (CN03's wavy figure,
    seed 000 Fig. 16b, in miniature)."""

    def __init__(self, stem, amp: float, lam_mm: float):
        self.stem, self.amp, self.k = stem, amp, 2 * np.pi / lam_mm
        self.axis = stem.axis

    def __call__(self, points_mm):
        p = np.asarray(points_mm, float)
        return self.stem(p) + self.amp * np.sin(self.k * p[:, 2] + 0.7) * np.cos(self.k * (0.6 * p[:, 0] + 0.3 * p[:, 1]))


@pytest.fixture(scope="module")
def wavy_block():
    truth = _Wavy(round_stem(PITH, SIZE), 0.8, 15.0)
    return make_block(truth, SIZE, px_per_mm=3.0, rng=np.random.default_rng(1))


def test_face_residual_falls_off_from_the_faces_and_is_the_spline_on_them():
    rng = np.random.default_rng(0)
    size = np.array([30.0, 40.0, 20.0])
    res = FaceResidual(size, 5.0, 4.0, {"front": rng.normal(size=(9, 7))})
    on = np.array([[10.0, 0.0, 8.0], [25.0, 0.0, 3.0]])
    np.testing.assert_allclose(res(on), res._splines["front"](on[:, [0, 2]]))
    deep = on + [0.0, 4.0, 0.0]  # one fall-off depth in: exp(-1) of the face's value
    np.testing.assert_allclose(res(deep), np.exp(-1) * res(on))
    assert np.all(res(on + [0.0, 20.0, 0.0]) == 0.0)  # five depths in: nothing
    # outside the block it is the face's value (the bake's margin nodes)
    np.testing.assert_allclose(res(on - [0.0, 1.0, 0.0]), res(on))


def test_residual_field_adds_and_forwards_to_its_base():
    stem = round_stem(PITH, SIZE)
    f = ResidualField(stem, lambda p: np.full(len(p), 0.25))
    p = np.array([[10.0, 10.0, 10.0]])
    np.testing.assert_allclose(f(p), stem(p) + 0.25)
    np.testing.assert_array_equal(f.axis, stem.axis)
    assert f.pith_years() == stem.pith_years()
    with pytest.raises(AttributeError):
        f.strands  # noqa: B018 - a stem without knots has none, nor has its residual field


def test_fit_face_residual_recovers_a_planted_wave_near_the_faces(wavy_block):
    obs = gather_observations(wavy_block)
    truth = wavy_block.true_field
    res = fit_face_residual(obs, truth.stem, SIZE)
    on_faces = obs.points_mm[::7]
    wave = truth(on_faces) - truth.stem(on_faces)
    err = res(on_faces) - wave
    # damped (RESIDUAL_* penalties) but most of the wave: residual rms well below the wave's
    assert np.sqrt(np.mean(err ** 2)) < 0.4 * np.sqrt(np.mean(wave ** 2))
    assert abs(res(np.array([[25.0, 25.0, 25.0]]))[0]) < 1e-6  # nothing invented deep inside


def test_a_planted_wave_is_kept_and_predicts_held_out_faces(wavy_block):
    """Stem + wave (0.8 ring, 15 mm): the residual fitted on five faces predicts the sixth
    (measured: held-out mean +6.1 points on the radial fit), the bake carries it, and the inside
    is closer to the truth (cut planes within 2 mm: 78.0 -> 84.9 %). The smooth hypotheses alone
    compete (radial, stem): "radial + residual", a smoothed RBF of the radial fit's residual,
    takes part of the same wave (FIT_VERSION 11: chosen at 76.0 held out against radial's 75.5,
    and the small-scale residual then adds +1.5)."""
    ev = fit_evidence(gather_observations(wavy_block), SIZE, residual=True, candidates=("radial", "stem"),
                      warn=False)
    assert ev.residual["kept"], ev.message
    assert ev.residual["gain"] >= 2.0
    assert "small-scale residual kept" in ev.message
    assert isinstance(ev.field, ResidualField) and ev.field.base is ev.hypotheses[ev.chosen]
    truth = wavy_block.true_field
    base = evaluate_fit(truth, ev.field.base, SIZE, pixel_mm=0.25)[0]["matched_2"]
    with_res = evaluate_fit(truth, ev.field, SIZE, pixel_mm=0.25)[0]["matched_2"]
    assert with_res > base + 3.0
    from woodcam.inference.evidence import bake_evidence

    grid = bake_evidence(ev, SIZE, list(range(6)))
    assert isinstance(grid, GridField) and grid.meta["residual"]["kept"]
    p = np.random.default_rng(3).uniform(1.0, 49.0, (300, 3))
    np.testing.assert_allclose(grid(p), ev.field(p), atol=0.02)  # the residual survives the bake


def test_on_a_plain_block_the_residual_is_not_kept():
    block = make_block(round_stem(PITH, SIZE), SIZE, px_per_mm=3.0, rng=np.random.default_rng(1))
    obs = gather_observations(block)
    ev = fit_evidence(obs, SIZE, residual=True, candidates=("radial", "stem"), warn=False)
    assert not ev.residual["kept"] and abs(ev.residual["gain"]) < 1.0
    assert "small-scale residual not kept" in ev.message
    assert ev.field is ev.hypotheses[ev.chosen]  # the stem untouched


def test_residual_refuses_the_everywhere_blend(wavy_block):
    obs = gather_observations(wavy_block, ["front", "top"])
    with pytest.raises(WoodcamError, match="residual=True needs blend"):
        fit_evidence(obs, SIZE, residual=True, blend="everywhere")


def test_fit_face_residual_needs_years(wavy_block):
    obs = gather_observations(wavy_block, ["front"])
    obs.years[:] = np.nan  # unnumbered ring-map rings
    with pytest.raises(WoodcamError, match="obs must hold ring points with years"):
        fit_face_residual(obs, wavy_block.true_field.stem, SIZE)


def test_fit_face_residual_with_points_on_part_of_one_face(wavy_block):
    """Points that reach only some of a face's B-splines (one corner of one face observed, as a
    fold of a three-face block may leave) still give every face its full coefficient grid."""
    obs = gather_observations(wavy_block, ["front"])
    corner = obs.subset((obs.points_mm[:, 0] < 20) & (obs.points_mm[:, 2] < 20))
    res = fit_face_residual(corner, wavy_block.true_field.stem, SIZE)
    assert all(c.shape == (20, 20) for c in res.coefs.values())  # 17 intervals of 3 mm + 3
    assert np.isfinite(res(corner.points_mm)).all()


@pytest.mark.slow
@pytest.mark.parametrize("cube", ["CN03", "H11"])
def test_real_cubes_all_faces_do_not_keep_the_residual(shared_data, cube):
    """On the real cubes the residual does not predict held-out faces, so it is not kept and the
    fit is the default's (measured: CN03 +0.5, H11 -0.2 points; in the outer leave-one-face-out
    of README's table it was kept in 3 of 12 folds: H11 front 5.9 -> 8.7 %, back 19.0 -> 20.2 %
    within 2 px, CN03 back 5.7 -> 2.7 %, chance there 4.2 %)."""
    from woodcam.block.io import read_mokume

    b = read_mokume(shared_data / "mokume" / cube)
    ev = fit_evidence(gather_observations(b), b.size_mm, residual=True, warn=False)
    assert not ev.residual["kept"] and ev.residual["gain"] < 1.0, ev.message
    assert ev.field is ev.hypotheses[ev.chosen]
    assert set(ev.residual["with"]) == set(b.faces)  # every face was held out and scored
