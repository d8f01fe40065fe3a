"""Face mapping of docs/conventions.md: round trips, table values, touching edges."""

import numpy as np
import pytest

from woodcam.errors import WoodcamError
from woodcam.frames import (
    FACE_NORMAL, FACES, CrossLayout, block_to_pixel, check_face, face_pixel_points,
    pixel_to_block, unfold_cross,
)

SIZE = (100.0, 80.0, 50.0)
SHAPES = {"front": (50, 100), "back": (50, 100), "top": (80, 100), "bottom": (80, 100),
          "left": (50, 80), "right": (50, 80)}


@pytest.mark.parametrize("face", FACES)
def test_round_trip(face, rng):
    shape = SHAPES[face]
    r = rng.uniform(-0.5, shape[0] - 0.5, 200)
    c = rng.uniform(-0.5, shape[1] - 0.5, 200)
    p = pixel_to_block(face, r, c, shape, SIZE)
    r2, c2 = block_to_pixel(face, p, shape, SIZE)
    np.testing.assert_allclose(r2, r, atol=1e-9)
    np.testing.assert_allclose(c2, c, atol=1e-9)


@pytest.mark.parametrize("face", FACES)
def test_points_lie_on_the_face_plane(face):
    p = face_pixel_points(face, SHAPES[face], SIZE).reshape(-1, 3)
    n = np.asarray(FACE_NORMAL[face])
    k = int(np.flatnonzero(n)[0])
    plane = SIZE[k] if n[k] > 0 else 0.0
    np.testing.assert_allclose(p[:, k], plane)
    # Inside the face rectangle, and covering it to within half a pixel.
    assert np.all(p >= 0) and np.all(p <= np.asarray(SIZE))


@pytest.mark.parametrize("face", FACES)
def test_face_pixel_points_are_pixel_to_block_of_every_pixel(face):
    """The broadcast (affine) form equals the per-pixel map at every pixel centre."""
    shape = SHAPES[face]
    r, c = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    np.testing.assert_allclose(face_pixel_points(face, shape, SIZE),
                               pixel_to_block(face, r, c, shape, SIZE), atol=1e-12)


def test_table_corners():
    """Pixel (0, 0) is the top-left seen from outside; spot-check the conventions table."""
    W, D, H = SIZE
    corner = lambda f: pixel_to_block(f, -0.5, -0.5, SHAPES[f], SIZE)
    np.testing.assert_allclose(corner("front"), (0, 0, H))
    np.testing.assert_allclose(corner("back"), (W, D, H))
    np.testing.assert_allclose(corner("top"), (0, D, H))
    np.testing.assert_allclose(corner("bottom"), (0, 0, 0))
    np.testing.assert_allclose(corner("left"), (0, D, H))
    np.testing.assert_allclose(corner("right"), (W, 0, H))


def _edge(face, side, n=11):
    """Block points along one border of a face image (continuous pixel coords on the border)."""
    R, C = SHAPES[face]
    t = np.linspace(0, 1, n)
    r, c = {"top": (np.full(n, -0.5), -0.5 + t * C), "bottom": (np.full(n, R - 0.5), -0.5 + t * C),
            "left": (-0.5 + t * R, np.full(n, -0.5)), "right": (-0.5 + t * R, np.full(n, C - 0.5))}[side]
    return pixel_to_block(face, r, c, SHAPES[face], SIZE)


@pytest.mark.parametrize("a, a_side, b, b_side", [
    ("front", "top", "top", "bottom"),
    ("front", "bottom", "bottom", "top"),
    ("front", "left", "left", "right"),
    ("front", "right", "right", "left"),
    ("right", "right", "back", "left"),
    ("back", "right", "left", "left"),  # the cross wraps around: back's right meets left's left
])
def test_edges_touching_in_the_cross_touch_on_the_block(a, a_side, b, b_side):
    np.testing.assert_allclose(_edge(a, a_side), _edge(b, b_side), atol=1e-9)


def test_mokume_letters():
    assert [check_face(x) for x in "ABCDEF"] == ["front", "top", "left", "bottom", "right", "back"]
    with pytest.raises(WoodcamError, match="face must be one of"):
        check_face("G")


def test_unfold_cross_places_faces():
    layout = CrossLayout(SIZE, 1.0)
    imgs = {f: np.full(SHAPES[f], i + 1, np.uint8) for i, f in enumerate(FACES)}
    cross = unfold_cross(imgs, SIZE)
    assert cross.shape == layout.shape == (2 * 80 + 50, 2 * 80 + 2 * 100)
    for i, f in enumerate(FACES):
        r0, c0 = layout.origin[f]
        h, w = SHAPES[f]
        assert np.all(cross[r0:r0 + h, c0:c0 + w] == i + 1)
    assert np.count_nonzero(cross) == sum(h * w for h, w in SHAPES.values())


def test_unfold_cross_rejects_wrong_size():
    with pytest.raises(WoodcamError, match="must be 80x100 px"):
        unfold_cross({"front": np.zeros((50, 100)), "top": np.zeros((10, 10))}, SIZE)


def test_bad_size_and_shape():
    with pytest.raises(WoodcamError, match="size_mm must be three positive"):
        pixel_to_block("front", 0, 0, (10, 10), (1, -1, 1))
    with pytest.raises(WoodcamError, match="image_shape"):
        pixel_to_block("front", 0, 0, (0, 10), SIZE)


def test_rings_show_of_a_block_whose_faces_round_at_zoom_2():
    """'woodcam rings show' failed at its default --zoom 2 on a block of 62 x 43.5 x 32 mm (a
    synth block): each face enlarged twice was a pixel off its slot of the cross. Another
    density is still refused."""
    import pytest

    from woodcam import unfold_cross
    from woodcam.detect.show import rings_picture
    from woodcam.errors import WoodcamError
    from woodcam.fields import builtin_block
    from woodcam.synth import synth_block

    block = synth_block(builtin_block("flat-sawn").field, (62.0, 43.5, 32.0), face_px=256, seed=0)
    for zoom in (2, 3):
        assert rings_picture(block, zoom=zoom).ndim == 3
    size = (62.0, 43.5, 32.0)
    with pytest.raises(WoodcamError, match="must be .* px to share the density"):
        unfold_cross({"front": np.zeros((32, 62)), "top": np.zeros((87, 124))}, size)


def test_block_to_pixel_names_the_shape_of_wrong_points_not_every_point():
    """A (5000, 2) array of points printed all its numbers in the error message."""
    with pytest.raises(WoodcamError, match=r"points_mm must have shape \(\.\.\., 3\) in mm; got shape "
                                           r"\(5000, 2\); pass block points") as err:
        block_to_pixel("top", np.zeros((5000, 2)), (9, 9), SIZE)
    assert len(str(err.value)) < 200
    with pytest.raises(WoodcamError, match=r"got 5\.0; pass block points"):
        block_to_pixel("top", 5.0, (9, 9), SIZE)
