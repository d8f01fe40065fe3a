"""Leave-one-face-out scoring against ring maps (woodcam.inference.holdout) and knot masks."""

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.block import Block, Face
from woodcam.errors import WoodcamError
from woodcam.frames import face_pixel_points
from woodcam.inference import gather_observations
from woodcam.inference.holdout import (
    BEST_PHASE, CONTROL, STRAIGHT, STRAIGHT_OWN, face_years, leave_one_face_out, ridge_pixels, ring_lines_px, score_face,
    straight_rings,
)


@pytest.fixture(scope="module")
def field():
    return random_field(np.random.default_rng(103))


@pytest.fixture(scope="module")
def mapped(field):
    """Ring maps only (no traces, no years), 5 px/mm on a 50 mm cube."""
    return make_block(field, px_per_mm=5, traces=False, ring_map=True)


def _px_from_ring(field, block, face, rc):
    """Distance (px) of pixel centres ``rc`` (k, 2) from the nearest integer iso-line of ``field``,
    to first order: |g - round(g)| / |grad g|."""
    f = block.faces[face]
    g = face_years(field, face, f.shape, block.size_mm)
    gr, gc = np.gradient(g)
    r, c = rc[:, 0].astype(int), rc[:, 1].astype(int)
    return np.abs(g[r, c] - np.round(g[r, c])) / np.maximum(np.hypot(gr, gc)[r, c], 1e-9)


def test_ridge_pixels_lie_on_the_ring_lines(field, mapped):
    for face in ("front", "top", "right"):
        ridge = ridge_pixels(mapped.faces[face].ring_map)
        assert len(ridge) > 200
        d = _px_from_ring(field, mapped, face, ridge)
        # The skeleton of a thresholded band is its centre line up to one pixel.
        assert np.mean(d <= 1.0) >= 0.97, face


def test_ring_lines_px_are_integer_isolines():
    # years = (col + 5) / 10 on a 64 x 64 image: vertical lines at cols 5, 15, ..., 55
    years = np.tile((np.arange(64) + 5) / 10.0, (64, 1))
    pts = ring_lines_px(years, step_px=0.25)
    assert set(np.round(pts[:, 1], 6)) == {5.0, 15.0, 25.0, 35.0, 45.0, 55.0}
    assert np.max(np.diff(np.sort(pts[np.isclose(pts[:, 1], 5.0)][:, 0]))) <= 0.25 + 1e-9
    excl = np.zeros((64, 64), bool)
    excl[:, 10:20] = True
    kept = set(np.round(ring_lines_px(years, exclude=excl)[:, 1], 6))
    assert kept == {5.0, 25.0, 35.0, 45.0, 55.0}


def test_true_field_scores_full_and_a_half_ring_shift_scores_low(field, mapped):
    for face in ("front", "left"):
        good = score_face(field, mapped, face)
        assert good.shares["ridge_1"] >= 97 and good.shares["line_1"] >= 97, good.shares
        bad = score_face(lambda p: field(p) + 0.5, mapped, face)
        assert bad.shares["ridge_1"] < 15 and bad.shares["line_1"] < 15, bad.shares


def test_leave_one_face_out_predicts_held_out_synthetic_faces(mapped, tmp_path):
    res = leave_one_face_out(mapped, ("radial",), out_dir=tmp_path)
    held = res["held_out"]["radial"]
    assert [s.face for s in held] == list(mapped.faces)
    # An eq. 7-9 field is in the radial model's family: each face is predicted from the other
    # five to within 2 px (0.4 mm) nearly everywhere (measured: mean 96-97 %, worst face 81 %,
    # where the fit extrapolates furthest; 82 % within 1 px).
    assert np.mean([s.shares["ridge_2"] for s in held]) >= 93
    assert np.mean([s.shares["line_2"] for s in held]) >= 93
    assert min(s.shares["ridge_2"] for s in held) >= 75
    # the chance control (every prediction moved half a ring) falls far below
    assert np.mean([s.shares["ridge_2"] for s in res[CONTROL]["radial"]]) < 40
    # the straight-ring control (right orientation and spacing, best phase) is reported and,
    # on the curved rings of an eq. 7-9 field, beaten by the held-out prediction
    straight = np.mean([s.shares["ridge_2"] for s in res[STRAIGHT]["radial"]])
    assert straight < np.mean([s.shares["ridge_2"] for s in held]) - 10
    assert (tmp_path / "eq79_radial.png").stat().st_size > 10_000
    assert "mean, held out" in (tmp_path / "eq79_holdout.md").read_text()
    assert STRAIGHT in (tmp_path / "eq79_holdout.md").read_text()
    # the like-for-like rows: the prediction with the straight control's oracle phase is at
    # least as good as without it (phase 0 is one of the choices), and the straight rings at
    # the prediction's own phase no better than at their best phase
    for fit, best, own, st in zip(held, res[BEST_PHASE]["radial"], res[STRAIGHT_OWN]["radial"],
                                  res[STRAIGHT]["radial"]):
        assert best.shares["ridge_2"] >= fit.shares["ridge_2"]
        assert own.shares["ridge_2"] <= st.shares["ridge_2"]
    assert BEST_PHASE in (tmp_path / "eq79_holdout.md").read_text()


def test_straight_rings_is_the_mean_plane():
    r, c = np.meshgrid(np.arange(20.0), np.arange(30.0), indexing="ij")
    plane = 0.3 + 0.1 * r - 0.05 * c
    np.testing.assert_allclose(straight_rings(plane), plane, atol=1e-9)
    bent = plane + 0.2 * np.sin(c / 5)
    assert np.abs(straight_rings(bent) - plane).max() < 0.2


def test_holdout_errors(mapped):
    one = Block(mapped.size_mm, {"front": mapped.faces["front"]}, name="one")
    with pytest.raises(WoodcamError, match="at least two faces with ring maps"):
        leave_one_face_out(one, ("radial",))
    bare = Block(mapped.size_mm, {"front": Face("front", mapped.faces["front"].shape),
                                  "top": mapped.faces["top"]}, name="bare")
    with pytest.raises(WoodcamError, match="no ring map to score against"):
        score_face(lambda p: p[:, 0], bare, "front")


def test_knot_mask_removes_ring_map_pixels(field, mapped):
    """Ring pixels on (or within the margin of) a knot mask are not observations."""
    face = mapped.faces["front"]
    knot = np.zeros(face.shape, bool)
    knot[100:150, 100:150] = True
    masked = Face("front", face.shape, ring_map=face.ring_map, extras={"knot_mask": knot})
    before = gather_observations(Block(mapped.size_mm, {"front": face}))
    after = gather_observations(Block(mapped.size_mm, {"front": masked}))
    centre = face_pixel_points("front", face.shape, mapped.size_mm)[125, 125]
    near = lambda o: np.sum(np.linalg.norm(o.points_mm - centre, axis=1) < 5.0 + 3.0)  # 25 px half side + margin
    assert near(before) > 20 and near(after) == 0
    assert len(after.points_mm) < len(before.points_mm)
    # traces too: a tracer's knot rings (or stem rings bent round it) inside the margin
    traced = make_block(field, px_per_mm=5, faces=("front",))
    t_face = traced.faces["front"]
    t_masked = Face("front", t_face.shape, traces=t_face.traces, extras={"knot_mask": knot})
    t_before = gather_observations(traced)
    t_after = gather_observations(Block(mapped.size_mm, {"front": t_masked}))
    assert near(t_before) > 20 and near(t_after) == 0
    assert 0 < len(t_after.points_mm) < len(t_before.points_mm)


def test_mokume_knot_point_grows_to_the_knot(shared_data):
    from woodcam.block.io import read_mokume

    b = read_mokume(shared_data / "mokume" / "H11")
    for face in ("left", "back"):  # Mokume C and F
        m = b.faces[face].extras["knot_mask"]
        # One marked pixel grown to the dark disc of the knot: between 2 % and 40 % of the face
        # (H11's knot is about 25 mm across on a 50 mm face), one connected piece.
        assert 0.02 < m.mean() < 0.40, m.mean()
        from scipy import ndimage

        assert ndimage.label(m)[1] == 1


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::woodcam.errors.WoodcamWarning")  # H11's folds are flagged contradicted
def test_real_cubes_leave_one_face_out(shared_data, tmp_path):
    """H11 and CN03 from their ring maps: each face predicted from the other five by the
    default (evidence) fit. Real rings wiggle and bend round knots, so the bar is the chance
    control (the same predictions moved half a ring), not near 100 %."""
    from woodcam.block.io import read_mokume

    # Measured within 2 px (issue 12, FIT_VERSION 8: rings numbered by the basin whose
    # neighbouring rings are one year apart): CN03 21.5 vs chance 2.3 % (9.2x; straight rings
    # with an oracle phase 25.6 %). FIT_VERSION 14: CN03 21.35 vs 2.74 (7.8x), and with the
    # evidence seeds 1-3 8.6x, 9.7x, 10.6x. H11's ratio to chance is a matter of seed (FIT_VERSION
    # 14: 1.37x, 1.00x, 0.92x, 1.07x with seeds 0-3; 13: 1.61x, 1.00x, 0.92x, 0.95x), so no
    # chance bar is claimed for it here: the 2x is the xfail test below.
    bars = {"CN03": 5.0}
    # Like for like, H11 with seeds 0-3: best phase over straight rings 1.08-1.47 (asserted at
    # 1.0); its prediction over the straight rings at their own phase 1.06-1.33 (1.1 is not
    # met with seed 2: not asserted).
    like_for_like = {"CN03": 1.15, "H11": 1.0}
    for name, like in like_for_like.items():
        b = read_mokume(shared_data / "mokume" / name)
        res = leave_one_face_out(b, ("evidence",), out_dir=tmp_path, progress=print)
        print(res["table"])
        ok = np.mean([s.shares["ridge_2"] for s in res["held_out"]["evidence"]])
        shifted = np.mean([s.shares["ridge_2"] for s in res[CONTROL]["evidence"]])
        if name in bars:
            assert ok > bars[name] * shifted, (name, ok, shifted)
        # Part 7, like for like (README): the straight-ring control takes its phase from the
        # held-out map, so the prediction is compared at that phase too, and the straight rings
        # at the prediction's own phase. Measured within 2 px: H11 21.1 vs 20.3 and 19.1 vs
        # 15.9, CN03 31.6 vs 25.6 and 21.5 vs 19.0.
        mean2 = lambda key: np.mean([s.shares["ridge_2"] for s in res[key]["evidence"]])  # noqa: E731
        assert mean2(BEST_PHASE) > like * mean2(STRAIGHT), (name, mean2(BEST_PHASE), mean2(STRAIGHT))
        if name in bars:
            assert ok > 1.1 * mean2(STRAIGHT_OWN), (name, ok, mean2(STRAIGHT_OWN))


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 12 not met: H11's held-out faces beat chance 1.32x on average "
                                       "over evidence seeds 0-3 (FIT_VERSION 24; the goal is 2x)")
@pytest.mark.filterwarnings("ignore::woodcam.errors.WoodcamWarning")
def test_h11_held_out_faces_beat_chance_twice_whatever_the_seed(shared_data):
    """Issue 12's done criterion on the real spruce cube H11, each face predicted from the
    other five, taken over the evidence fit's seeds 0-3 (seed 0 alone gave 1.61x before
    FIT_VERSION 14, 1.37x with it and 1.47x with 15 and 16; the others ~1.0x): the mean ratio to the
    chance control within 2 px must reach 2."""
    from woodcam.block.io import read_mokume

    b = read_mokume(shared_data / "mokume" / "H11")
    ratios = []
    for seed in range(4):
        res = leave_one_face_out(b, ("evidence",), seed=seed)
        ok = np.mean([s.shares["ridge_2"] for s in res["held_out"]["evidence"]])
        ratios.append(ok / np.mean([s.shares["ridge_2"] for s in res[CONTROL]["evidence"]]))
    print("H11 held out / chance, seeds 0-3:", np.round(ratios, 2))
    assert np.mean(ratios) >= 2.0, ratios


def test_eval_rings_confidence_draws_and_summarises_the_held_out_faces_confidence(field, mapped, tmp_path,
                                                                                 monkeypatch):
    """``eval rings REAL --methods evidence --confidence`` passed --confidence to the cut-plane
    scoring only: on a real block (no true field) held-out faces were scored and drawn without
    the evidence fit's confidence, and table/pictures were the same with and without it. The
    held-out faces now carry the fit's confidence: the table summarises it either way (its
    confident line points against its unsure ones), --confidence draws it under the overlays."""
    import copy

    import woodcam.inference.holdout as holdout
    from woodcam.block.io import write_block
    from woodcam.cli import main
    from woodcam.fields import GridField
    from woodcam.inference import bake

    grid = bake(field, mapped.size_mm)
    x = grid.origin_mm[0] + grid.spacing_mm[0] * np.arange(grid.years.shape[0])
    unsure = np.broadcast_to((x > 25.0)[:, None, None], grid.years.shape).astype(float)  # 1 year beyond x = 25 mm
    fit = GridField(grid.years, grid.origin_mm, grid.spacing_mm, grid.interpolation, grid.axis,
                    {"uncertainty": unsure})
    monkeypatch.setattr(holdout, "fit_block", lambda block, method, faces=None, seed=0: fit)  # the truth, half sure
    real = copy.copy(mapped)
    real.true_field = None
    real.faces = {k: mapped.faces[k] for k in ("front", "top", "right")}
    write_block(real, tmp_path / "blk")
    pngs = {}
    for flag in ([], ["--confidence"]):
        out = tmp_path / f"ev{len(flag)}"
        assert main(["eval", "rings", str(tmp_path / "blk"), "--methods", "evidence", *flag, "--out", str(out)]) == 0
        table = (out / "eq79_holdout.md").read_text()
        assert "Confidence on the held-out predicted ring lines" in table
        rows = {r.split("|")[1].strip(): [float(v) for v in r.split("|")[3:7]] for r in table.splitlines()
                if r.startswith("| ") and "| evidence |" in r}
        assert rows["right"][:2] == [0.02, 0.0]  # x = 50 mm: all unsure
        assert 30 < rows["front"][1] < 70 and 30 < rows["top"][1] < 70  # half sure
        assert rows["front"][2] > 90  # the truth: its sure lines lie on the ridge
        pngs[len(flag)] = (out / "eq79_evidence.png").read_bytes()
    assert pngs[0] != pngs[1]  # --confidence draws it
    res = leave_one_face_out(real, ["evidence"], confidence=True)
    assert all(sc.confidence_img is not None for sc in res["held_out"]["evidence"])


def test_the_held_out_picture_says_its_colours_and_shares(field, mapped, tmp_path, monkeypatch):
    """The leave-one-face-out PNG drew blue, red and yellow on its overlay and 'ridge 8/13%  line
    9/15%' under it with no word of what they are: its title carries the key."""
    import woodcam.inference.holdout as holdout

    figures = []
    real = holdout.write_figure
    monkeypatch.setattr(holdout, "write_figure", lambda fig, path, **kw: (figures.append(fig), real(fig, path, **kw))[1])
    scores = [score_face(field, mapped, face) for face in ("front", "top")]
    holdout.plot_holdout(tmp_path / "h.png", mapped, scores, title="b, radial: each face predicted")
    said = figures[0]._suptitle.get_text()
    assert said == "b, radial: each face predicted\n" + holdout.HOLDOUT_KEY
    assert "blue its ridge" in said and "red the predicted ring lines" in said and "within 1 / 2 px" in said
    assert (tmp_path / "h.png").stat().st_size > 0


def test_picture_titles_say_arf_in_words():
    """'eval appearance' titled its picture "held-out faces (ARF of field input)" and the
    leave-one-face-out PNG a column "predicted ARF": the papers' abbreviation of the annual-ring
    field, which no reader of the picture is told."""
    from woodcam.cli.appearance import holdout_title
    from woodcam.inference.holdout import HOLDOUT_COLUMNS

    assert holdout_title("H11", True) == "H11: held-out faces (input: the rings of the field)"
    assert holdout_title("H11", False) == "H11: held-out faces (input: the ring map)"
    assert HOLDOUT_COLUMNS[2] == "predicted rings (annual-ring field)"
    assert not any("ARF" in t for t in (*HOLDOUT_COLUMNS, holdout_title("b", True)))
