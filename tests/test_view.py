"""Tests of woodcam.view: off-screen screenshots, texture orientation, the wood cut plane.

Pictures are rendered off-screen at small sizes (no display needed) and judged by counting
pixels of known colours; the cut plane is checked against an analytic wood whose colour is its
position divided by the block size, and against closed-form section areas.
"""

from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")
trimesh = pytest.importorskip("trimesh")
from PIL import Image  # noqa: E402

from woodcam.errors import WoodcamError  # noqa: E402
from woodcam.tolerances import ON_FACE_TOL_MM  # noqa: E402
from woodcam import view  # noqa: E402
import woodcam.view.camera  # noqa: E402,F401
import woodcam.view.scene  # noqa: E402,F401
from woodcam.view import (  # noqa: E402
    OUTLINE_ACTOR, PART_ACTOR, SECTION_ACTOR, WASTE_ACTOR, CutPlaneCallback, block_outline,
    build_scene, cut_plane_image, mesh_to_pyvista, preview,
)

SIZE = (100.0, 80.0, 40.0)
SMALL = (320, 240)
RED = (220, 30, 30)
BLUE = (30, 60, 220)

#: One 8-bit step of colour quantisation (the section stores round(255 * rgb) as uint8).
RGB_ATOL = 0.5 / 255 + 1e-9


class PositionWood:
    """Colour = position / block size, so every point's colour is known in closed form."""

    def __init__(self, size=SIZE):
        self.size = np.asarray(size, dtype=float)
        self.normals = []

    def color(self, points_mm, normals):
        self.normals.append(np.array(normals))
        return np.clip(np.asarray(points_mm) / self.size, 0.0, 1.0)


class GreenWood:
    def color(self, points_mm, normals):
        return np.tile([0.0, 1.0, 0.0], (len(points_mm), 1))


def _checker(n_cells=8, px=64, colours=(RED, BLUE)):
    cell = px // n_cells
    odd = ((np.arange(px)[:, None] // cell + np.arange(px)[None, :] // cell) % 2).astype(bool)
    img = np.empty((px, px, 3), np.uint8)
    img[odd], img[~odd] = colours
    return Image.fromarray(img)


def _textured_box(extents=(60.0, 40.0, 20.0), center=(50.0, 40.0, 20.0), image=None):
    """A box with one uv chart per face (planar uv over the face) and a texture image."""
    box = trimesh.creation.box(extents=extents)
    box.apply_translation(center)
    box.unmerge_vertices()
    v, fn = box.vertices, box.face_normals
    uv = np.zeros((len(v), 2))
    lo, hi = box.bounds
    for k in range(3):
        on = np.abs(fn[:, k]) > 0.5
        ax = [i for i in range(3) if i != k]
        ids = box.faces[on].ravel()
        uv[ids] = (v[ids][:, ax] - lo[ax]) / (hi[ax] - lo[ax])
    visual = trimesh.visual.TextureVisuals(uv=uv, image=image or _checker())
    return trimesh.Trimesh(box.vertices, box.faces, visual=visual, process=False)


def _read(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB")).astype(int)


def _red(img):
    return (img[..., 0] > img[..., 1] + 60) & (img[..., 0] > img[..., 2] + 60)


def _blue(img):
    return (img[..., 2] > img[..., 0] + 60) & (img[..., 2] > img[..., 1] + 40)


def _green(img):
    return (img[..., 1] > img[..., 0] + 80) & (img[..., 1] > img[..., 2] + 80)


def _light_green(img):
    """Translucent green over a light background."""
    return ((img[..., 1] > img[..., 0] + 30) & (img[..., 1] > img[..., 2] + 30)
            & (img[..., 0] > 100))


# ---------------------------------------------------------------------------- screenshots


def test_screenshot_is_written_non_blank_and_differs_from_background(tmp_path):
    out = preview(_textured_box(), size_mm=SIZE, screenshot=tmp_path / "sub" / "part.png",
                  window_size=SMALL)
    assert out == tmp_path / "sub" / "part.png" and out.is_file()
    img = _read(out)
    assert img.shape == (SMALL[1], SMALL[0], 3)
    differs = np.any(img != 255, axis=-1).mean()   # background "white"
    # The framed block fills most of the picture, the part about a fifth of it.
    assert 0.2 < differs < 0.99, differs


def test_background_colour_is_used(tmp_path):
    out = preview(_textured_box(), size_mm=SIZE, screenshot=tmp_path / "p.png",
                  window_size=SMALL, background="black")
    img = _read(out)
    assert np.all(img[0, 0] == 0) and np.all(img[-1, -1] == 0)
    assert np.any(img != 0, axis=-1).mean() > 0.2


@pytest.fixture
def users_theme():
    """``pyvista.global_theme`` changed as a user's script may (dark background, red default
    colour, no lighting, edges, half opacity, transparent screenshots); restored afterwards."""
    import copy

    kept = copy.deepcopy(pv.global_theme)
    try:
        for attr, value in (("background", "black"), ("color", "red"), ("lighting", False),
                            ("show_edges", True), ("edge_color", "blue"), ("opacity", 0.5),
                            ("transparent_background", True)):
            setattr(pv.global_theme, attr, value)
        yield pv.global_theme
    finally:
        pv.global_theme.load_theme(kept)


def _read_as_written(path) -> np.ndarray:
    """The PNG's pixels as written: RGB (an RGBA one, a transparent background, is refused)."""
    img = Image.open(path)
    assert img.mode == "RGB", img.mode
    return np.asarray(img).astype(int)


def test_a_users_pyvista_theme_does_not_change_the_pictures(tmp_path, request):
    """The views draw woodcam's colours, background and shading whatever ``pyvista.global_theme``
    a user's script set: its lighting, edges, opacity and transparent background reached
    preview's picture (an RGBA PNG, a flat see-through part with blue edges) and its background
    the placement pictures' (black)."""
    from woodcam.view.compare import render_side_by_side
    from woodcam.view.scene import UNTEXTURED_PART_COLOR

    plain = _textured_box()
    plain.visual = trimesh.visual.ColorVisuals(plain)
    box = trimesh.creation.box((60.0, 40.0, 20.0))
    box.apply_translation((50.0, 40.0, 20.0))

    def pictures(tag):
        return (_read_as_written(preview(plain, size_mm=SIZE, screenshot=tmp_path / f"{tag}.png", window_size=SMALL)),
                _read_as_written(render_side_by_side([box], [GreenWood()], SIZE, ["a"], tmp_path / f"{tag}_s.png",
                                                     progress=False)))

    ours, ours_side = pictures("ours")
    request.getfixturevalue("users_theme")
    theirs, theirs_side = pictures("theirs")
    # the corner is the scene's background (white), the middle the untextured part, shaded
    assert np.all(theirs[0, 0] == 255) and np.all(theirs[-1, -1] == 255), theirs[0, 0]
    mid = theirs[SMALL[1] // 2, SMALL[0] // 2]
    part = np.asarray(UNTEXTURED_PART_COLOR) * 255
    assert np.allclose(mid / mid.max(), part / part.max(), atol=0.05), mid
    assert np.abs(theirs - ours).max() <= 2
    assert np.all(theirs_side[0, 0] == ours_side[0, 0]) and np.abs(theirs_side - ours_side).max() <= 2
    assert pv.global_theme.background.name == "black"  # the user's theme is left as it was


def test_checker_texture_shows_red_and_blue(tmp_path):
    img = _read(preview(_textured_box(), size_mm=SIZE, screenshot=tmp_path / "p.png",
                        window_size=SMALL))
    red, blue = _red(img).mean(), _blue(img).mean()
    assert red > 0.03 and blue > 0.03, (red, blue)
    # Untextured, the same box is wood-coloured: no red and no blue.
    plain = _textured_box()
    plain.visual = trimesh.visual.ColorVisuals(plain)
    img = _read(preview(plain, size_mm=SIZE, screenshot=tmp_path / "q.png", window_size=SMALL))
    assert _red(img).mean() < 0.002 and _blue(img).mean() < 0.002


def test_texture_orientation_v1_is_image_top_row(tmp_path):
    """A flat part with uv = (x/W, y/D): image top half red must land on the back (y > D/2).

    Seen from the top (``+Y`` up in the picture), the back is the upper half of the picture.
    """
    w, d = SIZE[0], SIZE[1]
    pts = np.array([[0, 0, 1], [w, 0, 1], [w, d, 1], [0, d, 1]], float)
    img = np.empty((64, 64, 3), np.uint8)
    img[:32], img[32:] = RED, BLUE                  # row 0 is the image's top
    mesh = trimesh.Trimesh(pts, [[0, 1, 2], [0, 2, 3]], process=False,
                           visual=trimesh.visual.TextureVisuals(
                               uv=pts[:, :2] / [w, d], image=Image.fromarray(img)))
    pic = _read(preview(mesh, size_mm=SIZE, screenshot=tmp_path / "p.png", window_size=SMALL,
                        camera="top"))
    rows = np.arange(pic.shape[0])[:, None] * np.ones(pic.shape[1])
    red_rows, blue_rows = rows[_red(pic)], rows[_blue(pic)]
    assert red_rows.size > 1000 and blue_rows.size > 1000
    assert red_rows.max() < blue_rows.min() + 3     # red above blue, split in one row or so


@pytest.mark.parametrize("suffix", ["glb", "obj"])
def test_preview_reads_a_textured_file(tmp_path, suffix):
    path = tmp_path / f"part.{suffix}"
    _textured_box().export(path)
    img = _read(preview(path, size_mm=SIZE, screenshot=tmp_path / "p.png", window_size=SMALL))
    assert _red(img).mean() > 0.03 and _blue(img).mean() > 0.03


def test_screenshot_with_wood_shows_the_section_and_cut_plane_false_hides_it(tmp_path):
    """Default cut: x = W/2, normal +X toward the camera; the part's near half is cut away.

    The part's cross-section (40 x 20 mm) is opaque wood (pure green), the waste around it
    translucent (light green over the background), the part's far half still textured.
    """
    box = _textured_box()
    with_cut = _read(preview(box, wood=GreenWood(), size_mm=SIZE,
                             screenshot=tmp_path / "a.png", window_size=SMALL))
    no_cut = _read(preview(box, wood=GreenWood(), size_mm=SIZE, cut_plane=False,
                           screenshot=tmp_path / "b.png", window_size=SMALL))
    pure = (with_cut[..., 1] > 200) & (with_cut[..., 0] < 60) & (with_cut[..., 2] < 60)
    assert pure.mean() > 0.015, pure.mean()
    assert _light_green(with_cut).mean() > 0.03, _light_green(with_cut).mean()
    # The opaque cap is the part's section: its pixels lie where the uncut part was.
    part_no_cut = _red(no_cut) | _blue(no_cut)
    saturated = (no_cut.max(axis=-1) - no_cut.min(axis=-1)) > 40   # any part face, shaded
    assert saturated[pure].mean() > 0.97
    assert _green(no_cut).mean() == 0.0 and _light_green(no_cut).mean() == 0.0
    # The part is clipped to one side of the plane, so less of the checker shows.
    assert (_red(with_cut) | _blue(with_cut)).sum() < 0.8 * part_no_cut.sum()


def test_a_cut_plane_that_misses_the_block_is_named(tmp_path):
    """preview --cut-origin 500,0,0 drew the part uncut without a word: the plane missed the
    block. A plane through it (or touching a face) says nothing."""
    import warnings

    from woodcam.errors import WoodcamWarning

    box = _textured_box()
    with pytest.warns(WoodcamWarning, match=r"the cut plane through \(500, 0, 0\) mm with normal "
                      r"\(1.0, 0.0, 0.0\) misses the block \(0 to 100x80x40 mm along X, Y, Z\)"):
        preview(box, wood=GreenWood(), size_mm=SIZE, cut_origin=(500.0, 0.0, 0.0),
                cut_normal=(1.0, 0.0, 0.0), screenshot=tmp_path / "a.png", window_size=SMALL)
    # in the message units, which the CLI sets to --units (preview --units inch --cut-origin
    # 20,0,0 said "(508.0, 0.0, 0.0) mm")
    from woodcam.units import message_units

    with message_units("inch"), pytest.warns(WoodcamWarning, match=r"through \(20, 0, 0\) in with normal "
                                             r"\(1.0, 0.0, 0.0\) misses the block \(0 to 3.937x3.15x1.575 in "
                                             r"along X, Y, Z\)"):
        preview(box, wood=GreenWood(), size_mm=SIZE, cut_origin=(508.0, 0.0, 0.0),
                cut_normal=(1.0, 0.0, 0.0), screenshot=tmp_path / "a.png", window_size=SMALL)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for origin in [(50.0, 0.0, 0.0), (100.0, 0.0, 0.0)]:
            preview(box, wood=GreenWood(), size_mm=SIZE, cut_origin=origin, cut_normal=(1.0, 0.0, 0.0),
                    screenshot=tmp_path / "b.png", window_size=SMALL)


def test_screenshot_without_size_frames_the_part(tmp_path):
    img = _read(preview(_textured_box(), screenshot=tmp_path / "p.png", window_size=SMALL))
    # No block: the framed part alone fills a large share of the picture.
    assert (_red(img) | _blue(img)).mean() > 0.25


def test_part_outside_the_block_stays_in_the_picture(tmp_path):
    far = _textured_box(center=(140.0, 40.0, 20.0))      # x in 110..170, block x in 0..100
    from woodcam.errors import WoodcamWarning

    # drawn, and said (test_preview_warns_of_a_part_reaching_outside_its_block)
    with pytest.warns(WoodcamWarning, match="lies outside its block"):
        img = _read(preview(far, size_mm=SIZE, screenshot=tmp_path / "p.png", window_size=SMALL))
    assert (_red(img) | _blue(img)).mean() > 0.05


def test_scene_of_two_meshes_is_concatenated(tmp_path):
    scene = trimesh.Scene([_textured_box(extents=(20, 20, 20), center=(20, 40, 20)),
                           _textured_box(extents=(20, 20, 20), center=(80, 40, 20))])
    poly, texture = mesh_to_pyvista(scene)
    assert poly.n_cells == 24 and texture is not None
    img = _read(preview(scene, size_mm=SIZE, screenshot=tmp_path / "p.png", window_size=SMALL))
    cols = np.nonzero(_red(img) | _blue(img))[1]
    # Two parts, left and right of the centre, with a gap between them.
    assert np.sum(cols < SMALL[0] * 0.4) > 200 and np.sum(cols > SMALL[0] * 0.6) > 200
    assert np.sum(np.abs(cols - SMALL[0] / 2) < 10) == 0


# ---------------------------------------------------------------------------- cut plane


@pytest.mark.parametrize(
    "origin, normal",
    [((30.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
     ((50.0, 40.0, 20.0), (0.0, -2.0, 0.0)),
     ((50.0, 40.0, 20.0), (1.0, 1.0, 0.3)),
     ((10.0, 0.0, 0.0), (1.0, 1.0, 1.0))],
)
def test_cut_plane_colours_equal_wood_colour_at_the_points(origin, normal):
    wood = PositionWood()
    section = cut_plane_image(wood, SIZE, origin, normal, resolution_mm=2.0)
    assert section.n_points > 10
    pts = np.asarray(section.points)
    rgb = np.asarray(section.point_data["RGB"])
    assert rgb.dtype == np.uint8
    np.testing.assert_allclose(rgb / 255.0, pts / np.asarray(SIZE), atol=RGB_ATOL)
    # Points lie on the plane, and the wood was asked with the plane's unit normal.
    n = np.asarray(normal) / np.linalg.norm(normal)
    np.testing.assert_allclose((pts - origin) @ n, 0.0, atol=1e-6)  # VTK clip round-off
    given = np.concatenate(wood.normals)
    np.testing.assert_allclose(given, np.broadcast_to(n, given.shape), atol=1e-12)
    np.testing.assert_allclose(section.field_data["normal"][0], n, atol=1e-12)


@pytest.mark.parametrize(
    "size, origin, normal, area",
    [
        # Normal to X: the whole D x H face.
        (SIZE, (30.0, 0.0, 0.0), (1.0, 0.0, 0.0), SIZE[1] * SIZE[2]),
        # Diagonal of a square-based block: W*sqrt(2) long, H high.
        ((100.0, 100.0, 40.0), (50.0, 50.0, 20.0), (1.0, -1.0, 0.0), 100 * np.sqrt(2) * 40),
        # Cuts off a corner: equilateral triangle of side 10*sqrt(2).
        (SIZE, (10.0, 0.0, 0.0), (1.0, 1.0, 1.0), np.sqrt(3) / 4 * 200.0),
    ],
)
def test_cut_plane_is_clipped_to_the_block(size, origin, normal, area):
    section = cut_plane_image(PositionWood(size), size, origin, normal, resolution_mm=1.0)
    pts = np.asarray(section.points)
    assert np.all(pts >= -ON_FACE_TOL_MM) and np.all(pts <= np.asarray(size) + ON_FACE_TOL_MM)
    # The clip is exact (cut edges lie on the box faces), so the area is the analytic one.
    got = section.triangulate().area
    assert got == pytest.approx(area, rel=1e-9)


def test_cut_plane_resolution_and_sample_cap():
    section = cut_plane_image(PositionWood(), SIZE, (30, 0, 0), (1, 0, 0), resolution_mm=0.5)
    # Normal to X: a regular grid over D x H with the requested spacing, corners included.
    assert section.n_points == (80 / 0.5 + 1) * (40 / 0.5 + 1)
    capped = cut_plane_image(PositionWood(), SIZE, (30, 0, 0), (1, 0, 0), resolution_mm=0.1,
                             max_samples=5000)
    assert 4000 < capped.n_points <= 5000
    assert capped.field_data["resolution_mm"][0] > 0.1
    # A long thin section (100 x 1 mm) still respects the cap.
    thin = cut_plane_image(PositionWood((100.0, 1.0, 40.0)), (100.0, 1.0, 40.0), (0, 0, 20),
                           (0, 0, 1), resolution_mm=0.01, max_samples=1000)
    assert 0 < thin.n_points <= 1000


def test_cut_plane_that_misses_the_block_is_empty():
    section = cut_plane_image(PositionWood(), SIZE, (150.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert section.n_points == 0


def test_cut_plane_splits_part_from_waste():
    """Box part 60 x 40 x 20 mm centred at (50, 40, 20), cut at x: the cap is 40 x 20 mm.

    The outline is exact along the grid rows (u = Y here) and within one row spacing across
    them (v = Z), so the cap's area is 800 mm^2 up to 2 edges x 40 mm x one spacing.
    """
    part, _ = mesh_to_pyvista(_textured_box())
    res = 0.5
    section = cut_plane_image(PositionWood(), SIZE, (50.0, 40.0, 20.0), (1, 0, 0),
                              resolution_mm=res, part=part)
    in_part = np.asarray(section.cell_data["in_part"]).astype(bool)
    cap = section.remove_cells(~in_part).triangulate()
    waste = section.remove_cells(in_part)
    p = np.asarray(cap.points)
    assert p[:, 1].min() == pytest.approx(20.0, abs=1e-6)
    assert p[:, 1].max() == pytest.approx(60.0, abs=1e-6)
    assert abs(p[:, 2].min() - 10.0) <= res and abs(p[:, 2].max() - 30.0) <= res
    cap_area = cap.area
    assert abs(cap_area - 800.0) <= 2 * 40 * res
    total = section.triangulate().area
    assert total == pytest.approx(SIZE[1] * SIZE[2], rel=1e-9)   # nothing lost in the split
    assert waste.n_cells > 0
    # Colours stay exact at every point, including the new points on the outline.
    np.testing.assert_allclose(np.asarray(section.point_data["RGB"]) / 255.0,
                               np.asarray(section.points) / np.asarray(SIZE), atol=RGB_ATOL)


def test_cut_plane_split_of_a_disk_matches_its_polygon():
    """A 64-sided cylinder (r = 30 mm) cut across its axis: the cap is the 64-gon."""
    cyl = trimesh.creation.cylinder(radius=30.0, height=30.0, sections=64)
    cyl.apply_translation((50.0, 40.0, 20.0))
    res = 0.25
    section = cut_plane_image(PositionWood(), SIZE, (50.0, 40.0, 20.0), (0, 0, 1),
                              resolution_mm=res, part=cyl)
    in_part = np.asarray(section.cell_data["in_part"]).astype(bool)
    cap = section.remove_cells(~in_part).triangulate()
    polygon = 0.5 * 64 * 30.0**2 * np.sin(2 * np.pi / 64)
    perimeter = 64 * 2 * 30.0 * np.sin(np.pi / 64)
    assert abs(cap.area - polygon) <= perimeter * res / 2
    r = np.hypot(*(np.asarray(cap.points)[:, :2] - (50.0, 40.0)).T)
    assert r.max() <= 30.0 + res


def test_cut_plane_callback_replaces_the_section_and_clips_the_part():
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        part, texture = mesh_to_pyvista(_textured_box())
        callback = CutPlaneCallback(plotter, part, texture, PositionWood(), SIZE,
                                    resolution_mm=2.0)
        assert PART_ACTOR in plotter.actors and SECTION_ACTOR not in plotter.actors
        n_actors = len(plotter.actors)
        for x in (30.0, 70.0):
            section = callback((1.0, 0.0, 0.0), (x, 40.0, 20.0))
            assert {SECTION_ACTOR, WASTE_ACTOR, OUTLINE_ACTOR} <= set(plotter.actors)
            cap, waste, outline = (callback.shown[n]
                                   for n in (SECTION_ACTOR, WASTE_ACTOR, OUTLINE_ACTOR))
            assert cap.n_cells + waste.n_cells == section.n_cells
            for shown in (cap, waste, outline):
                np.testing.assert_allclose(np.asarray(shown.points)[:, 0], x, atol=1e-9)
            for shown in (cap, waste):
                np.testing.assert_allclose(np.asarray(shown.point_data["RGB"]) / 255.0,
                                           np.asarray(shown.points) / np.asarray(SIZE),
                                           atol=RGB_ATOL)
            # The outline is the box's 40 x 20 mm rectangle at this x.
            o = np.asarray(outline.points)
            np.testing.assert_allclose([o[:, 1].min(), o[:, 1].max(), o[:, 2].min(),
                                        o[:, 2].max()], [20, 60, 10, 30], atol=1e-9)
            assert len(plotter.actors) == n_actors + 3   # replaced, not stacked
            # The part keeps the side opposite the normal.
            np.testing.assert_allclose(callback.clip_plane.GetOrigin(), (x, 40.0, 20.0))
            np.testing.assert_allclose(callback.clip_plane.GetNormal(), (-1.0, 0.0, 0.0))
        # A plane beside the part: no cap, no outline, all waste.
        callback((1.0, 0.0, 0.0), (10.0, 40.0, 20.0))
        assert SECTION_ACTOR not in plotter.actors and OUTLINE_ACTOR not in plotter.actors
        assert WASTE_ACTOR in plotter.actors
    finally:
        plotter.close()


def test_cut_plane_callback_clip_hides_the_part_on_the_normal_side():
    """Seen from the top, the part keeps only the side opposite the normal (+X: left half)."""
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        part, texture = mesh_to_pyvista(_textured_box())
        callback = CutPlaneCallback(plotter, part, texture)   # no wood: clipping only
        assert callback((1.0, 0.0, 0.0), (50.0, 40.0, 20.0)) is None
        view.camera.set_camera(plotter, "top", (0, SIZE[0], 0, SIZE[1], 0, SIZE[2]))
        img = plotter.screenshot(return_img=True).astype(int)
    finally:
        plotter.close()
    part_px = _red(img) | _blue(img)
    cols = np.nonzero(part_px)[1]
    centre_col = SMALL[0] / 2   # the camera frames the block centred: x = 50 mm is mid-picture
    assert cols.size > 2000
    assert cols.max() < centre_col + 3


def test_interactive_scene_widget_drives_the_cut():
    """The interactive scene, built on an off-screen plotter: moving the widget moves the cut."""
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        callback = build_scene(plotter, _textured_box(), wood=PositionWood(), size_mm=SIZE,
                               widget=True, max_samples=20_000)
        # pyvista 0.47+ keeps widgets under plotter.widgets; older ones on the plotter.
        widgets = getattr(plotter, "widgets", plotter).plane_widgets
        assert len(widgets) == 1
        widget = widgets[0]
        # Placed at the block centre, normal to the longest axis (X), section drawn at once.
        np.testing.assert_allclose(widget.GetOrigin(), (50.0, 40.0, 20.0))
        np.testing.assert_allclose(np.asarray(callback.section.points)[:, 0], 50.0, atol=1e-9)
        # Drag: the widget fires InteractionEvent; the section and the part's clip follow.
        widget.SetOrigin(80.0, 40.0, 20.0)
        widget.SetNormal(0.0, 0.0, 1.0)
        widget.InvokeEvent("InteractionEvent")
        section = callback.section
        np.testing.assert_allclose(np.asarray(section.points)[:, 2], 20.0, atol=1e-9)
        # The cap bounds the grid's samples; the part's outline adds points along it.
        assert section.n_points <= 20_000 * 1.05
        np.testing.assert_allclose(np.asarray(section.point_data["RGB"]) / 255.0,
                                   np.asarray(section.points) / np.asarray(SIZE), atol=RGB_ATOL)
        assert SECTION_ACTOR in plotter.actors
        cap = callback.shown[SECTION_ACTOR]
        np.testing.assert_allclose(np.asarray(cap.points)[:, 2], 20.0, atol=1e-9)
        np.testing.assert_allclose(callback.clip_plane.GetNormal(), (0.0, 0.0, -1.0))
        img = plotter.screenshot(return_img=True)
        assert np.any(img != 255, axis=-1).mean() > 0.2
    finally:
        plotter.close()


def test_interactive_scene_without_wood_clips_only():
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        callback = build_scene(plotter, _textured_box(), size_mm=SIZE, widget=True)
        assert callback is not None and callback.section is None
        assert SECTION_ACTOR not in plotter.actors and PART_ACTOR in plotter.actors
        # Without a widget and without a wood there is nothing to cut: no callback.
        plotter.clear()
        assert build_scene(plotter, _textured_box(), size_mm=SIZE) is None
    finally:
        plotter.close()


def test_default_cut_normal_faces_the_camera_along_the_longest_axis():
    size = np.asarray(SIZE)
    np.testing.assert_array_equal(view.camera.default_cut_normal("iso", size), [1, 0, 0])
    np.testing.assert_array_equal(view.camera.default_cut_normal("iso", size[[2, 1, 0]]), [0, 0, 1])
    np.testing.assert_array_equal(view.camera.default_cut_normal("front", size), [0, -1, 0])
    # top/bottom: the cut they get when one is asked for (--cut-origin/--cut-normal, the widget
    # dragged); by default they show no cut (test_top_and_bottom_show_the_outside_uncut)
    np.testing.assert_array_equal(view.camera.default_cut_normal("top", size), [0, 0, 1])
    assert view.camera.UNCUT_CAMERAS == ("top", "bottom")


@pytest.mark.parametrize("camera", ["top", "bottom"])
def test_top_and_bottom_show_the_outside_uncut(tmp_path, camera):
    """'preview bowl.glb --camera bottom' showed a ring at mid-height (the default cut faced the
    camera, along Z, and took the foot away) and '--camera top' of a pocketed tray a flat slab:
    straight down or up the default is the uncut outside (no wood on a plane: no green), a cut
    when asked for (--cut-origin), and the interactive widget starts on the face toward the camera."""
    box = _textured_box()
    plain = _read(preview(box, wood=GreenWood(), size_mm=SIZE, camera=camera,
                          screenshot=tmp_path / "a.png", window_size=SMALL))
    assert _green(plain).mean() == 0.0 and _light_green(plain).mean() == 0.0
    assert (_red(plain) | _blue(plain)).mean() > 0.1      # the part's face, whole
    asked = _read(preview(box, wood=GreenWood(), size_mm=SIZE, camera=camera, cut_origin=(50.0, 40.0, 20.0),
                          screenshot=tmp_path / "b.png", window_size=SMALL))
    assert _green(asked).mean() > 0.015
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        callback = build_scene(plotter, box, size_mm=SIZE, widget=True, camera=camera)
        assert callback is not None
        assert callback.clip_plane.GetOrigin()[2] == (40.0 if camera == "top" else 0.0)
    finally:
        plotter.close()


# ---------------------------------------------------------------------------- conversion


def test_mesh_to_pyvista_keeps_uv_and_image():
    mesh = _textured_box()
    poly, texture = mesh_to_pyvista(mesh)
    np.testing.assert_array_equal(np.asarray(poly.points), mesh.vertices)
    np.testing.assert_array_equal(np.asarray(poly.active_texture_coordinates), mesh.visual.uv)
    assert poly.n_cells == len(mesh.faces)
    assert texture is not None and texture.dimensions == (64, 64)


def test_mesh_to_pyvista_vertex_colours_and_untextured():
    mesh = trimesh.creation.box(extents=(10, 10, 10))
    mesh.visual.vertex_colors = np.tile([10, 200, 30, 255], (len(mesh.vertices), 1))
    poly, texture = mesh_to_pyvista(mesh)
    assert texture is None
    np.testing.assert_array_equal(poly.point_data["RGB"][0], [10, 200, 30])
    poly, texture = mesh_to_pyvista(trimesh.creation.box(extents=(10, 10, 10)))
    assert texture is None and poly.active_texture_coordinates is None


def test_block_outline_is_the_block_box():
    box, edges = block_outline(SIZE)
    np.testing.assert_allclose(box.bounds, (0, 100, 0, 80, 0, 40))
    assert edges.n_lines == 12
    np.testing.assert_allclose(edges.bounds, (0, 100, 0, 80, 0, 40))


# ---------------------------------------------------------------------------- bad inputs


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"size_mm": (100, -1, 40)}, "size_mm must be three positive"),
        ({"size_mm": (100, 40)}, "size_mm must be three positive"),
        ({"wood": PositionWood()}, "size_mm is needed with wood"),
        ({"wood": object(), "size_mm": SIZE}, "wood must have a method color"),
        ({"camera": "sideways"}, "camera must be one of iso, top"),
        ({"window_size": (0, 10)}, "window_size must be two integers"),
        ({"screenshot": "part.jpg"}, "screenshot must be a .png path"),
        ({"cut_normal": (0, 0, 0), "wood": GreenWood(), "size_mm": SIZE}, "non-zero direction"),
    ],
)
def test_preview_rejects_bad_arguments(tmp_path, kwargs, match):
    kwargs.setdefault("screenshot", tmp_path / "p.png")
    with pytest.raises(WoodcamError, match=match):
        preview(_textured_box(), **kwargs)


@pytest.mark.parametrize("bad", [None, 5, float("nan"), (np.nan, 0, 0), (0.5, 0.5), (1.5, 0, 0), (-1, 0, 0),
                                 (True, 0, 0), ""])
def test_scene_background_is_a_colour_when_the_options_are_made(bad):
    """SceneOptions(background=) was not checked: None drew pyvista's default blue, a number, NaN
    or (0.5, 0.5) failed in VTK's renderer as pyvista's bare TypeError/ValueError."""
    with pytest.raises(WoodcamError, match=r"preview: background must be a colour name matplotlib knows .* or an "
                                           r"RGB triple: .*; got "):
        view.SceneOptions(background=bad)


def test_a_background_name_pyvista_does_not_know_is_refused_before_drawing(tmp_path):
    with pytest.raises(WoodcamError, match="preview: background must be a colour name .*; got 'nope'"):
        preview(_textured_box(), screenshot=tmp_path / "p.png", window_size=SMALL, background="nope")
    assert not (tmp_path / "p.png").exists()
    ok = [view.SceneOptions(background=b).background for b in ("white", "#202020", [0.1, 0.2, 0.3],
                                                                (255, 255, 255), np.array([0.0, 0.5, 1.0]))]
    assert ok == ["white", "#202020", (0.1, 0.2, 0.3), (255, 255, 255), (0.0, 0.5, 1.0)]


@pytest.mark.parametrize("overlay, said", [
    ((np.zeros((2, 2, 3)), "red", 2.0), r"overlay must be a list of \(segments, colour, width\) tuples; got one tuple"),
    (5, "overlay must be a list of .*got 5"),
    ([(np.zeros((2, 2, 3)), "red")], r"overlay\[0\] must be \(segments \(k, 2, 3\) mm, colour, width px\)"),
    ([(np.zeros((2, 3)), "red", 2.0)], r"overlay\[0\] segments must be a \(k, 2, 3\) array .*got shape \(2, 3\)"),
    ([(np.full((1, 2, 3), np.nan), "red", 2.0)], r"overlay\[0\] segments must be .*finite mm"),
    ([(np.zeros((1, 2, 3)), "nope", 2.0)], r"overlay\[0\] colour must be a colour name .*; got 'nope'"),
    ([(np.zeros((1, 2, 3)), "red", 0)], r"overlay\[0\] width must be a finite number > 0; got 0"),
    ([(np.zeros((1, 2, 3)), "red", "a")], r"overlay\[0\] width must be a finite number > 0; got 'a'"),
])
def test_preview_overlay_is_checked_before_drawing(tmp_path, overlay, said):
    """preview(overlay=) was not checked: one tuple, a pair, segments of another shape were bare
    unpacking/reshape errors, NaN segments and a width of 0 were drawn, 'nope' failed in VTK,
    all after the scene was built."""
    with pytest.raises(WoodcamError, match=said):
        preview(_textured_box(), screenshot=tmp_path / "p.png", window_size=SMALL, overlay=overlay)
    assert not (tmp_path / "p.png").exists()


def test_preview_rejects_bad_meshes(tmp_path):
    # the file as given, not the parameter's name (it said "mesh_or_path: no file at ...")
    with pytest.raises(WoodcamError, match=r"^mesh file '.*missing.glb' does not exist"):
        preview(tmp_path / "missing.glb", screenshot=tmp_path / "p.png")
    with pytest.raises(WoodcamError, match="must be a trimesh.Trimesh"):
        preview(np.zeros((3, 3)), screenshot=tmp_path / "p.png")
    with pytest.raises(WoodcamError, match="no faces"):
        preview(trimesh.Trimesh(), screenshot=tmp_path / "p.png")
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"solid x\nendsolid x\n")
    with pytest.raises(WoodcamError, match=r"^mesh file '.*empty.stl' has no faces, nothing to preview"):
        preview(empty, screenshot=tmp_path / "p.png")


def test_interactive_without_display_says_use_screenshot(monkeypatch):
    monkeypatch.setattr(view.scene.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(WoodcamError, match="needs a display.*--screenshot"):
        preview(_textured_box(), size_mm=SIZE)


def test_preview_without_display_says_so_before_the_work(monkeypatch, tmp_path, glb_with, bars, capsys):
    """'woodcam preview PART.glb' without a display opened the block (a fit where the cache
    lacks it: seconds to minutes) and loaded pyvista before saying it needs one; it now says so
    first, with the command that renders a picture instead."""
    from woodcam.cli import EXIT_ERROR, main

    monkeypatch.setattr(view.scene.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    opened = []
    monkeypatch.setattr("woodcam.cli.options.stock_of_glb", lambda *a, **k: opened.append(a))
    glb = glb_with({"block": "builtin:rift"}, tmp_path / "p.glb")
    assert main(["preview", str(glb)]) == EXIT_ERROR
    err = capsys.readouterr().err.splitlines()
    assert err == [f"woodcam: error: preview: an interactive window needs a display, but neither DISPLAY nor "
                   f"WAYLAND_DISPLAY is set; render a picture instead with: woodcam preview {glb} --screenshot "
                   f"(writes {tmp_path / 'p_view.png'})"], err
    assert not opened and not [b for b in bars if b.desc == "preview"]  # no work began


@pytest.mark.parametrize(
    "wood, match",
    [
        (type("W255", (), {"color": lambda self, p, n: np.full((len(p), 3), 200.0)})(),
         r"rgb in \[0, 1\].*divide 0..255"),
        (type("WShape", (), {"color": lambda self, p, n: np.zeros(len(p))})(),
         r"shape \(n, 3\)"),
        (type("WNaN", (), {"color": lambda self, p, n: np.full((len(p), 3), np.nan)})(),
         "non-finite"),
    ],
)
def test_cut_plane_rejects_bad_wood_colours(wood, match):
    with pytest.raises(WoodcamError, match=match):
        cut_plane_image(wood, SIZE, (50, 40, 20), (1, 0, 0), resolution_mm=5.0)


def test_cut_plane_rejects_bad_arguments():
    with pytest.raises(WoodcamError, match="needs a wood"):
        cut_plane_image(None, SIZE, (50, 40, 20), (1, 0, 0))
    with pytest.raises(WoodcamError, match="resolution_mm must be a positive"):
        cut_plane_image(PositionWood(), SIZE, (50, 40, 20), (1, 0, 0), resolution_mm=0)
    with pytest.raises(WoodcamError, match="normal must be a non-zero"):
        cut_plane_image(PositionWood(), SIZE, (50, 40, 20), (0, 0, 0))
    with pytest.raises(WoodcamError, match="max_samples must be an integer"):
        cut_plane_image(PositionWood(), SIZE, (50, 40, 20), (1, 0, 0), max_samples=2)
    with pytest.raises(WoodcamError, match="origin must be three finite"):
        cut_plane_image(PositionWood(), SIZE, (50, np.nan, 20), (1, 0, 0))


def test_window_keys_switch_views_and_toggle_the_block(tmp_path):
    """The interactive window's keys, driven off screen through pyvista's key callbacks."""
    pv = pytest.importorskip("pyvista")
    import trimesh

    from woodcam.view.scene import KEY_HELP, add_view_keys, build_scene

    box = trimesh.creation.box((40.0, 30.0, 20.0))
    box.apply_translation([50.0, 40.0, 25.0])
    plotter = pv.Plotter(off_screen=True, window_size=(320, 240))
    try:
        build_scene(plotter, box, size_mm=(100.0, 80.0, 50.0), widget=False)
        add_view_keys(plotter, (100.0, 80.0, 50.0))
        keys = plotter.iren._key_press_event_callbacks
        keys["2"][-1]()  # top: the camera straight above the block's centre
        pos, focal = np.asarray(plotter.camera.position), np.asarray(plotter.camera.focal_point)
        assert np.allclose((pos - focal)[:2], 0.0, atol=1e-6) and pos[2] > focal[2]
        keys["1"][-1]()  # front: looking along +Y
        d = np.asarray(plotter.camera.focal_point) - np.asarray(plotter.camera.position)
        assert d[1] > 0 and np.allclose(d[[0, 2]], 0.0, atol=1e-6)
        keys["o"][-1]()
        assert plotter.camera.parallel_projection
        assert plotter.actors["woodcam-block"].GetVisibility()
        keys["h"][-1]()
        assert not plotter.actors["woodcam-block"].GetVisibility()
        assert "1 front" in KEY_HELP and "woodcam-keys" in plotter.actors
    finally:
        plotter.close()


@pytest.mark.parametrize("size", [(300.0, 60.0, 30.0), (100.0, 80.0, 50.0), (20.0, 20.0, 120.0)])
def test_placement_panels_frame_the_block_below_their_titles(size):
    """QA item 6: placements.png's panels had a fixed camera (made for a 100 mm block), which
    cut the block off at the panel's left edge and showed only one end of a 300 mm block. Each
    panel now frames its box: the eight corners, projected by the panel's own VTK camera, lie
    inside the panel and below its title band, and fill most of the panel's width or band."""
    from woodcam.view.compare import _TITLE_SHARE, frame_panel

    panel = 300
    plotter = pv.Plotter(off_screen=True, shape=(1, 2), window_size=(2 * panel, panel),
                         border=False)
    try:
        bounds = np.array([0.0, size[0], 0.0, size[1], 0.0, size[2]])
        corners = [(x, y, z) for x in bounds[:2] for y in bounds[2:4] for z in bounds[4:]]
        for i in range(2):
            plotter.subplot(0, i)
            plotter.add_mesh(pv.Box(bounds=tuple(bounds)).outline())
            frame_panel(plotter, bounds)
        plotter.render()
        for i in range(2):
            plotter.subplot(0, i)
            ren = plotter.renderer
            px = []
            for c in corners:
                ren.SetWorldPoint(*c, 1.0)
                ren.WorldToDisplay()
                px.append(ren.GetDisplayPoint()[:2])  # window px, origin bottom left
            px = np.array(px) - [i * panel, 0.0]
            band = (1 - _TITLE_SHARE) * panel
            assert px.min() >= 0 and px[:, 0].max() <= panel and px[:, 1].max() <= band, px
            span = px.max(axis=0) - px.min(axis=0)
            assert max(span[0] / panel, span[1] / band) >= 0.85, span
    finally:
        plotter.close()


def _face_samples(inset_mm: float):
    """A finely meshed part ``inset_mm`` inside the SIZE block, in the preview's iso scene
    (depth peeling and SSAA as :func:`preview`): colours (n, 3) at 360 points inside the part's
    front face (y = inset), the block actor's bounds, the camera's clipping range and position."""
    box = trimesh.creation.box([s - 2 * inset_mm for s in SIZE])
    box.apply_translation(np.asarray(SIZE) / 2)
    box = trimesh.Trimesh(*trimesh.remesh.subdivide_to_size(box.vertices, box.faces, 5.0))
    plotter = pv.Plotter(off_screen=True, window_size=(400, 300))
    try:
        build_scene(plotter, box, size_mm=SIZE, cut_plane=False)
        plotter.enable_depth_peeling()
        plotter.enable_anti_aliasing("ssaa")
        img = plotter.screenshot(return_img=True).astype(float)
        ren, cam = plotter.renderer, plotter.camera
        px = []
        for x in np.linspace(15, 85, 30):
            for z in np.linspace(8, 32, 12):
                ren.SetWorldPoint(x, inset_mm, z, 1.0)
                ren.WorldToDisplay()
                px.append(ren.GetDisplayPoint()[:2])
        px = np.rint(px).astype(int)
        colours = img[img.shape[0] - 1 - px[:, 1], px[:, 0]]
        return (colours, np.asarray(plotter.actors["woodcam-block"].GetBounds()),
                cam.clipping_range, np.asarray(cam.position))
    finally:
        plotter.close()


def test_a_part_face_on_a_block_face_is_drawn_clean():
    """QA item 11: a part face lying on a block face was drawn at the same depth as the
    translucent block face, and the two fought for each pixel (a screen-door pattern: colours
    spread over 16 levels on a flat, evenly lit face). The block's faces are now drawn outside
    the block, by many depth-buffer steps and less than a pixel, and the face is as even as one
    1 mm inside the block."""
    colours, block, (near, far), eye = _face_samples(0.0)
    inside, *_ = _face_samples(1.0)
    outset = np.abs(block - np.array([0, SIZE[0], 0, SIZE[1], 0, SIZE[2]]))
    corners = np.array([(x, y, z) for x in (0, SIZE[0]) for y in (0, SIZE[1]) for z in (0, SIZE[2])])
    d = np.linalg.norm(corners - eye, axis=1).max()
    depth_step = d**2 * (far - near) / (far * near * 2**24)  # mm, 24-bit depth at distance d
    assert outset.min() >= 10 * depth_step
    assert outset.max() <= 0.2  # mm; ~1 px at this size
    assert np.ptp(colours, axis=0).max() <= np.ptp(inside, axis=0).max() + 2
    np.testing.assert_allclose(colours.mean(axis=0), inside.mean(axis=0), atol=1.0)


def test_preview_draws_its_overlay_where_the_segments_are(tmp_path):
    """``preview(overlay=...)``: segments in the block frame over the scene in their colour.
    From the top (+Y up) a red line along X at Y = 60 mm, above a plain (wood-coloured) part,
    lies in the picture's upper half, in one band of rows across the block's width; a blue
    one along Y at X = 20 mm in one band of columns in the left half."""
    plain = _textured_box()
    plain.visual = trimesh.visual.ColorVisuals(plain)
    red = np.array([[[0.0, 60.0, 45.0], [100.0, 60.0, 45.0]]])
    blue = np.array([[[20.0, 0.0, 45.0], [20.0, 80.0, 45.0]]])
    img = _read(preview(plain, size_mm=SIZE, screenshot=tmp_path / "p.png", window_size=SMALL,
                        camera="top", overlay=[(red, "red", 3), (blue, (0.1, 0.2, 0.9), 3)]))
    rows, cols = np.nonzero(_red(img))
    assert cols.size > 100 and np.ptp(cols) > 0.6 * SMALL[0]
    assert np.ptp(rows) <= 6 and rows.max() < SMALL[1] / 2
    rows, cols = np.nonzero(_blue(img))
    assert rows.size > 100 and np.ptp(rows) > 0.6 * SMALL[1]
    assert np.ptp(cols) <= 6 and cols.max() < SMALL[0] / 2
    bare = _read(preview(plain, size_mm=SIZE, screenshot=tmp_path / "q.png", window_size=SMALL,
                         camera="top"))
    assert not _red(bare).any() and not _blue(bare).any()


def test_the_scene_samples_its_section_at_the_resolution_asked():
    """build_scene's resolution_mm (preview's too) is the section's sample spacing."""
    plotter = pv.Plotter(off_screen=True, window_size=SMALL)
    try:
        for res in (1.0, 4.0):
            plotter.clear()
            callback = build_scene(plotter, _textured_box(), wood=PositionWood(), size_mm=SIZE,
                                   cut_normal=(1.0, 0.0, 0.0), resolution_mm=res)
            section = callback.section
            assert section.field_data["resolution_mm"][0] == res
            # normal to X: a (D / res + 1) x (H / res + 1) grid, plus the part's outline
            assert (SIZE[1] / res + 1) * (SIZE[2] / res + 1) <= section.n_points \
                < (SIZE[1] / res + 1) * (SIZE[2] / res + 1) + 4 * (SIZE[1] + SIZE[2]) / res
    finally:
        plotter.close()


def _dirty_meshes():
    """A 10 mm box in a 30 mm block made slightly dirty four ways a user's mesh can be: an
    unreferenced vertex, a zero-area triangle (a sliver on a box edge, its own vertex on the
    edge's middle), a duplicated face, and a fin (one triangle both ways round: the vertex
    normals cancel)."""
    box = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    box.apply_translation((15.0, 15.0, 15.0))
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    a, b = f[0, 0], f[0, 1]
    mid = (v[a] + v[b]) / 2
    return {"unreferenced vertex": trimesh.Trimesh(np.vstack([v, [[3.0, 3.0, 3.0]]]), f, process=False),
            "zero-area triangle": trimesh.Trimesh(np.vstack([v, [mid]]), np.vstack([f, [[a, 8, b]]]),
                                                  process=False),
            "duplicate face": trimesh.Trimesh(v, np.vstack([f, f[:1]]), process=False),
            "fin": trimesh.Trimesh(np.array([[5.0, 5, 5], [15, 5, 5], [5, 15, 5]]), [[0, 1, 2], [0, 2, 1]],
                                   process=False)}


def test_a_dirty_mesh_gets_a_direction_at_every_vertex():
    """vertex_color_normals: trimesh's vertex normals where they are a direction, the vertex's
    largest triangle's normal where they cancel (a fin, a zero-area triangle's vertex), +Z where
    no triangle of any area uses the vertex."""
    from woodcam.appearance.wood import vertex_color_normals

    for name, mesh in _dirty_meshes().items():
        n = vertex_color_normals(mesh)
        assert n.shape == (len(mesh.vertices), 3) and np.allclose(np.linalg.norm(n, axis=1), 1.0), name
        good = np.linalg.norm(mesh.vertex_normals, axis=1) > 0.5
        assert np.array_equal(n[good], np.asarray(mesh.vertex_normals)[good]), name
    meshes = _dirty_meshes()
    assert np.array_equal(vertex_color_normals(meshes["unreferenced vertex"])[8], [0.0, 0.0, 1.0])
    fin = meshes["fin"]
    assert all(any(np.allclose(n, fn) for fn in fin.face_normals) for n in vertex_color_normals(fin))


def test_placement_panels_colour_a_users_slightly_dirty_mesh(tmp_path):
    """Since the wood refuses a zero normal, the placement panels (render_side_by_side) refused
    a mesh with an unreferenced vertex, a zero-area triangle or a fin (trimesh gives such
    vertices a zero normal): each is drawn, coloured by the wood."""
    import woodcam as w
    from woodcam.view.compare import render_side_by_side

    meshes = _dirty_meshes()
    wood = w.Wood(w.builtin_block("flat-sawn").field)
    png = render_side_by_side(list(meshes.values()), [wood] * len(meshes), (30.0, 30.0, 30.0),
                              list(meshes), tmp_path / "panels.png", panel_px=96)
    with Image.open(png) as im:
        assert im.size == (96 * len(meshes), 96)


def test_preview_warns_of_a_part_reaching_outside_its_block(tmp_path):
    """preview drew a part reaching past a --block smaller than it was baked from (or turned)
    without the "reaches outside its block" warning review gives; one check says it for both
    (woodcam.frames.check_part_in_block). A part wholly outside is drawn, with a warning; a part
    inside says nothing."""
    import warnings

    from woodcam.errors import WoodcamWarning

    box = _textured_box()                              # x 20..80, y 20..60, z 10..30 mm
    with pytest.warns(WoodcamWarning, match=r"^preview: the part reaches outside its block, 30 mm past its "
                      r"right face \(x = 50 mm\): the part's bounding box is \(20, 20, 10\) mm to \(80, 60, 30\) "
                      r"mm, the block's \(0, 0, 0\) mm to \(50, 80, 40\) mm; the part there would be carved from "
                      r"air, and the cut plane shows no wood of it"):
        preview(box, wood=GreenWood(), size_mm=(50.0, 80.0, 40.0), screenshot=tmp_path / "a.png",
                window_size=SMALL)
    with pytest.warns(WoodcamWarning, match=r"lies outside its block"):
        preview(box, size_mm=(10.0, 10.0, 10.0), screenshot=tmp_path / "b.png", window_size=SMALL)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        preview(box, size_mm=SIZE, screenshot=tmp_path / "c.png", window_size=SMALL)
