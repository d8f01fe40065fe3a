"""Issue 12 part 1: hypotheses chosen by leave-one-face-out evidence; flags; uncertainty."""

import warnings

import numpy as np
import pytest

from _eq79_blocks import make_block, random_field
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.fields.grid import GridField
from woodcam.inference import evaluate_fit, fit_block, gather_observations
from woodcam.inference.evidence import (ConfidenceWood, Hypothesis, choose, confidence, fit_evidence,
                                        holdout_evidence, radial_recipe, uncertainty_report)
from woodcam.inference.radial import RadialField, _smoothest_coefficients, fit_radial


@pytest.fixture(scope="module")
def block():
    rng = np.random.default_rng(7)
    return make_block(random_field(rng), px_per_mm=3.0, rng=rng)


@pytest.fixture(scope="module")
def obs(block):
    return gather_observations(block)


def _planted(obs, good: RadialField, tilt_deg: float = 25.0) -> RadialField:
    """A wrong pith hypothesis: the good axis tilted, its shape least-squares fitted to every
    face, so it reproduces the faces it was fitted to about as well as it can."""
    d = good.axis / np.linalg.norm(good.axis)
    perp = np.cross(d, [0.3, 0.5, 0.8])
    perp /= np.linalg.norm(perp)
    t = np.deg2rad(tilt_deg)
    wrong = RadialField(good.pith_mm + 8 * perp, np.cos(t) * d + np.sin(t) * perp, good.z_scale_mm,
                        good.K, good.M, good.coef, good.offset)
    return _smoothest_coefficients(obs, wrong, 0)


def test_planted_wrong_hypothesis_is_rejected_by_held_out_faces(block, obs):
    good = fit_radial(obs, block.size_mm)
    wrong = _planted(obs, good)
    hyps = [Hypothesis("planted", wrong, radial_recipe(wrong)), Hypothesis("radial", good, radial_recipe(good))]
    ev = holdout_evidence(hyps, obs)
    res = choose(hyps, ev)
    assert res.chosen == "radial"           # chosen although the planted one is listed first
    assert res.scores["radial"]["mean"] > 90.0
    assert res.scores["planted"]["mean"] < res.scores["radial"]["mean"] - 30.0
    assert not res.contradicted
    # the planted field alone is not returned silently: the held-out faces contradict it
    alone = choose(hyps[:1], holdout_evidence(hyps[:1], obs))
    assert alone.contradicted and "CONTRADICTED" in alone.message
    # and the truth agrees with the evidence
    acc_good = evaluate_fit(block.true_field, good, block.size_mm, pixel_mm=0.25)[0]["matched_2"]
    acc_wrong = evaluate_fit(block.true_field, wrong, block.size_mm, pixel_mm=0.25)[0]["matched_2"]
    assert acc_good > acc_wrong + 20


def _shifted(ev_scores: dict, by: float) -> dict:
    return {f: {"score": v["score"] + by, "share_2mm": v["share_2mm"]} for f, v in ev_scores.items()}


def test_a_refinement_competes_only_while_the_evidence_keeps_its_base(block, obs):
    """``Hypothesis.refines`` (the knots' bend refines the stem): a refinement whose base the
    held-out faces reject (the planted tilted axis, > 30 points below the best) is set aside
    even when it scores best itself; on a base the evidence keeps it competes as any other.
    Checked by breaking it: without the set-aside the first choice is the refinement."""
    good = fit_radial(obs, block.size_mm)
    wrong = _planted(obs, good)
    hyps = [Hypothesis("radial", good, radial_recipe(good)), Hypothesis("planted", wrong, radial_recipe(wrong))]
    ev = holdout_evidence(hyps, obs)
    # 6 points above radial: more than EVIDENCE_REFINE_GAIN_MARGIN (the test below)
    ev["refined"] = _shifted(ev["radial"], 6.0)
    on_wrong = hyps + [Hypothesis("refined", good, radial_recipe(good), refines="planted")]
    res = choose(on_wrong, ev)
    assert res.chosen == "radial" and "refined set aside" in res.message, res.message
    assert "refined" not in res.accepted
    on_good = hyps + [Hypothesis("refined", good, radial_recipe(good), refines="radial")]
    assert choose(on_good, ev).chosen == "refined"
    missing = hyps + [Hypothesis("refined", good, radial_recipe(good), refines="stem")]  # no such base
    assert choose(missing, ev).chosen == "radial"


def test_a_refinement_must_beat_every_plain_hypothesis_by_the_accept_margin(block, obs):
    """A refinement (the knots' bend on the stem) whose base is not the best plain hypothesis is
    chosen only when it beats the best plain hypothesis by more than
    ``EVIDENCE_REFINE_GAIN_MARGIN``: H11's fold without its right face (knot cones on) scored the
    stem 5 points below the best plain hypothesis and the bend 3.2 points above it, and chosen
    the bend predicted that face at 0.3 % within 2 px (the plain one 24.9 %). Its base is kept by
    the evidence here, so only the gain decides. Checked by breaking it: without the gain rule in
    ``_set_aside`` the refinement 3.2 points ahead is chosen and this test fails."""
    from woodcam.tolerances import EVIDENCE_REFINE_GAIN_MARGIN

    good = fit_radial(obs, block.size_mm)
    hyps = [Hypothesis("radial", good, radial_recipe(good)), Hypothesis("other", good, radial_recipe(good)),
            Hypothesis("refined", good, radial_recipe(good), refines="radial")]
    ev = holdout_evidence(hyps[:1], obs)
    ev["radial"] = _shifted(ev["radial"], -5.0)  # H11's right fold: the base 5 points below the best
    ev["other"] = _shifted(ev["radial"], 5.0)
    for gain, chosen in ((3.2, "other"), (EVIDENCE_REFINE_GAIN_MARGIN + 0.5, "refined")):
        ev["refined"] = _shifted(ev["other"], gain)
        res = choose(hyps, ev)
        assert res.chosen == chosen, (gain, res.message)
    res = choose(hyps, {**ev, "refined": _shifted(ev["other"], 3.2)})
    assert "refined set aside: it scores" in res.message and "refined" not in res.accepted, res.message


def test_a_refinement_of_the_best_plain_hypothesis_takes_its_place(block, obs):
    """Where its base is the best plain hypothesis, a refinement takes the base's place even
    when it scores below it (dev seed 63311 block 2, six noisy faces: the stem 84.6 %, its knots'
    bend 72.3 %, and 72.5 -> 92.3 % within 2 mm on the cut planes when the bend is chosen),
    unless it misses more than ``EVIDENCE_REFINE_MISS_RATIO`` times what the base misses (a bend
    the faces' rings do not show). Not when another plain hypothesis beats the base. Checked by
    breaking it: without the swap in ``choose`` the first assertion fails; without the miss
    ratio in ``_set_aside`` the second."""
    from woodcam.tolerances import EVIDENCE_REFINE_MISS_RATIO

    good = fit_radial(obs, block.size_mm)
    hyps = [Hypothesis("stem", good, radial_recipe(good)), Hypothesis("other", good, radial_recipe(good)),
            Hypothesis("refined", good, radial_recipe(good), refines="stem")]
    ev = holdout_evidence(hyps[:1], obs)
    ev["stem"] = {f: {"score": 84.6, "share_2mm": 90.0} for f in ev["stem"]}
    ev["other"] = _shifted(ev["stem"], -10.0)
    ev["refined"] = _shifted(ev["stem"], -12.3)
    res = choose(hyps, ev)
    assert res.chosen == "refined" and "refined takes the place of stem" in res.message, res.message
    worse = 100.0 - EVIDENCE_REFINE_MISS_RATIO * (100.0 - 84.6) - 0.5  # misses more than twice the stem's 15.4
    res = choose(hyps, {**ev, "refined": _shifted(ev["stem"], worse - 84.6)})
    assert res.chosen == "stem" and "refined set aside: it misses" in res.message, res.message
    res = choose(hyps, {**ev, "other": _shifted(ev["stem"], 1.0)})  # the stem is not the best plain one
    assert res.chosen == "other", res.message


def test_a_plain_hypothesis_built_on_a_refinement_set_aside_says_why_it_still_competes(block, obs):
    """Sweep h8 item 1: H11 from its six photos (detected with --rule dark-line) chose
    ``stem + knot bend + residual`` (63.0 %) in a message that also said ``stem + knot bend set
    aside: its base stem scores 43.3 %, more than 15 points below the best (62.1 %)`` - a best
    below the chosen one, and the chosen field built on the one set aside, without a word on why.
    The choice is the rule's (the residual on the bend is a plain hypothesis, FIT_VERSION 15:
    the refinement rules do not reach it); the message now names the best plain rival and says
    so. H11's scores, one face each; the choice itself is unchanged."""
    good = fit_radial(obs, block.size_mm)
    names = {"radial": None, "stem": None, "stem + bend": "stem", "stem + bend + residual": None}
    hyps = [Hypothesis(n, good, radial_recipe(good), refines=r) for n, r in names.items()]
    ev = holdout_evidence(hyps[:1], obs)
    for n, score in (("radial", 62.1), ("stem", 43.3), ("stem + bend", 52.3), ("stem + bend + residual", 63.0)):
        ev[n] = {f: {"score": score, "share_2mm": 90.0} for f in ev["radial"]}
    res = choose(hyps, ev)
    assert res.chosen == "stem + bend + residual", res.message
    assert ("stem + bend set aside: its base stem scores 43.3 %, more than 15 points below the best "
            "plain hypothesis, radial (62.1 %); stem + bend + residual is built on stem + bend but competes "
            "as a plain hypothesis: the rules that set it aside apply to refinements only") in res.message, res.message
    # where the choice is not built on it, nothing is added (the five-face H11 fit chose radial)
    ev["radial"] = {f: {"score": 73.4, "share_2mm": 90.0} for f in ev["radial"]}
    res = choose(hyps, ev)
    assert res.chosen == "radial" and "built on" not in res.message, res.message
    assert "more than 15 points below the best plain hypothesis, radial (73.4 %)" in res.message, res.message


def test_fit_evidence_with_a_planted_extra_hypothesis(block, obs):
    good = fit_radial(obs, block.size_mm)
    wrong = _planted(obs, good)
    res = fit_evidence(obs, block.size_mm, n_basins=2, extra=[Hypothesis("planted", wrong, radial_recipe(wrong))])
    assert res.chosen != "planted"
    assert "planted" not in res.accepted
    assert res.scores[res.chosen]["mean"] > 90.0


def test_year_labelled_rings_are_fitted_and_judged_on_the_years_given(block, obs, monkeypatch):
    """The radial fit renumbers a labelled trace it misfits by over half a year; that is its own
    correction, not what the other hypotheses are judged on. Planted: the radial numbering moves
    one correct trace of the front face a year (as it did to a trace in rings bent round a knot,
    README "Judged on the given years"); the true field, an extra hypothesis, still predicts
    every held-out face exactly. Checked by breaking it: judged on the radial numbering, the
    truth loses points on the front face and this test fails."""
    import woodcam.inference.evidence as ev
    from woodcam.frames import FACES
    from woodcam.inference.observations import RingObservations

    real = ev.fit_radial_hypotheses
    front = obs.face == FACES.index("front")
    groups, counts = np.unique(obs.group[front], return_counts=True)
    moved = groups[np.argmax(counts)]  # the front face's longest trace

    def misnumbered(o, *args, **kw):
        fields, numbered = real(o, *args, **kw)
        years = numbered.years + (numbered.group == moved)
        return fields, RingObservations(numbered.points_mm, years, numbered.group, numbered.face)

    monkeypatch.setattr(ev, "fit_radial_hypotheses", misnumbered)
    truth = block.true_field
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WoodcamWarning)  # broken, the truth is "contradicted"
        res = fit_evidence(obs, block.size_mm, n_basins=1, candidates=("radial",),
                           extra=[Hypothesis("truth", truth, lambda o: truth)])
    scores = {face: v for face, v in res.scores["truth"].items() if face != "mean"}
    assert scores and min(scores.values()) == 100.0, scores


def test_one_face_is_unverified_and_warns(block):
    one = gather_observations(block, ["front"])
    with pytest.warns(WoodcamWarning, match="only one face"):
        res = fit_evidence(one, block.size_mm, n_basins=1, candidates=("radial",))
    assert res.unverified and res.chosen == "radial"


def test_fit_block_evidence_grid_carries_meta_and_uncertainty(block, tmp_path):
    # Three faces: with the pith refitted per fold (no leak), two faces predict the third only
    # roughly, and the evidence may say so (a warning, "contradicted" in meta); the rings inside
    # are still held to the bar below.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WoodcamWarning)
        grid = fit_block(block, "evidence", faces=["front", "top", "left"])
    assert isinstance(grid.meta["contradicted"], bool)
    assert isinstance(grid, GridField)
    assert grid.meta["method"] == "evidence" and grid.meta["chosen"] in grid.meta["scores"]
    assert grid.meta["faces"] == ["front", "top", "left"]
    assert grid.meta["size_mm"] == [float(v) for v in block.size_mm]  # the box its faces are named in
    # uncertainty grows away from the observed faces: the back-bottom-right corner is unseen
    size = np.asarray(block.size_mm)
    near = grid.uncertainty_years([[1.0, 1.0, size[2] - 1]])
    far = grid.uncertainty_years([[size[0] - 1, size[1] - 1, 1.0]])
    assert far[0] > near[0] + 0.5
    assert 0 < confidence(far)[0] < confidence(near)[0] <= 1
    loaded = GridField.load(grid.save(tmp_path / "f.npz"))
    assert loaded.meta == grid.meta
    np.testing.assert_allclose(loaded.layers["uncertainty"], grid.layers["uncertainty"])
    acc = evaluate_fit(block.true_field, grid, block.size_mm, pixel_mm=0.25)[0]
    assert acc["matched_1"] > 90.0
    # the bake report line: a part in the unseen back-right-bottom corner is the uncertain one,
    # and the face to photograph is one the fit did not see
    corner = np.random.default_rng(1).uniform(0.7, 1.0, (500, 3)) * size
    corner[:, 2] = size[2] - corner[:, 2]  # bottom
    line = uncertainty_report(grid, corner, size, "bowl")
    assert "uncertain" in line and any(f"photograph the {f} face" in line for f in ("bottom", "right", "back"))
    near_seen = np.random.default_rng(2).uniform(0.0, 0.05, (500, 3)) * size
    near_seen[:, 2] = size[2] - near_seen[:, 2]
    assert "well constrained" in uncertainty_report(grid, near_seen, size, "lid")
    assert uncertainty_report(block.true_field, corner, size) is None
    rgb = ConfidenceWood(grid).color(np.concatenate([corner[:1], near_seen[:1]]))
    assert rgb[0, 0] > rgb[1, 0] and rgb[0, 1] < rgb[1, 1]  # redder where less sure


def test_candidates_are_checked(obs, block):
    with pytest.raises(WoodcamError, match="candidates must include 'radial'"):
        fit_evidence(obs, block.size_mm, candidates=("rbf",))


def test_blend_accepted_is_the_mean_of_the_accepted_hypotheses():
    from woodcam.inference.evidence import blend_accepted

    p = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    a, b_, c = (lambda q: q[:, 0]), (lambda q: q[:, 1] + 1.0), (lambda q: 100.0 * q[:, 2])
    hyps = [Hypothesis("a", a, None), Hypothesis("b", b_, None), Hypothesis("c", c, None)]
    ev = {"a": {"front": {"score": 90.0, "share_2mm": 90.0}}, "b": {"front": {"score": 87.0, "share_2mm": 87.0}},
          "c": {"front": {"score": 40.0, "share_2mm": 40.0}}}
    res = blend_accepted(choose(hyps, ev))
    assert res.chosen == "a" and res.accepted == ["a", "b"]
    # b is within EVIDENCE_ACCEPT_MARGIN of a and blended in, c (50 points behind) is not
    np.testing.assert_allclose(res(p), (p[:, 0] + p[:, 1] + 1.0) / 2)
    assert "blended with b" in res.message
    alone = blend_accepted(choose(hyps[:1], {"a": ev["a"]}))
    np.testing.assert_allclose(alone(p), p[:, 0])


def test_blend_away_from_faces_keeps_the_chosen_field_on_the_faces():
    """The default blend (issue 12 part 7): on an observed face the chosen hypothesis alone (the
    in-sample fit is untouched), deeper than EVIDENCE_BLEND_DEPTH_MM the mean of the accepted
    ones, linear in between; a face that was not observed is 'deep' like the inside."""
    from woodcam.frames import FACES
    from woodcam.inference.evidence import blend_away_from_faces
    from woodcam.tolerances import EVIDENCE_BLEND_DEPTH_MM as D

    a, b_, c = (lambda q: q[:, 0]), (lambda q: q[:, 1] + 1.0), (lambda q: 100.0 * q[:, 2])
    hyps = [Hypothesis("a", a, None), Hypothesis("b", b_, None), Hypothesis("c", c, None)]
    ev = {"a": {"front": {"score": 90.0, "share_2mm": 90.0}}, "b": {"front": {"score": 87.0, "share_2mm": 87.0}},
          "c": {"front": {"score": 40.0, "share_2mm": 40.0}}}
    size = (50.0, 40.0, 30.0)
    seen = [FACES.index("bottom"), FACES.index("left")]  # z = 0 and x = 0
    res = blend_away_from_faces(choose(hyps, ev), size, seen)
    z = np.array([0.0, D / 4, D / 2, D, 15.0, 30.0])  # 30: on the top face, not observed
    p = np.stack([np.full(len(z), 20.0), np.full(len(z), 7.0), z], axis=1)
    w = np.array([0.0, 0.25, 0.5, 1.0, 1.0, 1.0])
    mean = (p[:, 0] + p[:, 1] + 1.0) / 2  # c is 50 points behind: not accepted, not blended
    np.testing.assert_allclose(res(p), p[:, 0] + w * (mean - p[:, 0]))
    on_left = np.array([[0.0, 7.0, 15.0]])
    np.testing.assert_allclose(res(on_left), on_left[:, 0])
    assert "blended with b" in res.message
    # a chosen field holding knot strands keeps its knots alone: no blend
    knotted = lambda q: q[:, 0]  # noqa: E731
    knotted.strands = ()
    kept = blend_away_from_faces(choose([Hypothesis("a", knotted, None)] + hyps[1:], ev), size, seen)
    np.testing.assert_allclose(kept(p), p[:, 0])


def test_blend_mode_is_checked(obs, block):
    with pytest.raises(WoodcamError, match="blend must be one of away_from_faces"):
        fit_evidence(obs, block.size_mm, blend=True)


def test_the_blend_is_judged_by_the_folds_own_predictions():
    """The default blend is used only where the leave-one-face-out evidence prefers it: its
    score per face comes from the mean of its members' fold predictions (growth time and
    gradient at the held-out points), not from its members' scores."""
    from woodcam.inference.evidence import _blend_evidence

    y = np.arange(10.0)
    grad = np.tile([1.0, 0.0, 0.0], (10, 1))  # 1 year per mm
    pred = {("a", "front"): (y + 1.5, grad, y), ("b", "front"): (y - 1.5, grad, y),  # each 1.5 mm off
            ("a", "top"): (y + 1.5, grad, y), ("b", "top"): (y + 1.5, grad, y)}
    sc = _blend_evidence(["a", "b"], pred)
    assert sc["front"] == 100.0  # the errors cancel: within 1 mm
    assert sc["top"] == 50.0     # the same error twice: within 2 mm, not 1
    assert sc["mean"] == 75.0
    del pred[("b", "top")]       # a member that could not refit a fold: no evidence there
    assert _blend_evidence(["a", "b"], pred)["top"] == 0.0


@pytest.mark.parametrize("faces, advice", [
    (["front", "top", "left", "bottom", "right", "back"],
     "every face was used: check the rings found on the right face (woodcam rings show) or trace more of them"),
    (["front", "top", "left", "bottom", "back"], "photograph the right face or trace its rings"),
    (["front", "top", "left"], "photograph the right face or trace its rings"),
])
def test_uncertainty_report_never_asks_for_a_face_that_was_photographed(faces, advice):
    """The bake report's advice: the unseen face nearest the uncertain third, and, when every
    face was photographed, not 'photograph' a face the fit already used (H11 from six photos
    was told to photograph its bottom face)."""
    size = np.array([50.0, 40.0, 30.0])
    n = 11
    x = np.linspace(0.0, size[0], n)[:, None, None] * np.ones((1, n, n))
    unc = 0.05 + 3.0 * (x / size[0]) ** 4  # sure on the left, a guess near the right face
    grid = GridField(np.zeros((n, n, n)), (0.0, 0.0, 0.0), tuple(size / (n - 1)),
                     layers={"uncertainty": unc}, meta={"faces": faces})
    pts = np.random.default_rng(0).uniform(0, 1, (3000, 3)) * size
    line = uncertainty_report(grid, pts, size, "bowl")
    assert "right third (left-right)" in line and line.endswith(advice)


@pytest.mark.parametrize("spread_years, warned", [(0.0, False), (40.0, True)])
def test_a_bake_warns_of_uncertain_rings_only(tmp_path, spread_years, warned):
    """A bake printed 'warning: the rings of this box are well constrained' (good news as a
    warning); only rings that are a guess are a warning."""
    import trimesh

    from woodcam.appearance.wood import Wood
    from woodcam.fields.grid import GridField
    from woodcam.pipeline import preview_part
    from woodcam.stock import Stock

    size = (40.0, 30.0, 20.0)
    nodes = (9, 7, 5)
    x = np.stack(np.meshgrid(*[np.linspace(0, s, k) for s, k in zip(size, nodes)], indexing="ij"), -1)
    years = np.hypot(x[..., 0] - 20.0, x[..., 2] + 60.0) / 3.0  # flat-sawn rings, 3 mm wide
    grid = GridField(years, (0.0, 0.0, 0.0), (5.0, 5.0, 5.0),
                     layers={"uncertainty": np.full(nodes, spread_years)})
    stock = Stock("test", size, Wood(grid), "a fitted block", {})
    box = trimesh.creation.box((10, 10, 10))
    box.apply_translation((20, 15, 10))
    res = preview_part(box, stock, tmp_path / "box.glb", texels_per_mm=1, obj=False, screenshot=False)
    said = [w for w in res.warnings if "rings" in w]
    assert bool(said) is warned and all("uncertain" in w for w in said), res.warnings
    assert ("well constrained" in uncertainty_report(grid, box.vertices, size, "box")) is not warned
    assert uncertainty_report(grid, box.vertices, size, "box", confident_line=False) == (
        None if not warned else uncertainty_report(grid, box.vertices, size, "box"))


def test_a_turned_fitted_block_reads_its_uncertainty_where_its_years_are(tmp_path):
    """The bake's rings line and preview's --confidence overlay read the fit's uncertainty at the
    stock's own points in the SOURCE block's frame (``stock.wood.field``): a block turned by
    '~z90' (or resized) was sure where its source is a guess and the other way round. They read
    it where the years are now (Wood.uncertainty_years), and name the face to photograph as the
    fitted block's photos do."""
    import trimesh

    from woodcam.appearance.wood import Wood
    from woodcam.pipeline import preview_part
    from woodcam.stock import Stock

    size = (40.0, 30.0, 20.0)
    nodes = (9, 7, 5)
    x = np.stack(np.meshgrid(*[np.linspace(0, s, k) for s, k in zip(size, nodes)], indexing="ij"), -1)
    years = np.hypot(x[..., 0] - 20.0, x[..., 2] + 60.0) / 3.0
    unc = np.where(x[..., 0] > 22.0, 40.0, 0.0)  # sure on the left, a guess on the right
    grid = GridField(years, (0.0, 0.0, 0.0), (5.0, 5.0, 5.0), layers={"uncertainty": unc},
                     meta={"faces": ["front", "top", "left", "bottom"]})
    wood = Wood(grid)
    turned, tsize = wood.turned("z", 1, size)  # '~z90': its (x, y, z) is the block's (y, 30 - x, z)
    assert tsize == (30.0, 40.0, 20.0) and turned.has_uncertainty
    p = np.random.default_rng(0).uniform(0, 1, (2000, 3)) * tsize
    src = np.column_stack([p[:, 1], 30.0 - p[:, 0], p[:, 2]])
    np.testing.assert_allclose(turned.uncertainty_years(p), grid.uncertainty_years(src), atol=1e-9)
    np.testing.assert_allclose(ConfidenceWood(turned).color(p), ConfidenceWood(grid).color(src), atol=1e-9)
    moved = wood.shifted((10.0, 5.0, 0.0))
    np.testing.assert_allclose(moved.uncertainty_years(p[:, [1, 0, 2]] / 2),
                               grid.uncertainty_years(p[:, [1, 0, 2]] / 2 + (10.0, 5.0, 0.0)), atol=1e-9)
    # the back third of the turned block is the source's right (unseen) third: its rings are
    # the guess, and the face to photograph is the fitted block's right face, the turned block's
    # back (both named: the third is named in the turned block's frame)
    line = uncertainty_report(turned, p, tsize, "bowl")
    assert line.startswith("the rings in the back third (front-back) of this bowl are uncertain")
    assert line.endswith("photograph the fitted block's right face (this block's back) or trace its rings")
    # a bake from the turned stock: a box at the front (the source's sure left) is not warned
    stock = Stock("test~z90", tsize, turned, "a fitted block", {})
    box = trimesh.creation.box((8, 8, 8))
    box.apply_translation((24, 8, 10))
    res = preview_part(box, stock, tmp_path / "box.glb", texels_per_mm=1, obj=False, screenshot=False)
    assert not [w for w in res.warnings if "rings" in w], res.warnings
    box.apply_translation((-18, 26, 0))  # at the back: the source's right, a guess
    res = preview_part(box, stock, tmp_path / "box2.glb", texels_per_mm=1, obj=False, screenshot=False)
    assert [w for w in res.warnings if "rings" in w and "uncertain" in w], res.warnings


def test_a_resized_stock_is_told_the_fitted_blocks_nearest_face():
    """A stock cut out of a fitted block (``--stock WxDxH --stock-origin``, Wood.shifted) was
    told the face nearest its uncertain third in its own box: its right third, 10..50 mm into a
    100 mm block, is nearer the fitted block's LEFT face (the one to photograph), not its right."""
    from woodcam.appearance.wood import Wood
    from woodcam.stock import Stock, resize_stock

    size = (100.0, 30.0, 20.0)
    nodes = (21, 7, 5)
    x = np.stack(np.meshgrid(*[np.linspace(0, s, k) for s, k in zip(size, nodes)], indexing="ij"), -1)
    grid = GridField(x[..., 0] / 3.0, (0.0, 0.0, 0.0), (5.0, 5.0, 5.0),
                     layers={"uncertainty": 0.02 * x[..., 0]},  # a guess further right
                     meta={"faces": ["front", "back", "top", "bottom"], "size_mm": list(size)})
    small = resize_stock(Stock("test", size, Wood(grid), "a fitted block", {}), (40.0, 30.0, 20.0),
                         (10.0, 0.0, 0.0))
    p = np.random.default_rng(0).uniform(0, 1, (3000, 3)) * small.size_mm
    line = uncertainty_report(small.wood, p, small.size_mm, "bowl")
    assert line.startswith("the rings in the right third (left-right) of this bowl are uncertain")
    assert line.endswith("photograph the fitted block's left face or trace its rings")
    # the fitted block itself: its own right third, nearest its right face, as before
    whole = uncertainty_report(grid, np.random.default_rng(0).uniform(0, 1, (3000, 3)) * size, size, "bowl")
    assert whole.endswith("photograph the right face or trace its rings")


def test_a_stock_cut_at_the_fitted_blocks_corner_is_a_cut_piece():
    """Sweep h16 item C: resize_stock at origin (0, 0, 0) kept the parent's wood (no
    Wood.shifted), so the cut piece passed for the fitted block (in_source_frame) and the advice
    said "photograph the left face": this 40 mm stock's left, not the 100 mm fitted block's."""
    from woodcam.appearance.wood import Wood
    from woodcam.stock import Stock, resize_stock

    size = (100.0, 30.0, 20.0)
    x = np.stack(np.meshgrid(*[np.linspace(0, s, k) for s, k in zip(size, (21, 7, 5))], indexing="ij"), -1)
    grid = GridField(x[..., 0] / 3.0, (0.0, 0.0, 0.0), (5.0, 5.0, 5.0),
                     layers={"uncertainty": 0.02 * x[..., 0]},  # a guess further right
                     meta={"faces": ["front", "back", "top", "bottom"], "size_mm": list(size)})
    small = resize_stock(Stock("test", size, Wood(grid), "a fitted block", {}), (40.0, 30.0, 20.0))
    assert not small.wood.in_source_frame and small.spec == "test[40x30x20]"
    p = np.random.default_rng(0).uniform(0, 1, (3000, 3)) * small.size_mm
    np.testing.assert_allclose(small.wood.years(p), grid(p), atol=1e-9)  # the same wood, unmoved
    line = uncertainty_report(small.wood, p, small.size_mm, "bowl")
    assert line.startswith("the rings in the right third (left-right) of this bowl are uncertain")
    assert line.endswith("photograph the fitted block's left face or trace its rings"), line


def test_a_field_with_an_uncertainty_layer_but_no_reader_has_none():
    """Wood.has_uncertainty tested the layer alone (evaluate's copy also wanted a callable
    uncertainty_years): a field with an 'uncertainty' layer and no reader was said to carry
    one, and Wood.uncertainty_years raised AttributeError. One test now, for both."""
    from woodcam.appearance.wood import Wood
    from woodcam.fields.base import has_uncertainty

    class Layered:
        layers = {"uncertainty": np.zeros((2, 2, 2))}

        def __call__(self, p):
            return np.asarray(p, float)[:, 0]

    field = Layered()
    wood = Wood(field)
    assert not has_uncertainty(field) and not wood.has_uncertainty
    np.testing.assert_array_equal(wood.uncertainty_years([[1.0, 2.0, 3.0]]), [0.0])
    assert uncertainty_report(wood, [[1.0, 2.0, 3.0]], (4.0, 4.0, 4.0)) is None
    grid = GridField(np.zeros((2, 2, 2)), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0),
                     layers={"uncertainty": np.ones((2, 2, 2))})
    assert has_uncertainty(grid) and Wood(grid).has_uncertainty
