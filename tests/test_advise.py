"""Placement advice (woodcam place): knots avoided, long thin parts along the grain."""

from __future__ import annotations

import manifold3d
import numpy as np
import pytest

from woodcam.advise import advise_placement
from woodcam.cad.place import place_part
from woodcam.errors import WoodcamError
from woodcam.stock import open_stock


@pytest.fixture(scope="module")
def knotty():
    return open_stock("builtin:knotty")


def test_a_small_part_is_moved_off_the_knots(knotty):
    part = manifold3d.Manifold.cube([24.0, 18.0, 10.0])
    advice = advise_placement(part, knotty, rotations="z90", candidates=300)
    best, worst = advice.ranked[0], advice.ranked[-1]
    assert worst.terms["knots"] > 0.05  # the block has knots where a part could go
    assert best.terms["knots"] == 0.0
    # check the advice independently: the placed solid, sampled through its whole volume
    placed, _ = place_part(part, best.ops, knotty.size_mm)
    lo, hi = np.asarray(placed.bounding_box()).reshape(2, 3)
    grid = np.stack(np.meshgrid(*[np.linspace(a + 0.2, b - 0.2, 12) for a, b in zip(lo, hi)],
                                indexing="ij"), axis=-1).reshape(-1, 3)
    assert knotty.wood.features(grid)["knot"].max() < 0.5
    bad, _ = place_part(part, worst.ops, knotty.size_mm)
    lo, hi = np.asarray(bad.bounding_box()).reshape(2, 3)
    grid = np.stack(np.meshgrid(*[np.linspace(a + 0.2, b - 0.2, 12) for a, b in zip(lo, hi)],
                                indexing="ij"), axis=-1).reshape(-1, 3)
    assert knotty.wood.features(grid)["knot"].max() > 0.5


def test_a_long_thin_part_is_turned_along_the_grain():
    """The flat-sawn block turned a quarter about z runs its fibres along Y: a 60 mm stick
    modelled along X must be turned to run along Y."""
    stock = open_stock("builtin:flat-sawn~z90")
    stick = manifold3d.Manifold.cube([60.0, 8.0, 8.0])
    advice = advise_placement(stick, stock, rotations="z90", candidates=200)
    best = advice.ranked[0]
    assert best.ops[0] in ("rotate:z:90", "rotate:z:270")
    axis = best.matrix[:3, :3] @ np.array([1.0, 0.0, 0.0])
    centre = best.matrix[:3, 3]
    grain = stock.wood.features(centre[None])["grain"][0]
    runout_deg = np.degrees(np.arccos(abs(axis @ grain)))
    assert runout_deg < 10.0  # the builtin's fibres dip 4 degrees: the stick follows them
    assert advice.ranked[-1].terms["runout"] > 0.7  # across the grain, the worst


def test_no_orientation_fits_is_a_clear_error(knotty):
    with pytest.raises(WoodcamError, match="fits the 100x80x50 mm block in none"):
        advise_placement(manifold3d.Manifold.cube([120.0, 10.0, 10.0]), knotty, rotations="none")
    with pytest.raises(WoodcamError, match="rotations must be one of"):
        advise_placement(manifold3d.Manifold.cube([10.0, 10.0, 10.0]), knotty, rotations="any")


def test_no_fit_offers_only_the_fixes_that_make_the_part_fit(knotty):
    """A 200 mm stick in the 100x80x50 mm block was told to 'allow more rotations (--rotations
    all90), a smaller margin (--margin) or a bigger block': the first two cannot help (it is
    longer than every side). Now each fix offered makes it fit: all90 where an orientation of the
    24 fits, the largest margin that fits, and the block that holds the part as modelled."""
    def no_fit(size, **kw):
        with pytest.raises(WoodcamError) as err:
            advise_placement(manifold3d.Manifold.cube(size), knotty, candidates=4, **kw)
        return str(err.value).partition("margin; ")[2]

    assert no_fit([200.0, 20.0, 10.0]) == ("a bigger block (at least 202x80x50 mm for the part as modelled "
                                          "with the margin; a built-in block takes it as builtin:NAME:WxDxH)")
    assert no_fit([10.0, 10.0, 60.0]).startswith("allow more rotations (--rotations all90) or a bigger block "
                                                  "(at least 100x80x62 mm ")
    assert no_fit([90.0, 60.0, 10.0], margin_mm=8.0).startswith("a margin of at most 5 mm (--margin) or a "
                                                                 "bigger block (at least 106x80x50 mm ")
    assert no_fit([10.0, 10.0, 60.0], rotations="all90", margin_mm=30.0).startswith(
        "a margin of at most 20 mm (--margin) or a bigger block (at least 100x80x120 mm ")


def test_place_warns_of_a_part_in_inches_and_advises_only_what_is_left(knotty):
    """A part file in inches (read as mm: 25.4 x too small) was ranked as a speck without a
    word; a part too long in every one of the 24 orientations was told to 'allow more
    rotations'."""
    from woodcam.errors import WoodcamWarning

    with pytest.warns(WoodcamWarning, match=r"25.4 times larger it would still fit.*in inches scale it first: "
                                           r"woodcam.cad.place.place_part\(part, \['scale:25.4'\]"):
        advise_placement(manifold3d.Manifold.cube([3.0, 2.0, 0.5]), knotty, candidates=8)
    with pytest.raises(WoodcamError, match=r"with a 1 mm margin; a bigger block \(at least 122x80x50 mm"):
        advise_placement(manifold3d.Manifold.cube([120.0, 10.0, 10.0]), knotty, rotations="all90")
    with pytest.raises(WoodcamError, match=r"'z90' orientations with a 1 mm margin; a bigger block \(at least 122x80x50"):
        advise_placement(manifold3d.Manifold.cube([120.0, 10.0, 10.0]), knotty, rotations="z90")  # no all90: none fits


def test_the_part_report_warns_of_short_grain_only_across_the_fibres():
    import trimesh

    from woodcam.advise import part_report

    stick = trimesh.creation.box((70.0, 10.0, 8.0))
    stick.apply_translation([50.0, 40.0, 25.0])
    along = part_report(stick, open_stock("builtin:flat-sawn"))  # fibres along X, like the stick
    across = part_report(stick, open_stock("builtin:flat-sawn~z90"))  # fibres along Y
    assert along["volume_mm3"] == pytest.approx(5600.0)
    assert along["yield"] == pytest.approx(5600.0 / (100 * 80 * 50), abs=1e-4)
    assert all(r["runout_deg"] < 10 for r in along["regions"])
    assert not any("short grain" in w for w in along["warnings"])
    assert all(r["runout_deg"] > 80 for r in across["regions"])
    assert sum("short grain" in w for w in across["warnings"]) == 3
    # end grain: the stick's two 10 x 8 ends out of its surface, when fibres run along it
    ends = 2 * 10 * 8 / (2 * (70 * 10 + 70 * 8 + 10 * 8))
    assert along["end_grain"] == pytest.approx(ends, abs=0.03)


def test_knot_spots_find_the_knots_through_a_surface(knotty):
    import trimesh

    from woodcam.advise import knot_spots

    box = trimesh.creation.box(knotty.size_mm)
    box.apply_translation(np.asarray(knotty.size_mm) / 2)
    spots = knot_spots(box, knotty.wood)
    assert len(spots) >= 2  # the board through a whorl shows several knots on its faces
    at = np.array([s["at_mm"] for s in spots])
    assert (knotty.wood.features(at)["knot"] > 0.5).all()  # every spot sits on knot wood
    clear = open_stock("builtin:flat-sawn")
    assert knot_spots(box, clear.wood) == []


def test_every_placement_panel_names_the_same_terms(knotty, monkeypatch, tmp_path):
    """QA item 6: the "worst" panel's caption left out end grain and runout."""
    import woodcam.view.compare
    from woodcam.advise import render_advice

    titles = []
    monkeypatch.setattr(woodcam.view.compare, "render_side_by_side",
                        lambda meshes, woods, size, t, png, **kw: titles.extend(t))
    part = manifold3d.Manifold.cube([20.0, 10.0, 8.0])
    advice = advise_placement(part, knotty, rotations="none", candidates=50)
    render_advice(advice, part, knotty, tmp_path / "p.png", top=2)
    assert len(titles) == 3 and titles[-1].startswith("worst:")
    for title in titles:
        assert all(f"{term} " in title for term in ("score", "knots", "pith", "end grain",
                                                    "runout")), title


def test_the_picture_draws_at_most_max_panels_best_placements(knotty, monkeypatch, tmp_path):
    """'place --top 100000' drew a panel per placement (about 1.5 s each: minutes) into a
    picture too wide to read; --top is the table's, the picture stops at MAX_PANELS."""
    import woodcam.view.compare
    from woodcam.advise import MAX_PANELS, render_advice

    titles = []
    monkeypatch.setattr(woodcam.view.compare, "render_side_by_side",
                        lambda meshes, woods, size, t, png, **kw: titles.extend(t))
    part = manifold3d.Manifold.cube([20.0, 10.0, 8.0])
    advice = advise_placement(part, knotty, rotations="none", candidates=50)
    assert len(advice.ranked) > MAX_PANELS + 1
    render_advice(advice, part, knotty, tmp_path / "p.png", top=100)
    assert len(titles) == MAX_PANELS + 1 == 11, len(titles)
    assert titles[MAX_PANELS - 1].startswith(f"#{MAX_PANELS} ") and titles[-1].startswith("worst:")


def test_the_report_quotes_the_surface_knot_share_its_warning_gives(knotty):
    """The report's line gave the knot share of the surface and the wood 1-3 mm under it
    (19.8 %) beside a warning 'knots show on 15.3 % of the surface': two numbers for one thing."""
    import re

    import trimesh

    from woodcam.advise import part_report, report_rows, report_text

    for x in np.linspace(20, 280, 6):  # some of these boxes cross a knot of the knotty block
        box = trimesh.creation.box((30, 30, 30))
        box.apply_translation((x, knotty.size_mm[1] / 2, knotty.size_mm[2] / 2))
        rep = part_report(box, knotty)
        if rep["knots_surface"] > 0 and rep["knots"] != rep["knots_surface"]:
            break
    else:
        pytest.fail("no box showed a knot on its surface")
    text = report_text(rep, "box")
    warned = re.search(r"knots show on ([\d.]+) % of the surface", text).group(1)
    assert f"knots {warned} % of the surface (" in text
    # the regions' share counts the wood under the surface too, labelled so (it was a bare
    # 'knots 19.8 %' under a first line that leads with the surface's share), on the review page too
    for r in rep["regions"]:
        assert f"knots {100 * r['knots']:.1f} % with the wood 1-3 mm under it" in text
        assert report_rows(rep)[r["region"]].endswith(f"knots {100 * r['knots']:.1f} % with the wood "
                                                      "1-3 mm under it")
    old = {k: v for k, v in rep.items() if k != "knots_surface"}  # a report written before
    assert f"knots {100 * rep['knots']:.1f} %, pith" in report_text(old, "box")


def test_the_report_volume_is_the_summarys_for_a_tiny_part_and_a_normal_one():
    """Sweep h13 item 2: the report rounded the volume to 0.1 mm^3, so a 1.52 mm^3 part read
    9.154e-05 in^3 in the report under the bake summary's 9.263e-05 in^3 (the same mesh's
    volume, PartPreview.volume_mm3): now both are the mesh's volume, to 7 significant digits."""
    import trimesh

    from woodcam.advise import part_report
    from woodcam.units import fmt_volume

    stock = open_stock("builtin:flat-sawn")
    for radius in (0.715, 20.0):  # about 1.5 mm^3, and a normal part of about 33,500 mm^3
        ball = trimesh.creation.icosphere(subdivisions=3, radius=radius)
        ball.apply_translation([50.0, 40.0, 25.0])
        rep = part_report(ball, stock, samples=500)
        assert rep["volume_mm3"] == pytest.approx(ball.volume, rel=1e-6)
        for units in ("mm", "inch"):
            assert fmt_volume(rep["volume_mm3"], units) == fmt_volume(ball.volume, units)
    assert fmt_volume(1.5179342) == "1.518 mm^3" and fmt_volume(33_493.4) == "33493 mm^3"  # not "2 mm^3"


class _SlabWood:
    """An analytic wood for known answers: fibres along X, the pith a line along Z at
    ``pith_xy`` (years = distance / 2.5 mm), and one flat knot, z 16-18 mm over x 20-40 mm,
    y 15-35 mm, whose own years (along its branch) are 0.5: knot wood, not stem pith."""

    def __init__(self, pith_xy=(30.0, 25.0), grain=(1.0, 0.0, 0.0)):
        self.pith_xy = np.asarray(pith_xy, float)
        self.grain = np.asarray(grain, float)

    def features(self, p):
        p = np.asarray(p, float)
        knot = ((p[:, 2] >= 16) & (p[:, 2] <= 18) & (p[:, 0] >= 20) & (p[:, 0] <= 40)
                & (p[:, 1] >= 15) & (p[:, 1] <= 35))
        years = np.where(knot, 0.5, np.hypot(*(p[:, :2] - self.pith_xy).T) / 2.5)
        return {"years": years, "knot": knot.astype(float), "grain": np.tile(self.grain, (len(p), 1))}


def _slab_stock(pith_xy=(30.0, 25.0), grain=(1.0, 0.0, 0.0)):
    from woodcam.stock import Stock

    return Stock("slab", (100.0, 80.0, 50.0), _SlabWood(pith_xy, grain))


def test_the_part_report_terms_match_an_analytic_wood():
    """A 40 x 30 x 20 mm box (x 10-50, y 10-40, z 0-20) over _SlabWood: no knot on the surface
    or 1 mm under it, but 3 mm under the top face (z 17) the knot covers 400 of the surface's
    5200 mm^2 (one of three depths); the pith (within 5 mm of the axis at x 30, y 25) crosses the
    top and bottom faces (25 pi mm^2 each) at every depth but the top's 3 mm, which is knot;
    end grain is the two 30 x 20 mm ends."""
    import trimesh

    from woodcam.advise import part_report

    box = trimesh.creation.box((40.0, 30.0, 20.0))
    box.apply_translation((30.0, 25.0, 10.0))
    rep = part_report(box, _slab_stock(), samples=20000)
    assert rep["knots_surface"] == 0.0
    assert rep["knots"] == pytest.approx(400 / 5200 / 3, rel=0.1)
    assert rep["pith"] == pytest.approx(5 * 25 * np.pi / 5200 / 3, rel=0.1)
    assert rep["end_grain"] == pytest.approx(2 * 30 * 20 / 5200, rel=0.05)
    assert rep["warnings"] == ["a knot lies 1-3 mm under the surface (it may show after sanding)",
                               "the pith (within 2 years) reaches the part: expect checks"]
    assert all(r["runout_deg"] < 1 for r in rep["regions"])
    # the pith far from the part: none, and no warning of it
    assert part_report(box, _slab_stock((90.0, 70.0)), samples=2000)["pith"] == 0.0
    # end grain is within 45 degrees of the fibres: tilted 50 degrees from X toward Z, the
    # 40 x 30 mm top and bottom are end grain and the ends are not
    tilted = (np.cos(np.radians(50)), 0.0, np.sin(np.radians(50)))
    rep = part_report(box, _slab_stock(grain=tilted), samples=4000)
    assert rep["end_grain"] == pytest.approx(2 * 40 * 30 / 5200, rel=0.05)


def test_placements_score_pith_keep_the_margin_and_weigh_as_asked():
    """A 10 mm cube in _SlabWood with the pith through the block's centre (x 50, y 40): a
    placement scores pith exactly when the cube comes within 5 mm (2 years) of the axis; every
    placement keeps margin_mm from the faces, and the grid reaches it; score is the weighted sum
    of the terms with the weights given; a cube is not long and thin, so no runout; end grain
    is the turned part's."""
    from woodcam.advise import DEFAULT_WEIGHTS

    stock = _slab_stock((50.0, 40.0))
    part = manifold3d.Manifold.cube([10.0, 10.0, 10.0])
    weights = {"pith": 10.0, "end_grain": 0.0}
    w = {**DEFAULT_WEIGHTS, **weights}
    # all90: the cube turned every way (runout); none: a finer grid, some cubes on the knot
    for rotations in ("all90", "none"):
        advice = advise_placement(part, stock, rotations=rotations, candidates=500, margin_mm=2.0,
                                  weights=weights)
        assert advice.weights == w and w != DEFAULT_WEIGHTS
        near, on_knot = [], []
        for p in advice.ranked:
            assert p.score == pytest.approx(sum(w[k] * v for k, v in p.terms.items()), abs=1e-9)
            assert p.terms["runout"] < 0.05
            placed, _ = place_part(part, p.ops, stock.size_mm)
            lo, hi = np.asarray(placed.bounding_box()).reshape(2, 3)
            assert (lo >= 2.0 - 1e-6).all() and (hi <= np.asarray(stock.size_mm) - 2.0 + 1e-6).all(), p.ops
            near.append(lo.min() < 2.0 + 1e-6)
            on_knot.append(p.terms["knots"] > 0)
            d = np.linalg.norm(np.maximum(0.0, np.maximum(lo[:2] - (50, 40), (50, 40) - hi[:2])))
            if d < 4.5:
                assert p.terms["pith"] > 0, (p.ops, d)
            elif d > 5.5:  # knot wood (its own years 0.5) is not pith
                assert p.terms["pith"] == 0, (p.ops, d)
        assert any(near)
        assert advice.ranked[0].terms["pith"] == 0 and advice.ranked[-1].terms["pith"] > 0.1
    assert any(on_knot)
    # end grain is scored on the turned part: a 60 x 10 x 10 mm stick along the fibres (X) shows
    # its two 10 x 10 mm ends; turned a quarter, its 60 x 10 mm sides face along the fibres
    stick = manifold3d.Manifold.cube([60.0, 10.0, 10.0])
    for p in advise_placement(stick, _slab_stock((90.0, 70.0)), rotations="z90", candidates=8).ranked:
        quarter = p.ops[0] in ("rotate:z:90", "rotate:z:270")
        assert p.terms["end_grain"] == pytest.approx(1200 / 2600 if quarter else 200 / 2600, abs=0.03), p.ops


def test_the_candidates_asked_for_are_scored_when_only_some_orientations_fit(knotty):
    """``--candidates`` was split over every orientation, fitting or not: a 90 mm stick fits the
    100 x 80 x 50 mm block in 8 of the 24 axis-aligned orientations (its length along X), so
    200 asked scored 8 x 2^3 = 64; split over the 8 that fit, 8 x 3^3 = 216."""
    stick = manifold3d.Manifold.cube([90.0, 10.0, 10.0])
    advice = advise_placement(stick, knotty, rotations="all90", candidates=200, samples=100)
    orientations = {tuple(np.round(p.matrix[:3, :3]).astype(int).ravel()) for p in advice.ranked}
    assert len(orientations) == 8
    assert all(abs(p.matrix[:3, :3] @ np.array([1.0, 0.0, 0.0]))[0] > 0.99 for p in advice.ranked)
    assert advice.candidates == len(advice.ranked) == 216


def test_the_report_names_its_thirds_by_the_blocks_ends_whatever_the_eigenvector_sign(monkeypatch):
    """The thirds ran along an eigenvector whose sign numpy leaves arbitrary: the same bowl on
    the H11 cube baked at 5 and at 10 texels/mm had its knots in the 'last third' and then in the
    'first', and nothing said which end was first. A stick along X through _SlabWood's knot
    (x 20-40, z 16-18: only in the stick's left part, x 10-90) has its knots in the left third,
    and the report is the same with every eigenvector negated."""
    import trimesh

    from woodcam.advise import part_report

    stick = trimesh.creation.box((80.0, 10.0, 10.0))
    stick.apply_translation((50.0, 25.0, 17.0))
    rep = part_report(stick, _slab_stock(), samples=6000)
    assert [r["region"] for r in rep["regions"]] == ["left third", "middle third", "right third"]
    # the knot band meets the stick's y faces over 2 mm of height: 2 * 2 * 16.7 mm^2 of the left
    # third's 1167 mm^2 of surface, 2 * 2 * 3.3 of the middle's 1067 (the wood under the y
    # faces alike; under the z faces none)
    left, middle, right = (r["knots"] for r in rep["regions"])
    assert left == pytest.approx(4 * 16.67 / 1167, rel=0.25)
    assert middle == pytest.approx(4 * 3.33 / 1067, abs=0.006) and right == 0.0

    eigh = np.linalg.eigh
    monkeypatch.setattr(np.linalg, "eigh", lambda a: (eigh(a)[0], -eigh(a)[1]))
    assert part_report(stick, _slab_stock(), samples=6000) == rep


class Grey:
    """A user's wood that only draws colours (grey): a method color, no features."""

    def color(self, points_mm, normals):
        return np.full((len(points_mm), 3), 0.5)


def _colour_only_stock():
    """A 50 x 50 x 30 mm Stock of :class:`Grey`."""
    from woodcam.stock import Stock

    return Stock("mine", (50.0, 50.0, 30.0), Grey())


def _box_in_it():
    """A 10 mm cube in the middle of :func:`_colour_only_stock`."""
    import trimesh

    box = trimesh.creation.box((10, 10, 10))
    box.apply_translation((25, 25, 15))
    return box


def test_a_wood_that_only_draws_colours_is_refused_by_placement_advice_naming_it():
    """A Stock of a user's colour-only wood (a method color, no features) is a stock (baked,
    viewed), but advise_placement failed deep in its scoring with AttributeError "'Grey' object
    has no attribute 'features'" (part_report and knot_spots the same). Each refuses it at its
    door naming the argument, the rule, the kind given and the fix."""

    from woodcam.advise import knot_spots, part_report

    stock, box = _colour_only_stock(), _box_in_it()
    said = (r"{}: {} must read the wood, a method features\(points_mm \(n, 3\)\) -> dict with 'knot', 'years' "
            r"and 'grain' .*; got Grey, which only draws colours; open the stock with open_stock or pass Wood\(field\)")
    with pytest.raises(WoodcamError, match=said.format("advise_placement", r"stock\.wood")):
        advise_placement(manifold3d.Manifold.cube([10.0, 10.0, 10.0]), stock, candidates=4, samples=50)
    with pytest.raises(WoodcamError, match=said.format("part_report", r"stock\.wood")):
        part_report(box, stock, samples=50)
    with pytest.raises(WoodcamError, match=said.format("knot_spots", "wood")):
        knot_spots(box, stock.wood, samples=50)


def test_a_part_previewed_in_a_wood_that_only_draws_colours_is_baked_without_its_report(tmp_path):
    """preview_part of a Stock whose wood only draws colours (a user's, no features) failed with
    "field must be callable as field(points_mm) -> years; got Grey", from the rings' uncertainty
    line (Wood(wood)), nothing written, though such a stock is one to bake and view. The part is
    baked in its colours and written; the part report, which reads knots, pith and fibres the
    wood has not got, is left out with a WoodcamWarning saying why and how to have it; the
    uncertainty line, of a fitted field, is not asked of a wood that holds none."""
    import trimesh

    from woodcam.errors import WoodcamWarning
    from woodcam.pipeline import preview_part

    stock, box = _colour_only_stock(), _box_in_it()
    with pytest.warns(WoodcamWarning, match=r"p: no part report \(knots, pith, end grain, grain runout\): "
                      r"stock\.wood \(Grey\) only draws colours, .*open the stock with open_stock or pass "
                      r"Wood\(field\)") as said:
        result = preview_part(box, stock, tmp_path / "p.glb", texels_per_mm=2, obj=False, screenshot=False)
    assert said[0].filename == __file__  # the caller's line
    assert set(result.files) == {"glb"} and result.files["glb"].is_file() and result.report == {}
    assert not list(tmp_path.glob("p_report.*"))
    texture = trimesh.load(result.files["glb"], force="mesh").visual.material.baseColorTexture
    assert np.isin(np.asarray(texture.convert("RGB")), (127, 128)).mean() > 0.5  # the wood's grey


def test_a_woodified_object_has_no_pith_to_warn_of(tmp_path):
    """A block of a woodified object (``woodify:DIR/field.npz``, set straight or turned in the
    grown object) whose year 0 is the surface of the mesh it grew from: a part across year 0 is
    not warned of a pith and scores none, in the report and the placement terms alike (it was
    'the pith (within 2 years) reaches the part: expect checks' of the input mesh); the same
    wood read as a stem's still is."""
    import trimesh

    from woodcam.advise import part_report
    from woodcam.woodify.field import WoodifiedField
    from woodcam.woodify.speed import GrowthSpeed

    g = np.mgrid[0:41, 0:41, 0:41].astype(float) * 2.0 - 40.0
    grown = WoodifiedField(np.hypot(g[0], g[1]), (-40.0, -40.0, -40.0), 2.0,
                           GrowthSpeed(velocity_mm=100.0, time_scale_years=30.0), 20.0)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    box = trimesh.creation.box((20.0, 20.0, 10.0))
    box.apply_translation((20.0, 20.0, 10.0))  # across the block's centre, year 0 there
    for name, rot in (("straight", None), ("turned", turn)):
        grown.placed((40.0, 40.0, 20.0), (0.0, 0.0, 0.0), rot).save(tmp_path / f"{name}.npz")
        stock = open_stock(f"woodify:{tmp_path / f'{name}.npz'}")
        assert not stock.wood.has_pith
        assert stock.wood.years(np.array([[20.0, 20.0, 10.0]]))[0] < 2  # year 0 crosses the part
        rep = part_report(box, stock, samples=2000)
        assert rep["pith"] == 0.0 and not any("pith" in w for w in rep["warnings"]), (name, rep)
        advice = advise_placement(box, stock, rotations="none", candidates=8, margin_mm=0.5)
        assert all(p.terms["pith"] == 0.0 for p in advice.ranked), name
    # the same years as a stem's: its year 0 is a pith
    stock.wood.field.has_pith = True
    rep = part_report(box, stock, samples=2000)
    assert rep["pith"] > 0 and "the pith (within 2 years) reaches the part: expect checks" in rep["warnings"]
