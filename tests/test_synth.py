"""Synthetic blocks: traces on the true iso-lines, placement by sawing pattern, knobs, seeds."""

import json

import numpy as np
import pytest

from woodcam.block import Face
from woodcam.errors import WoodcamError
from woodcam.fields import evaluate
from woodcam.frames import FACES, CrossLayout, face_pixel_points, pixel_to_block
from woodcam.fields import PlacedField
from woodcam.synth import (
    PATTERNS, AnalyticLogField, cut_block, synth_benchmark_set, synth_block,
)

RING_MM = 2.5


def radial_log(points_log_mm):
    """Knot-free log, pith on z, circular rings RING_MM wide: years = r / w."""
    p = np.asarray(points_log_mm, float)
    return np.hypot(p[:, 0], p[:, 1]) / RING_MM


SIZE = (40.0, 30.0, 35.0)


def _grad(field, p, h=1e-4):
    e = np.eye(3) * h
    return np.array([(field(p + e[i]) - field(p - e[i]))[0] / (2 * h) for i in range(3)])


@pytest.mark.parametrize("pattern", PATTERNS)
def test_clean_traces_lie_on_integer_isolines(pattern):
    field = cut_block(radial_log, SIZE, pattern, tilt_deg=4.0, azimuth_deg=30.0)
    block = synth_block(field, SIZE, face_px=96, seed=1)
    n_checked = 0
    for name, face in block.faces.items():
        g = evaluate(field, face_pixel_points(name, face.shape, SIZE).reshape(-1, 3))
        expected_years = set(range(max(1, int(np.ceil(g.min()))), int(np.floor(g.max())) + 1))
        assert {t.year for t in face.traces} == expected_years, name
        for t in face.traces:
            pts = pixel_to_block(name, t.points_px[:, 0], t.points_px[:, 1], face.shape, SIZE)
            assert np.abs(field(pts) - t.year).max() < 1e-3
            assert t.points_px.min() >= -0.5 and (t.points_px <= np.array(face.shape) - 0.5).all()
            n_checked += len(pts)
    assert n_checked > 500


def test_traces_stay_on_isolines_of_a_field_with_a_kink():
    """A knot-like field: the minimum of two ring systems has a crease where they meet."""
    def two_piths(p):
        a = np.hypot(p[:, 0] - 10, p[:, 1] - 12) / 2.0
        b = np.hypot(p[:, 0] - 32, p[:, 2] - 20) / 1.5 + 2.0
        return np.minimum(a, b)

    block = synth_block(two_piths, SIZE, face_px=96)
    pts, years = block.trace_points_mm()
    assert len(pts) > 300
    assert np.abs(two_piths(pts) - years).max() < 1e-3
    assert 0 not in years


def test_block_trace_points_match_true_field():
    field = cut_block(radial_log, SIZE, "rift")
    block = synth_block(field, SIZE, face_px=64)
    pts, years = block.trace_points_mm()
    assert len(pts) > 100
    np.testing.assert_allclose(field(pts), years, atol=1e-3)


def test_cut_block_places_pith_by_pattern():
    d = 70.0
    centre = np.array(SIZE)[None] / 2
    for pattern, radial in [("flat-sawn", (0, 1, 0)), ("quarter-sawn", (1, 0, 0)),
                            ("rift", (np.sqrt(0.5), np.sqrt(0.5), 0))]:
        f = cut_block(radial_log, SIZE, pattern, distance_mm=d)
        # the block centre is d from the pith; the ring gradient there is the outward radial
        assert f(centre)[0] == pytest.approx(d / RING_MM, abs=1e-9)
        np.testing.assert_allclose(_grad(f, centre) * RING_MM, radial, atol=1e-6)
        # the pith runs along +Z: no change of growth time going up
        assert f(centre + [0, 0, 10])[0] == pytest.approx(d / RING_MM, abs=1e-9)
    f = cut_block(radial_log, SIZE, "pith-inside", distance_mm=5.0, angle_deg=90.0)
    assert f(centre - [5.0, 0, 0])[0] == pytest.approx(0.0, abs=1e-9)   # pith 5 mm to the left
    tilted = cut_block(radial_log, SIZE, "flat-sawn", distance_mm=d, tilt_deg=10.0)
    np.testing.assert_allclose(tilted.axis, [0, np.sin(np.radians(10)), np.cos(np.radians(10))], atol=1e-12)


def test_cut_block_rejects_contradicting_placements():
    with pytest.raises(WoodcamError, match="pith-inside.*needs the pith to cross"):
        cut_block(radial_log, SIZE, "pith-inside", distance_mm=100.0)
    with pytest.raises(WoodcamError, match="needs the pith outside"):
        cut_block(radial_log, SIZE, "quarter-sawn", distance_mm=5.0)
    with pytest.raises(WoodcamError, match="pattern must be one of"):
        cut_block(radial_log, SIZE, "plain")


def test_analytic_log_ring_width_varies_as_stated():
    log = AnalyticLogField(ring_width_mm=2.0, width_slope_per_mm=0.004)
    r = np.array([[50.0, 0, 0], [50.001, 0, 0]])
    width = 0.001 / np.diff(log(r))[0]                # mm per year = ring width
    assert width == pytest.approx(2.0 * (1 + 0.004 * 50), rel=1e-4)
    assert log.ring_width_at(50.0) == pytest.approx(2.4)
    assert log(np.zeros((1, 3)))[0] == 0.0


def test_dropout_removes_about_the_fraction_asked():
    field = cut_block(radial_log, (60, 60, 60), "rift", distance_mm=70)
    kw = dict(face_px=128, photo_noise=0, photo_variation=0, seed=3)
    clean = synth_block(field, (60, 60, 60), **kw)
    dropped = synth_block(field, (60, 60, 60), trace_dropout=0.3, trace_dropout_chunk_mm=2.0, **kw)
    n0 = sum(len(t.points_px) for f in clean.faces.values() for t in f.traces)
    n1 = sum(len(t.points_px) for f in dropped.faces.values() for t in f.traces)
    assert 1 - n1 / n0 == pytest.approx(0.3, abs=0.05)
    # what is left still lies on the iso-lines
    pts, years = dropped.trace_points_mm()
    assert np.abs(field(pts) - years).max() < 1e-3


@pytest.mark.parametrize("corr_mm", [0.0, 1.0])
def test_jitter_moves_points_by_about_sigma(corr_mm):
    size = (60, 60, 60)
    field = cut_block(radial_log, size, "flat-sawn", distance_mm=80)   # pith along Z: top face sees true radii
    block = synth_block(field, size, face_px=160, faces=["top"], trace_jitter_mm=0.2,
                        trace_jitter_corr_mm=corr_mm, seed=5)
    pts, years = block.trace_points_mm()
    offset_mm = (field(pts) - years) * RING_MM      # radial distance off the ring
    assert np.std(offset_mm) == pytest.approx(0.2, rel=0.15)
    assert abs(np.mean(offset_mm)) < 0.05


def test_labels_mislabelled_unlabelled_and_partial_faces():
    size = (50, 50, 50)
    field = cut_block(radial_log, size, "rift")
    block = synth_block(field, size, face_px=64, trace_faces=["front", "top", "left"],
                        ring_map_faces=["right"], mislabel_fraction=0.3, unlabelled_fraction=0.2, seed=2)
    assert {n for n, f in block.faces.items() if f.traces} == {"front", "top", "left"}
    assert {n for n, f in block.faces.items() if f.ring_map is not None} == {"right"}
    assert all(f.photo is not None for f in block.faces.values()) and len(block.faces) == 6
    traces = [(n, t) for n, f in block.faces.items() for t in f.traces]
    unl = sum(t.year is None for _, t in traces)
    wrong = []
    for n, t in traces:
        if t.year is None:
            continue
        f = block.faces[n]
        true_year = np.round(field(pixel_to_block(n, *t.points_px[:1].T, f.shape, size)))[0]
        wrong.append(t.year - true_year)
    assert set(wrong) <= {-1, 0, 1}
    assert unl / len(traces) == pytest.approx(0.2, abs=0.12)
    assert np.mean(np.abs(wrong)) == pytest.approx(0.3, abs=0.15)
    # off by one either way (TraceSpec: "+-1"), not always one way
    assert min(wrong.count(-1), wrong.count(1)) >= 0.25 * np.sum(np.abs(wrong)), wrong


def test_camera_and_annotation_knobs_do_what_they_say():
    """Each photo, ring-map and dropout setting against the same block rendered without it
    (same seed, one face: the random draws before the knob's own are the same)."""
    from scipy.ndimage import gaussian_filter

    size = (40, 40, 40)
    field = cut_block(radial_log, size, "rift", distance_mm=50)
    kw = dict(face_px=96, faces=["front"], photo_noise=0, photo_variation=0, photo_blur_px=0, seed=4)

    def photo(**over):
        return synth_block(field, size, **{**kw, **over}).faces["front"].photo.astype(float)

    clean = photo()
    # sensor noise: std photo_noise of full scale
    assert np.std(photo(photo_noise=0.02) - clean) / 255 == pytest.approx(0.02, rel=0.1)
    # lens blur: the clean photo through a Gaussian of photo_blur_px (up to the uint8 rounding)
    np.testing.assert_allclose(photo(photo_blur_px=2.0), gaussian_filter(clean, (2, 2, 0), mode="nearest"),
                               atol=1.0)
    # exposure and vignetting: the corners darker than the centre (measured 0.76-0.87 over seeds)
    r = photo(photo_variation=0.1) / np.maximum(clean, 1)
    h, w = r.shape[:2]
    corners = np.mean([r[:5, :5].mean(), r[:5, -5:].mean(), r[-5:, :5].mean(), r[-5:, -5:].mean()])
    assert corners / r[h // 2 - 2:h // 2 + 3, w // 2 - 2:w // 2 + 3].mean() < 0.92
    # ring-map noise: std ring_map_noise where the clean map is away from its 0/1 clip
    kw2 = dict(face_px=128, faces=["front"], ring_map_sigma_px=2.0, seed=4)
    rc = synth_block(field, size, **kw2, ring_map_noise=0.0).faces["front"].ring_map
    rn = synth_block(field, size, **kw2, ring_map_noise=0.05).faces["front"].ring_map
    mid = (rc > 0.2) & (rc < 0.8)
    assert mid.sum() > 1000 and np.std((rn - rc)[mid]) == pytest.approx(0.05, rel=0.1)

    # dropout removes pieces of trace_dropout_chunk_mm: the pieces left are about that long
    def piece_lengths(chunk_mm):
        b = synth_block(field, size, face_px=128, faces=["front", "top"], trace_dropout=0.5,
                        trace_dropout_chunk_mm=chunk_mm, photo_noise=0, photo_variation=0, seed=3)
        return [np.linalg.norm(np.diff(pixel_to_block(n, *t.points_px.T, f.shape, size), axis=0),
                               axis=1).sum() for n, f in b.faces.items() for t in f.traces]

    for chunk_mm in (1.0, 8.0):
        assert 0.5 * chunk_mm < np.median(piece_lengths(chunk_mm)) < 2.0 * chunk_mm, chunk_mm


def test_ring_map_bright_on_rings_dark_between():
    size = (40, 40, 40)
    field = cut_block(radial_log, size, "quarter-sawn")
    block = synth_block(field, size, face_px=128, ring_map_noise=0.0, ring_map_sigma_px=1.0)
    face = block.faces["top"]
    g = evaluate(field, face_pixel_points("top", face.shape, size).reshape(-1, 3)).reshape(face.shape)
    frac = np.abs(g - np.round(g))
    px_mm = 40 / 128
    assert face.ring_map[frac * RING_MM / px_mm < 0.2].min() > 0.9      # within 0.2 px of a ring
    assert face.ring_map[frac * RING_MM / px_mm > 3.0].max() < 1e-3     # 3 px away


def test_builtin_photo_is_dark_on_latewood_and_end_grain():
    """The photo follows the field at each face's own pixel points (catches a wrong mapping)."""
    size = (40, 40, 40)
    field = cut_block(radial_log, size, "rift", distance_mm=50)
    block = synth_block(field, size, face_px=96, photo_noise=0, photo_variation=0, seed=0)
    lum = {}
    for name, face in block.faces.items():
        g = evaluate(field, face_pixel_points(name, face.shape, size).reshape(-1, 3))
        frac = g - np.floor(g)
        y = face.photo.reshape(-1, 3).astype(float).mean(1)
        late, early = y[(frac > 0.85) & (frac < 0.97)].mean(), y[(frac > 0.05) & (frac < 0.4)].mean()
        assert late < early - 20, name
        lum[name] = y.mean()
    assert max(lum["top"], lum["bottom"]) < min(lum[n] for n in ("front", "back", "left", "right"))


def test_same_seed_same_block_other_seed_other_photos():
    field = cut_block(radial_log, SIZE, "rift")
    kw = dict(face_px=48, trace_dropout=0.2, trace_jitter_mm=0.1, mislabel_fraction=0.2)
    a, b = synth_block(field, SIZE, seed=7, **kw), synth_block(field, SIZE, seed=7, **kw)
    c = synth_block(field, SIZE, seed=8, **kw)
    for n in FACES:
        fa, fb = a.faces[n], b.faces[n]
        assert np.array_equal(fa.photo, fb.photo) and np.array_equal(fa.ring_map, fb.ring_map)
        assert [(t.year, t.points_px.tolist()) for t in fa.traces] == [(t.year, t.points_px.tolist()) for t in fb.traces]
    assert not np.array_equal(a.faces["front"].photo, c.faces["front"].photo)


def test_wood_appearance_is_used_on_face_points():
    class Grey:
        def color(self, points_mm, normals):
            # colour encodes the outward normal's axis: proves normals are FACE_NORMAL
            return np.broadcast_to(0.5 + 0.25 * np.asarray(normals), points_mm.shape)

    block = synth_block(cut_block(radial_log, SIZE, "rift"), SIZE, wood=Grey(), face_px=32,
                        photo_noise=0, photo_variation=0, photo_blur_px=0)
    assert (block.faces["top"].photo == np.round(np.array([0.5, 0.5, 0.75]) * 255)).all()
    assert (block.faces["left"].photo == np.round(np.array([0.25, 0.5, 0.5]) * 255)).all()
    with pytest.raises(WoodcamError, match="wood must have a color"):
        synth_block(radial_log, SIZE, wood=object())


def test_face_shapes_follow_cross_layout_and_bad_knobs_raise():
    block = synth_block(cut_block(radial_log, SIZE, "rift"), SIZE, px_per_mm=2.0)
    layout = CrossLayout(SIZE, 2.0)
    assert {n: f.shape for n, f in block.faces.items()} == {n: layout.face_shape(n) for n in FACES}
    with pytest.raises(WoodcamError, match=r"trace_dropout \(traces.dropout\) must be a fraction"):
        synth_block(radial_log, SIZE, trace_dropout=1.5)
    with pytest.raises(WoodcamError, match="unknown keyword 'trace_drop'"):
        synth_block(radial_log, SIZE, trace_drop=0.5)
    with pytest.raises(WoodcamError, match="face must be one of"):
        synth_block(radial_log, SIZE, faces=["side"])
    with pytest.raises(WoodcamError, match="photo of face 'front' must have shape"):
        Face("front", (10, 12), photo=np.zeros((12, 10, 3), np.uint8))


def test_benchmark_set_spans_and_reproduces(tmp_path):
    folders = synth_benchmark_set(tmp_path / "a", 4, seed=11, face_px=40, progress=False)
    index = json.loads((tmp_path / "a" / "index.json").read_text())
    assert [b["pattern"] for b in index["blocks"]] == list(PATTERNS)
    for b in index["blocks"]:
        assert all(30 <= s <= 80 for s in b["size_mm"])
        assert 1.5 * 0.95 <= b["ring_width_mm"] <= 6.0 * 1.05
        assert not b["knotted"]
    again = synth_benchmark_set(tmp_path / "b", 4, seed=11, face_px=40, progress=False)
    for fa, fb in zip(folders, again):
        for p in sorted(fa.iterdir()):
            assert p.read_bytes() == (fb / p.name).read_bytes(), p.name
    other = synth_benchmark_set(tmp_path / "c", 1, seed=12, face_px=40, progress=False)
    assert (other[0] / "front_photo.png").read_bytes() != (folders[0] / "front_photo.png").read_bytes()


def test_benchmark_set_uses_knotted_log_factory(tmp_path):
    calls = []

    def knotted(rng):
        calls.append(1)
        return AnalyticLogField(ring_width_mm=3.0)

    # a block labelled knotted must have a knot crossing it: a factory without knots is refused
    with pytest.raises(WoodcamError, match="knotted log field with knots"):
        synth_benchmark_set(tmp_path, 4, seed=0, face_px=24, progress=False, log_fields=knotted,
                            knotted_fraction=1.0)
    assert calls


def test_knotted_blocks_have_their_ring_width_in_the_index(tmp_path):
    """index.json gave knotted blocks ``ring_width_mm: null`` (clear ones a number): it is the
    knotted log's ring width, the same at every radius, as the block's meta says."""
    from woodcam.block.io import read_block
    from woodcam.synth import knotted_log_field

    synth_benchmark_set(tmp_path, 2, 5, face_px=24, log_fields=knotted_log_field, progress=False)
    blocks = json.loads((tmp_path / "index.json").read_text())["blocks"]
    assert [b["knotted"] for b in blocks] == [False, True]
    for b in blocks:
        assert 1.5 <= b["ring_width_mm"] <= 6.0 * 1.05, b
        assert read_block(tmp_path / b["name"]).meta["ring_width_mm"] == b["ring_width_mm"]
    knotted = read_block(tmp_path / blocks[1]["name"]).true_field.log_field
    assert blocks[1]["ring_width_mm"] == knotted.ring_width_mm == knotted.ring_width_at(80.0)


def test_placed_field_serialises_only_when_the_log_field_does():
    f = cut_block(AnalyticLogField(ring_width_mm=2.0, eccentricity=0.1), SIZE, "rift", tilt_deg=3)
    g = PlacedField.from_dict(json.loads(json.dumps(f.to_dict())))
    p = np.random.default_rng(0).uniform(0, 40, (100, 3))
    assert np.array_equal(f(p), g(p))
    # files written before the placement became a LogFrame stored (origin_mm, rotation)
    old = {"log_field": f.to_dict()["log_field"], "origin_mm": f.origin_mm.tolist(),
           "rotation": f.rotation.tolist()}
    np.testing.assert_allclose(PlacedField.from_dict(old)(p), f(p), atol=1e-9)
    np.testing.assert_allclose(PlacedField(f.log_field, f.origin_mm, f.rotation).to_log(p), f.to_log(p),
                               atol=1e-9)
    with pytest.raises(WoodcamError, match="must be a woodcam class"):
        cut_block(radial_log, SIZE, "rift").to_dict()


def test_benchmark_set_with_knotted_logs(tmp_path):
    """Knotted blocks come from the seed-001 log generator through the seed-003 knot field;
    their traces still lie on the integer iso-lines of the saved true field."""
    from woodcam.block.io import read_block
    from woodcam.frames import pixel_to_block
    from woodcam.synth import knotted_log_field

    folders = synth_benchmark_set(tmp_path, 1, 5, face_px=64, log_fields=knotted_log_field,
                                  knotted_fraction=1.0, progress=False)
    block = read_block(folders[0])
    assert block.meta["knotted"] and block.true_field is not None
    # the knot crosses the block (from the true field), and each face marks its knot wood
    from woodcam.synth import knot_crosses

    assert knot_crosses(block.true_field, block.size_mm)
    masks = [f.extras.get("knot_mask") for f in block.faces.values()]
    assert any(m is not None and m.any() for m in masks)
    for face in block.faces.values():
        for t in face.traces:
            p = pixel_to_block(face.name, t.points_px[:, 0], t.points_px[:, 1], face.shape, block.size_mm)
            np.testing.assert_allclose(block.true_field(p), t.year, atol=1e-3)


def test_synth_spec_round_trips_through_json_and_matches_the_flat_keywords(tmp_path):
    from woodcam.synth import PhotoSpec, SynthSpec, TraceSpec

    spec = SynthSpec(face_px=48, faces=("front", "top"), trace_faces=("top",), seed=3,
                     photo=PhotoSpec(noise=0.0, variation=0.0, blur_px=0.0),
                     traces=TraceSpec(jitter_mm=0.1, unlabelled_fraction=0.5))
    again = SynthSpec.load(spec.save(tmp_path / "spec.json"))
    assert again == spec and json.loads((tmp_path / "spec.json").read_text())["traces"]["jitter_mm"] == 0.1
    with pytest.raises(WoodcamError, match=r"synth spec has unknown keys \['colour'\]"):
        SynthSpec.from_dict({**spec.to_dict(), "colour": 1})
    field = cut_block(radial_log, SIZE, "rift")
    by_spec = synth_block(field, SIZE, spec)
    by_keywords = synth_block(field, SIZE, face_px=48, faces=["front", "top"], trace_faces=["top"],
                              seed=3, photo_noise=0.0, photo_variation=0.0, photo_blur_px=0.0,
                              trace_jitter_mm=0.1, unlabelled_fraction=0.5)
    assert sorted(by_spec.faces) == ["front", "top"] and by_spec.meta == by_keywords.meta
    for name in by_spec.faces:
        a, b = by_spec.faces[name], by_keywords.faces[name]
        assert np.array_equal(a.photo, b.photo)
        assert [(t.year, t.points_px.tolist()) for t in a.traces] == \
            [(t.year, t.points_px.tolist()) for t in b.traces]
    assert by_spec.faces["top"].traces and not by_spec.faces["front"].traces
    assert any(t.year is None for t in by_spec.faces["top"].traces)
    # keywords override a spec's settings
    assert synth_block(field, SIZE, spec, seed=4).meta["seed"] == 4


def test_a_smaller_set_into_a_folder_of_a_larger_one_is_refused(tmp_path, capsys):
    """'block synth --count 1 --seed 5' into a folder of 2 blocks of seed 0 replaced block_0000
    and index.json and left block_0001 of seed 0 beside them, unlisted (sweep h6)."""
    from woodcam.cli import main

    out = tmp_path / "set"
    assert main(["block", "synth", "--count", "2", "--out", str(out), "--face-px", "32", "--quiet"]) == 0
    before = (out / "block_0000" / "block.json").read_bytes()
    capsys.readouterr()
    assert main(["block", "synth", "--count", "1", "--seed", "5", "--out", str(out), "--face-px", "32",
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert (f"{str(out)!r} holds a set of 2 synthetic blocks (seed 0); 1 block of seed 5 written there "
            "would leave block_0001 of the old set beside them") in err, err
    assert (out / "block_0000" / "block.json").read_bytes() == before  # refused before any work
    # as many blocks or more replace every one listed: written
    assert main(["block", "synth", "--count", "2", "--seed", "5", "--out", str(out), "--face-px", "32",
                 "--quiet"]) == 0
    assert capsys.readouterr().out.startswith(f"wrote 2 blocks to {out} (")


def test_a_smaller_set_on_an_engine_into_a_folder_of_a_larger_one_is_refused(tmp_path, capsys):
    """The engine path (write_benchmark_set) wrote '--count 1' into a folder of 2 blocks of the
    same seed (its records matched) and left block_0001 there, unlisted in index.json."""
    from woodcam.cli import main

    out = tmp_path / "set"
    engine = ["--engine", "local", "--workers", "1"]
    assert main(["block", "synth", "--count", "2", "--out", str(out), "--face-px", "32", "--quiet", *engine]) == 0
    capsys.readouterr()
    assert main(["block", "synth", "--count", "1", "--out", str(out), "--face-px", "32", "--quiet", *engine]) == 2
    err = capsys.readouterr().err
    assert (f"{str(out)!r} holds a set of 2 synthetic blocks (seed 0); 1 block of seed 0 written there "
            "would leave block_0001 of the old set beside them") in err, err
    assert len(json.loads((out / "index.json").read_text())["blocks"]) == 2  # refused before any work


def test_the_summary_line_counts_one_block_in_the_singular(tmp_path, capsys):
    """'block synth --count 1' said "wrote 1 blocks to ..." (sweep h6)."""
    from woodcam.cli import main

    assert main(["block", "synth", "--count", "1", "--out", str(tmp_path / "one"), "--face-px", "32",
                 "--quiet"]) == 0
    assert capsys.readouterr().out.startswith(f"wrote 1 block to {tmp_path / 'one'} (")
