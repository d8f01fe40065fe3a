"""Appearance evaluation: the image measures against known answers; leave-one-face-out runs."""


import numpy as np
import pytest

from woodcam.appearance.evaluation import (
    MODELS, FaceEval, histogram_distance, leave_one_face_out, patch_distance, radial_power_spectrum, side_by_side,
    spectrum_distance, summarise,
)
from woodcam.block import Block, Face
from woodcam.errors import WoodcamError


def _stripes(h=64, w=64, period=8.0, phase=0.0):
    x = np.arange(w)
    s = 0.5 + 0.3 * np.sin(2 * np.pi * (x / period) + phase)
    return np.repeat(np.tile(s, (h, 1))[..., None], 3, axis=2)


def test_histogram_distance_of_a_uniform_shift_is_the_shift(rng):
    a = rng.uniform(0.2, 0.6, (40, 50, 3))
    assert histogram_distance(a, a) == 0.0
    assert histogram_distance(a, a + 0.1) == pytest.approx(0.1, abs=1e-9)
    # A permutation of the pixels keeps the colour distribution.
    perm = a.reshape(-1, 3)[rng.permutation(2000)].reshape(a.shape)
    assert histogram_distance(a, perm) == pytest.approx(0.0, abs=1e-12)


def test_power_spectrum_peaks_at_the_stripe_frequency_and_sees_blur():
    a = _stripes(period=8.0)
    p = radial_power_spectrum(a)
    assert np.argmax(p) + 1 == 64 // 8            # bins start at radius 1
    assert spectrum_distance(a, _stripes(phase=1.0)) < 0.05  # shift: same spectrum
    assert spectrum_distance(a, _stripes(period=4.0)) > 1.0  # other frequency: decades apart


def test_patch_distance_sees_texture_that_histograms_miss(rng):
    """Same colours, different arrangement: fine noise against its sorted (smooth) version."""
    a = rng.uniform(0.3, 0.7, (64, 64, 3))
    smooth = np.sort(a.reshape(-1, 3), axis=0).reshape(a.shape)
    assert histogram_distance(a, smooth) == pytest.approx(0.0, abs=1e-12)
    assert patch_distance(a, a) == 0.0
    assert patch_distance(a, smooth) > 0.05


def test_measures_reject_mismatched_images():
    with pytest.raises(WoodcamError, match="images must both be"):
        histogram_distance(np.zeros((4, 4, 3)), np.zeros((4, 5, 3)))


def _tiny_eval_block():
    from woodcam.fields.builtin import builtin_block
    from woodcam.synth import synth_block

    b = builtin_block("pith-inside")
    return synth_block(b.field, b.size_mm, face_px=64, seed=0, name="tiny"), b.field


def _assert_predictions_resemble_the_photo(r):
    """Every model's prediction is close to the held-out photo in colour (histogram and mean
    absolute difference) and far closer than a black image would be; its scores are its own."""
    black = histogram_distance(np.zeros_like(r.photo), r.photo)
    assert black > 0.4                                   # the photo is not dark itself
    for m in MODELS:
        pred = np.asarray(r.predictions[m], float)
        assert r.scores[m]["histogram"] == pytest.approx(histogram_distance(pred, r.photo), abs=1e-6)
        assert r.scores[m]["histogram"] < 0.25 * black, (m, r.face, r.scores[m])
        assert np.mean(np.abs(pred - r.photo)) < 0.15, (m, r.face)


def test_leave_one_face_out_runs_all_models(tmp_path):
    block, field = _tiny_eval_block()
    res = leave_one_face_out(block, field, resolution=40, quality="draft", epochs=1,
                             faces=["top", "front"], progress=False)
    assert [r.face for r in res] == ["top", "front"]
    # The pith runs along Z: top is end grain, front side grain.
    assert res[0].end_grain is True and res[1].end_grain is False
    for r in res:
        assert set(r.predictions) == set(MODELS)
        for m in MODELS:
            assert r.predictions[m].shape == r.photo.shape
            assert set(r.scores[m]) == {"histogram", "spectrum", "patch", "l1"}
        _assert_predictions_resemble_the_photo(r)
    s = summarise(res)
    assert s["end_grain"]["faces"] == ["top"] and s["side_grain"]["faces"] == ["front"]
    side_by_side(res, tmp_path / "sbs.png", title="tiny")
    from PIL import Image

    with Image.open(tmp_path / "sbs.png") as im:
        assert im.size[0] >= 4 * res[0].photo.shape[1]


def test_leave_one_face_out_on_ring_maps_without_a_field(bars):
    block, _ = _tiny_eval_block()
    res = leave_one_face_out(block, None, resolution=40, quality="draft", epochs=1, faces=["left"],
                             progress=True)
    # sweep h5 item 7: a bar over the held-out faces (each trains up to three nets)
    (faces,) = [b for b in bars if b.unit == "face"]
    assert faces.total == faces.n == 1 and faces.enabled
    assert res[0].end_grain is None and set(res[0].predictions) == set(MODELS)
    _assert_predictions_resemble_the_photo(res[0])


@pytest.mark.parametrize("name, end", [
    ("knotty", {"top", "bottom"}),          # the log upright; a knot crosses the front's centre
    ("flat-sawn", {"left", "right"}), ("pith-inside", {"top", "bottom"}),
])
def test_end_grain_faces_are_the_faces_mostly_of_end_grain(name, end):
    """builtin:knotty's front is side grain on 95 % of it, but a knot's fibres leave it at its
    centre, the one point end_grain_faces looked at: eval appearance labelled it 'end grain'
    and summarised it with the end-grain faces (sweep h4)."""
    from woodcam.appearance.evaluation import end_grain_faces
    from woodcam.stock import open_stock

    stock = open_stock(f"builtin:{name}")
    got = end_grain_faces(stock.wood.field, stock.size_mm)
    assert {f for f, e in got.items() if e} == end, got


def test_summarise_known_answers():
    """Mean of each measure per model over all / end-grain / side-grain faces (a face of unknown
    grain counts in "all" only), and on how many faces neural scores lower (better)."""
    from woodcam.appearance.evaluation import METRICS, FaceEval

    def face(name, end_grain, neural, agnostic, colormap):
        scores = {m: dict.fromkeys(METRICS, v) for m, v in zip(MODELS, (neural, agnostic, colormap))}
        return FaceEval(name, end_grain, np.zeros((2, 2, 3)), scores=scores)

    res = [face("top", True, 0.1, 0.3, 0.2), face("front", False, 0.5, 0.2, 0.4),
           face("left", None, 0.2, 0.4, 0.2), face("bottom", True, 0.3, 0.1, 0.5)]
    s = summarise(res)
    assert s["all"]["faces"] == ["top", "front", "left", "bottom"]
    assert s["end_grain"]["faces"] == ["top", "bottom"] and s["side_grain"]["faces"] == ["front"]
    for k in METRICS:
        assert s["all"]["neural"][k] == pytest.approx(0.275)   # median 0.25
        assert s["end_grain"]["agnostic"][k] == pytest.approx(0.2)
        assert s["side_grain"]["colormap"][k] == pytest.approx(0.4)
        # neural lower than agnostic on top and left; lower than colormap on top and bottom (a
        # tie, left, is no win)
        assert s["all"]["neural_beats_agnostic"][k] == "2/4"
        assert s["all"]["neural_beats_colormap"][k] == "2/4"
        assert s["end_grain"]["neural_beats_colormap"][k] == "2/2"
        assert s["side_grain"]["neural_beats_agnostic"][k] == "0/1"


def test_leave_one_face_out_needs_two_photos():
    one = Block((10, 10, 10), faces={"top": Face("top", (8, 8), photo=np.zeros((8, 8, 3), np.uint8))})
    with pytest.raises(WoodcamError, match="at least two faces"):
        leave_one_face_out(one, lambda p: p[:, 0], progress=False)


def test_cli_parser_wires_run(capsys, tmp_path):
    from woodcam.cli import appearance, build_parser, main

    a = build_parser().parse_args(["eval", "appearance", "builtin:rift", "--out", "x", "--quality",
                                   "draft", "--epochs", "2"])
    assert a.func is appearance.run and a.epochs == 2 and a.quality == "draft"
    # old name; a block folder that is not there: a wrong command line, the input door's (exit 2)
    assert main(["eval-appearance", "/nonexistent/folder", "--out", str(tmp_path)]) == 2
    assert "BLOCK of 'woodcam eval appearance' (block spec '/nonexistent/folder')" in capsys.readouterr().err


def test_a_grid_too_coarse_to_learn_from_names_resolution(capsys, tmp_path):
    """eval appearance --resolution 8 (in its range) failed with 'training images must be at least
    patch_px=8 pixels ...; use ... a smaller patch_px', an option no command has."""
    pytest.importorskip("torch")
    from woodcam.cli import main

    assert main(["eval", "appearance", "builtin:flat-sawn", "--out", str(tmp_path), "--resolution", "8",
                 "--quality", "draft", "--epochs", "1", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "patch_px" not in err and err.count("\n") == 1
    assert ("at least 8 cells on each side; the colour-volume grid gives 4x8, 6x8, 4x6, 4x6, 6x8 cells; "
            "raise its resolution (--resolution") in err


@pytest.mark.slow
@pytest.mark.parametrize("sample", ["H11", "CN03"])
def test_leave_one_face_out_on_mokume_cubes(shared_data, sample):
    """Real cubes without a fitted field: ring maps in, photos out (draft size)."""
    from woodcam.block.io import read_mokume

    block = read_mokume(shared_data / "mokume" / sample)
    res = leave_one_face_out(block, None, resolution=64, quality="draft", faces=["top", "front"],
                             end_grain={"top": True, "front": False}, progress=False)
    for r in res:
        assert r.photo.shape == (64, 64, 3)
        for m in MODELS:
            assert all(np.isfinite(v) for v in r.scores[m].values())


class _NormalColour:
    """An appearance that paints |normal|: lets the renders be checked geometrically."""

    def color(self, points_mm, normals):
        return np.abs(np.asarray(normals, float))


def test_renders_put_the_surface_where_the_geometry_says():
    from woodcam.appearance.evaluation import render_plane, render_sphere

    size = (40.0, 40.0, 40.0)
    plane = render_plane(_NormalColour(), size, normal=(0.0, 0.0, 1.0), px=64)
    # A horizontal cut through a cube seen from above: a square of colour |n| = (0, 0, 1).
    inside = np.all(plane != 1.0, axis=2) | np.all(plane == [0, 0, 1], axis=2)
    np.testing.assert_array_equal(plane[inside], np.tile([0.0, 0.0, 1.0], (int(inside.sum()), 1)))
    side = 40.0 / (np.sqrt(3) * 40.0)                       # block side over the view's width
    assert inside.mean() == pytest.approx(side ** 2, rel=0.1)
    sphere = render_sphere(_NormalColour(), size, px=128, light=(0, 0, 1))
    disc = np.any(sphere != 1.0, axis=2)
    assert disc.mean() == pytest.approx(np.pi / 4, rel=0.03)


@pytest.mark.parametrize("longest", [8, 16, 48, 256])
def test_the_side_by_side_labels_never_overlap(tmp_path, longest, rng):
    """At --resolution 48 the scores were drawn one photo's width apart (24-48 px) and overlapped,
    and the face's '(side grain)' ran into the next column's label: every label and image now
    has its own box, inside the figure, at any image size."""
    from PIL import Image

    from woodcam.appearance.evaluation import FaceEval, _side_by_side_layout

    shapes = {"front": (longest // 2, longest), "top": (max(1, longest * 4 // 5), longest),
              "left": (longest // 2, max(1, longest * 4 // 5))}
    res = []
    for i, (face, (h, w)) in enumerate(shapes.items()):
        photo = rng.uniform(0, 1, (h, w, 3))
        models = MODELS if i else MODELS[:-1]  # a model that did not run is labelled too
        res.append(FaceEval(face, [None, True, False][i], photo, {m: photo for m in models},
                            {m: {"histogram": 0.123, "spectrum": 12.34, "patch": 0.456} for m in models}))
    title = "builtin:flat-sawn: held-out faces (ARF of field input)"
    (w, h), items = _side_by_side_layout(res, title)
    boxes = [box for _, box, _ in items]
    assert all(0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h for x0, y0, x1, y1 in boxes)
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1], (a, b, items)
    texts = [what[2] for kind, _, what in items if kind == "text"]
    assert title in texts and "not run" in texts and "(end grain)" in texts
    side_by_side(res, tmp_path / "sbs.png", title=title)
    with Image.open(tmp_path / "sbs.png") as im:
        assert im.size == (w, h)
    # the three scores of a row side by side fit across the figure (the old one was 4 photos wide)
    from PIL import ImageDraw, ImageFont

    assert w > 3 * ImageDraw.Draw(Image.new("RGB", (1, 1))).textlength("0.123/12.34/0.456", font=ImageFont.load_default())


def test_eval_appearance_outputs_land_as_one_set_and_a_rerun_removes_the_earlier_runs(tmp_path, monkeypatch,
                                                                                      capsys):
    """Each block's PNG was written as it came and results.json at the end: a Ctrl-C left a new
    PNG beside an earlier run's results, and a rerun with fewer blocks kept the earlier run's
    pictures. Now the run's files land together (or none do) and the earlier run's it does
    not write again go, with a warning."""
    import re

    import woodcam.appearance.evaluation as evaluation
    from woodcam._atomic import write_text
    from woodcam.cli import main

    seen = []

    def held_out(block, field, **kwargs):
        seen.append(block.name)
        if len(seen) == stop_at[0]:
            raise KeyboardInterrupt
        return []

    stop_at = [None]
    monkeypatch.setattr(evaluation, "leave_one_face_out", held_out)
    monkeypatch.setattr(evaluation, "side_by_side", lambda res, path, **kw: write_text(path, "a picture"))
    monkeypatch.setattr(evaluation, "summarise", lambda res: {"all": {}})
    run = ["eval", "appearance", "--out", str(tmp_path), "--quiet"]
    assert main([*run, "builtin:flat-sawn", "builtin:rift"]) == 0
    first = {p.name: (p.stat().st_ino, p.read_bytes()) for p in tmp_path.iterdir()}
    assert {"flat-sawn.png", "rift.png", "results.json"} <= set(first)
    stop_at[0] = len(seen) + 2  # a Ctrl-C at the second block
    assert main([*run, "builtin:rift", "builtin:flat-sawn"]) == 130
    assert {p.name: (p.stat().st_ino, p.read_bytes()) for p in tmp_path.iterdir()} == first
    stop_at[0] = None
    capsys.readouterr()
    assert main([*run, "builtin:rift"]) == 0
    assert re.search(r"warning: removed 1 file\(s\) of an earlier run .*: flat-sawn.png$",
                     capsys.readouterr().err, re.M)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".woodcam-eval-appearance-files.json", "results.json",
                                                          "rift.png"]


def test_side_by_side_refuses_a_path_that_is_no_png_at_its_door(tmp_path, rng):
    """A path without a suffix failed in PIL, after the figure was drawn, with 'unknown file
    extension: .tmp' (the suffix of the atomic write's temporary); it is refused first, with the
    name to give, and a .png in any case is written."""
    photo = rng.uniform(0, 1, (8, 12, 3))
    res = [FaceEval("top", True, photo, {m: photo for m in MODELS},
                    {m: {"histogram": 0.1, "spectrum": 1.0, "patch": 0.2} for m in MODELS})]
    for name, good in (("sbs", "sbs.png"), ("sbs.jpg", "sbs.png"), ("sbs.tmp", "sbs.png")):
        with pytest.raises(WoodcamError, match=rf"side_by_side: path must end in .png \(a PNG image is written\); "
                                               rf"got '.*{name}'; e.g. '.*/{good}'$"):
            side_by_side(res, tmp_path / name)
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    side_by_side(res, tmp_path / "sbs.PNG")
    assert [p.name for p in tmp_path.iterdir()] == ["sbs.PNG"]
