"""Neural appearance (seed 000, 3.3): translation networks, colour volumes, eq. 10, cache, fallback.

The synthetic truth: a small cube whose photos are rendered clean (no camera noise, blur or
exposure) by a known colour function of the ARF, ``rgb = C0 + (C1 - C0) * ARF``, from a field
with a knot-like bump of extra growth. A network that learnt the appearance must reproduce that
function on faces and inside the block, knot included.
"""

from dataclasses import replace

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance, Wood
from woodcam.appearance.neural import (
    AppearanceFallbackWarning, NeuralAppearance, NoPhotosError, block_appearance, fit_neural_appearance,
    load_nets,
)
from woodcam.appearance.translation import TranslationNet, train_translation, translation_spec
from woodcam.appearance.volumes import (
    ColorVolumes, VolumeGrid, cache_key, face_pair, ring_map_like, translate_volume, years_volume,
)
from woodcam.block import Block, Face
from woodcam.errors import WoodcamError
from woodcam.fields import LogFrame, arf
from woodcam.fields.radial import RadialScalingField
from woodcam.frames import FACE_AXIS, FACES
from woodcam.synth import synth_block
from woodcam.tolerances import NEURAL_FACE_MAE, NEURAL_VOLUME_MAE

SIZE = (32.0, 32.0, 32.0)
C0 = np.array([0.86, 0.66, 0.46])
C1 = np.array([0.40, 0.25, 0.14])
KNOT_CENTRE = np.array([16.0, 16.0, 28.0])  # reaches the top face, as real knots do
KNOT_RADIUS_MM = 6.0


class KnottedField:
    """Pith along X below the block, plus a Gaussian bump of half a year around a knot centre
    (rings bulge around it, up to half a ring out of phase at its centre)."""

    def __init__(self):
        self.base = RadialScalingField(LogFrame((0.0, 16.0, -30.0), (1, 0, 0)), ring_width_mm=3.5)
        self.axis = (1.0, 0.0, 0.0)

    def __call__(self, p):
        p = np.asarray(p, float)
        d2 = ((p - KNOT_CENTRE) ** 2).sum(1) / KNOT_RADIUS_MM ** 2
        return self.base(p) + 0.5 * np.exp(-d2)


FIELD = KnottedField()


class KnownWood:
    """Colour = C0 + (C1 - C0) * ARF: the 'known colour function of the ARF'."""

    def __init__(self, field):
        self.field = field

    def color(self, points_mm, normals=None):
        return C0 + (C1 - C0) * arf(self.field(points_mm))[:, None]


def clean_block(field=FIELD, faces=FACES):
    return synth_block(field, SIZE, wood=KnownWood(field), face_px=96, faces=faces, photo_noise=0,
                       photo_variation=0, photo_blur_px=0, name="known")


SPEC = translation_spec("draft", seed=3)
GRID = VolumeGrid(SIZE, 48)


@pytest.fixture(scope="module")
def block():
    return clean_block()


@pytest.fixture(scope="module")
def fitted(block, tmp_path_factory):
    cache = tmp_path_factory.mktemp("cache")
    app = fit_neural_appearance(block, FIELD, resolution=48, quality="draft", seed=3, cache_dir=cache,
                                progress=False)
    return app, cache


def test_network_reproduces_an_unseen_face_of_its_axis(block):
    """Trained on the right face only, the X network draws the left face from its ARF."""
    right = face_pair(block, "right", GRID, SPEC, field=FIELD)
    left = face_pair(block, "left", GRID, SPEC, field=FIELD)
    net = train_translation([right], SPEC, progress=False)
    pred = net(left[0])
    truth = KnownWood(FIELD).color(GRID.face_points("left").reshape(-1, 3)).reshape(pred.shape)
    assert np.abs(pred - left[1]).mean() < NEURAL_FACE_MAE     # against the (resampled) photo
    # Against the known function, the photo's own resampling error (~0.023 here: ring steps
    # blurred by one cell) adds to the network's.
    resampling = np.abs(left[1] - truth).mean()
    assert np.abs(pred - truth).mean() < resampling + NEURAL_FACE_MAE
    # An untrained network is far off: the error bound is not vacuous.
    untrained = TranslationNet.from_state({**net.state(), "weights": {
        k: np.zeros_like(v) for k, v in net.state()["weights"].items()}})
    assert np.abs(untrained(left[0]) - truth).mean() > 3 * NEURAL_FACE_MAE


def test_training_is_reproducible_with_a_fixed_seed(block):
    pair = face_pair(block, "top", GRID, SPEC, field=FIELD)
    spec = translation_spec("draft", epochs=1, seed=11)
    a = train_translation([pair], spec, progress=False)(pair[0])
    b = train_translation([pair], spec, progress=False)(pair[0])
    np.testing.assert_array_equal(a, b)


def test_volumes_reproduce_the_known_colour_inside_the_block(fitted):
    app, _ = fitted
    assert app.volumes.volumes.shape == (3,) + GRID.shape + (3,)
    assert app.volumes.volumes.dtype == np.uint8
    rng = np.random.default_rng(0)
    p = rng.uniform(2.0, 30.0, (6000, 3))
    truth = KnownWood(FIELD).color(p)
    wood = Wood(FIELD, app)
    for k in range(3):
        n = np.zeros_like(p)
        n[:, k] = 1.0
        err = np.abs(wood.color(p, n) - truth).mean()
        assert err < NEURAL_VOLUME_MAE, (k, err)


def test_knot_survives_in_the_volumes(fitted):
    """Near the knot the colour follows the knotted ARF, not the ARF without the knot."""
    app, _ = fitted
    rng = np.random.default_rng(1)
    p = KNOT_CENTRE + rng.uniform(-0.6, 0.6, (4000, 3)) * KNOT_RADIUS_MM
    p = p[p[:, 2] < SIZE[2] - 0.5]
    n = np.tile([0.0, 0.0, 1.0], (len(p), 1))
    got = Wood(FIELD, app).color(p, n)
    with_knot = KnownWood(FIELD).color(p)
    without = KnownWood(FIELD.base).color(p)
    # The rings are squeezed around the knot, so trilinear lookup between cell centres blurs
    # them more: measure that part with an ideal volume (the known colour at the cell centres).
    ideal = np.rint(255 * KnownWood(FIELD).color(GRID.points().reshape(-1, 3))).astype(np.uint8)
    ideal = ColorVolumes(GRID, ideal.reshape((1,) + GRID.shape + (3,)), {}).sample(p, 0)
    lookup = np.abs(ideal - with_knot).mean()
    err_knot = np.abs(got - with_knot).mean()
    assert err_knot < lookup + NEURAL_FACE_MAE
    assert np.abs(got - without).mean() > 2 * err_knot


def test_volumes_are_cached_and_reused(fitted, block, monkeypatch):
    app, cache = fitted
    assert app.meta["cache"] == "miss"
    files = sorted(f.name for f in cache.iterdir() if f.suffix != ".lock")  # lock: woodcam._cache
    assert len(files) == 2 and any(f.endswith(".weights.npz") for f in files)

    def no_training(*a, **k):
        raise AssertionError("the cache should have been used")

    monkeypatch.setattr("woodcam.appearance.neural.train_axis_networks", no_training)
    again = fit_neural_appearance(block, FIELD, resolution=48, quality="draft", seed=3, cache_dir=cache,
                                  progress=False)
    assert again.meta["cache"] == "hit"
    np.testing.assert_array_equal(again.volumes.volumes, app.volumes.volumes)
    # The saved weights rebuild networks that give the cached volume back.
    nets = load_nets(next(cache.glob("*.weights.npz")))
    assert len(nets) == 3
    vol = translate_volume(nets[2], years_volume(FIELD, GRID), GRID, 2)
    assert np.abs(vol.astype(int) - app.volumes.volumes[2]).max() <= 1
    # Other settings, field or photos give other keys.
    s = app.meta["settings"]
    assert cache_key(block, FIELD, s) == app.meta["key"]
    assert cache_key(block, FIELD, {**s, "spec": {**s["spec"], "epochs": 9}}) != app.meta["key"]
    assert cache_key(block, FIELD.base, s) != app.meta["key"]
    other = clean_block(faces=("front", "top", "right"))
    assert cache_key(other, FIELD, s) != app.meta["key"]


def test_eq10_gives_one_volume_for_axis_aligned_normals(rng):
    grid = VolumeGrid((20.0, 30.0, 10.0), 16)
    vols = rng.integers(0, 256, (3,) + grid.shape + (3,), dtype=np.uint8)
    app = NeuralAppearance(ColorVolumes(grid, vols, {}))
    p = rng.uniform(0, 1, (500, 3)) * np.array(grid.size_mm)
    for k in range(3):
        n = np.zeros_like(p)
        n[:, k] = rng.choice([-1.0, 1.0], len(p))
        np.testing.assert_array_equal(app.color(None, p, n), app.volumes.sample(p, k))
    n = np.tile([0.6, 0.0, -0.8], (len(p), 1))
    want = (0.6 * app.volumes.sample(p, 0) + 0.8 * app.volumes.sample(p, 2)) / 1.4
    np.testing.assert_allclose(app.color(None, p, n), want, atol=1e-6)
    # The orientation-agnostic variant answers one volume for every normal.
    ag = app.agnostic(2)
    np.testing.assert_array_equal(ag.color(None, p, n), app.volumes.sample(p, 2))


def test_trilinear_lookup_is_exact_on_a_linear_ramp(rng):
    grid = VolumeGrid((40.0, 20.0, 10.0), 40)
    x = grid.centres(0)
    ramp = np.broadcast_to((x / x[-1] * 250)[:, None, None, None], grid.shape + (3,))
    vols = np.rint(ramp).astype(np.uint8)[None]
    cv = ColorVolumes(grid, vols, {})
    p = rng.uniform(0, 1, (300, 3)) * np.array(grid.size_mm)
    want = np.interp(p[:, 0], x, vols[0, :, 0, 0, 0].astype(float)) / 255
    np.testing.assert_allclose(cv.sample(p, 0)[:, 1], want, atol=1e-6)


def test_canonical_images_match_faces_and_round_trip(rng):
    grid = VolumeGrid((30.0, 20.0, 10.0), 30)
    v = rng.integers(0, 9, grid.shape)
    pts = grid.points()
    for face in FACES:
        k = FACE_AXIS[face]
        assert grid.image_shape(k) == grid.face_points(face).shape[:2]
        np.testing.assert_array_equal(grid.from_images(grid.to_images(v, k), k), v)
        # Slice 0 of the canonical images sits under the face at coordinate 0 with the same
        # in-plane layout as the face's canonical image.
        sl = grid.to_images(pts, k)[0]
        fp = grid.face_points(face)
        a, b = [i for i in range(3) if i != k]
        np.testing.assert_allclose(sl[..., [a, b]], fp[..., [a, b]], atol=1e-5)


def test_ring_map_like_peaks_on_ring_boundaries():
    g = np.tile(np.linspace(0.0, 4.0, 401), (3, 1))       # 0.01 years a cell, cell 0.01 mm
    m = ring_map_like(g, cell_mm=0.01, sigma_mm=0.05)
    assert np.allclose(m[:, ::100], 1.0)                   # on integer years
    assert np.all(m[:, 50::100] < 1e-6)                    # half-way between


def test_block_without_photos_falls_back_to_the_colour_map():
    bare = Block(SIZE, faces={"top": Face("top", (8, 8))}, name="bare")
    with pytest.warns(AppearanceFallbackWarning, match="no face photos.*colour map"):
        app = block_appearance(bare, FIELD, "neural")
    assert isinstance(app, ColorMapAppearance)
    with pytest.raises(NoPhotosError, match="no face photos"):
        fit_neural_appearance(bare, FIELD, cache_dir=False)


def test_errors_name_the_rule():
    with pytest.raises(WoodcamError, match="quality must be one of draft, normal, high"):
        translation_spec("best")
    with pytest.raises(WoodcamError, match=r"resolution must be an integer in \[4, 256\]"):
        VolumeGrid(SIZE, 512)
    with pytest.raises(WoodcamError, match="field must be a growth field"):
        fit_neural_appearance(replace(clean_block(faces=("top",)), true_field=None), None, cache_dir=False)
    with pytest.raises(WoodcamError, match="appearance must be one of colormap, neural"):
        block_appearance(clean_block(faces=("top",)), FIELD, "fancy")


def test_ring_map_source_uses_the_face_ring_map_or_the_field():
    blk = synth_block(FIELD, SIZE, wood=KnownWood(FIELD), face_px=96, ring_map_faces=("top",),
                      photo_noise=0, photo_variation=0, photo_blur_px=0, ring_map_noise=0.0)
    top = face_pair(blk, "top", GRID, SPEC, field=None, source="ring_map")[0][0]
    front = face_pair(blk, "front", GRID, SPEC, field=FIELD, source="ring_map")[0][0]
    # The synthetic ring map of the top face and the field's ring-map-like image agree.
    g = FIELD(GRID.face_points("top").reshape(-1, 3)).reshape(top.shape)
    like = ring_map_like(g, float(GRID.cell_mm[0]))
    assert np.corrcoef(top.ravel(), like.ravel())[0, 1] > 0.8
    assert front.max() > 0.9 and front.min() < 0.05
    with pytest.raises(WoodcamError, match="face 'front' needs a field"):
        face_pair(blk, "front", GRID, SPEC, field=None, source="ring_map")


def test_auto_source_prefers_ring_maps_for_fitted_fields(monkeypatch):
    seen = []

    def fake_train(block, grid, spec, *, source, **kw):
        seen.append(source)
        raise NoPhotosError("stop here")

    monkeypatch.setattr("woodcam.appearance.neural.train_axis_networks", fake_train)
    blk = clean_block(faces=("top", "left"))               # ring maps on every face, true field
    for field, want in ((None, "arf"), (FIELD.base, "ring_map")):
        with pytest.raises(NoPhotosError, match="stop here"):
            fit_neural_appearance(blk, field, cache_dir=False)
        assert seen.pop() == want
    with pytest.raises(WoodcamError, match="source must be one of auto, arf, ring_map"):
        fit_neural_appearance(blk, FIELD, source="photo", cache_dir=False)


# -- sub-cell detail (guided by the field's rings at the exact point) -------------------------------

def test_guide_slopes_recover_a_linear_colour_of_the_guide(rng):
    from woodcam.appearance.volumes import guide_slopes

    g = rng.uniform(0, 1, (12, 10, 8))
    colour = 0.2 + np.stack([0.5 * g, -0.3 * g, 0.1 * g], -1)
    s = guide_slopes(colour, g, eps=1e-6)
    np.testing.assert_allclose(s[2:-2, 2:-2, 2:-2], np.broadcast_to([0.5, -0.3, 0.1], s[2:-2, 2:-2, 2:-2].shape),
                               atol=1e-3)
    # A constant guide carries no detail: the slope is 0, not noise over a tiny variance.
    assert np.abs(guide_slopes(colour, np.full(g.shape, 0.4))).max() < 1e-4


def _ring_volume(grid, field, colour_of_arf):
    """A colour volume that is exactly ``colour_of_arf(ARF)`` at the cell centres, with its guide."""
    g = arf(years_volume(field, grid))
    return np.rint(colour_of_arf(g) * 255).astype(np.uint8), g


def test_sub_cell_detail_restores_sharp_rings_that_trilinear_blurs(rng):
    """Rings 2.5 mm apart on a 0.8 mm grid: trilinear lookup smears each latewood-to-earlywood
    step over a cell (the blur seen on bevels); the detail term puts it back at the field's exact
    ring boundary. The truth is the colour function evaluated at the points themselves."""
    from woodcam.appearance.volumes import guide_slopes

    field = RadialScalingField(LogFrame((-200.0, 10.0, 10.0), (0, 0, 1)), ring_width_mm=2.5)
    grid = VolumeGrid((24.0, 20.0, 20.0), 30)                       # 0.8 mm cells

    def colour_of_arf(a):
        return C0 + (C1 - C0) * np.asarray(a)[..., None]

    vol, guide = _ring_volume(grid, field, colour_of_arf)
    plain = ColorVolumes(grid, vol[None], {})
    sharp = ColorVolumes(grid, vol[None], {}, guide[None], guide_slopes(vol, guide)[None])
    p = rng.uniform(2, 18, (4000, 3))
    a = arf(field(p))
    truth = colour_of_arf(a)
    err_plain = np.abs(plain.sample(p, 0) - truth).mean()
    err_sharp = np.abs(sharp.sample(p, 0, a) - truth).mean()
    assert err_sharp < 0.35 * err_plain, (err_sharp, err_plain)
    assert err_sharp < 0.02
    # Without the point's guide the lookup is the plain trilinear one.
    np.testing.assert_array_equal(sharp.sample(p, 0), plain.sample(p, 0))


def test_detail_round_trips_through_the_cache_file(tmp_path, rng):
    grid = VolumeGrid((10.0, 8.0, 6.0), 10)
    vols = rng.integers(0, 256, (3,) + grid.shape + (3,), dtype=np.uint8)
    guides = rng.uniform(0, 1, (3,) + grid.shape)
    slopes = rng.normal(0, 0.2, (3,) + grid.shape + (3,))
    cv = ColorVolumes(grid, vols, {"a": 1}, guides, slopes)
    back = ColorVolumes.load(cv.save(tmp_path / "v.npz"))
    assert back.has_detail
    np.testing.assert_allclose(back.guides, guides, atol=1e-3)
    np.testing.assert_allclose(back.slopes, slopes, atol=1e-3)
    with pytest.raises(WoodcamError, match="guides and slopes must be given together"):
        ColorVolumes(grid, vols, {}, guides, None)
    with pytest.raises(WoodcamError, match="guides must have shape"):
        ColorVolumes(grid, vols, {}, guides[:1], slopes)


def test_volumes_save_under_any_name(tmp_path, rng):
    # np.savez given a path not ending in .npz writes <path>.npz: save('v.bin') left a 0-byte
    # v.bin (load: EOFError) and its data in a hidden temporary
    grid = VolumeGrid((10.0, 8.0, 6.0), 10)
    vols = rng.integers(0, 256, (3,) + grid.shape + (3,), dtype=np.uint8)
    path = ColorVolumes(grid, vols, {"a": 1}).save(tmp_path / "v.bin")
    assert path == tmp_path / "v.bin"
    np.testing.assert_array_equal(ColorVolumes.load(path).volumes, vols)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.bin"]


def test_mirror_augmentation_keeps_patch_and_photo_aligned(rng):
    import torch

    from woodcam.appearance.translation import _mirror

    x = torch.from_numpy(rng.normal(size=(64, 2, 6, 6)).astype(np.float32))
    y = x[:, :1] * 2 + 1                       # the "photo" is a pixelwise function of the input
    xm, ym = _mirror(torch, np.random.default_rng(0), x, y)
    np.testing.assert_array_equal(ym.numpy(), (xm[:, :1] * 2 + 1).numpy())
    flipped = [not torch.equal(xm[i], x[i]) for i in range(len(x))]
    assert 30 < sum(flipped) < 64              # 3/4 of patches mirrored in some way
    # Each patch is one of its four mirror images.
    for i in range(8):
        cands = [x[i], x[i].flip(2), x[i].flip(1), x[i].flip(1).flip(2)]
        assert any(torch.equal(xm[i], c) for c in cands)


def test_augmented_spec_trains_and_changes_the_network(block):
    pair = face_pair(block, "top", GRID, SPEC, field=FIELD)
    spec = translation_spec("draft", epochs=1, seed=11)
    a = train_translation([pair], spec, progress=False)(pair[0])
    b = train_translation([pair], replace(spec, augment=True), progress=False)(pair[0])
    assert np.isfinite(b).all() and not np.array_equal(a, b)


@pytest.mark.parametrize("source", ["arf", "ring_map"])
def test_point_guide_matches_the_slices_the_volume_was_made_from(source):
    """At cell centres the guide of a lookup equals the networks' ring input on the slices
    (ARF, or the ring-map-like image with the in-plane gradient), for each axis."""
    from woodcam.appearance.volumes import PLANE_AXES, point_guide

    grid = VolumeGrid((20.0, 16.0, 12.0), 40)
    years = years_volume(FIELD, grid)
    pts = grid.points()
    for axis in range(3):
        cell = float(grid.cell_mm[list(PLANE_AXES[axis])].mean())
        imgs = grid.to_images(years, axis)
        ring = arf(imgs) if source == "arf" else ring_map_like(imgs, cell)
        want = grid.from_images(ring, axis)[2:-2, 2:-2, 2:-2].ravel()
        got = point_guide(FIELD, pts[2:-2, 2:-2, 2:-2].reshape(-1, 3), axis, source, cell)
        # np.gradient's central differences over a cell against a tenth of a cell: close, not equal.
        tol = 1e-6 if source == "arf" else 0.05
        assert np.abs(got - want).mean() < tol / 5 and np.quantile(np.abs(got - want), 0.99) < 4 * tol


def test_fitted_volumes_carry_detail_that_brings_them_closer_to_the_truth(fitted):
    """The learnt volumes store guides and slopes; looking up with the field (as a Wood does)
    is closer to the known colour inside the block than the plain trilinear lookup."""
    app, _ = fitted
    assert app.volumes.has_detail and app.meta["settings"]["detail"] is True
    rng = np.random.default_rng(1)
    p = rng.uniform(2.0, 30.0, (6000, 3))
    truth = KnownWood(FIELD).color(p)
    n = np.zeros_like(p)
    n[:, 2] = 1.0
    plain = np.abs(app.color(None, p, n) - truth).mean()
    detailed = np.abs(app.color(FIELD, p, n) - truth).mean()
    assert detailed < 0.9 * plain, (detailed, plain)



@pytest.mark.parametrize("damage", ["truncated", "empty", "another net", "missing"])
def test_load_nets_refuses_broken_weights_in_one_line_naming_the_file(tmp_path, damage):
    """A cut or empty *.weights.npz was numpy's BadZipFile / EOFError, a missing one the bare
    FileNotFoundError, weights of a wider net than their header torch's many-line
    load_state_dict error."""
    from woodcam.appearance.neural import _save_nets
    from woodcam.appearance.translation import _build_net

    spec = translation_spec("draft")
    good = tmp_path / "good.weights.npz"
    _save_nets(good, [TranslationNet(_build_net(2, spec.channels), spec, 2, 0.0, 0.0)])
    assert len(load_nets(good)) == 1
    path = tmp_path / "bad.weights.npz"
    if damage == "truncated":
        path.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    elif damage == "empty":
        path.write_bytes(b"")
    elif damage == "another net":
        wide = replace(spec, channels=2 * spec.channels)
        _save_nets(path, [TranslationNet(_build_net(2, wide.channels), wide, 2, 0.0, 0.0)])
        arrays = dict(np.load(path))
        arrays["header"] = np.load(good)["header"]       # the header of the narrower net
        np.savez(path, **arrays)
    with pytest.raises(WoodcamError) as e:
        load_nets(path)
    msg = str(e.value)
    assert "\n" not in msg and str(path) in msg and "woodcam cache clear" in msg, msg
