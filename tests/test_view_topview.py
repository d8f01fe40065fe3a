"""The numpy top view of a height-field stock (woodcam.view.topview): no VTK."""

from __future__ import annotations

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.view.topview import top_view, write_top_view


def test_a_flat_stock_shows_its_texture_unshaded_inside_a_white_margin():
    """Seen from +Z: +X right, +Y up. Each quadrant of the chart (row 0 at Y = D, column 0 at
    X = 0) lands in its own quadrant of the picture, so a flip of either axis is caught."""
    tex = np.zeros((40, 60, 3), np.uint8)
    tex[:20, :30] = (200, 100, 50)   # back left (row 0 is Y = D, column 0 is X = 0)
    tex[:20, 30:] = (200, 50, 100)   # back right
    tex[20:, :30] = (50, 100, 200)   # front left
    tex[20:, 30:] = (100, 200, 50)   # front right
    img = top_view(np.full((8, 12), 5.0), (60.0, 40.0, 10.0), tex, window_size=(160, 120),
                   margin_px=20)
    assert img.shape == (120, 160, 3)
    # 60 x 40 mm fitted in 120 x 80 px: 2 px/mm, centred
    assert (img[:20] == 255).all() and (img[:, :20] == 255).all()
    assert (img[100:] == 255).all() and (img[:, 140:] == 255).all()
    np.testing.assert_array_equal(img[30, 40], (200, 100, 50))  # back: upper half, left: left
    np.testing.assert_array_equal(img[30, 120], (200, 50, 100))
    np.testing.assert_array_equal(img[90, 40], (50, 100, 200))
    np.testing.assert_array_equal(img[90, 120], (100, 200, 50))


def test_slopes_facing_the_light_are_brighter_and_segments_are_drawn():
    hm = np.tile(np.linspace(0, 10, 50), (40, 1))  # rises to +X: faces -X, the light
    tex = np.full((40, 50, 3), 150, np.uint8)
    img = top_view(hm, (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0).astype(int)
    flat = top_view(np.zeros((40, 50)), (50.0, 40.0, 10.0), tex, window_size=(100, 80),
                    margin_px=0).astype(int)
    assert img[40, 50, 0] > flat[40, 50, 0] == 150
    down = top_view(hm[:, ::-1], (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0)
    assert down[40, 50, 0] < 150  # the falling slope faces away from the light
    # Along Y (heightmap row 0 at Y = 0): rising to +Y faces -Y, away from the light above the
    # back; rising to -Y faces it.
    rise_y = np.tile(np.linspace(0, 10, 40)[:, None], (1, 50))
    back = top_view(rise_y, (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0)
    front = top_view(rise_y[::-1], (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0)
    assert back[40, 50, 0] < 150 < front[40, 50, 0]
    # The shading sits where its slope is: a ramp over the front-left quadrant only (rows
    # 0..19 are Y < 20 mm, columns 0..24 X < 25 mm) lights the picture's lower left alone.
    ramp = np.zeros((40, 50))
    ramp[:20, :25] = np.linspace(0, 5, 25)
    lit = top_view(ramp, (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0).astype(int)
    assert lit[70, 20, 0] > 150                                  # X 10 mm, Y 5 mm
    assert lit[10, 20, 0] == lit[10, 80, 0] == lit[70, 80, 0] == 150  # the three flat quadrants
    seg = np.array([[[0.0, 20.0, 1.0], [50.0, 20.0, 1.0]]])  # Y = 20 mm: the middle row
    lined = top_view(np.zeros((40, 50)), (50.0, 40.0, 10.0), tex, window_size=(100, 80),
                     margin_px=0, overlay=[(seg, "red", 1.0)])
    assert (lined[40, 5:95, 0] > lined[40, 5:95, 2] + 50).all()  # red across the middle row
    np.testing.assert_array_equal(lined[10], flat[10])


def test_top_view_png_and_errors(tmp_path):
    tex = np.full((4, 4, 3), 90, np.uint8)
    path = write_top_view(tmp_path / "t.png", np.zeros((4, 4)), (4.0, 4.0, 1.0), tex,
                          window_size=(64, 64))
    from PIL import Image

    with Image.open(path) as im:
        assert im.size == (64, 64)
    with pytest.raises(WoodcamError, match="heightmap must be"):
        top_view(np.zeros(4), (4.0, 4.0, 1.0), tex)
    with pytest.raises(WoodcamError, match="overlay colour"):
        top_view(np.zeros((4, 4)), (4.0, 4.0, 1.0), tex,
                 overlay=[(np.zeros((1, 2, 3)), "mauve", 1.0)])


def test_the_margin_is_the_background_by_the_views_one_rule():
    """top_view had no background (always white) where stock_view and preview take one: the
    margin is now ``background`` read by colour_rgb (floats in 0..1, a name), white by default;
    the stock inside is unchanged (test_view_stockview's one-colour test: the same RGB as
    stock_view's)."""
    tex = np.full((40, 60, 3), 90, np.uint8)
    args = (np.full((8, 12), 5.0), (60.0, 40.0, 10.0), tex)
    white = top_view(*args, window_size=(160, 120), margin_px=20)
    for background, rgb in (((1.0, 0.5, 0.0), (255, 128, 0)), ("tab:green", (44, 160, 44))):
        img = top_view(*args, window_size=(160, 120), margin_px=20, background=background)
        assert (img[:20] == rgb).all() and (img[:, 140:] == rgb).all()
        np.testing.assert_array_equal(img[20:100, 20:140], white[20:100, 20:140])
    assert (white[:20] == 255).all()
    with pytest.raises(WoodcamError, match="top_view: background must be .*; got None"):
        top_view(*args, background=None)


def test_the_toolpath_reds_and_blues_are_the_stock_views_and_the_vtk_previews():
    """One set of overlay colours (woodcam.view.scene.OVERLAY_COLORS, VTK's values of the
    names): a sparse line is blended over the texture at the overlay opacity."""
    from woodcam.view.topview import _OVERLAY_ALPHA

    tex = np.full((40, 50, 3), 150, np.uint8)
    seg = np.array([[[0.0, 20.0, 1.0], [50.0, 20.0, 1.0]]])
    for name, rgb in (("red", (255, 0, 0)), ("royalblue", (65, 105, 225))):
        img = top_view(np.zeros((40, 50)), (50.0, 40.0, 10.0), tex, window_size=(100, 80),
                       margin_px=0, overlay=[(seg, name, 1.0)])
        want = np.round((1 - _OVERLAY_ALPHA) * np.float32(150)
                        + _OVERLAY_ALPHA * np.asarray(rgb, np.float32))
        np.testing.assert_allclose(img[40, 50], want, atol=1)


@pytest.mark.parametrize("colour", [(1000, 0, 0), (-100, 0, 0), ("a", "b", "c"), (255, 0), True,
                                    (255.0, 0, 0), (1, 0, 0)])
def test_an_overlay_colour_that_is_no_rgb_0_255_is_refused_by_both_numpy_views(colour):
    """top_view and stock_view each had their own copy of the overlay colour rule, which took
    any finite triple: top_view blended (1000, 0, 0) into a pixel its uint8 cast wrapped to
    (106, 68, 68), (-100, 0, 0) into a darker grey, and ('a', 'b', 'c') was numpy's bare
    ValueError. One rule now (woodcam.view.scene.colour_rgb) refuses them in both, naming
    the view; the names and 0..255 triples draw the same pixels as before. A float triple is
    0..1 (pyvista's rule, as preview draws it): (255.0, 0, 0) and the ambiguous whole (1, 0, 0)
    are refused."""
    tex = np.full((40, 50, 3), 150, np.uint8)
    seg = np.array([[[0.0, 20.0, 1.0], [50.0, 20.0, 1.0]]])
    said = (r"overlay colour must be a colour name matplotlib knows .* or an RGB triple: whole numbers in "
            r"0\.\.255, .* or floats in 0\.\.1, .*; got ")
    with pytest.raises(WoodcamError, match="top_view: " + said):
        top_view(np.zeros((40, 50)), (50.0, 40.0, 10.0), tex, window_size=(100, 80), margin_px=0,
                 overlay=[(seg, colour, 1.0)])
    from woodcam.view.scene import colour_rgb

    with pytest.raises(WoodcamError, match="stock_view: " + said):
        colour_rgb(colour, "stock_view")
    np.testing.assert_array_equal(colour_rgb("royalblue", "top_view"), [65, 105, 225])
    np.testing.assert_array_equal(colour_rgb((0, 255, 7), "top_view"), [0, 255, 7])
    np.testing.assert_array_equal(colour_rgb(np.array([0, 255, 7], np.uint8), "top_view"), [0, 255, 7])
    np.testing.assert_array_equal(colour_rgb((0.0, 1.0, 0.5), "top_view"), [0, 255, 127.5])
    np.testing.assert_array_equal(colour_rgb((0, 1.0, 0), "top_view"), [0, 255, 0])  # a float: 0..1


def test_shading_and_overlay_on_cells_that_are_not_square_and_a_stock_off_centre():
    """Cells 1 mm along X and 2 mm along Y (a 50 x 40 mm stock on a 20 x 50 heightmap): a ramp
    of slope 0.2 along X, then along Y, is shaded by Lambert's law with its own normal
    (-0.2, 0, 1) or (0, -0.2, 1), relative to a flat top; the stock sits off the picture's
    corner (50 px margin left and right), and a segment lands on its own pixels there."""
    from woodcam.view.topview import _AMBIENT, _LIGHT

    def shade(normal):
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        return (_AMBIENT + (1 - _AMBIENT) * max(n @ _LIGHT, 0)) / (_AMBIENT + (1 - _AMBIENT) * _LIGHT[2])

    tex = np.full((40, 50, 3), 150, np.uint8)
    x = (np.arange(50) + 0.5) * 1.0
    y = (np.arange(20) + 0.5) * 2.0
    size = (50.0, 40.0, 20.0)
    for hm, normal in ((np.tile(0.2 * x, (20, 1)), (-0.2, 0, 1)),
                       (np.tile(0.2 * y[:, None], (1, 50)), (0, -0.2, 1))):
        img = top_view(hm, size, tex, window_size=(200, 80), margin_px=0).astype(int)
        # 2 px/mm: the stock covers columns 50-149, all rows; white beside it
        assert (img[:, :50] == 255).all() and (img[:, 150:] == 255).all()
        assert abs(img[40, 100, 0] - 150 * shade(normal)) <= 1, (normal, img[40, 100])
    seg = np.array([[[0.0, 20.0, 1.0], [50.0, 20.0, 1.0]]])  # Y = 20 mm across the stock
    lined = top_view(np.zeros((20, 50)), size, tex, window_size=(200, 80), margin_px=0,
                     overlay=[(seg, "red", 1.0)]).astype(int)
    assert (lined[40, 55:145, 0] > lined[40, 55:145, 2] + 50).all()
    assert (lined[:, :48] == 255).all() and (lined[:, 152:] == 255).all()
