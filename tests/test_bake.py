"""Tests of woodcam.bake: an independent check of the baked texture against the wood's colour.

The check never calls the baker's helpers: it picks random points on the baked mesh's own
triangles, interpolates the mesh's own UVs barycentrically, samples the texture image bilinearly
(texel centres at ((c + .5) / w, 1 - (r + .5) / h), the OBJ/trimesh convention) and compares with
``wood.color`` at the 3D point.

Error bound (per channel), for the smooth test appearance below::

    |sampled - color(p, n)| <= A / L * s_max * sqrt(2) * K     (position: the four bilinear
                                                                  texels lie within L-inf 1 texel
                                                                  of p, i.e. <= sqrt(2) texels)
                               + B * dn_max                    (normal: texels may belong to a
                                                                  neighbouring triangle)
                               + 0.5 / 255                     (uint8 rounding)

``s_max`` is the largest mm-per-texel stretch of any triangle's UV map (singular value of the
texel -> mm Jacobian; 1 / texels_per_mm for an undistorted chart), ``dn_max`` the largest normal
change within one chart over a texel footprint (face mode: between faces sharing a vertex; smooth
mode: normal-field Jacobian times sqrt(2) texels), and ``K = 2`` because a border texel takes the
affine map of the nearest triangle of the chart, extrapolated up to ~1.5 texels beyond it, which
can double the 3D offset at chart corners. ``A / L * s_max * sqrt(2)`` alone is ~0.01 here.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import trimesh

from woodcam.bake import bake
from woodcam.errors import WoodcamError, WoodcamWarning

# Smooth test appearance: rgb_j = 0.5 + A sin(d_j . p / L + phase_j) + B n_j, in [0.1, 0.9].
_A = 0.25
_B = 0.15
_L = 4.0  # mm


class SmoothWood:
    """A smooth stand-in for woodcam.appearance.Wood (position- and normal-dependent)."""

    dirs = np.array([[1.0, 0.3, 0.2], [-0.2, 1.0, 0.4], [0.3, -0.4, 1.0]])
    dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    phase = np.array([0.0, 1.0, 2.0])

    def color(self, points_mm, normals):
        # einsum, not ``points_mm @ dirs.T``: OpenBLAS threads an (n, 3) x (3, 3) product and on
        # the loaded 2-core machine that took 1.4 s for 2M points instead of 0.04-0.08 s.
        phase = np.einsum("nk,jk->nj", points_mm, self.dirs) / _L + self.phase
        return 0.5 + _A * np.sin(phase) + _B * normals


#: Darkest colour the appearance can produce; anything darker in the texture is unpainted.
_MIN_RGB = 0.5 - _A - _B


def _box():
    m = trimesh.creation.box((40.0, 30.0, 20.0))
    m.apply_translation([20.0, 15.0, 10.0])
    return m


def _carved():
    """A 40 x 30 x 20 mm block with a 16 mm through hole and a 10 mm pocket: a carved part."""
    block = _box()
    hole = trimesh.creation.cylinder(radius=8.0, height=40.0, sections=48)
    hole.apply_translation([14.0, 15.0, 10.0])
    pocket = trimesh.creation.box((10.0, 10.0, 10.0))
    pocket.apply_translation([32.0, 15.0, 18.0])
    return trimesh.boolean.difference([block, hole, pocket], engine="manifold")


def _sphere():
    m = trimesh.creation.icosphere(subdivisions=3, radius=12.0)
    m.apply_translation([20.0, 20.0, 20.0])
    return m


# ------------------------------------------------------------------------------------------------
# independent sampling helpers (no woodcam.bake code)


def _surface_samples(mesh, n, rng):
    """Random points on the mesh's triangles: (face ids (k,), barycentrics (k, 3)). A quarter lie
    on triangle edges and a few on vertices, where seams would show first."""
    faces = rng.integers(0, len(mesh.faces), n)
    r = rng.random((n, 2))
    flip = r.sum(axis=1) > 1.0
    r[flip] = 1.0 - r[flip]
    bary = np.column_stack([1.0 - r.sum(axis=1), r])
    on_edge = rng.random(n) < 0.25
    which = rng.integers(0, 3, n)
    bary[on_edge, which[on_edge]] = 0.0
    bary[on_edge] /= bary[on_edge].sum(axis=1, keepdims=True)
    on_vertex = rng.random(n) < 0.05
    bary[on_vertex] = np.eye(3)[which[on_vertex]]
    return faces, bary


def _bilinear(image, uv):
    """Sample ``image (h, w, 3) float`` at trimesh/OBJ ``uv (k, 2)`` (v up, texel centres at
    ((c + .5) / w, 1 - (r + .5) / h)), clamp to edge. Returns colours (k, 3) and the four texel
    (rows, cols) each sample reads with non-zero weight."""
    h, w = image.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = (1.0 - uv[:, 1]) * h - 0.5
    x0 = np.floor(x).astype(int)
    y0 = np.floor(y).astype(int)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    xs = np.clip(np.stack([x0, x0 + 1]), 0, w - 1)
    ys = np.clip(np.stack([y0, y0 + 1]), 0, h - 1)
    c = (image[ys[0], xs[0]] * (1 - fx) * (1 - fy) + image[ys[0], xs[1]] * fx * (1 - fy)
         + image[ys[1], xs[0]] * (1 - fx) * fy + image[ys[1], xs[1]] * fx * fy)
    # texels with a non-zero weight (a zero-weight neighbour may legitimately be unpainted)
    rows = [ys[0], ys[0], ys[1], ys[1]]
    cols = [xs[0], xs[1], xs[0], xs[1]]
    wts = [(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy]
    used = [(rr[wt[:, 0] > 0], cc[wt[:, 0] > 0]) for rr, cc, wt in zip(rows, cols, wts)]
    return c, used


def _texel_jacobians(mesh, image_shape, values):
    """Per face, the largest singular value of d(values)/d(texel coords): (f,)."""
    h, w = image_shape[:2]
    uv = np.asarray(mesh.visual.uv, dtype=np.float64)
    xy = np.column_stack([uv[:, 0] * w, (1.0 - uv[:, 1]) * h])[mesh.faces]  # (f, 3, 2)
    v = values[mesh.faces]
    duv = np.stack([xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]], axis=2)  # (f, 2, 2)
    dv = np.stack([v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]], axis=2)  # (f, d, 2)
    det = np.linalg.det(duv)
    ok = np.abs(det) > 1e-9
    jac = dv[ok] @ np.linalg.inv(duv[ok])
    return np.linalg.svd(jac, compute_uv=False)[:, 0]


def _max_normal_jump_per_vertex(mesh):
    """Largest |n_a - n_b| between faces sharing a vertex of the (seam-split) mesh, i.e. inside
    one chart."""
    fn = np.asarray(mesh.face_normals)
    nv = len(mesh.vertices)
    lo = np.full((nv, 3), np.inf)
    hi = np.full((nv, 3), -np.inf)
    for k in range(3):
        np.minimum.at(lo, mesh.faces[:, k], fn)
        np.maximum.at(hi, mesh.faces[:, k], fn)
    used = np.isfinite(lo[:, 0])
    return float(np.linalg.norm(hi[used] - lo[used], axis=1).max())


def _check_against_wood(tex_mesh, image_u8, original, normals_mode, rng, n=20000,
                        coverage=None):
    """Return (max error, bound) of the texture sampled at random surface points."""
    image = image_u8.astype(np.float64) / 255.0
    faces, bary = _surface_samples(tex_mesh, n, rng)
    tri = tex_mesh.faces[faces]
    points = np.einsum("kc,kcd->kd", bary, tex_mesh.vertices[tri])
    uv = np.einsum("kc,kcd->kd", bary, np.asarray(tex_mesh.visual.uv)[tri])
    sampled, used = _bilinear(image, uv)

    s_max = float(_texel_jacobians(tex_mesh, image.shape, np.asarray(tex_mesh.vertices)).max())
    if normals_mode == "face":
        nrm = np.asarray(tex_mesh.face_normals)[faces]
        dn_max = _max_normal_jump_per_vertex(tex_mesh)
    else:
        # vertex normals of the ORIGINAL (unsplit) mesh, matched by position
        from scipy.spatial import cKDTree

        dist, idx = cKDTree(original.vertices).query(tex_mesh.vertices)
        assert dist.max() < 1e-4
        vn = np.asarray(original.vertex_normals)[idx]
        nrm = np.einsum("kc,kcd->kd", bary, vn[tri])
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        dn_max = float(_texel_jacobians(tex_mesh, image.shape, vn).max()) * math.sqrt(2.0) * 2.0
    expected = SmoothWood().color(points, nrm)
    err = float(np.abs(sampled - expected).max())
    bound = _A / _L * s_max * math.sqrt(2.0) * 2.0 + _B * dn_max + 0.5 / 255 + 1e-9
    if coverage is not None:
        for rows, cols in used:
            assert coverage[rows, cols].all(), "a surface point samples an unpainted texel"
    return err, bound, s_max


# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make, normals, tpm",
    [(_box, "face", 4.0), (_carved, "face", 4.0), (_sphere, "smooth", 6.0)],
    ids=["box", "carved", "sphere-smooth"],
)
def test_baked_texture_matches_wood_at_random_surface_points(make, normals, tpm):
    mesh = make()
    result = bake(mesh, SmoothWood(), texels_per_mm=tpm, normals=normals)
    out = result.mesh
    image = np.asarray(out.visual.material.baseColorTexture.convert("RGB"))
    assert image.shape == result.atlas.shape
    err, bound, s_max = _check_against_wood(out, image, mesh, normals, np.random.default_rng(0),
                                            coverage=result.coverage_mask)
    assert err <= bound, f"max colour error {err:.4f} > bound {bound:.4f}"
    # texel size: charts are near-isometric, so the stretch stays close to 1 / texels_per_mm
    assert s_max <= 1.5 / result.texels_per_mm
    assert result.texels_per_mm == pytest.approx(tpm)


def test_smallest_padding_still_meets_the_bound():
    """padding_px=2 leaves each chart exactly its own 1-texel bilinear ring."""
    mesh = _carved()
    result = bake(mesh, SmoothWood(), texels_per_mm=4.0, padding_px=2)
    err, bound, _ = _check_against_wood(result.mesh, result.atlas, mesh, "face",
                                        np.random.default_rng(5), coverage=result.coverage_mask)
    assert err <= bound


def test_flat_charts_are_second_order_accurate():
    """On a box every chart is planar with one normal and border texels continue the same affine
    map, so the texture is exactly f sampled at texel centres and bilinear interpolation errs by
    at most (h_x^2 |f_xx| + h_y^2 |f_yy|) / 8 <= A (s / L)^2 / 4 plus rounding. A half-texel
    offset in the UV convention would add ~A / L * s / 2 = 0.008 and fail this."""
    mesh = _box()
    result = bake(mesh, SmoothWood(), texels_per_mm=4.0)
    err, _, s_max = _check_against_wood(result.mesh, result.atlas, mesh, "face",
                                        np.random.default_rng(4), coverage=result.coverage_mask)
    tight = _A * (s_max / _L) ** 2 / 4.0 + 0.5 / 255 + 1e-9
    assert err <= tight, f"{err:.5f} > {tight:.5f}"


def test_glb_round_trip_keeps_the_bake_within_the_bound(tmp_path):
    """The whole chain: bake -> GLB on disk -> reload -> the same independent check."""
    from woodcam.export import export_glb, load_textured

    mesh = _carved()
    result = bake(mesh, SmoothWood(), texels_per_mm=3.0)
    path = export_glb(result.mesh, tmp_path / "carved.glb")
    loaded = load_textured(path)
    image = np.asarray(loaded.visual.material.baseColorTexture.convert("RGB"))
    np.testing.assert_array_equal(image, result.atlas)
    err, bound, _ = _check_against_wood(loaded, image, mesh, "face", np.random.default_rng(1),
                                        coverage=result.coverage_mask)
    assert err <= bound


def test_wrong_v_convention_would_fail_the_check():
    """Guard that the check can fail: sampling the image upside down breaks the bound."""
    mesh = _box()
    result = bake(mesh, SmoothWood(), texels_per_mm=4.0)
    image = result.atlas[::-1].copy()
    err, bound, _ = _check_against_wood(result.mesh, image, mesh, "face",
                                        np.random.default_rng(2))
    assert err > 3 * bound


@pytest.mark.parametrize("factor", [2, 4, 8])
def test_mip_levels_never_sample_unpainted_texels(factor):
    mesh = _carved()
    result = bake(mesh, SmoothWood(), texels_per_mm=4.0)
    h, w, _ = result.atlas.shape
    assert h % 8 == 0 and w % 8 == 0  # mip levels 1..3 halve exactly
    mip = result.atlas.astype(np.float64).reshape(h // factor, factor, w // factor, factor, 3)
    mip = mip.mean(axis=(1, 3)) / 255.0
    out = result.mesh
    faces, bary = _surface_samples(out, 20000, np.random.default_rng(3))
    uv = np.einsum("kc,kcd->kd", bary, np.asarray(out.visual.uv)[out.faces[faces]])
    sampled, _ = _bilinear(mip, uv)
    # Black (unpainted) texels would pull samples far below the darkest wood colour.
    assert sampled.min() >= _MIN_RGB - 1.0 / 255


def test_undilated_atlas_is_black_between_charts_and_dilation_fills_it():
    """Without the dilation the mip check above would fail: unpainted texels exist, and the
    dilated atlas has none left darker than the wood."""
    result = bake(_carved(), SmoothWood(), texels_per_mm=4.0)
    assert not result.coverage_mask.all()
    assert result.atlas.min() >= math.floor(_MIN_RGB * 255)
    painted = result.atlas[result.coverage_mask]
    assert painted.min() >= math.floor(_MIN_RGB * 255)


def test_vertices_are_split_copies_and_faces_keep_their_order():
    mesh = _carved()
    result = bake(mesh, SmoothWood(), texels_per_mm=2.0)
    out = result.mesh
    assert len(out.faces) == len(mesh.faces)
    assert len(out.vertices) >= len(mesh.vertices)
    np.testing.assert_allclose(out.vertices, mesh.vertices[result.vertex_map], atol=1e-5)
    np.testing.assert_allclose(out.face_normals, mesh.face_normals, atol=1e-6)
    assert out.area == pytest.approx(mesh.area, rel=1e-6)
    uv = np.asarray(out.visual.uv)
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    assert set(result.timings) >= {"unwrap", "rasterise", "color", "dilate"}


def test_smooth_normals_are_the_inputs_split_with_the_vertices_and_timed_in_the_total():
    """normals="smooth": the result mesh shades with the INPUT's vertex normals (no seam where
    the unwrap split vertices), made where the atlas is; normals recomputed on the split mesh
    differ there (a split vertex averages only its own chart's faces: up to 0.09 on this
    sphere), so the equality below is not one by chance. ``total`` spans every step."""
    mesh = _sphere()
    smooth = bake(mesh, SmoothWood(), texels_per_mm=2.0, normals="smooth")
    vmap = smooth.vertex_map
    assert len(smooth.mesh.vertices) > len(mesh.vertices)  # seams split some vertices
    np.testing.assert_array_equal(smooth.mesh.vertex_normals, np.asarray(mesh.vertex_normals)[vmap])
    recomputed = trimesh.Trimesh(smooth.mesh.vertices, smooth.mesh.faces, process=False).vertex_normals
    split = np.bincount(vmap)[vmap] > 1
    assert np.linalg.norm(recomputed - smooth.mesh.vertex_normals, axis=1)[split].max() > 0.05
    t = smooth.timings
    assert t["total"] >= t["unwrap"] + t["rasterise"] + t["color"] + t["dilate"]


def test_texel_density_is_the_one_asked_for():
    mesh = _box()
    result = bake(mesh, SmoothWood(), texels_per_mm=5.0)
    out = result.mesh
    mm_per_texel = _texel_jacobians(out, result.atlas.shape, np.asarray(out.vertices))
    # A box unwraps into flat charts without distortion.
    np.testing.assert_allclose(mm_per_texel, 1 / 5.0, rtol=0.02)


def test_too_large_atlas_lowers_density_with_a_warning():
    mesh = _box()
    with pytest.warns(UserWarning, match="texels_per_mm lowered from 100"):
        result = bake(mesh, SmoothWood(), texels_per_mm=100.0, max_atlas_px=256)
    assert max(result.atlas.shape[:2]) <= 256
    assert result.texels_per_mm < 100.0
    assert any("max_atlas_px=256" in m for m in result.warnings)
    out = result.mesh
    mm_per_texel = _texel_jacobians(out, result.atlas.shape, np.asarray(out.vertices))
    np.testing.assert_allclose(mm_per_texel, 1 / result.texels_per_mm, rtol=0.05)


def test_the_atlas_warning_of_an_inch_run_speaks_inches():
    """Sweep h13 item 5: the warning said "(texel 0.0254 mm) so the 5200 mm^2 surface" under
    --units inch (woodcam.units.message_units)."""
    from woodcam.units import message_units

    with message_units("inch"), pytest.warns(UserWarning, match="texels_per_mm lowered") as caught:
        bake(_box(), SmoothWood(), texels_per_mm=100.0, max_atlas_px=256)
    text = str(caught[0].message)
    assert " mm" not in text and " in) so the 8.06 in^2 surface fits" in text, text


@pytest.mark.parametrize("efficiency", [1.0, 20.0], ids=["mild", "far"])
def test_atlas_overshoot_is_rescaled_or_re_unwrapped(monkeypatch, efficiency):
    """Fool the size prediction so xatlas' atlas overshoots max_atlas_px (here by 18 % and 35 %:
    xatlas runs again at a lower density, whose result overshoots by < 1 % and is scaled down).
    The atlas fits, the density is reported and the bake still meets the bound."""
    bake_module = __import__("importlib").import_module("woodcam.bake")  # the module: woodcam.bake is bake()

    monkeypatch.setattr(bake_module, "_PACK_EFFICIENCY", efficiency)
    mesh = _carved()
    with pytest.warns(UserWarning, match="texels_per_mm lowered from 6"):
        result = bake(mesh, SmoothWood(), texels_per_mm=6.0, max_atlas_px=384)
    assert max(result.atlas.shape[:2]) <= 384
    out = result.mesh
    stretch = _texel_jacobians(out, result.atlas.shape, np.asarray(out.vertices))
    assert np.median(stretch) == pytest.approx(1 / result.texels_per_mm, rel=0.05)
    err, bound, _ = _check_against_wood(out, result.atlas, mesh, "face",
                                        np.random.default_rng(6), coverage=result.coverage_mask)
    assert err <= bound


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"texels_per_mm": 0.0}, "texels_per_mm must be a finite number > 0"),
        ({"texels_per_mm": float("nan")}, "texels_per_mm must be a finite number > 0"),
        ({"normals": "vertex"}, r"normals must be one of \('face', 'smooth'\)"),
        ({"padding_px": 1}, "padding_px must be an integer >= 2"),
        ({"max_atlas_px": 10}, "max_atlas_px must be an integer in \\[64, 65536\\]"),
    ],
)
def test_bad_arguments_raise_clear_errors(kwargs, match):
    with pytest.raises(WoodcamError, match=match):
        bake(_box(), SmoothWood(), **kwargs)


def test_wood_without_color_and_bad_color_shape_are_rejected():
    with pytest.raises(WoodcamError, match="wood must have a method color"):
        bake(_box(), object())

    class Grey:
        def color(self, points_mm, normals):
            return np.full(len(points_mm), 0.5)

    with pytest.raises(WoodcamError, match=r"wood.color must return rgb of shape \(n, 3\)"):
        bake(_box(), Grey(), texels_per_mm=1.0)

    class Bytes:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 200.0)

    with pytest.raises(WoodcamError, match=r"rgb in \[0, 1\].*divide 0..255"):  # was clipped silently
        bake(_box(), Bytes(), texels_per_mm=1.0)


def test_rasteriser_paints_exactly_the_bilinear_footprint_of_its_triangles():
    """Unit check of the conservative rasteriser against dense sampling, on compact triangles,
    big ones and long slivers (the row-span walk of every shape): every texel that bilinear
    sampling at a point of a triangle reads is painted, and nothing farther than the footprint
    (L-inf 1 texel + the 0.02 margin) from every triangle is."""
    from scipy.spatial import cKDTree

    from woodcam.bake import _rasterise

    xy = np.array([
        [2.3, 2.7], [9.1, 3.2], [4.4, 8.9],            # compact
        [12.2, 3.0], [45.1, 5.5], [12.9, 4.1],         # long sliver
        [6.0, 14.0], [40.0, 18.0], [20.0, 44.0],       # big triangle
        [44.5, 30.2], [46.0, 44.7], [44.9, 30.3],      # thin, nearly vertical sliver
    ])
    faces = np.arange(len(xy)).reshape(-1, 3)
    width = height = 48
    owner = _rasterise(xy, faces, width, height).reshape(height, width)

    step = 0.05
    samples = []
    for f in faces:
        p = xy[f]
        n = int(np.ceil(np.linalg.norm(p - np.roll(p, 1, axis=0), axis=1).max() / step))
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        a, b = i[keep] / n, j[keep] / n
        samples.append(p[0] + a[:, None] * (p[1] - p[0]) + b[:, None] * (p[2] - p[0]))
    samples = np.concatenate(samples)

    # required: texels with positive bilinear weight at some sample point
    x = samples[:, 0] - 0.5
    y = samples[:, 1] - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    need = np.zeros((height, width), dtype=bool)
    for dy in (0, 1):
        for dx in (0, 1):
            wx = (x - x0) if dx else (1 - (x - x0))
            wy = (y - y0) if dy else (1 - (y - y0))
            ok = (wx > 0) & (wy > 0)
            need[np.clip(y0[ok] + dy, 0, height - 1), np.clip(x0[ok] + dx, 0, width - 1)] = True
    painted = owner >= 0
    assert not (need & ~painted).any(), "a texel in some bilinear footprint is unpainted"

    # tight: painted texel centres lie within L-inf 1.02 (+ sampling step) of a triangle
    rows, cols = np.nonzero(painted)
    centres = np.column_stack([cols + 0.5, rows + 0.5])
    dist, _ = cKDTree(samples).query(centres, p=np.inf)
    assert dist.max() <= 1.02 + step
    # and the footprint is not degenerate: most painted texels are truly needed
    assert painted.sum() <= need.sum() * 1.1


def _crashing_layout(original, crash_when):
    """A stand-in for the xatlas worker that dies natively (SIGSEGV) when ``crash_when(pieces)``."""
    import os
    import signal

    def layout(verts, faces, pieces, **kw):
        if crash_when(pieces):
            os.kill(os.getpid(), signal.SIGSEGV)
        return original(verts, faces, pieces, **kw)

    return layout


def test_a_native_crash_in_the_unwrap_is_retried_in_pieces(monkeypatch):
    import woodcam._xatlas_worker as _xatlas_worker

    mesh = _carved()
    monkeypatch.setattr(_xatlas_worker, "layout",
                        _crashing_layout(_xatlas_worker.layout, lambda p: len(p) == 1))
    with pytest.warns(WoodcamWarning, match="xatlas crashed unwrapping the surface in 1 piece"):
        result = bake(mesh, SmoothWood(), texels_per_mm=3.0, unwrap="xatlas")
    # the two-piece atlas is as exact as a one-piece one
    err, bound, _ = _check_against_wood(result.mesh, result.atlas, mesh, "face",
                                        np.random.default_rng(5), coverage=result.coverage_mask)
    assert err <= bound
    np.testing.assert_array_equal(result.vertex_map.max() < len(mesh.vertices), True)


def test_a_unwrap_that_always_crashes_is_one_clear_error(monkeypatch):
    import woodcam._xatlas_worker as _xatlas_worker

    monkeypatch.setattr(_xatlas_worker, "layout",
                        _crashing_layout(_xatlas_worker.layout, lambda p: True))
    with pytest.raises(WoodcamError, match=r"xatlas crashed \(native fault\).*up to 8 pieces"):
        bake(_box(), SmoothWood(), texels_per_mm=2.0, unwrap="xatlas")


def test_the_unwrap_worker_does_not_outlive_an_interrupted_bake(monkeypatch, tmp_path):
    """Ctrl-C during a long unwrap waited for the worker (the pool's exit joined it), and a killed
    woodcam left it running for minutes at gigabytes."""
    import os
    import signal
    import threading
    import time

    import woodcam._xatlas_worker as _xatlas_worker

    pid_file = tmp_path / "worker.pid"

    def slow_layout(verts, faces, pieces, **kw):
        pid_file.write_text(str(os.getpid()))
        time.sleep(120)

    monkeypatch.setattr(_xatlas_worker, "layout", slow_layout)
    timer = threading.Timer(3.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            bake(_box(), SmoothWood(), texels_per_mm=2.0, unwrap="xatlas")
    finally:
        timer.cancel()
    assert time.perf_counter() - t0 < 30.0  # not the worker's 120 s
    worker = int(pid_file.read_text())
    time.sleep(0.5)
    with pytest.raises(ProcessLookupError):  # killed and reaped
        os.kill(worker, 0)


def test_a_mesh_with_a_far_or_nan_vertex_is_refused():
    """A box with one vertex at 1e12 mm ran for minutes at 7.7 GB; a NaN vertex was scipy's
    ValueError."""
    box = _box()
    for bad in (1e12, np.nan):
        v = np.asarray(box.vertices).copy()
        v[0, 0] = bad
        with pytest.raises(WoodcamError, match="vertices must be finite and span at most 10000 mm"):
            bake(trimesh.Trimesh(v, box.faces, process=False), SmoothWood(), texels_per_mm=2.0)
    with pytest.raises(WoodcamError, match=r"max_atlas_px must be an integer in \[64, 65536\]"):
        bake(box, SmoothWood(), texels_per_mm=2.0, max_atlas_px=10**9)


def test_the_82k_triangle_icosphere_that_crashed_xatlas_bakes():
    """Regression: xatlas segfaults on this closed sphere in one piece (issue 16)."""
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=40.0)
    with pytest.warns(WoodcamWarning, match="xatlas crashed"):
        result = bake(sphere, SmoothWood(), texels_per_mm=1.0, unwrap="xatlas")
    assert len(result.mesh.faces) == 81920
    assert result.coverage_mask.mean() > 0.5



def test_the_82k_triangle_icosphere_bakes_with_projected_charts_without_a_crash():
    """The default unwrap (woodcam's projected charts, xatlas only packs) never reaches the
    xatlas charting that segfaults on this sphere, and honours the density on every face."""
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=40.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", WoodcamWarning)  # no crash-and-retry message
        result = bake(sphere, SmoothWood(), texels_per_mm=4.0)
    assert len(result.mesh.faces) == 81920
    assert result.density_stretch > 1.0  # projected charts were used
    assert result.uv_fill >= 0.5
    mm_per_texel = _texel_jacobians(result.mesh, result.atlas.shape,
                                    np.asarray(result.mesh.vertices))
    assert mm_per_texel.max() <= 1.0 / result.texels_per_mm * (1 + 1e-3)


def _helicoid(turns: float, pitch_mm: float = 2.0):
    """An open helical ramp (r 10..30 mm) whose normals all lie within ~6 degrees of +Z; with
    more than one turn its projection on the XY plane covers the same ground twice."""
    n_a, n_r = int(96 * turns), 4
    a = np.linspace(0.0, 2 * np.pi * turns, n_a + 1)
    r = np.linspace(10.0, 30.0, n_r + 1)
    aa, rr = np.meshgrid(a, r, indexing="ij")
    verts = np.column_stack([rr.ravel() * np.cos(aa.ravel()), rr.ravel() * np.sin(aa.ravel()),
                             pitch_mm * aa.ravel() / (2 * np.pi)])
    idx = np.arange(len(verts)).reshape(n_a + 1, n_r + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    faces = np.vstack([q[:, [0, 2, 1]], q[:, [0, 3, 2]]])
    return trimesh.Trimesh(verts, faces, process=False)


@pytest.mark.parametrize("turns, folds", [(0.8, False), (1.5, True)])
def test_projected_charts_that_fold_over_themselves_are_left_to_xatlas(turns, folds):
    from woodcam.bake import _projected_charts

    ramp = _helicoid(turns)
    assert (_projected_charts(ramp) is None) == folds
    result = bake(ramp, SmoothWood(), texels_per_mm=2.0)
    assert (result.density_stretch == 1.0) == folds  # xatlas' charts: exact density
    if not folds:  # (xatlas' own atlas of the folded ramp misses the bound too: not ours)
        err, bound, _ = _check_against_wood(result.mesh, result.atlas, ramp, "face",
                                            np.random.default_rng(7),
                                            coverage=result.coverage_mask)
        assert err <= bound


def test_a_native_crash_while_packing_projected_charts_falls_back_to_xatlas(monkeypatch):
    import os
    import signal

    import woodcam._xatlas_worker as _xatlas_worker

    def crash(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGSEGV)

    monkeypatch.setattr(_xatlas_worker, "pack", crash)
    mesh = _sphere()
    with pytest.warns(WoodcamWarning, match="xatlas crashed packing the projected UV charts"):
        result = bake(mesh, SmoothWood(), texels_per_mm=4.0)
    assert any("crashed packing" in m for m in result.warnings)  # in the bake's report too
    assert result.density_stretch == 1.0
    err, bound, _ = _check_against_wood(result.mesh, result.atlas, mesh, "face",
                                        np.random.default_rng(8), coverage=result.coverage_mask)
    assert err <= bound


def test_a_zero_area_face_does_not_break_the_projected_charts():
    """Regression: a degenerate triangle alone in its chart had no mean normal (NaN uv)."""
    box = _box()
    verts = np.vstack([box.vertices, box.vertices[:1] + [0.0, 0.0, 1e-3]])
    faces = np.vstack([box.faces, [[0, 0, len(box.vertices)]]])
    mesh = trimesh.Trimesh(verts, faces, process=False)
    result = bake(mesh, SmoothWood(), texels_per_mm=4.0)
    assert np.isfinite(np.asarray(result.mesh.visual.uv)).all()
    keep = np.arange(len(box.faces))
    err, bound, _ = _check_against_wood(result.mesh.submesh([keep], append=True), result.atlas,
                                        box, "face", np.random.default_rng(9))
    assert err <= bound


def test_fragmented_projected_charts_of_a_noisy_mesh_fall_back_to_xatlas(monkeypatch):
    """A scanned-looking sphere (0.3 mm noise on its vertices): its normals jump between cones, the
    projected charts fragment and pack poorly, so xatlas' charts are made too and kept when
    fuller; a clean sphere keeps the projected charts."""
    bake_module = __import__("importlib").import_module("woodcam.bake")  # the module: woodcam.bake is bake()

    rng = np.random.default_rng(3)
    noisy = trimesh.creation.icosphere(subdivisions=4, radius=30.0)
    noisy.vertices += rng.normal(scale=0.3, size=noisy.vertices.shape)
    assert bake_module._projected_charts(noisy)[4] > bake_module._MAX_SMALL_CHART_AREA
    auto = bake(noisy, SmoothWood(), texels_per_mm=4.0)
    monkeypatch.setattr(bake_module, "_MIN_PROJECTED_FILL", 0.0)  # projected charts only
    projected = bake(noisy, SmoothWood(), texels_per_mm=4.0)
    assert projected.density_stretch > 1.0 and projected.uv_fill < 0.4
    assert auto.density_stretch == 1.0 and auto.uv_fill > projected.uv_fill
    clean = trimesh.creation.icosphere(subdivisions=4, radius=30.0)
    assert bake_module._projected_charts(clean)[4] == 0.0


# ------------------------------------------------------------------------------------------------
# rebake_texture: a picture laid on by any coordinates, moved into an even-density atlas


def test_rebake_texture_puts_the_pictures_colours_where_the_picture_had_them():
    """A picture of four solid quadrants laid on the box by its (x, y) (a projection that
    squeezes the box's sides to lines): every surface point away from a quadrant's border shows
    its quadrant's colour in the rebaked atlas, faces keep their order, texel density is even."""
    from woodcam.bake import rebake_texture

    mesh = _box()
    colours = np.array([[[200, 30, 30], [30, 200, 30]], [[30, 30, 200], [220, 220, 40]]], np.uint8)
    picture = np.repeat(np.repeat(colours, 32, axis=0), 32, axis=1)      # (64, 64, 3), row 0 on top
    # the box on the picture's middle half (clear of its repeating edges); v up: y = 30 is on top
    uv = 0.25 + mesh.vertices[:, :2] / [80.0, 60.0]
    result = rebake_texture(mesh, uv[mesh.faces], picture, texels_per_mm=3.0)
    out = result.mesh
    assert np.array_equal(result.vertex_map[out.faces], np.asarray(mesh.faces))
    assert result.texels_per_mm == 3.0 and result.coverage_mask.any()
    atlas = np.asarray(out.visual.material.baseColorTexture.convert("RGB")).astype(float)
    faces, bary = _surface_samples(out, 5000, np.random.default_rng(1))
    tri = out.faces[faces]
    points = np.einsum("kc,kcd->kd", bary, out.vertices[tri])
    sampled, _ = _bilinear(atlas, np.einsum("kc,kcd->kd", bary, np.asarray(out.visual.uv)[tri]))
    inner = (np.abs(points[:, 0] - 20) > 1.5) & (np.abs(points[:, 1] - 15) > 1.5)
    expected = colours[(points[:, 1] < 15).astype(int), (points[:, 0] > 20).astype(int)]
    assert inner.sum() > 3000
    assert np.abs(sampled[inner] - expected[inner]).max() <= 1.0


def test_rebake_texture_refuses_a_picture_that_is_not_rgb():
    """A grey (h, w) picture was read as h rows of w-wide colours and built a 2^18 x 2^18
    atlas index (MemoryError); now refused at the door, naming ``image``."""
    from woodcam.bake import rebake_texture

    mesh = _box()
    uv = mesh.vertices[:, :2] / [40.0, 30.0]
    for bad in (np.zeros((64, 64), np.uint8), np.zeros((64, 64, 4), np.uint8), np.zeros((0, 8, 3))):
        with pytest.raises(WoodcamError, match=r"rebake_texture: image must be an \(h, w, 3\) RGB array; "
                           rf"got shape \({bad.shape[0]}, {bad.shape[1]}"):
            rebake_texture(mesh, uv[mesh.faces], bad, texels_per_mm=3.0)
