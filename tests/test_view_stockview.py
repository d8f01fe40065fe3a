"""The numba view of a height-field stock (woodcam.view.stockview): no VTK, same picture."""

from __future__ import annotations

import re

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.pipeline import bake_heightfield
from woodcam.toolpath.mesh import HeightfieldCharts
from woodcam.view.scene import BLOCK_COLOR, BLOCK_OPACITY
from woodcam.view.stockview import _camera_array, stock_view, write_stock_view
from woodcam.view.topview import top_view

W, D, H = 40.0, 30.0, 20.0
WIN = (320, 240)


class _CoordWood:
    """Colour = the point's block-frame position scaled to [0, 1]: pixels say what they show."""

    def color(self, points_mm, normals):
        return np.clip(np.asarray(points_mm) / np.array([W, D, H]), 0, 1)


def _pixel(points_mm, camera="iso"):
    """Picture pixel (row, col) of block-frame points, from the view's own camera."""
    cam = _camera_array(camera, np.array([W, D, H]), WIN, 1)
    q = np.atleast_2d(points_mm) - cam[:3]
    x, y, z = q @ cam[3:6], q @ cam[6:9], q @ cam[9:12]
    return (np.floor(cam[14] - cam[12] * y / z).astype(int),
            np.floor(cam[13] + cam[12] * x / z).astype(int))


@pytest.fixture(scope="module")
def bowl():
    """A stock with a spherical bowl (radius 12 mm, 8 mm deep) at (15, 15), baked by
    position."""
    ny, nx = 60, 80
    x = (np.arange(nx) + 0.5) * W / nx
    y = (np.arange(ny) + 0.5) * D / ny
    X, Y = np.meshgrid(x, y)
    r2 = (X - 15) ** 2 + (Y - 15) ** 2
    hm = np.where(r2 < 12 ** 2, np.maximum(H - 8, H + 4 - np.sqrt(np.maximum(0, 256 - r2))), H)
    hm = np.minimum(hm, H)
    b = bake_heightfield(hm, (W, D, H), _CoordWood(), texels_per_mm=4.0)
    charts = HeightfieldCharts(np.zeros((1, 1)), (W, D, H), b.texels_per_mm).charts
    return hm, b.atlas, charts


def test_each_face_shows_its_own_chart_at_its_own_place(bowl):
    """Top, walls and the bowl, iso camera, no cut: the colour at a projected point is the
    point's own texel, lit (the light scales all channels alike, the specular adds white)."""
    hm, atlas, charts = bowl
    img = stock_view(hm, (W, D, H), atlas, charts, window_size=WIN).astype(float)
    # top, front wall, right wall, top, and the bowl's far wall (z from the bowl's sphere)
    for p in ([32.0, 22.0, H], [30.0, 0.0, 8.0], [W, 20.0, 10.0], [36.0, 8.0, H],
              [15.0, 25.0, H + 4 - np.sqrt(256 - 100)]):
        r, c = _pixel(p)
        rgb = img[r[0], c[0]]
        want = 255 * np.array(p) / np.array([W, D, H])
        # rgb = light * texel + specular (white, the same in every channel): fit both
        (light, spec), *_ = np.linalg.lstsq(np.column_stack([want, np.ones(3)]), rgb, rcond=None)
        assert 0.5 < light < 1.3 and spec >= -3
        np.testing.assert_allclose(light * want + spec, rgb, atol=6)


def test_the_cut_plane_shows_the_wood_inside_unlit(bowl):
    """With a wood, the camera's half is cut away at X = W / 2: a point of the plane inside the
    stock shows the wood's own colour there (unlit), a point of the top beyond the plane is
    gone."""
    hm, atlas, charts = bowl
    img = stock_view(hm, (W, D, H), atlas, charts, wood=_CoordWood(),
                     window_size=WIN).astype(float)
    whole = stock_view(hm, (W, D, H), atlas, charts, window_size=WIN).astype(float)
    p = np.array([W / 2, 22.0, 6.0])
    r, c = _pixel(p)
    # seen through the block's translucent near face, as in the VTK picture
    tint = BLOCK_OPACITY * 255 * np.asarray(BLOCK_COLOR)
    np.testing.assert_allclose(img[r[0], c[0]],
                               (1 - BLOCK_OPACITY) * 255 * p / np.array([W, D, H]) + tint,
                               atol=3)
    r, c = _pixel([34.0, 25.0, H])  # on the removed half's top
    assert np.abs(img[r[0], c[0]] - whole[r[0], c[0]]).max() > 10


def test_toolpath_lines_over_the_stock_show_and_lines_on_it_hide(bowl):
    hm, atlas, charts = bowl
    flat = np.full_like(hm, H)
    plain = stock_view(flat, (W, D, H), atlas, charts, window_size=WIN, supersample=1)
    above = np.array([[[5.0, 15.0, H + 3], [35.0, 15.0, H + 3]]])
    on = np.array([[[5.0, 15.0, H], [35.0, 15.0, H]]])
    img = stock_view(flat, (W, D, H), atlas, charts, window_size=WIN, supersample=1,
                     overlay=[(above, "red", 1.0), (on, (0, 0, 255), 1.0)])
    r, c = _pixel([20.0, 15.0, H + 3])
    assert tuple(img[r[0], c[0]]) == (255, 0, 0)
    r, c = _pixel([20.0, 15.0, H])
    diff = np.abs(img.astype(int) - plain).max(axis=-1)
    assert diff[r[0] - 1:r[0] + 2, c[0] - 1:c[0] + 2].max() == 0  # hidden in the surface


def test_png_and_errors(tmp_path, bowl):
    hm, atlas, charts = bowl
    path = write_stock_view(tmp_path / "v.png", hm, (W, D, H), atlas, charts, window_size=WIN,
                            camera="front")
    from PIL import Image

    with Image.open(path) as im:
        assert im.size == WIN
    with pytest.raises(WoodcamError, match="heightmap must be"):
        stock_view(hm[0], (W, D, H), atlas, charts)
    with pytest.raises(WoodcamError, match="charts lacks"):
        stock_view(hm, (W, D, H), atlas, {"top": charts["top"]})
    for colour in ("mauve", (1000, 0, 0), ("a", "b", "c")):  # one rule with top_view's (colour_rgb)
        with pytest.raises(WoodcamError, match="stock_view: overlay colour must be a colour name .* in 0..255"
                                               ".* floats in 0..1"):
            stock_view(hm, (W, D, H), atlas, charts, window_size=WIN,
                       overlay=[(np.zeros((1, 2, 3)), colour, 1.0)])
    with pytest.raises(WoodcamError, match="supersample"):
        stock_view(hm, (W, D, H), atlas, charts, supersample=0)
    with pytest.raises(WoodcamError, match="camera must be"):
        stock_view(hm, (W, D, H), atlas, charts, camera="up")


def _preview_overlay_colour(tmp_path, colour):
    """The colour :func:`woodcam.view.preview` hands pyvista for an overlay of ``colour``: its
    overlay's add_mesh is caught (and the render stopped there)."""
    pv = pytest.importorskip("pyvista")
    import trimesh

    from woodcam.view import preview

    class Caught(Exception):
        pass

    seen = []
    add_mesh = pv.Plotter.add_mesh

    def catch(self, mesh, *args, **kwargs):
        if "render_lines_as_tubes" in kwargs:  # the overlay's lines
            seen.append(kwargs["color"])
            raise Caught
        return add_mesh(self, mesh, *args, **kwargs)

    box = trimesh.creation.box(extents=(W, D, H))
    box.apply_translation((W / 2, D / 2, H / 2))
    segments = np.array([[[5.0, 15.0, H + 3], [35.0, 15.0, H + 3]]])
    mp = pytest.MonkeyPatch()
    mp.setattr(pv.Plotter, "add_mesh", catch)
    try:
        with pytest.raises(Caught):
            preview(box, size_mm=(W, D, H), screenshot=tmp_path / "p.png", window_size=(64, 48),
                    cut_plane=False, overlay=[(segments, colour, 1.0)])
    finally:
        mp.undo()
    return pv.Color(seen[0]).int_rgb


@pytest.mark.parametrize("colour, rgb", [((1.0, 0.0, 0.0), (255, 0, 0)), ((0.25, 0.5, 1.0), (64, 128, 255)),
                                         ((65, 105, 225), (65, 105, 225))])
def test_an_overlay_triple_is_one_colour_in_every_view(bowl, tmp_path, colour, rgb):
    """preview handed (1.0, 0.0, 0.0) to pyvista, which reads floats in 0..1: red; top_view and
    stock_view read the same triple in 0..255: nearly black (top_view blended (1, 0, 0) into
    its texture, a grey (68, 68, 68) where "red" is (208, 68, 68)). One rule now
    (woodcam.view.scene.colour_rgb: whole numbers 0..255, floats 0..1) for all three: the
    stock view draws a line over the stock in exactly that RGB, the top view draws the same
    pixels as for that whole-number triple, and preview hands pyvista that RGB."""
    _one_colour_in_every_view(bowl, tmp_path, colour, rgb)


def _one_colour_in_every_view(bowl, tmp_path, colour, rgb):
    """stock_view draws ``colour`` as exactly ``rgb`` over the stock, top_view draws the same
    pixels as for the whole-number triple ``rgb``, and preview hands pyvista ``rgb``."""
    hm, atlas, charts = bowl
    flat = np.full_like(hm, H)
    above = np.array([[[5.0, 15.0, H + 3], [35.0, 15.0, H + 3]]])
    img = stock_view(flat, (W, D, H), atlas, charts, window_size=WIN, supersample=1,
                     overlay=[(above, colour, 1.0)])
    r, c = _pixel([20.0, 15.0, H + 3])
    assert tuple(img[r[0], c[0]]) == rgb
    tex = np.full((40, 50, 3), 150, np.uint8)
    seg = np.array([[[0.0, 20.0, 1.0], [50.0, 20.0, 1.0]]])
    top = [top_view(np.zeros((40, 50)), (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0,
                    overlay=[(seg, col, 1.0)]) for col in (colour, rgb)]
    assert tuple(top[1][40, 50]) != (150, 150, 150)  # the line is drawn there
    np.testing.assert_array_equal(top[0], top[1])
    assert _preview_overlay_colour(tmp_path, colour) == rgb


@pytest.mark.parametrize("colour, rgb", [("orange", (255, 165, 0)), ("tab:blue", (31, 119, 180)),
                                         ("xkcd:sky blue", (117, 187, 253)), ("#ff8000", (255, 128, 0)),
                                         ("RoyalBlue", (65, 105, 225)), ("red", (255, 0, 0))])
def test_a_colour_name_is_one_colour_in_every_view(bowl, tmp_path, colour, rgb):
    """top_view and stock_view knew two names, "red" and "royalblue", and refused "orange",
    "tab:blue" or "#ff8000", which preview drew by pyvista's table. One name table now,
    matplotlib's (woodcam.view.scene.colour_rgb), for all three views: the same RGB."""
    _one_colour_in_every_view(bowl, tmp_path, colour, rgb)


def test_the_cli_overlay_colours_are_the_name_tables():
    """OVERLAY_COLORS resolves the CLI's two names without importing matplotlib: its values
    are the table's."""
    import matplotlib.colors

    from woodcam.view.scene import OVERLAY_COLORS

    for name, rgb in OVERLAY_COLORS.items():
        assert tuple(round(255 * v) for v in matplotlib.colors.to_rgb(name)) == rgb


def _every_view_refuses(bowl, tmp_path, colour, said):
    """preview, top_view and stock_view each refuse an overlay of ``colour`` with a WoodcamError
    naming the view and the argument, then ``said`` (a regex); no picture is written."""
    import trimesh

    from woodcam.view import preview
    from woodcam.view.topview import top_view

    hm, atlas, charts = bowl
    seg = np.zeros((1, 2, 3))
    with pytest.raises(WoodcamError, match=r"preview: overlay\[0\] " + said):
        preview(trimesh.creation.box(), screenshot=tmp_path / "p.png", window_size=(64, 48),
                overlay=[(seg, colour, 1.0)])
    with pytest.raises(WoodcamError, match="top_view: overlay " + said):
        top_view(hm, (W, D, H), atlas, window_size=(100, 80), overlay=[(seg, colour, 1.0)])
    with pytest.raises(WoodcamError, match="stock_view: overlay " + said):
        stock_view(hm, (W, D, H), atlas, charts, window_size=(64, 48), overlay=[(seg, colour, 1.0)])
    assert not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("colour, fix", [("royal_blue", "did you mean 'royalblue'"),
                                         ("banana", "did you mean 'xkcd:banana'"),
                                         ("nope", r"give a CSS4 name, e.g. 'royalblue'"),
                                         ("C0", "style cycle"), ("none", "opaque"),
                                         ("#ff000080", "opaque"), ("", "give a CSS4 name")])
def test_a_colour_name_not_in_the_table_is_refused_by_every_view(bowl, tmp_path, colour, fix):
    """preview took pyvista's own names and spellings ('banana', 'royal_blue') and an alpha
    ('#ff000080'), which the numpy views refused with the two names they knew. Every view
    refuses a name outside matplotlib's table, the style cycle and a transparent colour alike,
    naming itself, the argument, the value and a fix (the close matches)."""
    pytest.importorskip("pyvista")
    _every_view_refuses(bowl, tmp_path, colour,
                        f"colour must be a colour name matplotlib knows .*; got {re.escape(repr(colour))}; .*{fix}")


@pytest.mark.parametrize("colour", [(255.0, 0, 0), (1, 0, 0), (1000, 0, 0), (-0.5, 0.0, 0.0),
                                    (0.5, float("nan"), 0.2), ("1", "0", "0"), (255, 0),
                                    (1.0, 0.0, 0.0, 1.0), True, np.array([1.5, 0.0, 0.0])])
def test_an_overlay_triple_refused_is_refused_by_every_view(bowl, tmp_path, colour):
    """A triple whose scale is a guess ((255.0, 0, 0): a float above 1; (1, 0, 0): whole
    numbers reading nearly black that meant red in 0..1), out of range, not three numbers:
    refused by preview, top_view and stock_view alike, each naming itself, the argument, the
    rule and the value (preview drew (1.0, 0, 0, 1.0) and top_view (255.0, 0, 0) as red,
    stock_view took ('1', '0', '0') as near black)."""
    pytest.importorskip("pyvista")
    _every_view_refuses(bowl, tmp_path, colour, r"colour must be a colour name matplotlib knows .* or an "
                        r"RGB triple: whole numbers in 0\.\.255, .*floats in 0\.\.1.*; got ")


def test_a_colour_of_none_is_refused_by_every_view(bowl, tmp_path):
    """colour=None meant two things: preview handed it to pyvista, which drew its theme's colour
    (light blue (173, 216, 230) by default, changed by any pyvista.global_theme.color), while
    top_view and stock_view refused it, as every view refuses a background of None. One
    meaning now: None is no colour, refused by every view for an overlay and a background."""
    pytest.importorskip("pyvista")
    import trimesh

    from woodcam.view import preview

    _every_view_refuses(bowl, tmp_path, None,
                        r"colour must be a colour name matplotlib knows .*; got None; None is no colour .*'royalblue'")
    hm, atlas, charts = bowl
    for view_of in (lambda: preview(trimesh.creation.box(), screenshot=tmp_path / "p.png", window_size=(64, 48),
                                    background=None),
                    lambda: stock_view(hm, (W, D, H), atlas, charts, window_size=(64, 48), background=None)):
        with pytest.raises(WoodcamError, match="background must be .*; got None; None is no colour"):
            view_of()
    assert not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("background, rgb", [((1.0, 0.5, 0.0), (255, 128, 0)), ((30, 60, 90), (30, 60, 90)),
                                             ("white", (255, 255, 255)), ("tab:green", (44, 160, 44))])
def test_a_background_is_one_colour_in_every_view(bowl, tmp_path, background, rgb):
    """stock_view read its background in 0..255 whatever it was: (1.0, 0.5, 0.0) drew (1, 0, 0),
    nearly black, and "white" was numpy's bare ValueError, where preview (pyvista) drew orange
    and white. Both read a background by the overlays' one rule (colour_rgb) now: the corner
    pixel is that RGB in stock_view and in preview's screenshot; and in top_view, which took no
    background (always white)."""
    pytest.importorskip("pyvista")
    import trimesh
    from PIL import Image

    from woodcam.view import preview

    hm, atlas, charts = bowl
    img = stock_view(hm, (W, D, H), atlas, charts, window_size=(64, 48), supersample=1,
                     background=background)
    assert tuple(img[0, 0]) == rgb
    top = top_view(hm, (W, D, H), _top_texels(atlas, charts), window_size=(64, 48), margin_px=8,
                   background=background)
    assert tuple(top[0, 0]) == rgb and tuple(top[-1, -1]) == rgb
    box = trimesh.creation.box(extents=(W, D, H))
    box.apply_translation((W / 2, D / 2, H / 2))
    png = preview(box, size_mm=(W, D, H), screenshot=tmp_path / "p.png", window_size=(64, 48),
                  cut_plane=False, background=background)
    with Image.open(png) as im:
        corner = np.asarray(im.convert("RGB"))[0, 0].astype(int)
    assert np.abs(corner - rgb).max() <= 1, corner


@pytest.mark.parametrize("background, fix", [((1, 0, 0), "ambiguous"), ((255.0, 0.0, 0.0), "whole numbers"),
                                             ((0.0, 0.0, 0.0, 1.0), "three numbers"),
                                             ("nope", "give a CSS4 name"),
                                             ("royal_blue", "did you mean 'royalblue'")])
def test_a_background_refused_is_refused_by_every_view(bowl, tmp_path, background, fix):
    """preview read a whole (1, 0, 0) background as pyvista does, in 0..255: nearly black, where
    the same triple as an overlay colour is refused as ambiguous; stock_view drew (255.0, 0, 0)
    red and (0, 0, 0, 1) was numpy's broadcast error. The one rule refuses them in both (and in
    SceneOptions), naming the view, the argument, the value and a fix."""
    pytest.importorskip("pyvista")
    import trimesh

    from woodcam.view import SceneOptions, preview

    hm, atlas, charts = bowl
    said = f"background must be a colour name matplotlib knows .*; got {re.escape(repr(background))}; .*{fix}"
    with pytest.raises(WoodcamError, match="preview: " + said):
        preview(trimesh.creation.box(), screenshot=tmp_path / "p.png", window_size=(64, 48),
                background=background)
    with pytest.raises(WoodcamError, match="preview: " + said):
        SceneOptions(background=background)
    with pytest.raises(WoodcamError, match="stock_view: " + said):
        stock_view(hm, (W, D, H), atlas, charts, window_size=(64, 48), background=background)
    with pytest.raises(WoodcamError, match="top_view: " + said):
        top_view(hm, (W, D, H), _top_texels(atlas, charts), window_size=(64, 48), margin_px=8, background=background)
    assert not (tmp_path / "p.png").exists()


def _top_texels(atlas, charts):
    """The atlas's top chart, as top_view takes it."""
    x0, y0, w, h = (int(v) for v in charts["top"][:4])
    return atlas[y0:y0 + h, x0:x0 + w]


def test_it_frames_the_stock_as_the_vtk_screenshot_does(bowl, tmp_path):
    """The same stock drawn by VTK (:func:`woodcam.view.preview` of the baked mesh, cut plane)
    and here: the silhouettes (non-white pixels) agree and the colours are close."""
    pytest.importorskip("pyvista")
    from PIL import Image

    from woodcam.view import preview

    import pyvista as pv

    hm, atlas, charts = bowl
    b = bake_heightfield(hm, (W, D, H), _CoordWood(), texels_per_mm=4.0)
    png = tmp_path / "vtk.png"
    # skip only where VTK itself cannot draw off screen (no EGL/OSMesa): a failure of preview
    # is a failure (any exception of preview was a skip)
    from woodcam.view.scene import _prefer_egl_off_screen

    _prefer_egl_off_screen()  # as preview does before its plotter
    try:
        probe = pv.Plotter(off_screen=True, window_size=(32, 32))
        probe.add_mesh(pv.Cube())
        probe.screenshot(return_img=True)
        probe.close()
    except Exception as err:
        pytest.skip(f"VTK cannot render off screen here: {err}")
    preview(b.mesh, wood=_CoordWood(), size_mm=(W, D, H), screenshot=png, window_size=WIN)
    vtk = np.asarray(Image.open(png).convert("RGB")).astype(int)
    ours = stock_view(hm, (W, D, H), atlas, charts, wood=_CoordWood(),
                      window_size=WIN).astype(int)
    a, b_ = vtk.min(axis=-1) < 245, ours.min(axis=-1) < 245
    assert (a & b_).sum() / (a | b_).sum() > 0.95
    both = a & b_
    assert np.median(np.abs(vtk[both] - ours[both]).max(axis=-1)) < 25


def test_preview_heightfield_draws_its_screenshot_without_vtk(tmp_path, bowl, monkeypatch):
    """``preview_heightfield(screenshot=True)`` writes NAME_view.png from the atlas it baked
    (pyvista is never asked for) and keeps the atlas and its charts on the result."""
    import sys

    from PIL import Image

    from woodcam.pipeline import preview_heightfield
    from woodcam.stock import open_stock

    hm, _, _ = bowl
    monkeypatch.setitem(sys.modules, "pyvista", None)  # an import of it would fail
    stock = open_stock("builtin:flat-sawn")
    stock_hm = hm - H + stock.size_mm[2]  # the bowl on the block's top
    res = preview_heightfield(stock_hm, stock, tmp_path / "s.glb", texels_per_mm=2.0, obj=False,
                              screenshot=True)
    assert res.files["png"] == tmp_path / "s_view.png"
    with Image.open(res.files["png"]) as im:
        assert im.size == (1280, 960)
        img = np.asarray(im.convert("RGB"))
    assert (img.min(axis=-1) < 200).mean() > 0.1  # the stock is drawn, not a white picture
    top = res.chart_texels("top")
    assert top.shape[:2] == (int(np.ceil(stock.size_mm[1] * 2)), int(np.ceil(stock.size_mm[0] * 2)))


def _bake(hm):
    b = bake_heightfield(hm, (W, D, H), _CoordWood(), texels_per_mm=4.0)
    return hm, b.atlas, HeightfieldCharts(np.zeros((1, 1)), (W, D, H), b.texels_per_mm).charts


def _assert_lit(rgb, p):
    """``rgb`` is the texel of block point ``p`` (colour = p / size) under the lights: light *
    texel + a white specular, as in test_each_face_shows_its_own_chart_at_its_own_place."""
    want = 255 * np.asarray(p, float) / np.array([W, D, H])
    (light, spec), *_ = np.linalg.lstsq(np.column_stack([want, np.ones(3)]), rgb, rcond=None)
    assert 0.5 < light < 1.3 and spec >= -3, (rgb, want)
    np.testing.assert_allclose(light * want + spec, rgb, atol=8, err_msg=f"{rgb} is not {want}")


def test_each_named_camera_looks_at_its_face_the_right_way_up():
    """A flat stock from each named camera: the picture's centre shows that face (the channel
    of its axis at 0 or full), and the picture's right and up run along the block axes a person
    facing that face sees (conventions.md; 'top' has +Y up, 'bottom' -Y up)."""
    hm, atlas, charts = _bake(np.full((60, 80), H))
    # camera: (channel, its value at the face: 0 or 1, channel rising to the right and its
    # sign, channel rising upward and its sign)
    faces = {"front": (1, 0, 0, 1, 2, 1), "back": (1, 1, 0, -1, 2, 1), "left": (0, 0, 1, -1, 2, 1),
             "right": (0, 1, 1, 1, 2, 1), "top": (2, 1, 0, 1, 1, 1), "bottom": (2, 0, 0, 1, 1, -1)}
    for camera, (ch, value, ch_right, s_right, ch_up, s_up) in faces.items():
        img = stock_view(hm, (W, D, H), atlas, charts, camera=camera, window_size=WIN).astype(int)
        r, c = WIN[1] // 2, WIN[0] // 2
        centre = img[r, c]
        assert (centre[ch] < 20) if value == 0 else (centre[ch] > 120), (camera, centre)
        assert s_right * (img[r, c + 40, ch_right] - img[r, c - 40, ch_right]) > 20, camera
        assert s_up * (img[r - 25, c, ch_up] - img[r + 25, c, ch_up]) > 20, camera


def test_each_wall_follows_its_own_border_of_the_heightmap():
    """Slots open through the front wall (x 10-20, y 0-15) and the right wall (y 10-20,
    x 25-40), 10 mm deep: each wall stops at its own border's height, so its camera looks into
    the slot there (at the slot's far end) and sees the wall elsewhere."""
    ny, nx = 60, 80
    X, Y = np.meshgrid((np.arange(nx) + 0.5) * W / nx, (np.arange(ny) + 0.5) * D / ny)
    hm = np.full((ny, nx), H)
    hm[(X > 10) & (X < 20) & (Y < 15)] = H - 10
    hm[(Y > 10) & (Y < 20) & (X > 25)] = H - 10
    hm, atlas, charts = _bake(hm)
    z = H - 5
    for camera, wall, seen in (("front", [15.0, 0.0, z], [15.0, 15.0, z]),   # into the slot
                               ("front", [30.0, 0.0, z], None),
                               ("back", [15.0, D, z], None),
                               ("left", [0.0, 15.0, z], None),
                               ("right", [W, 15.0, z], [25.0, 15.0, z]),      # into the slot
                               ("right", [W, 25.0, z], None)):
        img = stock_view(hm, (W, D, H), atlas, charts, camera=camera, window_size=WIN).astype(float)
        r, c = _pixel(wall, camera)
        _assert_lit(img[r[0], c[0]], wall if seen is None else seen)


def test_the_cut_follows_the_camera_and_the_background_is_used(bowl):
    """From the right the cut plane is X = W / 2 (the right camera's own axis): the wood at
    mid-width shows through the block's translucent right face; around the block the given
    background. From the top (and bottom) no cut, as preview's: the outside, the same picture
    as without a wood (it showed a horizontal cut at mid-height, the stock's top surface, which
    the user asked to see, cut away; woodcam.view.camera.UNCUT_CAMERAS)."""
    hm, atlas, charts = bowl
    img = stock_view(hm, (W, D, H), atlas, charts, wood=_CoordWood(), camera="right",
                     window_size=WIN, background=(0, 0, 0)).astype(float)
    assert (img[0, 0] == 0).all() and (img[-1, -1] == 0).all()
    p = np.array([W / 2, 25.0, H / 2])
    r, c = _pixel(p, "right")
    tint = BLOCK_OPACITY * 255 * np.asarray(BLOCK_COLOR)
    np.testing.assert_allclose(img[r[0], c[0]], (1 - BLOCK_OPACITY) * 255 * p / np.array([W, D, H]) + tint,
                               atol=3)
    top = stock_view(hm, (W, D, H), atlas, charts, wood=_CoordWood(), camera="top", window_size=WIN)
    np.testing.assert_array_equal(top, stock_view(hm, (W, D, H), atlas, charts, camera="top",
                                                  window_size=WIN))
