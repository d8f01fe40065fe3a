"""Computational parquetry (seed 002): single use, coverage, fabricability, crops, errors.

Every check on cut paths reads the written SVG/DXF files back (svgelements, ezdxf); nothing is
taken from memory.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.parquetry import (
    ParquetryJob,
    ParquetryParams,
    Veneer,
    build_parquetry,
    feature_cost,
    load_scan,
    read_job,
    slice_veneers,
    write_job,
)
from woodcam.parquetry.cutpaths import (
    check_piece,
    rasterise,
    read_dxf_pieces,
    read_svg_pieces,
    read_svg_segments,
)
from woodcam.parquetry.features import rotate
from woodcam.parquetry.output import write_parquetry

PPM = 2.0        # working resolution of the small test runs (px/mm)


@pytest.fixture(scope="module")
def sheets():
    """Two book-matched walnut-ish leaves and one maple leaf, 120 x 80 mm at 2 px/mm."""
    from woodcam.stock import open_stock

    a = slice_veneers(open_stock("builtin:flat-sawn", species="walnut"), 2, (120, 80),
                      px_per_mm=PPM, id_prefix="walnut")
    b = slice_veneers(open_stock("builtin:rift", species="maple"), 1, (120, 80),
                      px_per_mm=PPM, id_prefix="maple")
    return a + b


@pytest.fixture(scope="module")
def finished(sheets, tmp_path_factory):
    """One complete run with seams on a crop of skimage's camera, written to files."""
    from skimage import data

    target = data.camera()[40:300, 120:380].astype(np.float32) / 255.0
    prm = ParquetryParams(image_size_mm=70, px_per_mm=PPM)
    run = build_parquetry(target, sheets, prm)
    out = tmp_path_factory.mktemp("parq")
    from woodcam.export import export_glb

    res = write_parquetry(run, out, glb_writer=export_glb)
    return run, out, res


def test_run_is_complete_with_seams(finished):
    run, out, _res = finished
    assert run.complete and not run.message
    p = run.panels[0]
    assert p.cells.shape == (5, 5) and p.seams_v is not None and len(p.seams_v) == 4
    for name in ("render.png", "baseline.png", "target_matched.png", "assembly.svg", "result.json",
                 "panel.glb"):
        assert (out / name).is_file(), name
    result = json.loads((out / "result.json").read_text())
    assert len(result["patches"]) == 25
    assert result["fabricability"]["problems"] == {}


def test_panel_size_mm_is_in_mm(finished):
    """Parquetry.size_mm is the panel's (width, height) in mm, not its pixels: the 70 mm panel of
    5 x 5 patches of 14 mm at 2 px/mm is 70 x 70 mm (140 x 140 px)."""
    run, out, _res = finished
    p = run.panels[0]
    assert p.matched.shape == (140, 140)
    assert p.size_mm == pytest.approx((70.0, 70.0))
    assert p.size_mm == pytest.approx(json.loads((out / "result.json").read_text())["summary"]["panels"][0]["size_mm"])


def test_result_json_size_is_the_cut_files_size_when_a_patch_is_not_whole_pixels(sheets, tmp_path):
    """result.json's size_mm was cells x patch_mm, the cut files' size pixels / px_per_mm: a
    patch is a whole number of pixels (patch_px, rounded), so 6.8 mm patches at 2 px/mm are
    14 px (7 mm) and the 3 x 3 panel 21 mm, where result.json said 20.4. Both are
    Parquetry.size_mm now."""
    import re

    prm = ParquetryParams(image_size_mm=20, patch_mm=6.8, px_per_mm=PPM)
    assert prm.patch_px == 14 and prm.patch_mm * PPM != prm.patch_px
    run = build_parquetry(np.full((40, 40), 0.5, np.float32), sheets[:1], prm)
    write_parquetry(run, tmp_path)
    p = run.panels[0]
    assert p.size_mm == pytest.approx((21.0, 21.0))
    summary = json.loads((tmp_path / "result.json").read_text())["summary"]
    assert summary["panels"][0]["size_mm"] == pytest.approx(list(p.size_mm))
    svg = (tmp_path / "assembly.svg").read_text()
    assert re.search(r'width="([\d.]+)mm" height="([\d.]+)mm"', svg).groups() == ("21.000", "21.000")


def test_single_use_on_every_sheet_from_svg_and_dxf(finished):
    """Rasterise every parsed-back cut path onto its sheet: no sheet pixel is used twice, and
    only usable wood is used; the kerf keeps pieces apart by at least kerf - 1 px. The DXF's
    pieces are the SVG's, each in its place: the DXF read back (y down) covers the same area,
    and in the file itself (y up) a piece spans ``H - y`` of the SVG's ``y``."""
    import ezdxf
    from ezdxf import bbox
    from shapely.geometry import Polygon

    run, out, _ = finished
    kerf = run.params.kerf
    used = placed = 0
    for v in run.veneers:
        f_svg = out / f"veneer_{v.id}.svg"
        if not f_svg.exists():
            continue
        _W, H = v.size_mm
        h, w = v.mask.shape
        svg, dxf = read_svg_pieces(f_svg), read_dxf_pieces(out / f"veneer_{v.id}.dxf", H)
        for polys in (svg, dxf):
            n = rasterise(polys, (h, w), v.px_per_mm)
            assert n.max() == 1, f"sheet {v.id}: a pixel is used by {n.max()} pieces"
            assert not (n > 0)[~v.mask].any()
            used += len(polys)
        assert dxf.keys() == svg.keys()
        msp = ezdxf.readfile(str(out / f"veneer_{v.id}.dxf")).modelspace()
        for pid, poly in svg.items():
            a, b = Polygon(poly), Polygon(dxf[pid])
            assert a.symmetric_difference(b).area < 0.01 * a.area, (v.id, pid)
            ext = bbox.extents(msp.query(f'*[layer=="PIECE_{pid}"]'))
            assert (ext.extmin.y, ext.extmax.y) == pytest.approx(
                (H - poly[:, 1].max(), H - poly[:, 1].min()), abs=0.05), (v.id, pid)
            assert (ext.extmin.x, ext.extmax.x) == pytest.approx(
                (poly[:, 0].min(), poly[:, 0].max()), abs=0.05), (v.id, pid)
            placed += 1
        # Pieces grown by half the kerf (less half a pixel of rasterisation) still never touch.
        from shapely.geometry import Polygon

        grown = {k: np.asarray(Polygon(q).buffer(kerf / 2 - 0.5 / v.px_per_mm).exterior.coords)
                 for k, q in read_svg_pieces(f_svg).items()}
        assert rasterise(grown, (h, w), v.px_per_mm).max() == 1
    assert used == 2 * 25 and placed == 25


def test_every_target_pixel_covered_once_from_assembly_svg(finished):
    run, out, _ = finished
    p = run.panels[0]
    n = rasterise(read_svg_pieces(out / "assembly.svg"), p.matched.shape, PPM)
    assert (n == 1).all(), f"{(n == 0).sum()} pixels uncovered, {(n > 1).sum()} covered twice"
    # And the labels used for the render agree with the cut paths pixel by pixel.
    for pid, poly in read_svg_pieces(out / "assembly.svg").items():
        inside = rasterise({pid: poly}, p.matched.shape, PPM) > 0
        assert (p.labels[inside] == pid).mean() > 0.999


def test_fragments_fabricable_from_files(finished):
    """Parsed-back pieces: at least min_piece_mm wide, no concave bend under the tool radius;
    sheet outlines are rigid motions of the panel outlines (same area)."""
    run, out, _ = finished
    prm = run.params
    from shapely.geometry import Polygon

    panel = read_svg_pieces(out / "assembly.svg")
    checked = 0
    for v in run.veneers:
        f = out / f"veneer_{v.id}.svg"
        if not f.exists():
            continue
        for pid, segs in read_svg_segments(f).items():
            assert check_piece(segs, prm.min_piece_mm, prm.tool_diameter_mm / 2) == []
            assert Polygon(panel[pid]).area == pytest.approx(Polygon(read_svg_pieces(f)[pid]).area, rel=1e-3)
            checked += 1
    assert checked == 25


def test_fabricability_check_catches_thin_and_tight_pieces():
    """The checker itself: a 3 mm strip is too narrow, an L with a sharp inner corner is too
    tight for a 2 mm tool, a 10 mm square is fine."""
    def poly(pts):
        pts = [np.array(p, float) for p in pts]
        return [("L", a, b) for a, b in zip(pts, pts[1:] + pts[:1])]

    assert check_piece(poly([(0, 0), (10, 0), (10, 10), (0, 10)]), 5, 1) == []
    assert any("narrower" in m for m in check_piece(poly([(0, 0), (20, 0), (20, 3), (0, 3)]), 5, 1))
    ell = poly([(0, 0), (20, 0), (20, 10), (10, 10), (10, 20), (0, 20)])
    assert any("concave" in m for m in check_piece(ell, 5, 1))
    # a 2 mm wide, 16 mm long tongue on a square
    tongue = poly([(0, 0), (10, 0), (10, 4), (26, 4), (26, 6), (10, 6), (10, 10), (0, 10)])
    assert any("narrower" in m for m in check_piece(tongue, 5, 0))


def test_check_piece_says_min_piece_in_the_message_units():
    """Sweep h16 item B: under --units inch the narrowness problems said "0.0155 in^2 of it is
    narrower than min_piece_mm = 5 mm": the area in inches beside the length in mm."""
    from woodcam.units import message_units, say_area

    def poly(pts):
        pts = [np.array(p, float) for p in pts]
        return [("L", a, b) for a, b in zip(pts, pts[1:] + pts[:1])]

    strip = poly([(0, 0), (20, 0), (20, 3), (0, 3)])
    tongue = poly([(0, 0), (10, 0), (10, 4), (26, 4), (26, 6), (10, 6), (10, 10), (0, 10)])
    assert "min_piece_mm = 5 mm (a disc" in check_piece(strip, 5, 1)[0]
    with message_units("inch"):
        said = check_piece(strip, 5, 1) + check_piece(tongue, 5, 0)
        assert said[0].startswith("narrower than min_piece_mm = 0.1969 in (a disc"), said
        assert any(" in^2 of it is narrower than min_piece_mm = 0.1969 in away" in m for m in said), said
        assert not any(" mm" in m for m in said), said
        assert say_area(645.16, units="mm") == "645.2 mm^2"  # a summary's units over the message's
    assert say_area(645.16, units="inch") == "1 in^2"


def test_seams_are_6_connected_and_in_their_bands(finished):
    run, _, _ = finished
    p = run.panels[0]
    o = run.params.overlap_px
    for lines in (p.seams_v, p.seams_h):
        for ln in lines:
            assert np.abs(np.diff(ln.raw)).max() <= 1
            nominal = ln.index * p.cell_px
            t = np.linspace(ln.knots[0], ln.knots[-1], 500)
            assert np.abs(ln(t) - nominal).max() <= o
    # the seams are not all straight: the DP moved them
    assert any(np.ptp(ln.raw) > 0 for ln in p.seams_v)


def test_cut_files_escape_names_and_place_labels_as_the_svg(tmp_path):
    """A veneer named oak&ash<1> made an SVG title no XML reader accepts; the DXF's ids sat
    left-aligned on the inner point (the SVG centres them 1 mm lower) and its header extents
    stayed at +-1e20; its TOOLPATH and ENGRAVE layers were not in the LAYER table."""
    import xml.etree.ElementTree as ET

    import ezdxf
    from shapely.geometry import Polygon

    from woodcam.parquetry.cutpaths import svg_document, write_dxf

    sq = [("L", np.array(a, float), np.array(b, float))
          for a, b in (((10, 10), (40, 10)), ((40, 10), (40, 30)), ((40, 30), (10, 30)), ((10, 30), (10, 10)))]
    doc = svg_document(50, 40, [(7, sq)], 1.0, title="woodcam veneer oak&ash<1>")
    root = ET.fromstring(doc)
    assert root.find("{http://www.w3.org/2000/svg}title").text == "woodcam veneer oak&ash<1>"
    text = root.find(".//{http://www.w3.org/2000/svg}text")
    write_dxf(tmp_path / "v.dxf", 40, [(7, sq)], 1.0)
    dxf = ezdxf.readfile(str(tmp_path / "v.dxf"))
    (label,) = dxf.modelspace().query("TEXT")
    assert label.dxf.text == "7" and label.dxf.halign == 1 and label.dxf.valign == 0  # centred on its baseline
    c = Polygon([s[1] for s in sq]).representative_point()
    assert (float(text.get("x")), float(text.get("y"))) == pytest.approx((c.x, c.y + 1.0), abs=1e-3)
    assert tuple(label.dxf.align_point)[:2] == pytest.approx((c.x, 40 - (c.y + 1.0)), abs=1e-6)  # y up
    # TOOLPATH and ENGRAVE were used by the entities but missing from the LAYER table
    used = {e.dxf.layer for e in dxf.modelspace()}
    assert used == {"PIECE_7", "TOOLPATH", "ENGRAVE"} and used <= {layer.dxf.name for layer in dxf.layers}
    lo, hi = dxf.header["$EXTMIN"], dxf.header["$EXTMAX"]
    assert lo[0] == pytest.approx(9.0, abs=0.1) and hi[0] == pytest.approx(41.0, abs=0.1)  # the tool path
    assert lo[1] == pytest.approx(9.0, abs=0.1) and hi[1] == pytest.approx(31.0, abs=0.1)


@pytest.mark.parametrize("mode, patch_mm", [("exhaustive", 7.0), ("fast", 14.0)])
@pytest.mark.parametrize("rot", [0, 4])
def test_crop_of_a_veneer_is_rebuilt_from_that_crop(sheets, mode, patch_mm, rot):
    """A target cut from one sheet (rotated by one of the n_rot angles) comes back from the
    same place at (near) zero cost; square patches, no kerf, no histogram blend.

    At rotation 0 the features are identical and every patch must come back exactly. A rotated
    crop is resampled from the rotated colour while the bank rotates the features, so costs are
    small but not zero: the exhaustive search must still find every patch; the fast search
    (4x coarser first) at least 3 in 4, the rest at a cost as low."""
    v = sheets[2]
    n_rot = 15
    angle = 360.0 * rot / n_rot
    rgb, mask, _ = rotate(v.rgb, v.mask, angle)
    ys, xs = np.nonzero(mask)
    cy, cx = int(ys.mean()), int(xs.mean())
    half = round(2 * patch_mm * PPM)          # 4 x 4 patches
    crop = rgb[cy - half:cy + half, cx - half:cx + half]
    assert mask[cy - half:cy + half, cx - half:cx + half].all()
    prm = ParquetryParams(image_size_mm=4 * patch_mm, patch_mm=patch_mm, px_per_mm=PPM, w_hist=0.0,
                          overlap_mm=0, kerf_mm=0, n_rot=n_rot, mode=mode)
    run = build_parquetry(crop, sheets, prm, seams=False)
    assert run.complete and len(run.patches) == 16
    exact = [(q.match.sheet, q.match.rot, q.match.x - (cx - half), q.match.y - (cy - half))
             == (2, rot, q.grown[1], q.grown[0]) for q in run.patches]
    costs = np.array([q.cost_px for q in run.patches])
    if rot == 0:
        # zero up to float32 cancellation in sum S^2 - 2 sum S T + sum T^2 (values ~0.1 per px)
        assert all(exact) and costs.max() < 1e-5
        assert np.abs(run.panels[0].render - crop).max() < 1e-4
    else:
        assert np.mean(exact) >= (1.0 if mode == "exhaustive" else 0.75)
        assert costs.mean() < 2e-4
    # a random target costs far more: the near-zero costs above are a real find
    noise = np.random.default_rng(0).random(crop.shape).astype(np.float32)
    other = build_parquetry(noise, sheets, prm, seams=False)
    assert np.mean([q.cost_px for q in other.patches]) > 20 * max(costs.mean(), 1e-5)


def test_render_beats_mean_colour_baseline_on_feature_cost(finished):
    run, _, _ = finished
    p = run.panels[0]
    assert feature_cost(p, p.render, run.params) < feature_cost(p, p.baseline, run.params)


def test_the_default_leaves_pass_the_memory_guard_and_absurd_ones_do_not(monkeypatch):
    """The README's '--veneer-from builtin:flat-sawn' with the default leaves (two of 600 x
    400 mm at 4 px/mm) was refused as a 9600x7200x3 grid over MAX_GRID_CELLS: the guard counted
    every supersample as held, though they are summed as they come (23 M values held)."""
    import woodcam.parquetry.veneers as veneers
    from woodcam.parquetry.job import job_veneers
    from woodcam.stock import open_stock

    monkeypatch.setattr(veneers, "_supersampled",  # the guard, not minutes of sampling
                        lambda colour, nh, nw, *a: np.full((nh, nw, 3), 0.5, np.float32))
    # the default leaves of a block whose face holds them (builtin:flat-sawn's own 100 x 50 mm
    # face gets leaves of its size: wood beyond it is refused, see test_parquetry_cli)
    leaves = job_veneers(ParquetryJob(blocks=[{"spec": "builtin:flat-sawn:600x80x400"}]), open_stock=open_stock)
    assert [v.rgb.shape for v in leaves] == [(1600, 2400, 3)] * 2
    with pytest.raises(WoodcamError, match="1000 leaves of 600 x 400 mm at 4 px/mm .* MAX_GRID_CELLS"):
        slice_veneers(open_stock("builtin:flat-sawn"), 1000, (600, 400))
    # one 2 x 1.5 m leaf: 144 M values held, under the cell limit, but 5 GB with its sampling
    with pytest.raises(WoodcamError, match=r"1 leaves of 2000 x 1500 mm .*\(memory\) needs [0-9.e+]* bytes.* MAX_ALLOC_BYTES"):
        slice_veneers(open_stock("builtin:flat-sawn"), 1, (2000, 1500))


def test_sliced_leaf_pixels_are_the_mean_of_their_point_samples():
    """supersample=s: each pixel is the mean of the s x s point samples inside it, i.e. the
    s-times finer single-sample leaf averaged over s x s blocks (also on the turned leaf)."""
    from woodcam.stock import open_stock

    st = open_stock("builtin:flat-sawn", species="walnut")
    coarse = slice_veneers(st, 2, (30, 20), px_per_mm=2.0, supersample=3, adaptive=False)
    fine = slice_veneers(st, 2, (30, 20), px_per_mm=6.0, supersample=1)
    for c, f in zip(coarse, fine):
        blocks = f.rgb.reshape(40, 3, 60, 3, 3).mean(axis=(1, 3))
        assert np.abs(c.rgb - blocks).max() < 1e-5
    # point samples alias the latewood lines into stair-steps: more Sobel energy than averaged
    from woodcam.parquetry.features import edge, intensity

    single = slice_veneers(st, 1, (60, 40), px_per_mm=4.0, supersample=1)[0]
    averaged = slice_veneers(st, 1, (60, 40), px_per_mm=4.0)[0]
    e1, e3 = (float((edge(intensity(v.rgb)) ** 2).mean()) for v in (single, averaged))
    assert e3 < 0.9 * e1
    with pytest.raises(WoodcamError, match="supersample must be an integer in"):
        slice_veneers(st, 1, (30, 20), supersample=0)


def test_adaptive_supersampling_matches_full_at_a_third_of_the_samples():
    """The adaptive leaf (centre samples; all 3 x 3 only where the wood varies at the pixel's
    scale, and only across the grain where it runs along a pixel axis) is the full 3 x 3 leaf
    to a few 1e-4 on average with its Sobel energy within 2 %, from well under half the
    samples; a smooth field is never supersampled."""
    from woodcam.parquetry.features import edge, intensity
    from woodcam.stock import open_stock

    st = open_stock("builtin:flat-sawn", species="walnut")
    counted = {"n": 0}

    class Counting:
        spec, size_mm = st.spec, st.size_mm

        class wood:
            @staticmethod
            def color(p, n):
                counted["n"] += len(p)
                return st.wood.color(p, n)

    full = slice_veneers(st, 1, (60, 40), px_per_mm=4.0, adaptive=False)[0].rgb
    fast = slice_veneers(Counting, 1, (60, 40), px_per_mm=4.0)[0].rgb
    assert np.abs(full - fast).mean() < 6e-4
    e_full, e_fast = (float((edge(intensity(a)) ** 2).mean()) for a in (full, fast))
    assert abs(e_fast / e_full - 1) < 0.02
    assert counted["n"] < 0.45 * 9 * full.shape[0] * full.shape[1]

    class Smooth(Counting):
        class wood:
            @staticmethod
            def color(p, n):
                counted["n"] += len(p)
                return np.repeat(0.5 + 0.001 * p[:, :1], 3, axis=1)

    counted["n"] = 0
    smooth = slice_veneers(Smooth, 1, (60, 40), px_per_mm=4.0)[0]
    assert counted["n"] == 240 * 160
    assert np.allclose(smooth.rgb[0, :, 0], 0.5 + 0.001 * (np.arange(240) + 0.5) / 4.0, atol=1e-6)


def _grain_and_calm_bank():
    """A fast-mode bank of two sheets of tone 0.5: sheet 0 with +-0.1 grain every 2 px (which
    the coarse low-pass removes entirely), sheet 1 flat."""
    from woodcam.parquetry.matching import SheetBank

    calm = np.full((96, 96), 0.5, np.float32)
    grain = np.full((96, 384), 0.5, np.float32)
    grain[:, ::2] += 0.1
    grain[:, 1::2] -= 0.1
    return SheetBank([grain, calm], [np.ones(grain.shape, bool), np.ones(calm.shape, bool)],
                     n_rot=1, mode="fast", coarse_factor=4, top_k=2)


def test_coarse_search_prefers_calm_wood_for_a_flat_target():
    """Two sheets of the same mean tone, one flat and one with 2 px grain that the coarse
    low-pass removes entirely: for a flat target the fast search's coarse stage ranks the calm
    sheet first (its detail-amplitude channel), and the exact choice is the calm sheet."""
    from woodcam.parquetry.matching import _coarse

    bank = _grain_and_calm_bank()
    tmpl = bank.features(np.full((28, 28), 0.5, np.float32))
    cands = bank.atlas.search(_coarse(tmpl, 4), 50)
    assert bank.atlas.tiles[cands[0][0]][0] == 1
    by_sheet = {}
    for t, _x, _y, c in cands:
        by_sheet.setdefault(bank.atlas.tiles[t][0], c)
    # the grained sheet's coarse cost carries its detail energy (0.5^2 (0.1^2 + edge^2) per px)
    assert 1 in by_sheet and by_sheet.get(0, np.inf) > by_sheet[1] + 1e-3
    m = bank.best(tmpl)
    assert m.sheet == 1 and m.cost < 1e-6


def test_detail_weight_scales_the_coarse_cost_of_grain_and_flat_fraction():
    """The coarse SSD with the detail channel weighted w is sum_c w_c (S_c - T_c)^2: against a
    flat template, calm and grained wood of the same low-passed tone differ only in the
    detail channel, so their cost gap grows exactly w times; the flat share is 1 for a flat
    target and 0 for one with contrast in every window."""
    from woodcam.parquetry.matching import _coarse, _flat_fraction

    bank = _grain_and_calm_bank()
    tc = _coarse(bank.features(np.full((28, 28), 0.5, np.float32)), 4)

    def gap(w):
        best = {}
        for t, _x, _y, c in bank.atlas.search(tc, 400, detail_weight=w):
            best.setdefault(bank.atlas.tiles[t][0], c)
        return best[0] - best[1]

    assert gap(1.0) > 1e-3
    assert gap(3.0) == pytest.approx(3.0 * gap(1.0), rel=1e-3)
    assert _flat_fraction(np.full((28, 28), 0.4, np.float32)) == 1.0
    checker = (np.indices((28, 28)).sum(0) % 2).astype(np.float32)
    assert _flat_fraction(checker) == 0.0
    assert _flat_fraction(np.kron(checker, np.ones((4, 4), np.float32)), 4.0) == 0.0


def test_used_wood_slivers_do_not_send_the_search_to_the_exact_scan():
    """A flat target drains the one flat region of a sheet (the rest is a tone lighter). The
    coarse map's used wood is optimistic, so the slivers left between used pieces stay its
    cheapest anchors; every one of them is dead at full resolution. They are remembered once
    and never re-ranked again, so the exact scan of every rotation (seconds per patch on the
    issue's sheets: coffee ran for 20 CPU-min) runs only for the last call, when the wood is
    gone, and the run still stops only when no free window is left anywhere."""
    import cv2

    from woodcam.parquetry.matching import SheetBank

    rng = np.random.default_rng(0)
    g = 0.5 + 0.01 * cv2.GaussianBlur(rng.standard_normal((300, 900)).astype(np.float32), (0, 0), 3)
    g[:, 300:] += 0.1
    bank = SheetBank([g], [np.ones(g.shape, bool)], n_rot=15, kerf_px=4, mode="fast",
                     coarse_factor=8, top_k=1)
    tmpl = bank.features(np.full((40, 40), 0.5, np.float32))
    placed = 0
    while (m := bank.best(tmpl)) is not None:
        bank.take(m, 40, 40)
        placed += 1
    assert placed > 60 and bank.dead_anchors > 50
    # without the memory: 24 exact scans (14 CPU-s); forgotten between calls: 20 re-ranks a patch
    assert bank.fallback_scans <= 1
    assert bank.exact_reranks < 5 * placed
    for j in range(len(bank.angles_deg)):
        _, (h, w) = bank.rotation(0, j)
        r = max(h, w)
        assert not any(bank.is_free(0, bank.footprint(0, j, x, y, 40, 40))
                       for _, x, y in bank.exact_costs(0, j, r, r, r, tmpl)), j


def test_fast_grown_leaves_are_calmer_than_quarter_sawn():
    """``builtin:fast-grown`` (10 mm rings, flat-sawn 500 mm from the pith) is the calm veneer
    source: against a flat target at 0.7 mm pixels (the camera's at 360 mm) its maple leaf costs
    about half the structural penalty of the quarter-sawn and flat-sawn blocks' maple leaves
    (0.18 vs 0.33 when written)."""
    from woodcam.parquetry.matching import _structure_penalty
    from woodcam.stock import open_stock

    pen = {}
    for spec in ("builtin:fast-grown:600x400x50", "builtin:quarter-sawn:600x400x50",
                 "builtin:flat-sawn:600x400x50"):
        leaf = slice_veneers(open_stock(spec, species="maple"), 1, (80, 60), px_per_mm=4.0,
                             id_prefix="m")[0]
        g = leaf.rgb @ np.array([0.299, 0.587, 0.114], np.float32)
        pen[spec] = _structure_penalty(g, np.full_like(g, g.mean()), 2.8)
    calm = pen.pop("builtin:fast-grown:600x400x50")
    assert all(calm < 0.6 * p for p in pen.values()), (calm, pen)


def test_structure_penalty_looks_at_the_target_pixels():
    """SSIM's contrast-structure penalty against a flat target: grain finer than the target's
    pixels (2 px stripes, ``scale`` 2) averages out there and costs nothing; bands as wide as
    several target pixels cost as much as at the working grid; grain that follows the target's
    own bands costs nothing at either scale."""
    from woodcam.parquetry.matching import _structure_penalty

    flat = np.full((64, 64), 0.5, np.float32)
    fine = flat.copy()
    fine[:, ::2] += 0.05
    fine[:, 1::2] -= 0.05
    bands = flat + np.where((np.arange(64) // 8) % 2 == 0, 0.05, -0.05).astype(np.float32)[None, :]
    assert _structure_penalty(fine, flat) > 0.7
    assert _structure_penalty(fine, flat, 2.0) < 1e-3
    assert _structure_penalty(bands, flat, 2.0) > 0.5
    assert _structure_penalty(bands, bands, 2.0) < 1e-3 and _structure_penalty(bands, bands) < 1e-3

def test_metrics_on_the_target_native_grid(sheets):
    """A 64 px target on a 70 mm panel at 2 px/mm (140 px) carries 0.9 px/mm: the "native"
    metrics compare on its own 64 x 64 pixels, where the matched target against itself scores
    SSIM 1, and fall back to the working grid for a target finer than that grid."""
    import cv2
    from skimage import data

    from woodcam.parquetry import ssim_vs_matched

    small = cv2.resize(data.camera()[40:300, 120:380], (64, 64), interpolation=cv2.INTER_AREA)
    prm = ParquetryParams(image_size_mm=70, px_per_mm=PPM)
    run = build_parquetry(small.astype(np.float32) / 255, sheets, prm, seams=False)
    p = run.panels[0]
    assert p.matched.shape == (140, 140) and p.native_shape == (64, 64)
    grey = np.repeat(p.matched[..., None], 3, axis=2)
    assert ssim_vs_matched(p, grey, grid="native") > 0.999
    # detail finer than the target's pixels (a 2 px checker of +-0.05) is averaged away there:
    # it adds less than a tenth of what it adds on the working grid
    checker = grey + 0.05 * (((np.indices((140, 140)).sum(0) % 2) * 2 - 1)[..., None])
    added = [feature_cost(p, checker, prm, g) - feature_cost(p, grey, prm, g) for g in ("native", "working")]
    assert 0 <= added[0] < 0.1 * added[1]
    with pytest.raises(WoodcamError, match="grid must be one of"):
        feature_cost(p, grey, prm, "print")
    # a target finer than the working grid: native is the working grid
    fine = build_parquetry(data.camera()[:256, :256].astype(np.float32) / 255, sheets,
                           ParquetryParams(image_size_mm=28, px_per_mm=PPM), seams=False)
    q = fine.panels[0]
    assert ssim_vs_matched(q, q.render, grid="native") == ssim_vs_matched(q, q.render)


def test_running_out_of_wood_stops_with_a_message_and_writes(sheets, tmp_path):
    from skimage import data

    prm = ParquetryParams(image_size_mm=140, px_per_mm=PPM)
    # said before the matching: the sheet holds less wood than the panel takes
    with pytest.warns(WoodcamWarning, match=r"^the veneers cannot cover the panel \(target0 210 x 140 mm\): they hold "
                      r"9204 mm\^2 of usable wood half the kerf in from its edges, .* so at most 12% of it can be made"):
        run = build_parquetry(data.coffee().astype(np.float32) / 255, sheets[:1], prm)
    assert not run.complete
    assert f"placed {len(run.patches)} patches" in run.message
    res = write_parquetry(run, tmp_path)
    assert (tmp_path / "render.png").is_file() and res["summary"]["complete"] is False
    # what was placed still obeys single use
    v = run.veneers[0]
    n = rasterise(read_svg_pieces(tmp_path / f"veneer_{v.id}.svg"), v.mask.shape, v.px_per_mm)
    assert n.max() == 1 and len(run.patches) > 5


def test_too_little_wood_counts_the_kerf():
    """The too-little-wood warning left the kerf out, so a job that fitted only without it was
    not warned of and ran out: four 10 mm patches from a 20 x 30 mm sheet at a 2 mm kerf (600
    mm^2 against 400) placed 2. Each piece now takes its window grown by half the kerf (10 x 10
    + 2 x 20 + pi = 143.1 mm^2) from the wood half the kerf in from the sheet's edges (18 x 28
    mm); without a kerf the same job fits, and a sheet with room for the kerf is not warned of."""
    target = np.zeros((20, 20, 3), np.float32)

    def run(kerf_mm, h, w):
        prm = ParquetryParams(px_per_mm=1.0, patch_mm=10, overlap_mm=0, kerf_mm=kerf_mm, image_size_mm=20, n_rot=1)
        v = Veneer("s", np.full((h, w, 3), 0.5, np.float32), 1.0, np.ones((h, w), bool))
        return build_parquetry(target, [v], prm, seams=False)

    assert run(0.0, 20, 30).complete  # no warning (an error here)
    with pytest.warns(WoodcamWarning, match=r"^the veneers cannot cover the panel \(target0 20 x 20 mm\): they hold "
                      r"504 mm\^2 of usable wood half the kerf in from its edges, and the 4 patches of 10 mm, each "
                      r"piece with its 0 mm overlap and the 2 mm kerf round it, every piece of wood used once, take "
                      r"at least 573 mm\^2, so at most 88% of it can be made; add at least 69 mm\^2 of veneer"):
        short = run(2.0, 20, 30)
    assert not short.complete and len(short.patches) == 2
    assert run(2.0, 14, 60).complete  # 12 x 58 = 696 mm^2 clear of the kerf: no warning


def test_a_rerun_without_a_job_removes_the_old_job_file_and_says_what_it_removed(sheets, tmp_path):
    """An API call without ``job`` left an earlier run's job.json beside a result.json it does
    not describe; and the files removed as an earlier run's were removed without a word (a
    user's own veneer_notes.svg among them)."""
    prm = ParquetryParams(image_size_mm=20, px_per_mm=PPM)
    run = build_parquetry(np.full((40, 40), 0.5, np.float32), sheets[:1], prm)
    (tmp_path / "job.json").write_text("{}")  # an earlier run's
    (tmp_path / "veneer_notes.svg").write_text("<svg/>")  # the user's, matching a cut-file name
    with pytest.warns(WoodcamWarning, match=r"removed 2 file\(s\) of an earlier run .*: "
                      r"veneer_notes\.svg, job\.json$"):
        res = write_parquetry(run, tmp_path)
    assert not (tmp_path / "job.json").exists() and not (tmp_path / "veneer_notes.svg").exists()
    assert "job.json" not in {p.rsplit("/", 1)[-1] for p in res["files"]}


def test_a_rerun_removes_exactly_the_files_the_earlier_run_listed(sheets, tmp_path):
    """A rerun removed earlier outputs by file pattern, so a user's veneer_notes.svg went with
    them: each run lists its files (.woodcam-parquetry-files.json, written atomically) and a
    rerun removes exactly the listed files it does not write again; a file named like an
    output that no run wrote is left, with a warning naming it."""
    prm = ParquetryParams(image_size_mm=20, px_per_mm=PPM)
    grey = np.full((40, 40), 0.5, np.float32)
    first = write_parquetry(build_parquetry(grey, sheets[:1], prm), tmp_path)
    listed = json.loads((tmp_path / ".woodcam-parquetry-files.json").read_text())["files"]
    # the files written end with their list, named as woodify names its own
    assert first["files"][-1] == str(tmp_path / ".woodcam-parquetry-files.json")
    assert listed == [f.rsplit("/", 1)[-1] for f in first["files"][:-1]]
    old = sheets[0].id
    assert f"veneer_{old}.svg" in listed
    (tmp_path / "veneer_notes.svg").write_text("<svg/>")   # the user's, named like a cut file
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.warns(WoodcamWarning) as rec:
        second = write_parquetry(build_parquetry(grey, sheets[2:3], prm), tmp_path)
    said = [str(w.message) for w in rec if issubclass(w.category, WoodcamWarning)]
    assert any(m.startswith("removed 2 file(s)") and m.endswith(f"veneer_{old}.svg, veneer_{old}.dxf")
               for m in said), said
    assert any(m.startswith("left 1 file(s)") and m.endswith(": veneer_notes.svg") for m in said), said
    names = sorted(q.name for q in tmp_path.iterdir())
    assert names == sorted(["veneer_notes.svg", "notes.txt", *(f.rsplit("/", 1)[-1] for f in second["files"])])
    assert json.loads((tmp_path / ".woodcam-parquetry-files.json").read_text())["files"] == \
        [f.rsplit("/", 1)[-1] for f in second["files"][:-1]]


def test_adaptive_patches_split_by_w_adaptive(sheets):
    from skimage import data

    img = data.astronaut()[:256, :256].astype(np.float32) / 255
    keep = build_parquetry(img, sheets, ParquetryParams(image_size_mm=56, px_per_mm=PPM, n_adaptive=1,
                                                        w_adaptive=50.0), seams=False)
    split = build_parquetry(img, sheets, ParquetryParams(image_size_mm=56, px_per_mm=PPM, n_adaptive=1,
                                                         w_adaptive=0.01), seams=False)
    assert {q.cells for q in keep.patches} == {2} and len(keep.patches) == 4
    assert {q.cells for q in split.patches} == {1} and len(split.patches) == 16
    for r in (keep, split):
        assert (r.panels[0].labels >= 0).all()


def test_sliced_leaves_are_book_matched():
    from woodcam.stock import open_stock

    a, b = slice_veneers(open_stock("builtin:flat-sawn"), 2, (60, 40), thickness_mm=0.3, kerf_mm=0.1,
                         px_per_mm=3.0)
    g0, g1 = a.rgb.mean(2), b.rgb.mean(2)
    mirrored = np.corrcoef(g0.ravel(), g1[:, ::-1].ravel())[0, 1]
    straight = np.corrcoef(g0.ravel(), g1.ravel())[0, 1]
    # the leaves are 0.7 mm apart, so latewood lines have moved a little: 0.79 measured
    assert mirrored > 0.6 and abs(straight) < 0.2


def test_job_file_round_trip_and_paper_keys(tmp_path):
    for name in ("a.png", "t.png", "wood.jpg", "m.png", "target.jpg"):  # a job's files must exist
        (tmp_path / name).touch()
    job = ParquetryJob(scans=[{"texture": str(tmp_path / "a.png"), "mask": None, "id": "a",
                               "scale": 1.0, "dpi": 300.0}],
                       targets=[{"filename": str(tmp_path / "t.png"), "scale": 1.0}],
                       params=ParquetryParams(n_rot=9, w_edge=0.3, priority="center"))
    write_job(job, tmp_path / "job.json")
    d = json.loads((tmp_path / "job.json").read_text())
    assert d["num_source_rotations"] == 9 and d["weight_sobel"] == 0.3 and d["sort_patches_saliency"] is False
    back = read_job(tmp_path / "job.json")
    assert back.params == job.params and back.scans[0]["id"] == "a"
    # the reference code's own sample (Table 1 names map across; its keys woodcam reads no
    # value from are said: they were silently dropped, the run unlike the reference code's)
    paper = {"source_textures": [{"texture": "wood.jpg", "mask": "m.png", "id": "f1", "scale": 0.7, "dpi": 300.0}],
             "targets": [{"filename": "target.jpg", "scale": 1.0, "dpi": 300.0, "morphed_grid": "grid/grid.json"}],
             "num_source_rotations": 15, "min_patch_size": 48, "patch_levels": 1, "patch_quality_factor": 1.5,
             "weight_intensity": 0.5, "weight_sobel": 0.5, "weight_gabor": 0.0, "histogram_matching": 0.5,
             "filter_resolution": 32, "num_filter_directions": 4, "filter_bandwidth_octaves": 1.0,
             "sort_patches_saliency": True}
    (tmp_path / "paper.json").write_text(json.dumps(paper))
    with pytest.warns(WoodcamWarning, match=r"paper.json': woodcam reads no value from min_patch_size "
                      r"\(woodcam's patch side is patch_mm.*; targets\[0\] dpi and scale \(the panel's "
                      r"shorter side is image_size_mm.*; targets\[0\].morphed_grid \(woodcam cuts a square "
                      r"grid of patches\); the run may differ from the reference code's") as w:
        j = read_job(tmp_path / "paper.json")
    assert len(w) == 1 and "gabor" not in str(w[0].message)  # weight 0: no effect there either
    assert (j.params.n_adaptive, j.params.w_adaptive, j.params.priority) == (1, 1.5, "saliency")
    assert j.scans[0]["texture"] == str((tmp_path / "wood.jpg").resolve())
    # downsample: the reference code ignores it too, so nothing to say (a warning said the run
    # might differ from the reference code's)
    (tmp_path / "down.json").write_text(json.dumps({"targets": [{"filename": "target.jpg"}], "downsample": 2}))
    read_job(tmp_path / "down.json")  # no warning (they are errors here)
    paper["weight_gabor"] = 0.3
    (tmp_path / "paper.json").write_text(json.dumps(paper))
    with pytest.warns(WoodcamWarning, match=r"weight_gabor = 0.3 \(woodcam matches intensity and Sobel"):
        read_job(tmp_path / "paper.json")


def test_a_job_files_block_specs_are_written_absolute_and_read_from_its_folder(tmp_path, monkeypatch):
    """woodcam.blocks specs naming a block folder, log:PATH or woodify:PATH were written as typed
    and read from the working folder (a job file's textures from its own): a rerun from
    elsewhere opened another block or none. Now written absolute, read as the textures are."""
    (tmp_path / "jobs").mkdir()
    (tmp_path / "jobs" / "t.png").touch()
    monkeypatch.chdir(tmp_path)
    specs = ["blk~z90", "log:logs/l.json@2:60x40x20", "woodify:grown/field.npz", "builtin:flat-sawn", "log:gran1@3"]
    job = ParquetryJob(blocks=[{"spec": s, "sheets": 2} for s in specs], targets=[{"filename": "jobs/t.png"}])
    write_job(job, tmp_path / "out" / "job.json")
    written = [b["spec"] for b in json.loads((tmp_path / "out" / "job.json").read_text())["woodcam"]["blocks"]]
    assert written == [f"{tmp_path}/blk~z90", f"log:{tmp_path}/logs/l.json@2:60x40x20",
                       f"woodify:{tmp_path}/grown/field.npz", "builtin:flat-sawn", "log:gran1@3"]
    (tmp_path / "jobs" / "job.json").write_text(json.dumps(
        {"targets": [{"filename": "t.png"}], "woodcam": {"blocks": [{"spec": s} for s in specs]}}))
    monkeypatch.chdir(tmp_path / "out")
    for name in ("blk", "logs", "grown"):  # there, as read_job refuses a path that is not
        (tmp_path / "jobs" / name).mkdir()
    (tmp_path / "jobs" / "logs" / "l.json").touch()
    (tmp_path / "jobs" / "grown" / "field.npz").touch()
    read = [b["spec"] for b in read_job(tmp_path / "jobs" / "job.json").blocks]
    jobs = tmp_path / "jobs"
    assert read == [f"{jobs}/blk~z90", f"log:{jobs}/logs/l.json@2:60x40x20", f"woodify:{jobs}/grown/field.npz",
                    "builtin:flat-sawn", "log:gran1@3"]


# -- bad input ------------------------------------------------------------------------------
_T = [{"filename": "t.png"}]


@pytest.mark.parametrize("job, match", [
    ({"targets": "t.png"}, r"'targets' must be a list of objects; got str"),
    ({"targets": [{}]}, r"targets\[0\] needs a 'filename' path"),
    ({"targets": _T, "source_textures": [{"dpi": 300}]}, r"source_textures\[0\] needs a 'texture'"),
    ({"targets": _T, "source_textures": [{"texture": "a.png", "dpi": -3}]}, r"source_textures\[0\].dpi must be > 0"),
    ({"targets": _T, "woodcam": 3}, r"'woodcam' and 'woodcam.params' must be objects"),
    ({"targets": _T, "woodcam": {"mokume": "CN03"}}, r"'woodcam.mokume' must be a list"),
    ({"targets": _T, "woodcam": {"blocks": [{"spec": "builtin:flat-sawn", "sheets": "2"}]}},
     r"woodcam.blocks\[0\].sheets must be a whole number; got '2'"),
    ({"targets": _T, "num_source_rotations": "abc"}, r"num_source_rotations must be a whole number; got 'abc'"),
    ({"targets": _T, "num_source_rotations": 0}, r"num_source_rotations must be in \[1, 360\]"),
    ({"targets": _T, "woodcam": {"params": {"patch_mm": "14"}}}, r"patch_mm must be a finite number"),
    ({"targets": _T, "woodcam": {"params": {"single_use": 1}}}, r"single_use must be true or false"),
    ([_T], r"must hold a JSON object; got list"),
    ({"targets": _T, "woodcam": {"image_size_mm": 50}}, r"key woodcam.image_size_mm is unknown.*woodcam.params"),
    # a typo was ignored, the run made with the default; a string read as true
    ({"targets": _T, "num_source_rotation": 3}, r"key 'num_source_rotation' is unknown \(neither woodcam nor "
     r"the reference code reads it\); the known ones there: downsample, .*num_source_rotations, "),
    ({"targets": [{"filename": "t.png", "scal": 0.5}]}, r"key targets\[0\].'scal' is unknown .*: dpi, "
     r"filename, morphed_grid, scale$"),
    ({"targets": _T, "sort_patches_saliency": "no"}, r"sort_patches_saliency must be true or false; got 'no'"),
    # a typo in a block ran with the default; px_per_mm silently won over dpi and scale
    ({"targets": _T, "woodcam": {"blocks": [{"spec": "builtin:flat-sawn", "sheet": 3}]}},
     r"key woodcam.blocks\[0\].'sheet' is unknown \(woodcam reads no such key\); the known ones there: axis, "
     r"height_mm, id, kerf_mm, sheets, spec, species, thickness_mm, width_mm$"),
    ({"targets": _T, "source_textures": [{"texture": "t.png", "px_per_mm": 4, "dpi": 300, "scale": 0.5}]},
     r"source_textures\[0\] gives px_per_mm \(4\) and dpi/scale \(300/0.5\); the resolution is one or the "
     r"other: keep px_per_mm alone, or dpi \(times scale\)$"),
    # a TypeError: the file-exists check joined the mask to the job's folder before its type was checked
    ({"targets": _T, "source_textures": [{"texture": "t.png", "dpi": 300, "mask": 5}]},
     r"source_textures\[0\].mask must be a path or null; got 5$"),
    ({"targets": _T, "source_textures": [{"texture": "t.png", "dpi": 300, "id": 7}]},
     r"source_textures\[0\].id must be a name .*; got 7$"),
    ({"targets": _T, "source_textures": [{"json": "t.json", "scale": 1}]},
     r"source_textures\[0\] describes its texture in another file \('json': 't.json'\), which woodcam does "
     r"not read; give its 'texture', 'dpi' and 'mask' in this entry"),
])
def test_a_bad_job_file_is_one_error_naming_the_entry(job, match, tmp_path):
    """Each of these was a KeyError, TypeError, AttributeError or ValueError traceback from the
    CLI (``woodcam parquetry --config``) before the job's entries were checked at the door."""
    (tmp_path / "job.json").write_text(json.dumps(job))
    with pytest.raises(WoodcamError, match=match):
        read_job(tmp_path / "job.json")


_B = {"spec": "builtin:flat-sawn"}


@pytest.mark.parametrize("entry, said", [
    ({"sheets": 0}, "woodcam.blocks[0].sheets must be in [1, 1000] (leaves sliced from the block); got 0; e.g. 2, "
     "or remove the key for the default, 2"),
    ({"sheets": 10**6}, "woodcam.blocks[0].sheets must be in [1, 1000]"),
    ({"thickness_mm": -1}, "woodcam.blocks[0].thickness_mm must be > 0 mm (a leaf's thickness); got -1; remove the "
     "key for the default"),
    ({"width_mm": 0}, "woodcam.blocks[0].width_mm must be > 0 mm (a leaf's width); got 0"),
    ({"kerf_mm": -0.1}, "woodcam.blocks[0].kerf_mm must be >= 0 mm (the saw kerf between leaves); got -0.1"),
    ({"axis": "w"}, "woodcam.blocks[0].axis must be \"x\", \"y\" or \"z\" (the normal of the slicing planes, block "
     "frame); got 'w'; remove the key for the default, \"y\""),
    ({"species": "purple"}, "woodcam.blocks[0].species must be one of the presets oak, "),
    ({"spec": "builtin:nope"}, "woodcam.blocks[0].spec 'builtin:nope': unknown built-in block 'nope'; choose one "
     "of: flat-sawn, "),
    ({"spec": "builtin:flat-sawn:a"}, "woodcam.blocks[0].spec 'builtin:flat-sawn:a': the size must be WxDxH in mm"),
])
def test_a_job_files_bad_block_entry_is_said_at_the_door_in_its_keys(entry, said, tmp_path, monkeypatch):
    """A job file's woodcam.blocks entry was checked when its leaves were cut, in Python's words
    and without the file: '"sheets": 0' -> 'n_sheets must be an integer >= 1; got 0; e.g. 4',
    '"species": "purple"' -> '... or species=None for the block's own', '"spec": "builtin:nope"'
    -> 'unknown built-in block 'nope'; ...' (no key, no file), after the job's scans were read."""
    path = tmp_path / "job.json"
    path.write_text(json.dumps({"targets": _T, "woodcam": {"blocks": [{**_B, **entry}]}}))
    with pytest.raises(WoodcamError) as info:
        read_job(path)
    text = str(info.value)
    assert text.startswith(f"job file {str(path)!r}: {said}"), text
    assert "species=None" not in text and "n_sheets" not in text, text
    # a good entry passes the door
    path.write_text(json.dumps({"targets": _T, "woodcam": {"blocks": [{**_B, "sheets": 3, "species": "walnut",
                                                                        "axis": "x", "kerf_mm": 0}]}}))
    (tmp_path / "t.png").touch()
    assert read_job(path).blocks[0]["sheets"] == 3


@pytest.mark.parametrize("job, said", [
    ({"num_source_rotations": "abc"}, "num_source_rotations must be a whole number; got 'abc'; remove the key for "
     "the default, 15"),
    ({"woodcam": {"params": {"patch_mm": "14"}}}, "woodcam.params.patch_mm must be a finite number; got '14'; "
     "remove the key for the default, 14.0"),
    ({"woodcam": {"params": {"overlap_mm": "a"}}}, "woodcam.params.overlap_mm must be a finite number; got 'a'; "
     "remove the key for the default"),
    ({"woodcam": {"params": {"patch_mm": 3}}}, "woodcam.params.patch_mm must be at least "
     "woodcam.params.min_piece_mm = 5 mm (the smallest piece that can be cut and assembled); got 3 mm; use a "
     "larger woodcam.params.patch_mm or lower woodcam.params.min_piece_mm"),
    ({"woodcam": {"params": {"overlap_mm": 6}}}, "woodcam.params.overlap_mm must be in [0, (woodcam.params.patch_mm "
     "- woodcam.params.min_piece_mm) / 2 = (14 - 5) / 2 = 4.5] mm so every piece stays >= woodcam.params.min_piece_mm "
     "wide; got 6 mm; use woodcam.params.overlap_mm 4.5 or less, a larger woodcam.params.patch_mm or a smaller "
     "woodcam.params.min_piece_mm"),
    ({"patch_levels": 9}, "patch_levels must be in [0, 4] here: its largest patch, woodcam.params.patch_mm * "
     "2^patch_levels = 14 * 2^9 = 7168 mm"),
    ({"woodcam": {"params": {"flat_rerank": 2}}}, "woodcam.params.flat_rerank must be >= woodcam.params.rerank = 4 "
     "(the candidates every patch re-ranks); got 2; use woodcam.params.flat_rerank 4 to turn"),
    ({"woodcam": {"params": {"bogus": 2}}}, "key woodcam.params.bogus is unknown; known: ['coarse_factor', "),
])
def test_a_job_files_bad_parameter_is_said_in_its_keys(job, said, tmp_path):
    """A job file's bad parameter was said in Python terms: 'parquetry parameter n_rot must be a
    whole number; got 'abc'; leave it out for the default, n_rot=15' of the file's
    num_source_rotations, 'use --overlap-mm 4.5' of its woodcam.params.overlap_mm, and without
    the file's name; the same values given in Python keep Python's words."""
    path = tmp_path / "job.json"
    path.write_text(json.dumps({"targets": _T, **job}))
    with pytest.raises(WoodcamError) as info:
        read_job(path)
    text = str(info.value)
    assert text.startswith(f"job file {str(path)!r}: {said}"), text
    assert "n_rot=" not in text and "--" not in text and "parquetry parameter" not in text, text
    with pytest.raises(WoodcamError, match=r"parquetry parameter n_rot must be a whole number; got 'abc'; leave it "
                       r"out for the default, n_rot=15$"):
        ParquetryParams(n_rot="abc")
    with pytest.raises(WoodcamError, match=r"^overlap_mm \(--overlap-mm\) must be .*; use --overlap-mm 4.5 or less"):
        ParquetryParams(overlap_mm=6)


def test_a_job_files_missing_file_is_named_by_its_entry_and_folder(tmp_path, monkeypatch):
    """A job file's missing target, texture or mask was 'cannot decode the image ... the file is
    damaged' once the run reached it; a path written from the working folder rather than the
    job file's (as the reference code, which tries the working folder first, allows) said
    nothing of where it was looked for. Now refused at the door, naming the entry and both."""
    from PIL import Image

    (tmp_path / "jobs").mkdir()
    Image.new("RGB", (40, 30)).save(tmp_path / "jobs" / "t.png")
    Image.new("RGB", (40, 30)).save(tmp_path / "s.png")
    monkeypatch.chdir(tmp_path)
    for entries, said in (
            ({"targets": [{"filename": "nope.png"}]}, r"targets\[0\].filename 'nope.png': no such file "
             r"'.*jobs/nope.png' \(a job file's paths are relative to its folder\); check the path"),
            ({"targets": [{"filename": "t.png"}], "source_textures": [{"texture": "s.png", "dpi": 300}]},
             r"source_textures\[0\].texture 's.png': no such file '.*jobs/s.png' \(a job file's paths are "
             r"relative to its folder\); 's.png' is there from the working folder: give the path from the "
             r"job file's folder, or an absolute one"),
            ({"targets": [{"filename": "t.png"}], "source_textures": [{"texture": "t.png", "dpi": 300,
                                                                         "mask": "m.png"}]},
             r"source_textures\[0\].mask 'm.png': no such file")):
        (tmp_path / "jobs" / "job.json").write_text(json.dumps(entries))
        with pytest.raises(WoodcamError, match=r"job file 'jobs/job.json': " + said):
            read_job("jobs/job.json")
    from woodcam.parquetry.veneers import read_image

    with pytest.raises(WoodcamError, match=r"^target image: no such file 'nope.png'; check the path$"):
        read_image("nope.png", "target image")


def test_a_job_files_image_that_is_a_folder_is_refused_at_the_door(tmp_path):
    """A job file's target, texture or mask naming a folder was 'target image: cannot read
    '.../notmok' (Is a directory); check the file's permissions and that its disk or share is
    readable' once the run read it; a Mokume entry naming a file the same. Now refused as read."""
    from PIL import Image

    from woodcam.parquetry.job import JobPathError

    (tmp_path / "d").mkdir()
    Image.new("RGB", (40, 30)).save(tmp_path / "t.png")
    for entries, said in (
            ({"targets": [{"filename": "d"}]}, f"targets[0].filename 'd': {str(tmp_path / 'd')!r} is a folder; it "
             "must be an image file (PNG, JPEG or TIFF)"),
            ({"source_textures": [{"texture": "d", "dpi": 300}]}, "source_textures[0].texture 'd': "),
            ({"source_textures": [{"texture": "t.png", "dpi": 300, "mask": "d"}]}, "source_textures[0].mask 'd': "),
            ({"woodcam": {"mokume": ["t.png"]}}, f"woodcam.mokume[0] 't.png': {str(tmp_path / 't.png')!r} is a file; "
             "it must be a Mokume sample folder (its A_col.png .. F_col.png)")):
        (tmp_path / "job.json").write_text(json.dumps({"targets": [{"filename": "t.png"}], **entries}))
        with pytest.raises(JobPathError) as info:
            read_job(tmp_path / "job.json")
        assert str(info.value).startswith(f"job file {str(tmp_path / 'job.json')!r}: {said}"), str(info.value)


def test_a_job_file_with_nan_is_refused(tmp_path):
    (tmp_path / "job.json").write_text('{"targets": [{"filename": "t.png"}], "weight_sobel": NaN}')
    with pytest.raises(WoodcamError, match="finite numbers"):
        read_job(tmp_path / "job.json")


def test_parameters_of_the_wrong_type_are_refused_by_name():
    with pytest.raises(WoodcamError, match="patch_mm must be a finite number; got nan"):
        ParquetryParams(patch_mm=float("nan")).check()
    with pytest.raises(WoodcamError, match="n_rot must be a whole number; got 2.5"):
        ParquetryParams(n_rot=2.5).check()
    for kw, said in ((dict(n_rot=10**9), r"n_rot must be in \[1, 360\]"),  # a MemoryError
                     (dict(px_per_mm=200.0), r"px_per_mm must be in \(0, 50\]"),  # OpenCV: 1.6 GB
                     (dict(min_piece_mm=-100.0), "min_piece_mm must be >= 0"),
                     # 0 was taken: tool paths on the outlines, no kerf between the pieces
                     (dict(tool_diameter_mm=0.0), r"tool_diameter_mm \(--tool-diameter\) must be > 0 mm"),
                     (dict(tool_diameter_mm=-1.0), r"must be > 0 mm.*got -1")):
        with pytest.raises(WoodcamError, match=said):
            ParquetryParams(**kw).check()
    prm = ParquetryParams(n_rot=9.0, overlap_mm=None).check()  # a whole float (JSON may write 9.0)
    assert prm.n_rot == 9 and type(prm.n_rot) is int


def test_parameters_are_checked_when_made_and_flat_rerank_has_one_floor():
    """ParquetryParams(patch_mm='14') or n_rot=0 was taken and failed only when a run called
    check(); flat_rerank's floor is rerank, the candidates every patch re-ranks (the CLI refused
    --flat-rerank below a fixed 4, so a job file's rerank 2 could not be turned off with 2)."""
    import dataclasses

    for kw, said in ((dict(patch_mm="14"), "patch_mm must be a finite number; got '14'"),
                     (dict(n_rot=0), r"n_rot must be in \[1, 360\]"),
                     (dict(flat_rerank=3), r"flat_rerank \(--flat-rerank\) must be >= rerank = 4 .*got 3; use 4"),
                     (dict(flat_detail=0.5), r"flat_detail \(--flat-detail\) must be >= 1; got 0.5")):
        with pytest.raises(WoodcamError, match=said):
            ParquetryParams(**kw)
    with pytest.raises(WoodcamError, match=r"flat_rerank \(--flat-rerank\) must be >= rerank = 6"):
        dataclasses.replace(ParquetryParams(), rerank=6, flat_rerank=5)
    off = ParquetryParams(rerank=2, flat_rerank=2)  # the flat-window re-rank off at rerank 2
    assert (off.rerank, off.flat_rerank) == (2, 2)


def test_the_cli_leaves_flat_reranks_floor_to_the_parameters(tmp_path, capsys):
    """--flat-rerank 2 is refused by the parameters' rule, naming the option and the rerank it
    must reach (exit 2, a wrong command line, as the other rules between the options'
    parameters), not by a fixed 4 of the CLI's."""
    from woodcam.cli import main
    from woodcam.cli.options import RANGES

    assert RANGES[("parquetry", "flat_rerank")][0] == 1  # rerank's own floor; the rest is check()'s
    # inputs that are there (the input door refuses missing ones first), never read: the rule is
    # the command line's, before any work
    for name in ("t.png", "v.png"):
        (tmp_path / name).write_bytes(b"")
    argv = ["parquetry", str(tmp_path / "t.png"), "--veneer", str(tmp_path / "v.png"), "--flat-rerank", "2",
            "--out", str(tmp_path / "o"), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "flat_rerank (--flat-rerank) must be >= rerank = 4 (the candidates" in err
    assert not (tmp_path / "o").exists()


def test_unreadable_image(tmp_path):
    bad = tmp_path / "scan.png"
    bad.write_text("not an image")
    with pytest.raises(WoodcamError, match="cannot be read as an image"):
        load_scan(bad, dpi=300)


def test_a_large_target_is_read_up_to_woodcams_pixel_limit_and_in_one_float_array(tmp_path, monkeypatch):
    """PIL's own bomb guard (89 Mpx; an error above 179 Mpx) came before woodcam's limit
    (268 Mpx): a 200 Mpx target was refused as 'damaged or cannot be read as an image', and
    WOODCAM_MAX_IMAGE_PIXELS could not raise it. Shown here with PIL's guard at 1000 px: a
    100 x 100 target is read; over woodcam's limit it is refused naming the limit, however far
    over. And the read made two float copies (astype, then / 255): its peak is now one."""
    import tracemalloc
    import warnings

    from PIL import Image

    from woodcam.parquetry.veneers import read_image

    Image.fromarray(np.random.default_rng(0).integers(0, 256, (100, 100, 3), np.uint8)).save(
        tmp_path / "t.png")
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 1000)
    a = read_image(tmp_path / "t.png", "target image")
    assert a.shape == (100, 100, 3) and a.dtype == np.float32
    # over the limit: PIL's warning (up to twice it; an error here, as filterwarnings says, and
    # ignored as the CLI does), PIL's error (beyond), woodcam's own check from the header
    for cap, ignore, said in ((5000, False, "is 10000 pixels"), (2000, False, "is 10000 pixels"),
                              (5000, True, "is 100x100 px")):
        monkeypatch.setenv("WOODCAM_MAX_IMAGE_PIXELS", str(cap))
        monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 1000)
        with pytest.raises(WoodcamError, match=f"target image: .*t.png' {said}, more than the limit "
                           f"MAX_IMAGE_PIXELS = {cap} pixels; downscale it, or raise the limit with "
                           "WOODCAM_MAX_IMAGE_PIXELS=N"), warnings.catch_warnings():
            if ignore:
                warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            read_image(tmp_path / "t.png", "target image")
    monkeypatch.delenv("WOODCAM_MAX_IMAGE_PIXELS")
    Image.fromarray(np.random.default_rng(0).integers(0, 256, (500, 400, 3), np.uint8)).save(
        tmp_path / "t.png")
    tracemalloc.start()
    try:
        a = read_image(tmp_path / "t.png", "target image")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1.4 * a.nbytes  # the float image and the 8-bit one (a quarter of it)
    assert np.array_equal(a * 255, np.round(a * 255)) and a.max() <= 1.0
    # a mask is thresholded on its 8-bit values: grey 128 (0.502) is wood, 127 is not
    Image.new("RGB", (4, 1)).save(tmp_path / "s.png")
    m = np.array([[[128] * 3, [127] * 3, [255, 128, 0], [255, 127, 0]]], np.uint8)
    Image.fromarray(m).save(tmp_path / "m.png")
    assert load_scan(tmp_path / "s.png", dpi=100, mask=tmp_path / "m.png").mask.tolist() == [
        [True, False, True, False]]


def test_a_phone_photo_is_read_upright(tmp_path):
    """A veneer or target photographed with a phone (landscape pixels, EXIF orientation 6) is
    read as viewers show it: 40 px wide and 60 px tall, its left half dark; raw it lay on its
    side, 60 x 40."""
    from PIL import Image

    from woodcam.parquetry.veneers import read_image

    upright = np.full((60, 40, 3), 220, np.uint8)
    upright[:, :20] = 30
    exif = Image.Exif()
    exif[0x0112] = 6  # Orientation: rotate 90 degrees clockwise to display
    Image.fromarray(np.rot90(upright).copy()).save(tmp_path / "phone.jpg", quality=95, exif=exif)
    a = read_image(tmp_path / "phone.jpg")
    assert a.shape == (60, 40, 3)
    assert a[:, :18].mean() < 0.2 and a[:, 22:].mean() > 0.8


def test_mask_of_another_size(tmp_path):
    from PIL import Image

    Image.new("RGB", (40, 30), (200, 150, 100)).save(tmp_path / "s.png")
    Image.new("L", (20, 30), 255).save(tmp_path / "m.png")
    # both files named: 'the mask must have the image's size 40x30 px; got 20x30' named neither,
    # and a job of several scans and masks left the user to find which
    with pytest.raises(WoodcamError, match=re.escape(
            f"veneer 's': its mask {str(tmp_path / 'm.png')!r} is 20x30 px and its scan {str(tmp_path / 's.png')!r} "
            "40x30 px; the mask must have the scan's size (one mask pixel per scan pixel); resample the mask to "
            "the scan")):
        load_scan(tmp_path / "s.png", dpi=100, mask=tmp_path / "m.png")


def test_zero_usable_wood(tmp_path):
    from PIL import Image

    Image.new("RGB", (40, 30), (200, 150, 100)).save(tmp_path / "s.png")
    Image.new("L", (40, 30), 0).save(tmp_path / "m.png")
    with pytest.raises(WoodcamError, match=re.escape(
            f"veneer 's' has zero usable wood: its mask {str(tmp_path / 'm.png')!r} has no white pixel (white, a "
            "mean of R, G and B above half, marks usable wood); paint the usable wood white, or give no mask")):
        load_scan(tmp_path / "s.png", dpi=100, mask=tmp_path / "m.png")
    # a scan given no mask whose pixels are all transparent was told 'its mask is empty; check
    # the mask (white = usable wood)'
    Image.new("RGBA", (40, 30), (200, 150, 100, 0)).save(tmp_path / "cutout.png")
    with pytest.raises(WoodcamError, match=re.escape(
            f"veneer 'cutout' has zero usable wood: every pixel of the scan {str(tmp_path / 'cutout.png')!r} is "
            "transparent (a cut-out's background is no wood)")) as info:
        load_scan(tmp_path / "cutout.png", dpi=100)
    assert "mask" not in str(info.value)
    # half transparent, the mask white only over the transparent half: said as such
    a = np.zeros((30, 40, 4), np.uint8)
    a[..., :3], a[:, :20, 3] = 150, 255
    Image.fromarray(a).save(tmp_path / "half.png")
    m = np.zeros((30, 40), np.uint8)
    m[:, 20:] = 255
    Image.fromarray(m).save(tmp_path / "right.png")
    with pytest.raises(WoodcamError, match=r"has no white pixel where the scan is opaque \(white"):
        load_scan(tmp_path / "half.png", dpi=100, mask=tmp_path / "right.png")


def test_patch_below_min_piece():
    with pytest.raises(WoodcamError, match="patch_mm must be at least min_piece_mm = 5 mm"):
        ParquetryParams(patch_mm=4).check()


def test_sheet_smaller_than_one_patch():
    v = Veneer("tiny", np.full((20, 20, 3), 0.5, np.float32), 2.0, np.ones((20, 20), bool))
    with pytest.raises(WoodcamError, match="'tiny' is 10.0 x 10.0 mm, smaller than one patch"):
        build_parquetry(np.zeros((50, 50, 3), np.float32), [v], ParquetryParams(px_per_mm=2.0))



def test_a_sheet_too_small_for_a_patch_and_its_whole_pixel_kerf_is_refused():
    """The search keeps ceil(kerf_px) whole pixels clear at each edge (matching._clear_of): a
    13 px sheet passed the size check for a 10 px patch at a 1.2 px kerf (12.4 px) and the run
    placed nothing ('the veneers ran out of free wood'). It needs 10 + 2 x 2 = 14 px."""
    prm = ParquetryParams(px_per_mm=1.0, patch_mm=10, overlap_mm=0, kerf_mm=1.2, image_size_mm=20)
    target = np.zeros((20, 20, 3), np.float32)
    v = Veneer("s13", np.full((13, 13, 3), 0.5, np.float32), 1.0, np.ones((13, 13), bool))
    with pytest.raises(WoodcamError, match=r"'s13' is 13.0 x 13.0 mm, smaller than one patch with its "
                       r"overlap and the kerf round it \(14 mm\)"):
        build_parquetry(target, [v], prm, seams=False)
    v = Veneer("s14", np.full((14, 14, 3), 0.5, np.float32), 1.0, np.ones((14, 14), bool))
    with pytest.warns(WoodcamWarning, match="the veneers cannot cover the panel"):  # one of its 4 patches
        assert len(build_parquetry(target, [v], prm, seams=False).patches) == 1


def test_a_run_that_placed_one_patch_says_one_patch():
    """'placed 1 patches covering 1 of 16 cells' and 'camera: 4 x 4 cells, 56 x 56 mm, 1 patches'
    (woodcam parquetry camera.png --veneer scan.png:130:half_mask.png, issue 19's walk-through)."""
    from woodcam.parquetry.output import format_summary, summary

    prm = ParquetryParams(px_per_mm=1.0, patch_mm=10, overlap_mm=0, kerf_mm=1.2, image_size_mm=20)
    v = Veneer("s14", np.full((14, 14, 3), 0.5, np.float32), 1.0, np.ones((14, 14), bool))
    with pytest.warns(WoodcamWarning, match="the veneers cannot cover the panel"):
        run = build_parquetry(np.zeros((20, 20, 3), np.float32), [v], prm, seams=False)
    assert run.message.startswith("the veneers ran out of free wood: placed 1 patch covering 1 of 4 cells; the "
                                  "rest of the panel is left empty. "), run.message
    text = format_summary(summary(run), {})
    assert text.splitlines()[0] == "target0: 2 x 2 cells, 20 x 20 mm, 1 patch", text


@pytest.mark.parametrize("kerf_mm, margin", [(0.0, 0), (0.5, 1), (1.0 - 1e-12, 1), (1.0, 1), (1.0 + 1e-12, 1),
                                             (1.2, 2), (2.0, 2), (2.5, 3)])
def test_the_size_check_and_the_search_agree_on_the_kerf_at_the_sheet_edge(kerf_mm, margin):
    """The engine's smallest sheet (a patch and edge_margin_px at both sides) and the wood the
    search may use (SheetBank.usable, matching._clear_of) follow one kerf rule, also at whole
    pixels (1 px: the pixel next to the edge lies exactly 1 + 1/2 + 1/2 px from the one off the
    sheet). At that side a piece is placed; one pixel less holds no patch-wide run of usable
    wood, and the size check refuses it."""
    from woodcam.parquetry.matching import SheetBank, edge_margin_px

    assert edge_margin_px(kerf_mm) == margin
    prm = ParquetryParams(px_per_mm=1.0, patch_mm=10, overlap_mm=0, kerf_mm=kerf_mm, image_size_mm=20)
    side = prm.patch_px + 2 * margin
    target = np.zeros((20, 20, 3), np.float32)
    for n in (side, side - 1):
        bank = SheetBank([np.zeros((n, n), np.float32)], [np.ones((n, n), bool)], n_rot=1, kerf_px=kerf_mm)
        run_px = int(bank.usable[0].sum(axis=1).max())  # the widest run of usable wood in a row
        assert run_px == n - 2 * margin
        v = Veneer(f"s{n}", np.full((n, n, 3), 0.5, np.float32), 1.0, np.ones((n, n), bool))
        if n == side:
            with pytest.warns(WoodcamWarning, match="the veneers cannot cover the panel"):  # one of its 4 patches
                assert len(build_parquetry(target, [v], prm, seams=False).patches) == 1
        else:
            assert run_px < prm.patch_px
            with pytest.raises(WoodcamError, match=rf"'s{n}' is .* smaller than one patch with its overlap "
                               rf"and the kerf round it \({side:g} mm\)"):
                build_parquetry(target, [v], prm, seams=False)


def test_adaptive_patches_with_seams_cover_once_and_use_wood_once(tmp_path):
    """Mixed 14 and 28 mm pieces with seams: the cut files still tile the panel exactly and
    never share wood."""
    from skimage import data

    from woodcam.stock import open_stock

    sheets = (slice_veneers(open_stock("builtin:flat-sawn", species="walnut"), 1, (300, 200),
                            px_per_mm=PPM, id_prefix="w")
              + slice_veneers(open_stock("builtin:rift", species="maple"), 1, (300, 200),
                              px_per_mm=PPM, id_prefix="m"))
    img = data.astronaut()[:256, :256].astype(np.float32) / 255
    run = build_parquetry(img, sheets, ParquetryParams(image_size_mm=112, px_per_mm=PPM, n_adaptive=1))
    assert run.complete and {q.cells for q in run.patches} == {1, 2}
    res = write_parquetry(run, tmp_path)
    assert res["problems"] == {}
    n = rasterise(read_svg_pieces(tmp_path / "assembly.svg"), run.panels[0].matched.shape, PPM)
    assert (n == 1).all()
    for v in run.veneers:
        f = tmp_path / f"veneer_{v.id}.svg"
        if f.exists():
            assert rasterise(read_svg_pieces(f), v.mask.shape, PPM).max() == 1


@pytest.mark.parametrize("n_adaptive", [1, 2])
def test_adaptive_patches_cover_a_panel_of_whole_cells_not_a_multiple_of_the_top_square(sheets, tmp_path, n_adaptive):
    """A 5 x 7 cell panel with top squares of 2 or 4 cells: the last row and column were one
    square of their short side each, leaving 5 cells (n_adaptive 1) uncovered, the run
    incomplete with no message. Every cell is covered, the cut files tile the panel once."""
    from skimage import data

    img = data.astronaut()[:256, :360].astype(np.float32) / 255
    run = build_parquetry(img, sheets, ParquetryParams(image_size_mm=70, px_per_mm=PPM,
                                                       n_adaptive=n_adaptive, w_adaptive=50.0))
    p = run.panels[0]
    assert p.cells.shape == (5, 7)
    assert run.complete and run.placed == run.planned == 35 and (p.cells >= 0).all()
    res = write_parquetry(run, tmp_path)
    assert res["problems"] == {}
    n = rasterise(read_svg_pieces(tmp_path / "assembly.svg"), p.matched.shape, PPM)
    assert (n == 1).all(), f"{(n == 0).sum()} pixels uncovered, {(n > 1).sum()} covered twice"


def test_planted_violation_is_repaired_and_files_pass(sheets, tmp_path):
    """A seam given a sharp zig-zag (bends far tighter than the 1 mm tool radius) is caught by
    the checker, repaired by straightening, and the written files then pass the checks when
    parsed back; every panel pixel is still covered exactly once."""
    from skimage import data

    from woodcam.parquetry.engine import _render_panel, repair_fabricability
    from woodcam.parquetry.output import run_pieces
    from woodcam.parquetry.seams import _line_from, labels_from_lines

    target = data.camera()[40:300, 120:380].astype(np.float32) / 255.0
    prm = ParquetryParams(image_size_mm=42, px_per_mm=PPM)
    run = build_parquetry(target, sheets, prm, repair=False)
    p = run.panels[0]
    assert run.complete and p.seams_v is not None
    assert all(not pc.problems for pc in run_pieces(run))
    H = p.matched.shape[0]
    line = p.seams_v[0]
    vals = line(np.arange(H) + 0.5)
    # zig-zag of +-6 px on three of the spline's knots (every 8 px) in the first row of cells
    y = np.arange(H) + 0.5
    vals = vals + 6.0 * (np.abs(y - 8) < 2) - 6.0 * (np.abs(y - 16) < 2) + 6.0 * (np.abs(y - 24) < 2)
    p.seams_v[0] = _line_from(vals, "v", 1, H, line.raw)
    p.labels = labels_from_lines(p, p.seams_v, p.seams_h)
    _render_panel(p, run.bank, run.veneers)
    planted = {pc.id: pc.problems for pc in run_pieces(run) if pc.problems}
    assert planted and any("concave" in m for v in planted.values() for m in v), planted

    repaired = repair_fabricability(run)
    assert set(planted) <= set(repaired)
    res = write_parquetry(run, tmp_path)
    assert res["problems"] == {}
    assert json.loads((tmp_path / "result.json").read_text())["fabricability"]["repaired"]
    checked = 0
    for v in run.veneers:
        f = tmp_path / f"veneer_{v.id}.svg"
        if f.exists():
            for segs in read_svg_segments(f).values():
                assert check_piece(segs, prm.min_piece_mm, prm.tool_diameter_mm / 2) == []
                checked += 1
    assert checked == len(run.patches)
    n = rasterise(read_svg_pieces(tmp_path / "assembly.svg"), p.matched.shape, PPM)
    assert (n == 1).all()


def test_pieces_keep_the_kerf_clear_of_the_sheet_edge_and_unusable_wood(sheets, tmp_path):
    """Parsed back from the written veneer SVG and DXF: every piece grown by the kerf (the wood
    the router takes round it) lies on its sheet and off the mask's unusable wood (a hole in
    the first sheet), whatever the rotation; the old rule let pieces lie on the sheet's edge."""
    from skimage import data
    from shapely.geometry import Polygon, box
    from shapely.ops import unary_union

    v0 = sheets[0]
    yy, xx = np.mgrid[:v0.mask.shape[0], :v0.mask.shape[1]]
    hole = v0.mask & ((yy - 80) ** 2 + (xx - 120) ** 2 >= 40 ** 2)
    mine = [Veneer(v0.id, v0.rgb, v0.px_per_mm, hole, v0.source, v0.sheet_mm), *sheets[1:]]
    target = data.camera()[40:300, 120:380].astype(np.float32) / 255.0
    run = build_parquetry(target, mine, ParquetryParams(image_size_mm=70, px_per_mm=PPM))
    assert run.complete
    write_parquetry(run, tmp_path)
    kerf = run.params.kerf
    checked = 0
    for v in run.veneers:
        f = tmp_path / f"veneer_{v.id}.svg"
        if not f.exists():
            continue
        W, H = v.size_mm
        sx, sy = v.pixel_scale()
        r, c = np.nonzero(~v.mask)
        off = unary_union([box(x * sx / PPM, y * sy / PPM, (x + 1) * sx / PPM, (y + 1) * sy / PPM)
                           for y, x in zip(r, c)])
        for polys in (read_svg_pieces(f), read_dxf_pieces(tmp_path / f"veneer_{v.id}.dxf", H)):
            for pid, q in polys.items():
                edge = min(q[:, 0].min(), q[:, 1].min(), W - q[:, 0].max(), H - q[:, 1].max())
                assert edge >= kerf - 1e-3, f"piece {pid} lies {edge:.3f} mm from the edge of {v.id}"
                if not off.is_empty:
                    gap = Polygon(q).distance(off)
                    assert gap >= kerf - 1e-3, f"piece {pid} lies {gap:.3f} mm from unusable wood"
                checked += 1
    assert checked == 2 * len(run.patches)
    assert any(f.name == f"veneer_{v0.id}.svg" for f in tmp_path.iterdir())


def test_is_free_quick_accept_gives_the_rasterised_answer():
    """is_free's bounding-box shortcut must answer exactly as rasterising the footprint does:
    random used wood, random rotations, anchors and sizes (down to 2 px and off the sheet)."""
    from woodcam.parquetry.matching import SheetBank, _polygon_pixels

    rng = np.random.default_rng(3)
    g = np.full((120, 150), 0.5, np.float32)
    bank = SheetBank([g], [np.ones(g.shape, bool)], n_rot=15, mode="fast", coarse_factor=4)
    taken = bank.taken[0]
    taken[rng.random(taken.shape) < 0.002] = True
    taken[40:60, 70:100] = True
    quick = 0
    for _ in range(3000):
        j = int(rng.integers(15))
        th, tw = (int(v) for v in rng.integers(2, 40, 2))
        x, y = (float(v) for v in rng.integers(-10, 200, 2))
        poly = bank.footprint(0, j, x, y, th, tw)
        rr, cc = _polygon_pixels(poly, taken.shape)
        lo, hi = poly.min(0), poly.max(0)
        on = lo.min() >= -0.5 - 1e-6 and hi[0] <= 150 - 0.5 + 1e-6 and hi[1] <= 120 - 0.5 + 1e-6
        want = bool(on and rr.size and not taken[rr, cc].any())
        assert bank.is_free(0, poly) == want, (j, th, tw, x, y)
        quick += want
    assert quick > 100


def test_is_free_tests_taken_wood_before_the_exact_edge_test_and_keeps_its_answers(monkeypatch):
    """is_free ran the exact (shapely, ~2 ms) kerf test before the cheap taken-pixel test; now
    the exact test runs only for a footprint clear of taken wood, and only on the unusable
    squares that may come within the kerf. The answers are those of the exact test on every
    square of the grown box (random unusable wood, rotations, sizes, kerfs)."""
    import shapely

    from woodcam.parquetry.matching import SheetBank

    rng = np.random.default_rng(5)
    g = np.full((90, 120), 0.5, np.float32)
    usable = rng.random(g.shape) > 0.01
    usable[30:45, 50:80] = False
    for kerf in (0.0, 1.3, 3.0):
        bank = SheetBank([g], [usable], n_rot=15, kerf_px=kerf, mode="fast", coarse_factor=4)
        off = ~usable
        for _ in range(400):
            j = int(rng.integers(15))
            th, tw = (int(v) for v in rng.integers(2, 30, 2))
            x, y = (float(v) for v in rng.integers(-5, 130, 2))
            poly = bank.footprint(0, j, x, y, th, tw)
            lo, hi = poly.min(0) - kerf, poly.max(0) + kerf
            on = lo.min() >= -0.5 - 1e-6 and hi[0] <= 120 - 0.5 + 1e-6 and hi[1] <= 90 - 0.5 + 1e-6
            rr, cc = np.nonzero(off)
            squares = shapely.box(cc - 0.5, rr - 0.5, cc + 0.5, rr + 0.5)
            fp = shapely.Polygon(poly)
            clear = (bool((shapely.distance(fp, squares) >= kerf - 1e-6).all()) if kerf > 0 else
                     bool((shapely.area(shapely.intersection(fp, squares)) <= 1e-9).all()))
            assert bank.clears_edges(0, poly) == (on and clear), (kerf, j, th, tw, x, y)
    calls = []
    monkeypatch.setattr(SheetBank, "clears_edges", lambda self, i, poly: calls.append(i) or True)
    bank.taken[0][:] = True
    assert not bank.is_free(0, bank.footprint(0, 3, 40.0, 40.0, 10, 10)) and calls == []


def test_flat_window_weighting_is_on_by_default(sheets, monkeypatch):
    """The defaults (flat_detail 3, flat_rerank 12; README "flat windows"): a flat target's
    coarse search weighs the detail channel 3 times and re-ranks up to 12 candidates, a target
    with contrast everywhere keeps weight 1 and 4; flat_detail=1, flat_rerank=4 turns it off."""
    from woodcam.parquetry import ParquetryParams, build_parquetry
    from woodcam.parquetry.matching import SheetBank, _Atlas

    assert (ParquetryParams().flat_detail, ParquetryParams().flat_rerank) == (3.0, 12)
    weights, reranks = [], []
    search, rerank_batch = _Atlas.search, SheetBank._rerank_batch

    def spy_search(self, template, k, trim=(0, 0, 0, 0), exclude=None, detail_weight=1.0):
        weights.append(detail_weight)
        return search(self, template, k, trim, exclude, detail_weight)

    def spy_rerank(self, template, batch, dead, struct_px, rerank=None):
        reranks.append(rerank)
        return rerank_batch(self, template, batch, dead, struct_px, rerank)

    monkeypatch.setattr(_Atlas, "search", spy_search)
    monkeypatch.setattr(SheetBank, "_rerank_batch", spy_rerank)
    flat = np.full((64, 64), 0.45, np.float32)
    prm = ParquetryParams(image_size_mm=28, px_per_mm=PPM)
    build_parquetry(flat, sheets, prm, seams=False)
    assert set(weights) == {3.0} and set(reranks) == {12}
    weights.clear(), reranks.clear()
    checker = np.kron(np.indices((32, 32)).sum(0) % 2, np.ones((2, 2))).astype(np.float32)
    build_parquetry(checker, sheets, prm, seams=False)
    assert set(weights) == {1.0} and set(reranks) == {4}
    weights.clear(), reranks.clear()
    off = ParquetryParams(image_size_mm=28, px_per_mm=PPM, flat_detail=1.0, flat_rerank=4)
    build_parquetry(flat, sheets, off, seams=False)
    assert set(weights) == {1.0} and set(reranks) == {4}


def test_cut_files_state_the_real_sheet_size_not_the_pixel_grid(tmp_path):
    """A 101 px scan at 50 dpi is 51.308 mm, but resampled to 2 px/mm it has 103 px and its cut
    file said 51.5 mm; an 8 x 6 in leaf (203.2 x 152.4 mm) at 4 px/mm said 203.25 x 152.5 mm.
    The files now state the real size and place the pieces in real sheet mm."""
    import re

    from skimage import data

    from woodcam.stock import open_stock

    st = open_stock("builtin:flat-sawn", species="walnut")
    (leaf,) = slice_veneers(st, 1, (203.2, 152.4), px_per_mm=0.5, id_prefix="leaf")
    assert leaf.size_mm == (203.2, 152.4) and leaf.rgb.shape[:2] == (76, 102)
    (big,) = slice_veneers(st, 1, (60.3, 60.3), px_per_mm=50 / 25.4, id_prefix="src")
    scan = Veneer("scan", big.rgb[:101, :101], 50 / 25.4, np.ones((101, 101), bool))
    real = 101 / (50 / 25.4)
    assert scan.resampled(PPM).size_mm == pytest.approx((real, real), abs=1e-12)
    img = data.camera()[:128, :128].astype(np.float32) / 255.0
    run = build_parquetry(img, [scan], ParquetryParams(image_size_mm=28, px_per_mm=PPM))
    write_parquetry(run, tmp_path)
    svg = (tmp_path / "veneer_scan.svg").read_text()
    w, h = (float(v) for v in re.search(r'width="([\d.]+)mm" height="([\d.]+)mm"', svg).groups())
    assert (w, h) == (round(real, 3), round(real, 3))
    result = json.loads((tmp_path / "result.json").read_text())
    assert result["veneers"][0]["size_mm"] == pytest.approx([real, real])
    # the panel-to-sheet affine carries the scale of the sheet's rounded pixel grid
    s = real * PPM / 103
    for q in result["patches"]:
        lin = np.asarray(q["panel_to_sheet_mm"])[:, :2]
        np.testing.assert_allclose(np.linalg.norm(lin, axis=1), [s, s], rtol=1e-9)


def test_preparing_the_rotated_sheets_has_a_bar(sheets, monkeypatch):
    """Rotating every sheet n_rot times took seconds to minutes (7 s for two 600 x 400 mm leaves
    at 3 px/mm) before the first patch, with no bar between slicing and matching."""
    import woodcam._progress as _progress

    seen = []
    real = _progress.progress_bar

    def spy(*a, desc, **k):
        seen.append((desc, k.get("enabled", True)))
        return real(*a, desc=desc, **k)

    monkeypatch.setattr(_progress, "progress_bar", spy)
    target = np.full((40, 40, 3), 0.5, np.float32)
    build_parquetry(target, sheets[:1], ParquetryParams(image_size_mm=28, px_per_mm=PPM, n_rot=3),
                    progress=True)
    assert seen[:2] == [("rotating sheets", True), ("matching patches", True)]


def test_transparent_pixels_are_named_with_the_fix_for_what_the_image_is_for(tmp_path):
    """The alpha warning assumed a photo ('a cut-out? crop the image') for parquetry masks and
    target logos too, and a 16-bit grey PNG's transparent colour was dropped without a word.
    A mask: paint unusable wood black; a target: flatten it onto the background wanted; a scan's
    are no usable wood."""
    from PIL import Image

    from woodcam.parquetry.job import ParquetryJob, job_targets

    rgba = np.zeros((20, 20, 4), np.uint8)
    rgba[..., :3], rgba[..., 3] = 180, 255
    rgba[:5, :, 3] = 0
    Image.fromarray(rgba).save(tmp_path / "logo.png")
    Image.fromarray(rgba).save(tmp_path / "mask.png")
    Image.new("RGB", (20, 20), (150, 100, 60)).save(tmp_path / "scan.png")
    with pytest.warns(WoodcamWarning, match=r"target image: .*logo.png' has transparent pixels \(25 % of them, "
                      r"a logo or cut-out\?\), .*; flatten it onto the background you want the panel to show$"):
        job_targets(ParquetryJob(targets=[{"filename": str(tmp_path / "logo.png")}]))
    with pytest.warns(WoodcamWarning, match=r"veneer mask: .*mask.png' has transparent pixels \(25 % of them, "
                      r"transparency does not mark wood as unusable\), .*; paint unusable wood black and "
                      r"usable wood white, every pixel opaque$"):
        load_scan(tmp_path / "scan.png", dpi=100, mask=tmp_path / "mask.png")
    grey = np.full((20, 20), 30000, np.uint16)
    grey[:2] = 0
    Image.fromarray(grey).save(tmp_path / "grey16.png", transparency=0)
    # a scan's transparent pixels (here its transparent colour) are no usable wood, not warned of
    # (test_a_cut_out_scans_transparent_pixels_are_no_usable_wood)
    assert np.array_equal(load_scan(tmp_path / "grey16.png", dpi=100).mask, grey != 0)


def test_adaptive_levels_are_bounded_by_the_panel():
    """n_adaptive took any int: the top squares of 2^n cells are clipped to the panel's shorter
    side, so a level past it made no patch of patch_mm * 2^n (a job file's 10^9 asked for
    2^(10^9)-cell squares). The most is the panel's: 4 on the default 364 mm (26 patches)."""
    assert ParquetryParams().max_adaptive == 4 and ParquetryParams(n_adaptive=4).n_adaptive == 4
    assert ParquetryParams(image_size_mm=70, n_adaptive=2).max_adaptive == 2  # 5 patches
    for n in (5, 10 ** 9):
        with pytest.raises(WoodcamError, match=r"n_adaptive \(--n-adaptive\) must be in \[0, 4\] here: its "
                           r"largest patch, .* must fit the panel's shorter side, 364 mm \(26 patches"):
            ParquetryParams(n_adaptive=n)


def test_flatten_gives_the_per_curve_loops_points_bit_for_bit():
    """Refactor check: cutpaths.flatten, all curves at once, gives the very points (and dtype)
    of the loop it replaced (one numpy sum per segment) on outlines of lines and cubic Béziers,
    lines only and curves only."""
    from woodcam.parquetry.cutpaths import flatten

    def loop(segs, n=8):
        ts = np.linspace(0, 1, n, endpoint=False)
        pts = []
        for s in segs:
            if s[0] == "L":
                pts.append(s[1][None])
            else:
                p0, p1, p2, p3 = s[1:]
                u = 1 - ts
                pts.append((u ** 3)[:, None] * p0 + (3 * u * u * ts)[:, None] * p1
                           + (3 * u * ts * ts)[:, None] * p2 + (ts ** 3)[:, None] * p3)
        return np.concatenate(pts)

    rng = np.random.default_rng(0)
    for share_lines in (0.3, 0.0, 1.0):
        for _ in range(200):
            segs = [("L", rng.uniform(0, 300, 2), rng.uniform(0, 300, 2)) if rng.random() < share_lines
                    else ("C", *rng.uniform(-50, 300, (4, 2))) for _ in range(rng.integers(1, 40))]
            for n in (8, 3):
                want, got = loop(segs, n), flatten(segs, n)
                assert got.dtype == want.dtype and got.shape == want.shape
                assert np.array_equal(got, want)


def test_a_flat_target_area_stays_flat_after_histogram_matching():
    """A flat 200/255 background round a dark disc, resampled to the panel (cv2.resize in
    float32), came out a few float32 ulps apart (0.78431356 to 0.7843139); eq. 2 ranked those
    as distinct grey levels, and the flat area was matched to a fine grid pattern spread over a
    fifth of the wood's histogram (std 0.058, 0.575 to 0.791; a 1 x 1 px target to five levels
    of stripes). Levels within the tolerance are one level, which keeps one quantile."""
    from woodcam.parquetry.engine import prepare_target
    from woodcam.parquetry.features import match_histogram
    from woodcam.tolerances import PARQUETRY_GREY_LEVEL_TOL

    yy, xx = np.mgrid[:300, :300]
    img = np.full((300, 300, 3), 200 / 255, np.float32)
    img[(yy - 150) ** 2 + (xx - 150) ** 2 < 60 ** 2] = 30 / 255
    wood = np.random.default_rng(0).uniform(0.3, 0.8, 100_000).astype(np.float32)
    t = prepare_target(img, ParquetryParams(image_size_mm=84, px_per_mm=4).check(), wood)
    h, w = t.matched.shape
    y, x = np.mgrid[:h, :w]
    far = (y - h / 2) ** 2 + (x - w / 2) ** 2 > (0.3 * h) ** 2  # away from the disc's edge
    assert np.ptp(t.target_rgb[far]) < 1e-6  # flat, to float32 noise
    assert np.ptp(t.matched[far]) < 1e-6  # the noise (1 - w_hist) carries, not the wood's spread
    dark = (y - h / 2) ** 2 + (x - w / 2) ** 2 < (0.15 * h) ** 2
    assert np.ptp(t.matched[dark]) < 1e-6 and t.matched[dark][0] < t.matched[far][0]
    # levels a 16-bit image tells apart stay apart; exactly equal ones share their mean rank
    step = np.float32(1 / 65535)
    g = np.array([0.5, 0.5 + step, 0.5 + 2 * step, 0.5, 0.5 + 2 * step], np.float32)
    assert step > PARQUETRY_GREY_LEVEL_TOL
    m = match_histogram(g, np.linspace(0, 1, 1001, dtype=np.float32), 1.0)
    assert m[0] == m[3] and m[2] == m[4] and m[0] < m[1] < m[2]
    assert m[1] == pytest.approx(0.5, abs=1e-3) and m[0] == pytest.approx(0.2, abs=1e-3)


def test_a_cut_out_scans_transparent_pixels_are_no_usable_wood(tmp_path):
    """A veneer scan saved as a cut-out (its background transparent) was read as the colour
    stored under the transparency, with a warning to flatten it onto its background: its
    background was usable wood, and 4 of 16 pieces of a run were cut from it. Its pixels that
    are not fully opaque are now no usable wood, with or without a mask (which they narrow)."""
    from PIL import Image

    from woodcam.parquetry import load_scan

    rgb = (np.random.default_rng(0).random((120, 160, 3)) * 255).astype(np.uint8)
    alpha = np.full((120, 160), 255, np.uint8)
    alpha[:, :50] = 0  # the background
    alpha[:10, 50:] = 128  # a soft edge: not wood either
    Image.fromarray(np.dstack([rgb, alpha])).save(tmp_path / "cut.png")
    want = alpha == 255
    v = load_scan(tmp_path / "cut.png", px_per_mm=2)  # no warning (filterwarnings = error)
    assert v.mask.shape == want.shape and np.array_equal(v.mask, want)
    assert np.array_equal(v.rgb, rgb.astype(np.float32) / 255)  # the colours as stored
    mask = np.ones((120, 160), bool)
    mask[100:] = False
    assert np.array_equal(load_scan(tmp_path / "cut.png", px_per_mm=2, mask=mask).mask, want & mask)
    Image.fromarray(np.dstack([rgb, np.full((120, 160), 255, np.uint8)])).save(tmp_path / "opaque.png")
    assert load_scan(tmp_path / "opaque.png", px_per_mm=2).mask.all()
