"""woodcam.appearance.knots.KnotShading: the one knot shading, checked and applied."""

import numpy as np
import pytest

from woodcam.appearance import ColorMapAppearance
from woodcam.appearance.knots import KnotShading
from woodcam.errors import WoodcamError


def test_apply_darkens_knots_and_draws_the_outline():
    rgb = np.full((4, 3), 0.8)
    feats = {"knot": np.array([0.0, 1.0, 1.0, 0.0]), "dead": np.array([0.0, 0.0, 1.0, 0.0]),
             "outline": np.array([0.0, 0.0, 0.0, 1.0])}
    out = KnotShading(0.5, 0.5, (0.1, 0.1, 0.1)).apply(rgb, feats)
    assert np.allclose(out[0], 0.8) and np.allclose(out[1], 0.4)       # 0.8 (1 - 0.5)
    assert np.allclose(out[2], 0.2) and np.allclose(out[3], 0.1)       # 0.8 (0.5)(0.5); outline


def test_defaults_are_the_colour_maps_and_shorthands_replace_them():
    k = KnotShading()
    assert (k.alive_darkening, k.dead_darkening, k.outline_rgb) == (0.25, 0.45, (0.16, 0.10, 0.06))
    assert ColorMapAppearance("oak").knots == k
    app = ColorMapAppearance("oak", knot_darkening_alive=0.1, dead_outline_rgb=(0, 0, 0))
    assert app.knots == KnotShading(0.1, 0.45, (0.0, 0.0, 0.0))


@pytest.mark.parametrize("kwargs, message", [
    ({"alive_darkening": 1.5}, r"KnotShading.alive_darkening must be a number in \[0, 1\]; got 1.5"),
    ({"dead_darkening": -0.1}, "KnotShading.dead_darkening must be"),
    ({"outline_rgb": (0.1, 0.2)}, "KnotShading.outline_rgb must be three numbers"),
    ({"outline_rgb": (0.1, 0.2, 3)}, "KnotShading.outline_rgb must be three numbers"),
])
def test_bad_settings_are_named(kwargs, message):
    with pytest.raises(WoodcamError, match=message):
        KnotShading(**kwargs)


def test_wood_colors_checks_every_wood_in_one_place():
    """Wood.color and any duck-typed wood go through the same contract check."""
    from woodcam.appearance import Wood
    from woodcam.appearance.wood import wood_colors

    class Appearance:
        def color(self, field, points_mm, normals):
            return np.full((len(points_mm), 3), 2.0)        # out of range

    p = np.zeros((5, 3))
    with pytest.raises(WoodcamError, match=r"appearance.color must return rgb in \[0, 1\]"):
        Wood(lambda q: q[:, 0], Appearance()).color(p, np.ones((5, 3)))

    class Half:
        def color(self, points_mm, normals):
            return np.full((len(points_mm), 3), 0.5)

    out = wood_colors(Half(), p, (0.0, 0.0, 1.0))               # one normal for all points
    assert out.shape == (5, 3) and np.all(out == 0.5)
    with pytest.raises(WoodcamError, match="wood must have a method color"):
        wood_colors(object(), p, (0.0, 0.0, 1.0))
