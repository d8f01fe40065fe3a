"""Colour-map appearance: eq. 10, end grain, rings where the field says, fitting to photos."""

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance, Wood, axis_weights, blend_axis_colors, get_species
from woodcam.appearance.colormap import LUT_BINS
from woodcam.block import Block, Face
from woodcam.errors import WoodcamError
from woodcam.fields import LogFrame, arf, builtin_block
from woodcam.fields.radial import RadialScalingField
from woodcam.frames import FACE_NORMAL, FACES, face_image_size_mm, face_pixel_points

AXIS_Z = RadialScalingField(LogFrame((-40.0, 20.0, 0.0), (0, 0, 1)), ring_width_mm=3.0)


def test_eq10_axis_aligned_normals_pick_one_colouring(rng):
    a, b, c = (rng.uniform(0, 1, (50, 3)) for _ in range(3))
    for k, want in enumerate((a, b, c)):
        n = np.zeros((50, 3))
        n[:, k] = rng.choice([-1.0, 1.0], 50)
        np.testing.assert_allclose(blend_axis_colors(a, b, c, n), want, rtol=1e-6)


def test_eq10_weights_sum_to_one_and_follow_abs_normal(rng):
    n = rng.normal(size=(100, 3))
    w = axis_weights(n)
    np.testing.assert_allclose(w.sum(1), 1, rtol=1e-6)
    np.testing.assert_allclose(w, np.abs(n) / np.abs(n).sum(1, keepdims=True), rtol=1e-5)
    assert np.allclose(axis_weights(np.zeros((2, 3))), 1 / 3)


def test_end_grain_darker_than_side_grain(rng):
    """Pith along Z: top (normal Z) is end grain, front (normal -Y) side grain."""
    wood = Wood(AXIS_Z, ColorMapAppearance("oak"))
    p = rng.uniform(0, 50, (20000, 3))
    top = wood.color(p, np.tile([0.0, 0, 1], (len(p), 1)))
    side = wood.color(p, np.tile([0.0, -1, 0], (len(p), 1)))
    assert top.mean() < 0.85 * side.mean()
    # ... and rougher: more relative variation at the same ring phase.
    a = arf(AXIS_Z(p))
    mid = (a > 0.1) & (a < 0.3)
    rel = lambda c: (c[mid].std(0) / c[mid].mean(0)).mean()
    assert rel(top) > 1.3 * rel(side)


def test_rings_where_the_field_says(rng):
    """Latewood (ARF near 1) is darker than earlywood (ARF near 0) on every face."""
    wood = Wood(AXIS_Z, ColorMapAppearance("pine"))
    p = rng.uniform(0, 50, (40000, 3))
    a = wood.arf(p)
    for n in ([0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]):
        c = wood.color(p, np.tile(n, (len(p), 1))).mean(1)
        assert c[a > 0.85].mean() < c[a < 0.2].mean() - 0.08


def test_pores_run_along_the_grain():
    """Colour varies slowly along the fibres and fast across them on side grain."""
    wood = Wood(RadialScalingField(LogFrame((0, -500.0, 0), (0, 0, 1)), 1e6), ColorMapAppearance("oak"))
    t = np.linspace(0, 20, 4001)
    along = np.stack([np.full_like(t, 7.0), np.zeros_like(t), t], 1)
    across = np.stack([t, np.zeros_like(t), np.full_like(t, 7.0)], 1)
    n = np.tile([0, -1.0, 0], (len(t), 1))
    d_along = np.abs(np.diff(wood.color(along, n).mean(1))).mean()
    d_across = np.abs(np.diff(wood.color(across, n).mean(1))).mean()
    assert d_across > 4 * d_along


def test_colour_is_continuous_across_a_cut(rng):
    """Solid texture: two nearby points get nearly the same colour (no per-face randomness)."""
    wood = Wood(AXIS_Z, ColorMapAppearance("maple"))
    p = rng.uniform(5, 45, (2000, 3))
    n = np.tile([0, -1.0, 0], (len(p), 1))
    d = np.abs(wood.color(p, n) - wood.color(p + 1e-4, n)).max()
    assert d < 0.01


def test_threads_give_identical_colours(rng):
    p = rng.uniform(0, 50, (200_000, 3))
    n = rng.normal(size=p.shape)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    a = Wood(AXIS_Z, threads=1).color(p, n)
    b = Wood(AXIS_Z, threads=2).color(p, n)
    np.testing.assert_array_equal(a, b)


def _untextured(name, **changes):
    """Preset ``name`` without streaks and end-grain mottling (and with ``changes``)."""
    from dataclasses import replace

    return replace(get_species(name), streak_contrast=0.0, endgrain_roughness=0.0, **changes)


def test_end_grain_is_the_side_grain_colour_darkened_by_the_preset(rng):
    """Without noise, pure end grain (normal along the fibres) is side grain times
    ``1 - endgrain_darkening``; side grain is the species ramp itself."""
    species = _untextured("oak", pore_contrast=0.0)
    app = ColorMapAppearance(species)
    wood = Wood(AXIS_Z, app)
    p = rng.uniform(0, 50, (5000, 3))
    side = wood.color(p, np.tile([0.0, -1, 0], (len(p), 1)))
    top = wood.color(p, np.tile([0.0, 0, 1], (len(p), 1)))
    np.testing.assert_allclose(side, app.ramp(wood.arf(p)), atol=1e-5)
    np.testing.assert_allclose(top, side * (1 - species.endgrain_darkening), atol=1e-5)


def test_the_noise_seed_changes_the_texture_only_and_repeats(rng):
    """``seed`` picks the pores and streaks: another seed, other texture; the same seed, the
    same colours."""
    p = rng.uniform(0, 50, (20000, 3))
    n = np.tile([0.0, -1, 0], (len(p), 1))
    c0, c1, c1_again = (Wood(AXIS_Z, ColorMapAppearance("oak", seed=s)).color(p, n) for s in (0, 1, 1))
    np.testing.assert_array_equal(c1, c1_again)
    assert np.abs(c0 - c1).mean() > 0.01
    np.testing.assert_allclose(c0.mean(0), c1.mean(0), atol=0.01)   # texture, not colour


def test_ring_porous_pores_sit_in_the_earlywood_only(rng):
    """A ring-porous preset (oak) has its pores in the earlywood: in the latewood (ARF near 1)
    side grain is the bare ramp colour; a diffuse-porous one keeps them there too."""
    p = rng.uniform(0, 50, (60000, 3))
    n = np.tile([0.0, -1, 0], (len(p), 1))
    for porous in (True, False):
        app = ColorMapAppearance(_untextured("oak", ring_porous=porous))
        wood = Wood(AXIS_Z, app)
        a = wood.arf(p)
        ratio = (wood.color(p, n) / app.ramp(a)).mean(1)       # 1 - pore darkening
        late, early = a > 0.99, a < 0.3
        assert late.sum() > 100
        assert ratio[early].min() < 0.8                         # pores in the earlywood
        if porous:
            np.testing.assert_allclose(ratio[late], 1.0, atol=1e-3)
        else:
            assert ratio[late].min() < 0.8


def test_a_fitted_ramp_is_read_at_the_ring_phase(rng):
    """A fitted ramp holds the colour at each bin's centre phase ``(i + 0.5) / LUT_BINS``; the
    renderer interpolates between centres, per axis. Known answer: a ramp linear in the phase
    (red = phase on X, 0.5 phase on Y, 0.8 phase on Z) renders red = that multiple of the phase."""
    from dataclasses import replace

    centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
    scale = np.array([1.0, 0.5, 0.8])
    luts = np.stack([np.stack([s * centres, 1 - centres, np.full(LUT_BINS, 0.5)], 1) for s in scale])
    app = replace(ColorMapAppearance(_untextured("oak", pore_contrast=0.0)), axis_luts=luts)
    wood = Wood(AXIS_Z, app)
    p = rng.uniform(0, 50, (20000, 3))
    phase = np.mod(AXIS_Z(p), 1.0)
    inner = (phase > centres[0]) & (phase < centres[-1])      # held flat beyond the end centres
    for k in range(3):
        rgb = wood.color(p, np.tile(np.eye(3)[k], (len(p), 1)))
        np.testing.assert_allclose(rgb[inner, 0], scale[k] * phase[inner], atol=1e-4)
        np.testing.assert_allclose(rgb[inner, 1], 1 - phase[inner], atol=1e-4)


def _render_block(field, luts, size=(60.0, 50.0, 40.0), px_per_mm=2.0):
    """Faces coloured exactly by a known colour-of-ring-phase function (``luts`` at the phase
    bin centres, phase = years mod 1 = sqrt(ARF)) per block axis."""
    faces = {}
    for f in FACES:
        h, w = face_image_size_mm(f, size)
        shape = (round(h * px_per_mm), round(w * px_per_mm))
        a = np.sqrt(arf(field(face_pixel_points(f, shape, size).reshape(-1, 3))))
        k = int(np.flatnonzero(FACE_NORMAL[f])[0])
        rgb = np.stack([np.interp(a, (np.arange(LUT_BINS) + 0.5) / LUT_BINS, luts[k, :, c]) for c in range(3)], 1)
        faces[f] = Face(f, shape, photo=np.round(rgb * 255).astype(np.uint8).reshape(shape + (3,)))
    return Block(size, faces)


def test_fit_to_photos_recovers_per_axis_colour_of_ring_phase():
    centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
    truth = np.stack([
        np.stack([0.8 - 0.3 * centres, 0.6 - 0.25 * centres, 0.4 - 0.2 * centres], 1) * s
        for s in (0.7, 1.0, 0.95)
    ])
    block = _render_block(AXIS_Z, truth)
    fitted = ColorMapAppearance.fit_to_block(block, AXIS_Z).axis_luts
    # Bin-mean of a linear ramp within a bin of width 1/32: error <= slope/64 + 1/255 rounding.
    np.testing.assert_allclose(fitted, truth, atol=0.3 / 64 + 1 / 255 + 1e-3)


class _KnottedAxisZ:
    """AXIS_Z whose knot features are 1 inside a 6 mm ball at ``KNOT_AT`` (a stand-in knot)."""

    def __call__(self, p):
        return AXIS_Z(p)

    def knot_features(self, p):
        inside = np.linalg.norm(np.asarray(p, float) - KNOT_AT, axis=1) < 6.0
        return {"knot": inside.astype(float)}


KNOT_AT = np.array([30.0, 0.0, 20.0])     # on the front face (y = 0) of the 60x50x40 block


def _clear_ramp_block():
    """``(truth (3, LUT_BINS, 3), block)``: linear dark-going ramps per axis and the axis-Z block
    rendered with them."""
    centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
    truth = np.tile(np.stack([0.8 - 0.3 * centres, 0.6 - 0.25 * centres, 0.4 - 0.2 * centres], 1),
                    (3, 1, 1))
    return truth, _render_block(AXIS_Z, truth)


@pytest.mark.parametrize("by", ["knot_mask", "field"])
def test_fit_learns_the_ring_colours_from_clear_wood_only(by):
    """Bug seen on the real spruce cube H11: knot pixels (dark, with rings of their own) were
    binned by the stem's ARF, so a face with a knot gave a ramp darkened and flattened (its
    ring contrast even changed sign). A dark knot painted on the front photo, known from the
    face's knot mask or from the field's knot features, must leave the fitted ramp at the
    truth."""
    truth, block = _clear_ramp_block()
    front = block.faces["front"]
    pts = face_pixel_points("front", front.shape, block.size_mm).reshape(-1, 3)
    knot = _KnottedAxisZ().knot_features(pts)["knot"].reshape(front.shape) > 0.5
    assert knot.mean() > 0.03
    front.photo[knot] = (60, 35, 20)                    # knot wood: dark brown
    if by == "knot_mask":
        front.extras["knot_mask"] = knot
        field = AXIS_Z
    else:
        field = _KnottedAxisZ()
    fitted = ColorMapAppearance.fit_to_block(block, field, anchor="field").axis_luts
    np.testing.assert_allclose(fitted, truth, atol=0.3 / 64 + 1 / 255 + 1e-3)


def test_fit_with_only_some_faces_keeps_species_ramp_elsewhere():
    centres = (np.arange(LUT_BINS) + 0.5) / LUT_BINS
    truth = np.tile(np.stack([0.5 + 0 * centres] * 3, 1), (3, 1, 1))
    block = _render_block(AXIS_Z, truth)
    block.faces = {f: block.faces[f] for f in ("front", "back")}
    app = ColorMapAppearance.fit_to_block(block, AXIS_Z)
    assert np.isfinite(app.axis_luts[1]).all()
    assert np.isnan(app.axis_luts[0]).all() and np.isnan(app.axis_luts[2]).all()
    # X and Z, without photos, render exactly as the species preset does; Y takes the photos'
    # flat grey (times the pores and streaks, the same in both)
    p = np.random.default_rng(0).uniform(0, 40, (2000, 3))
    fitted, preset = Wood(AXIS_Z, app), Wood(AXIS_Z, ColorMapAppearance("oak"))
    for n in ([1.0, 0, 0], [0, 0, 1.0]):
        normals = np.tile(n, (len(p), 1))
        np.testing.assert_array_equal(fitted.color(p, normals), preset.color(p, normals))
    plain = ColorMapAppearance.fit_to_block(block, AXIS_Z, _untextured("oak", pore_contrast=0.0))
    c = Wood(AXIS_Z, plain).color(p, np.tile([0, 1.0, 0], (len(p), 1)))
    np.testing.assert_allclose(c, 0.5, atol=1 / 255)


def test_fit_without_photos_is_a_clear_error():
    with pytest.raises(WoodcamError, match="has no face photos"):
        ColorMapAppearance.fit_to_block(Block((10, 10, 10)), AXIS_Z)


def test_bad_species_and_normals():
    with pytest.raises(WoodcamError, match="species must be one of"):
        ColorMapAppearance("balsa-wood")
    # the one species rule (open_stock calls it too): an unhashable value is refused, not a TypeError
    with pytest.raises(WoodcamError, match=r"species must be one of the presets .*got \['oak'\].*species=None"):
        get_species(["oak"])
    with pytest.raises(WoodcamError, match="normals must have the shape"):
        Wood(AXIS_Z).color(np.zeros((3, 3)), np.zeros((2, 3)))


def test_knots_show_darker_and_dead_knots_outlined():
    """The built-in knotty block: knot wood is darker than the stem wood around it, and the
    dead knot's outline is darker still."""
    from woodcam.stock import open_stock

    stock = open_stock("builtin:knotty")
    shape = (100, 200)
    p = face_pixel_points("front", shape, stock.size_mm).reshape(-1, 3)
    rgb = stock.wood.color(p, np.tile([0.0, -1.0, 0.0], (len(p), 1))).mean(1)
    f = stock.wood.field.knot_features(p)
    alive = (f["knot"] > 0.9) & (f["dead"] < 0.1)
    outline = f["outline"] > 0.9
    clear = f["knot"] < 0.01
    assert alive.sum() > 100 and outline.sum() > 20
    assert rgb[alive].mean() < rgb[clear].mean() - 0.1
    assert rgb[outline].mean() < rgb[alive].mean() - 0.1


def test_fit_to_real_block_reads_ring_colours_off_its_ring_maps():
    """Bug seen on the Mokume cubes: a field fitted to ring maps sits a fraction of a ring off
    the photos' rings, and the ARF-binned ramp came out flat (bakes without rings). Anchored on
    the ring maps, the ramp keeps most of the true ring contrast; on the field, it loses it."""
    from woodcam.synth import synth_block

    size = (40.0, 30.0, 30.0)
    block = synth_block(AXIS_Z, size, face_px=160, seed=3, photo_noise=0.0, photo_variation=0.0)
    luma = np.array([0.299, 0.587, 0.114])

    def contrast(app):
        lum = app.axis_luts @ luma                      # (3, LUT_BINS)
        return lum.max(axis=1) - lum.min(axis=1)

    truth = contrast(ColorMapAppearance.fit_to_block(block, AXIS_Z))   # true field: anchor=field
    assert truth.min() > 0.1

    def off(p):          # rings up to 0.35 of a ring off, the error varying across the block
        p = np.asarray(p, float)
        return AXIS_Z(p) + 0.35 * np.sin(2 * np.pi * (p[:, 0] + p[:, 1] + p[:, 2]) / 30.0)

    on_field = contrast(ColorMapAppearance.fit_to_block(block, off, anchor="field"))
    on_maps = contrast(ColorMapAppearance.fit_to_block(block, off))    # auto: not the true field
    assert np.all(on_maps > 0.5 * truth), (on_maps, truth)
    assert np.all(on_field < 0.5 * on_maps), (on_field, on_maps)
    # Latewood (ARF near 1) darker than earlywood, as in the photos.
    lut = ColorMapAppearance.fit_to_block(block, off).axis_luts @ luma
    assert np.all(lut[:, -1] < lut[:, 0])


def test_fit_anchor_is_checked():
    block = _render_block(AXIS_Z, np.full((3, LUT_BINS, 3), 0.5))
    with pytest.raises(WoodcamError, match="anchor must be one of"):
        ColorMapAppearance.fit_to_block(block, AXIS_Z, anchor="photo")
    with pytest.raises(WoodcamError, match="needs a ring map on every photographed face"):
        ColorMapAppearance.fit_to_block(block, AXIS_Z, anchor="ring_map")


def test_register_ring_phase_moves_a_fitted_fields_rings_onto_the_ring_map():
    """A field up to 0.35 of a ring off (the error varying across the face) is moved back onto
    the true rings where the ring map has lines; the ring order is kept (no whole-year jumps)."""
    from woodcam.appearance.colormap import register_ring_phase
    from woodcam.synth import synth_block

    size = (40.0, 30.0, 30.0)
    block = synth_block(AXIS_Z, size, face_px=160, seed=3)
    face = block.faces["front"]
    pts = face_pixel_points("front", face.shape, size).reshape(-1, 3)
    true = AXIS_Z(pts).reshape(face.shape)
    off = true + 0.35 * np.sin(2 * np.pi * (pts[:, 0] + pts[:, 2]) / 30.0).reshape(face.shape)

    def phase_err(g):
        d = np.abs(g - true)
        return np.minimum(d % 1, 1 - d % 1)

    reg = register_ring_phase(off, face.ring_map, sigma_px=12 * 160 / 256)
    assert phase_err(reg).mean() < 0.3 * phase_err(off).mean(), (phase_err(reg).mean(), phase_err(off).mean())
    assert np.abs(reg - true).max() < 0.5                     # no ring skipped
    # A map without lines leaves the field as it is.
    np.testing.assert_array_equal(register_ring_phase(off, np.zeros(face.shape), 5.0), off)


def test_a_latewood_band_across_the_whole_year_is_fitted_and_rendered_sharp(rng):
    """Bug seen on H11: registered on a ring map, whose lines sit on the dark latewood band, a
    photo's latewood straddles the whole year (phase 0.94-1 and 0-0.06). Binned by the ARF
    (= phase^2), the first bin spans phase 0-0.18 and averaged that half of the band with
    earlywood. Binned by phase, both halves come back dark, fitted and rendered."""
    from dataclasses import replace

    from woodcam.appearance import get_species

    dark, light = np.array([0.45, 0.35, 0.25]), np.array([0.85, 0.75, 0.6])

    def truth(phase):
        band = np.minimum(phase, 1 - phase) < 0.06
        return np.where(band[:, None], dark, light)

    size, px = (60.0, 50.0, 40.0), 4.0
    faces = {}
    for f in FACES:
        h, w = face_image_size_mm(f, size)
        shape = (round(h * px), round(w * px))
        phase = np.mod(AXIS_Z(face_pixel_points(f, shape, size).reshape(-1, 3)), 1.0)
        faces[f] = Face(f, shape, photo=np.round(truth(phase) * 255).astype(np.uint8).reshape(shape + (3,)))
    app = ColorMapAppearance.fit_to_block(Block(size, faces), AXIS_Z, anchor="field")
    for k in range(3):
        np.testing.assert_allclose(app.axis_luts[k, [0, 1, -2, -1]], np.tile(dark, (4, 1)), atol=0.03)
        np.testing.assert_allclose(app.axis_luts[k, 4:-4], np.tile(light, (LUT_BINS - 8, 1)), atol=0.01)
    plain = replace(get_species("spruce"), pore_contrast=0.0, streak_contrast=0.0,
                    endgrain_roughness=0.0)
    wood = Wood(AXIS_Z, replace(app, species=plain))
    p = rng.uniform(0, 40, (20000, 3))
    phase = np.mod(AXIS_Z(p), 1.0)
    rgb = wood.color(p, np.tile([0.0, -1.0, 0.0], (len(p), 1)))
    inner = np.minimum(phase, 1 - phase) < 0.04          # inside the band, off its edges
    np.testing.assert_allclose(rgb[inner].mean(0), dark, atol=0.03)


class _EvaluatingKnottedAxisZ(_KnottedAxisZ):
    """:class:`_KnottedAxisZ` that also answers ``evaluate`` (as the knotted log fields do),
    counting which of its entry points the fit calls."""

    def __init__(self):
        self.calls: list[str] = []

    def __call__(self, p):
        self.calls.append("call")
        return super().__call__(p)

    def knot_features(self, p):
        self.calls.append("knot_features")
        return super().knot_features(p)

    def evaluate(self, p, *, directions=False):
        self.calls.append("evaluate")
        return {"years": AXIS_Z(p), **super().knot_features(p)}


def test_the_fit_samples_a_knotted_field_once_per_face():
    """A field with ``evaluate`` gives years and knot weights in one pass of its knot model;
    the fit uses it instead of calling the field and its knot features separately, and still
    leaves the knot out of the ramps."""
    truth, block = _clear_ramp_block()
    front = block.faces["front"]
    pts = face_pixel_points("front", front.shape, block.size_mm).reshape(-1, 3)
    front.photo[_KnottedAxisZ().knot_features(pts)["knot"].reshape(front.shape) > 0.5] = (60, 35, 20)
    field = _EvaluatingKnottedAxisZ()
    fitted = ColorMapAppearance.fit_to_block(block, field, anchor="field").axis_luts
    np.testing.assert_allclose(fitted, truth, atol=0.3 / 64 + 1 / 255 + 1e-3)
    assert field.calls == ["evaluate"] * len(block.faces)


# -- the knot's own colour, the axis's best face, per-face exposure (issue 12, H11) ---------------

KNOT_R_MM, KNOT_RING_MM = 8.0, 2.0


class _RingedKnot:
    """AXIS_Z with a knot whose wood has rings of its own: a branch of radius ``KNOT_R_MM``
    along Y through ``KNOT_AT`` (crossing the front and back faces), its growth time
    ``0.3 + r / KNOT_RING_MM`` round the branch; ``knot_error(p)`` and ``stem_error(p)`` years
    are added in the knot and the stem (a fitted field's rings off the photos')."""

    def __init__(self, knot_error=None, stem_error=None):
        self.knot_error, self.stem_error = knot_error, stem_error

    def evaluate(self, p, *, directions=False):
        p = np.asarray(p, float)
        r = np.hypot(p[:, 0] - KNOT_AT[0], p[:, 2] - KNOT_AT[2])
        inside = r < KNOT_R_MM
        knot_years = 0.3 + r / KNOT_RING_MM + (0.0 if self.knot_error is None else self.knot_error(p))
        zeros = np.zeros(len(p))
        stem_years = AXIS_Z(p) + (0.0 if self.stem_error is None else self.stem_error(p))
        out = {"years": np.where(inside, knot_years, stem_years), "knot": inside.astype(float),
               "dead": zeros, "outline": zeros}
        if directions:
            out["direction"] = np.tile([0.0, 0.0, 1.0], (len(p), 1))
        return out

    def __call__(self, p):
        return self.evaluate(p)["years"]

    def knot_features(self, p):
        out = self.evaluate(p)
        return {k: out[k] for k in ("knot", "dead", "outline")}


def _ramp(early, late, late_bins):
    """``(LUT_BINS, 3)``: ``early`` colour with a ``late`` (latewood) band of the last
    ``late_bins`` bins before each ring boundary, as photos show it."""
    late_band = np.arange(LUT_BINS) >= LUT_BINS - late_bins
    return np.where(late_band[:, None], np.asarray(late, float), np.asarray(early, float))


STEM_LATE_BINS, KNOT_LATE_BINS = 4, 10
STEM = _ramp((0.85, 0.72, 0.55), (0.60, 0.45, 0.30), STEM_LATE_BINS)
KNOT = _ramp((0.55, 0.38, 0.25), (0.30, 0.18, 0.10), KNOT_LATE_BINS)


def _knotted_block(field, px_per_mm=4.0, size=(60.0, 50.0, 40.0), photo_field=None):
    """Faces of ``photo_field`` (default ``field``) coloured by ``STEM`` / ``KNOT`` of the ring
    phase, with ring maps (1 within 0.05 of a ring boundary of the stem, 0 elsewhere) and the
    knots' masks."""
    photo_field = photo_field or field
    faces = {}
    for f in FACES:
        h, w = face_image_size_mm(f, size)
        shape = (round(h * px_per_mm), round(w * px_per_mm))
        out = photo_field.evaluate(face_pixel_points(f, shape, size).reshape(-1, 3))
        phase, knot = np.mod(out["years"], 1.0), out["knot"] > 0.5
        b = np.minimum((phase * LUT_BINS).astype(int), LUT_BINS - 1)   # each bin its own colour
        rgb = np.where(knot[:, None], KNOT[b], STEM[b])
        ring = ((np.minimum(phase, 1 - phase) < 0.05) & ~knot).astype(np.float32)
        faces[f] = Face(f, shape, photo=np.round(rgb * 255).astype(np.uint8).reshape(shape + (3,)),
                        ring_map=ring.reshape(shape), extras={"knot_mask": knot.reshape(shape)})
    return Block(size, faces)


def _plain(app):
    """``app`` without noise (pores, streaks, end-grain mottling): colours are the ramps'."""
    from dataclasses import replace

    return replace(app, species=replace(app.species, pore_contrast=0.0, streak_contrast=0.0,
                                        endgrain_roughness=0.0))


def test_a_knot_is_baked_in_the_colours_and_rings_of_the_photos_knot():
    """Bug seen on H11: knot wood was the stem's ramp darkened by one constant (a flat grey
    ellipse on the bakes, where the photos show a brown knot with rings of its own). With the
    block's true field, the knot's ramp is fitted from the photos' knot pixels by its own ring
    phase, and the bake of the front face reproduces the photo, knot included."""
    field = _RingedKnot()
    block = _knotted_block(field)
    app = ColorMapAppearance.fit_to_block(block, field, "spruce", anchor="field")
    np.testing.assert_allclose(app.knot_lut, KNOT, atol=1 / 255 + 1e-3)
    front = block.faces["front"]
    pts = face_pixel_points("front", front.shape, block.size_mm).reshape(-1, 3)
    baked = Wood(field, _plain(app)).color(pts, np.tile([0.0, -1.0, 0.0], (len(pts), 1)))
    photo = front.photo.reshape(-1, 3) / 255.0
    knot = front.extras["knot_mask"].ravel()
    phase = np.mod(field(pts), 1.0)
    # off the earlywood-latewood steps, where the bake interpolates between two bins
    steady = np.ones(len(pts), bool)
    for late_bins in (STEM_LATE_BINS, KNOT_LATE_BINS):
        steady &= np.abs(phase - (LUT_BINS - late_bins) / LUT_BINS) > 1.0 / LUT_BINS
    assert (knot & steady).sum() > 500
    np.testing.assert_allclose(baked[knot & steady], photo[knot & steady], atol=1.5 / 255)
    np.testing.assert_allclose(baked[~knot & steady], photo[~knot & steady], atol=1.5 / 255)
    # a darkening asked for (the CLI's --knot-darkening) replaces the photos' knot colour
    asked = ColorMapAppearance.fit_to_block(block, field, "spruce", anchor="field", knot_lut=None)
    assert asked.knot_lut is None


def test_a_fitted_knot_draws_the_photos_knot_contrast_where_its_rings_miss_the_photos():
    """A fitted knot's rings sit off the photos' (H11: the knot fitted from its masks has its
    own centre and ring count; ring maps have no lines in knots to register on): binned by
    that phase the knot ramp is flat, one dark ellipse. From a fitted field (ring-map anchor),
    the knot ramp keeps the photos' knot colour and ring contrast, latewood dark as the stem's."""
    luma = np.array([0.299, 0.587, 0.114])
    spiral = _RingedKnot(lambda p: 3.0 * np.arctan2(p[:, 2] - KNOT_AT[2], p[:, 0] - KNOT_AT[0]) / (2 * np.pi))
    block = _knotted_block(spiral, photo_field=_RingedKnot())
    truth = np.ptp(KNOT @ luma)
    binned = ColorMapAppearance.fit_to_block(block, spiral, "spruce", anchor="field").knot_lut
    assert np.ptp(binned @ luma) < 0.3 * truth                      # the flat ellipse
    app = ColorMapAppearance.fit_to_block(block, spiral, "spruce", anchor="ring_map")
    lum = app.knot_lut @ luma
    assert np.ptp(lum) > 0.5 * truth, (np.ptp(lum), truth)
    knot_px = np.concatenate([f.photo[f.extras["knot_mask"]] for f in block.faces.values()]) / 255.0
    np.testing.assert_allclose(app.knot_lut.mean(axis=0), knot_px.mean(axis=0), atol=0.02)
    # the darkest bins are the stem's latewood (the end of the year)
    assert np.argmin(lum) >= LUT_BINS - 6 or np.argmin(lum) <= 1


def test_an_axis_takes_its_ring_shape_from_the_face_whose_rings_the_field_finds():
    """Bug seen on H11: the field misses the rings of a knotted face (its photo's rings sweep
    round the knot), that face bins to a flat ramp, and pooled by pixel count with the other
    face of its axis it halved the rings of both bakes. Here the back photo's rings are
    scrambled against the field and its ring map: the front/back ramp keeps the rings the
    front face shows, as strong as the other axes'."""
    luma = np.array([0.299, 0.587, 0.114])
    field = _RingedKnot()
    block = _knotted_block(field)
    wobble = _RingedKnot(stem_error=lambda p: 0.5 * np.sin(p[:, 2]))      # half a ring, every ~6 mm
    scrambled = _knotted_block(field, photo_field=wobble)
    block.faces["back"].photo = scrambled.faces["back"].photo
    app = ColorMapAppearance.fit_to_block(block, field, "spruce", anchor="ring_map")
    contrast = np.ptp(app.axis_luts @ luma, axis=1)
    assert contrast[1] > 0.9 * contrast[0], contrast
    assert contrast[0] > 0.7 * np.ptp(STEM @ luma), contrast


def test_each_face_bakes_at_its_own_photos_exposure():
    """H11's photos of opposite faces differ in brightness (clear wood: luminance 0.76 on top,
    0.66 on the bottom), and a ramp per axis baked both at their mean. The fitted exposure
    puts each face at its photo's, and the wood between them in between."""
    field = _RingedKnot()
    block = _knotted_block(field)
    bottom = block.faces["bottom"]
    bottom.photo = np.round(bottom.photo * 0.8).astype(np.uint8)
    app = _plain(ColorMapAppearance.fit_to_block(block, field, "spruce", anchor="ring_map"))
    wood = Wood(field, app)
    for f in ("top", "bottom"):
        face = block.faces[f]
        pts = face_pixel_points(f, face.shape, block.size_mm).reshape(-1, 3)
        baked = wood.color(pts, np.tile(FACE_NORMAL[f], (len(pts), 1)).astype(float))
        np.testing.assert_allclose(baked.mean(axis=0), face.photo.reshape(-1, 3).mean(axis=0) / 255.0,
                                   atol=0.01)
    gain = app.axis_exposure[2]                                     # (bottom, top) x RGB
    np.testing.assert_allclose(gain[0] / gain[1], 0.8, atol=0.01)
    # halfway between them, the gain halfway between theirs
    from dataclasses import replace

    mid = face_pixel_points("top", block.faces["top"].shape, block.size_mm).reshape(-1, 3).copy()
    mid[:, 2] = block.size_mm[2] / 2
    up = np.tile([0.0, 0.0, 1.0], (len(mid), 1))
    unexposed = Wood(field, replace(app, axis_exposure=None, exposure_span_mm=None))
    ratio = wood.color(mid, up) / unexposed.color(mid, up)
    np.testing.assert_allclose(ratio, np.broadcast_to(gain.mean(axis=0), ratio.shape), rtol=1e-4)


def test_exposure_settings_are_checked():
    with pytest.raises(WoodcamError, match="axis_exposure and exposure_span_mm go together"):
        ColorMapAppearance("spruce", axis_exposure=np.ones((3, 2, 3)))
    with pytest.raises(WoodcamError, match=r"axis_exposure must have shape \(3, 2, 3\)"):
        ColorMapAppearance("spruce", axis_exposure=np.ones((3, 3)), exposure_span_mm=np.zeros((3, 2)))
    with pytest.raises(WoodcamError, match="knot_lut must have shape"):
        ColorMapAppearance("spruce", knot_lut=np.ones((4, 3)))


@pytest.mark.parametrize("normals, said", [
    (np.array([[0.0, 0.0, 1.0]], np.float32), r"normals must have the shape of points_mm \(5, 3\); got \(1, 3\)"),
    ([[0.0, 0.0, 1.0]], r"must have the shape of points_mm \(5, 3\); got \(1, 3\)"),
    (None, r"must be real numbers with the shape of points_mm \(5, 3\); got None"),
    (np.zeros((5, 3)) + 1j, "got an array of complex numbers"),
], ids=["one float32 normal", "one normal", "None", "complex"])
def test_the_appearance_checks_the_normals_it_is_given(normals, said):
    """ColorMapAppearance.color (the appearance seam, public) passed its normals to the compiled
    kernel as np.asarray(float32): one normal for five points was read past its end (NaN and
    another array's memory as colours, no error), None was numba's TypingError, complex normals
    lost their imaginary parts. What Wood.color passes (float32 (n, 3), checked there) gives the
    same colours as before."""
    field = builtin_block("flat-sawn").field
    app = ColorMapAppearance("oak")
    pts = np.random.default_rng(0).uniform(0, 40, (5, 3))
    with pytest.raises(WoodcamError, match=said):
        app.color(field, pts, normals)
    up = np.tile(np.float32([0, 0, 1]), (5, 1))
    assert np.array_equal(app.color(field, pts, up), Wood(field, app).color(pts, up))


@pytest.mark.parametrize("name, value, got", [
    ("axis_luts", "abc", "'abc'; convert the text to numbers first"),
    ("axis_luts", np.zeros((3, 32, 3)) + 0j, r"an array of complex numbers \(dtype complex128, shape \(3, 32, 3\)\); "
                                             r"pass real numbers \(e\.g\. np\.real\(axis_luts\)"),
    ("knot_lut", np.zeros((32, 3)) + 0j, r"an array of complex numbers \(dtype complex128, shape \(32, 3\)\)"),
    ("axis_exposure", "a", "'a'"),
])
def test_fitted_tables_must_be_real_numbers(name, value, got):
    """The fitted tables were read with np.asarray(float32): a string was numpy's bare ValueError
    and complex numbers were taken as their real parts under numpy's ComplexWarning."""
    kw = {name: value} | ({"exposure_span_mm": np.zeros((3, 2))} if name == "axis_exposure" else {})
    with pytest.raises(WoodcamError, match=rf"{name} must be real numbers of shape \(.*\); got {got}"):
        ColorMapAppearance("spruce", **kw)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::woodcam.errors.WoodcamWarning")  # H11's folds are flagged contradicted
def test_h11_bakes_its_knot_dark_and_ringed_and_each_face_at_its_photos_colour(shared_data, tmp_path, monkeypatch):
    """The real spruce cube H11 (its field fitted to the ring maps and knot masks, ~1 min),
    each face baked where its photo is. Measured before the knot ramp and the per-face
    exposure: the knot 0.11 of luminance lighter than the photo's on face C (left) and its
    ring-scale contrast 0.64 of the photo's; face means up to 0.08 off (bottom, blue)."""
    from scipy import ndimage

    from woodcam.block.io import read_mokume
    from woodcam.stock import open_stock

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    folder = shared_data / "mokume" / "H11"
    wood = open_stock(str(folder), species="spruce").wood
    block = read_mokume(folder)
    luma = np.array([0.299, 0.587, 0.114])

    def ring_scale(im):  # H11's rings are 6-30 px apart on its 256-px photos
        return ndimage.gaussian_filter(im, 1.0) - ndimage.gaussian_filter(im, 6.0)

    for f, face in block.faces.items():
        pts = face_pixel_points(f, face.shape, block.size_mm).reshape(-1, 3)
        baked = wood.color(pts, np.tile(np.asarray(FACE_NORMAL[f], float), (len(pts), 1)))
        photo = face.photo.reshape(-1, 3) / 255.0
        np.testing.assert_allclose(baked.mean(axis=0), photo.mean(axis=0), atol=0.025, err_msg=f)
        if f not in ("left", "back"):          # faces C and F: the knot's two exits
            continue
        core = ndimage.binary_erosion(face.extras["knot_mask"], iterations=8)
        lb, lp = (baked @ luma).reshape(face.shape), (photo @ luma).reshape(face.shape)
        assert abs(lb[core].mean() - lp[core].mean()) < 0.06, (f, lb[core].mean(), lp[core].mean())
        contrast = ring_scale(lb)[core].std() / ring_scale(lp)[core].std()
        assert 0.75 < contrast < 1.5, (f, contrast)


def test_a_texture_frame_is_checked_once_and_fibres_map_like_points():
    """The colour map and the built-in photos each mapped the wood point and fibre into the
    texture frame and each checked it (two wordings): LogFrame.direction_to_log (the inverse of
    direction_to_block) and fields.base.check_texture_frame, one message for every caller."""
    from woodcam.synth import synth_block

    frame = LogFrame((3.0, -2.0, 1.0), (0.3, 0.2, 1.0), (1.0, 0.5, 0.0))
    d = np.random.default_rng(0).normal(size=(50, 3))
    np.testing.assert_allclose(frame.direction_to_block(frame.direction_to_log(d)), d, atol=1e-12)
    np.testing.assert_allclose(frame.direction_to_log(d), frame.to_log(d) - frame.to_log(np.zeros((1, 3))),
                               atol=1e-12)
    messages = set()
    for make in (lambda: ColorMapAppearance(texture_frame="frame"),
                 lambda: synth_block(lambda p: np.zeros(len(p)), (10, 10, 10), texture_frame="frame")):
        with pytest.raises(WoodcamError, match="texture_frame must be a LogFrame") as exc:
            make()
        messages.add(str(exc.value))
    assert len(messages) == 1, messages
