"""The Table-1 ring accuracy metric on cut planes against known answers."""

import numpy as np
import pytest

from _eq79_blocks import random_field
from woodcam.errors import WoodcamError
from woodcam.inference.evaluate import CutPlane, evaluate_fit, markdown_table, sample_plane


class _Cylinder:
    """years = distance from the vertical line x = y = 25 mm, in units of 2 mm rings."""

    def __call__(self, p):
        return np.hypot(p[:, 0] - 25, p[:, 1] - 25) / 2.0


PLANE = (CutPlane("z", (0.5, 0.5, 0.5), (0, 0, 1)),)


def test_perfect_fit_scores_100():
    s, _ = evaluate_fit(_Cylinder(), _Cylinder(), (50, 50, 50), planes=PLANE, pixel_mm=0.2)
    assert s["matched_1"] == 100 and s["unmatched_1"] == 100 and s["coverage_1"] == 100


def test_shift_by_one_year_fails_matched_passes_unmatched():
    true = _Cylinder()
    s, _ = evaluate_fit(true, lambda p: true(p) + 1, (50, 50, 50), planes=PLANE, pixel_mm=0.2)
    assert s["matched_1"] == 0  # ring n+1 sits 2 mm from ring n: matching by year fails
    assert s["unmatched_1"] == 100  # every predicted line lies on some true line


def test_radial_offset_in_mm_sets_the_share():
    # predicted rings 1.5 mm too far out: none within 1 mm, all within 2 mm
    true = _Cylinder()
    s, _ = evaluate_fit(true, lambda p: true(p) - 0.75, (50, 50, 50), planes=PLANE, pixel_mm=0.1)
    assert s["matched_1"] == 0
    assert s["matched_2"] > 98  # lines clipped at the block edge end at slightly different places


def test_oblique_plane_covers_its_cut_polygon_only():
    sample = sample_plane(CutPlane("xyz", (0.5, 0.5, 0.5), (1, 1, 1)), (50, 50, 50), 0.5)
    inside = sample.points_mm[sample.inside]
    assert inside.min() >= -1e-9 and inside.max() <= 50 + 1e-9
    # a regular hexagon of side 50/sqrt(2) mm: area 3 sqrt(3)/2 * 1250 = 3248 mm^2
    assert sample.inside.sum() * 0.25 == pytest.approx(3247.6, rel=0.02)
    with pytest.raises(WoodcamError, match="does not cross the block"):
        sample_plane(CutPlane("out", (2, 2, 2), (0, 0, 1)), (50, 50, 50))


def test_markdown_table_bolds_the_better_method():
    row = {"name": "b", "a": {"matched_1": 50.0, "matched_2": 60.0, "unmatched_1": 70.0,
                              "unmatched_2": 80.0, "coverage_1": 1.0, "fit_s": 1.0}}
    row["c"] = {k: v + 1 for k, v in row["a"].items()}
    text = markdown_table([row], ["a", "c"])
    assert "| 50.0 | **51.0** |" in text


def test_eq79_helper_is_exact_on_its_own_field():
    f = random_field(np.random.default_rng(5))
    s, _ = evaluate_fit(f, f, (50, 50, 50), planes=PLANE, pixel_mm=0.25)
    assert s["matched_1"] == 100


class _HalfWrong:
    """A fit that is exact where x < 25 mm and 1.5 rings (3 mm) off beyond, with an
    uncertainty layer that knows it: 0 years where x < 25, 2 years beyond."""

    layers = {"uncertainty": None}

    def __call__(self, p):
        return _Cylinder()(p) + np.where(p[:, 0] < 25, 0.0, 1.5)

    def uncertainty_years(self, p):
        return np.where(np.asarray(p)[:, 0] < 25, 0.0, 2.0)


def test_confidence_summary_splits_right_and_wrong_lines(tmp_path):
    """The eval's confidence summary (issue 12 parts 5-6) on a fit whose uncertainty marks
    exactly its wrong half: confident lines on the truth, unsure ones 3 mm off their year's
    true line; the picture is drawn."""
    from woodcam.inference.evaluate import confidence_summary, plot_planes

    s, scores = evaluate_fit(_Cylinder(), _HalfWrong(), (50, 50, 50), planes=PLANE, pixel_mm=0.2,
                             keep_lines=True)
    assert 40 < s["confident_share"] < 60, s
    assert s["confidence_mean"] == pytest.approx(s["confident_share"] / 100, abs=0.02)
    # (a few % of the confident points lie on the iso-lines the fit's jump at x = 25 draws)
    assert s["matched_2_confident"] > 95 and s["matched_2_unsure"] < 5, s
    sc = scores[0]
    assert sc.confidence.shape == sc.d_matched.shape
    sure, unsure = sc.confidence == 1.0, sc.confidence < 0.01   # parallel to the line points' errors
    assert np.mean(sc.d_matched[sure] <= 2.0) > 0.95 and np.mean(sc.d_matched[unsure] > 2.0) > 0.95
    # the confidence image is the plane's grid: sure where x < 25 mm, unsure beyond, NaN outside
    sample = sample_plane(PLANE[0], (50, 50, 50), 0.2)
    img, left = sc.confidence_img, sample.points_mm[..., 0] < 25
    assert img.shape == sample.inside.shape and np.isnan(img[~sample.inside]).all()
    assert np.all(img[sample.inside & left] == 1.0) and np.all(img[sample.inside & ~left] < 0.01)
    # a plain fit carries no confidence: no keys, nothing drawn
    s2, sc2 = evaluate_fit(_Cylinder(), _Cylinder(), (50, 50, 50), planes=PLANE, pixel_mm=0.2)
    assert "confidence_mean" not in s2 and sc2[0].confidence is None
    assert confidence_summary(np.array([1.0, 0.0]), np.array([0.1, 3.0]))["matched_2_unsure"] == 0
    png = plot_planes(tmp_path / "c.png", {"evidence": scores}, confidence=True)
    assert png.stat().st_size > 1000


def test_the_cut_plane_picture_says_what_its_planes_and_shares_are(tmp_path, monkeypatch):
    """'eval rings' cut-plane PNG titled its panels 'radial z=0.5 / 100% <1mm' with no word that
    0.5 is a fraction of the block's height nor of what the % counts: its title carries the key."""
    import woodcam.inference.evaluate as evaluate

    figures = []
    real = evaluate.write_figure
    monkeypatch.setattr(evaluate, "write_figure", lambda fig, path, **kw: (figures.append(fig), real(fig, path, **kw))[1])
    _, scores = evaluate_fit(_Cylinder(), _Cylinder(), (50, 50, 50), planes=PLANE, pixel_mm=0.5, keep_lines=True)
    for title in ("b (full): black = true rings, colour = fitted", ""):
        evaluate.plot_planes(tmp_path / "p.png", {"radial": scores}, title=title)
        said = figures[-1]._suptitle.get_text()
        assert said == (f"{title}\n" if title else "") + evaluate.PLANES_KEY
        assert "fractions of the block's width x, depth y, height z" in said
        assert "within 1 mm of the true line of the same year" in said
