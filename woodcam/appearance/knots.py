"""Knot shading: how knot wood is coloured, the one home for every renderer and both CLIs.

Seed 003 (sec. 4.3, user parameters "darken strength for knots", "darken strength for dead
knots", "outline thickness for dead knots"): after a colour map turns growth time into wood
colour, knot wood is darkened and dead knots get a dark bark ring. The field supplies the
weights (``knot``, ``dead``, ``outline``, each ``(n,)`` in 0..1, from
``KnottedLogField.knot_features``; the outline's thickness is a field parameter,
``KnotParams.outline_mm``); :class:`KnotShading` turns them into colour::

    rgb = rgb (1 - alive_darkening knot) (1 - dead_darkening dead)
    rgb = rgb (1 - outline) + outline_rgb outline

The colour map's compiled kernel (:mod:`woodcam.appearance.colormap`) does the same per point;
``tests/test_fast_kernels.py`` ties it to :meth:`KnotShading.apply`.

Defaults: the colour map's (0.25 / 0.45, outline (0.16, 0.10, 0.06)), chosen over the section
renderer's former 0.35 / 0.30 / (0.22, 0.14, 0.08) because they are what ``woodcam bake`` and the
demo have shipped and documented (``--knot-darkening``), and they keep live knots close to the
stem wood while dead knots, which are encased with bark and resin, read clearly darker (41 % of
the wood's brightness instead of 46 %).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import WoodcamError


@dataclass(frozen=True)
class KnotShading:
    """How knot wood is coloured (see module docstring).

    Attributes
    ----------
    alive_darkening : float in [0, 1]
        Relative darkening of knot wood (weight ``knot``).
    dead_darkening : float in [0, 1]
        Extra relative darkening of dead knot wood (weight ``dead``).
    outline_rgb : (3,) float in [0, 1]
        Colour of the bark ring round dead knots (weight ``outline``).
    """

    alive_darkening: float = 0.25
    dead_darkening: float = 0.45
    outline_rgb: tuple[float, float, float] = (0.16, 0.10, 0.06)

    def __post_init__(self):
        for name in ("alive_darkening", "dead_darkening"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.floating)) and 0.0 <= v <= 1.0):
                raise WoodcamError(f"KnotShading.{name} must be a number in [0, 1]; got {v!r}; "
                                   f"e.g. {getattr(KnotShading, name)}")
        try:
            rgb = tuple(float(c) for c in self.outline_rgb)
        except (TypeError, ValueError):
            rgb = ()
        if len(rgb) != 3 or not all(0.0 <= c <= 1.0 for c in rgb):
            raise WoodcamError("KnotShading.outline_rgb must be three numbers in [0, 1]; got "
                               f"{self.outline_rgb!r}; e.g. (0.16, 0.10, 0.06)")
        object.__setattr__(self, "outline_rgb", rgb)

    def factor(self, knot, dead) -> np.ndarray:
        """Brightness factor ``(n,)`` of knot wood: ``(1 - a knot) (1 - d dead)``."""
        return ((1.0 - self.alive_darkening * np.asarray(knot, float))
                * (1.0 - self.dead_darkening * np.asarray(dead, float)))

    def apply(self, rgb, features: dict) -> np.ndarray:
        """Shade colours ``rgb (n, 3)`` in [0, 1] by knot ``features`` (``knot``, ``dead``,
        ``outline``, each ``(n,)``); returns ``(n, 3)`` float in [0, 1]."""
        c = np.asarray(rgb, float) * self.factor(features["knot"], features["dead"])[:, None]
        ol = np.asarray(features["outline"], float)[:, None]
        c = c * (1.0 - ol) + np.asarray(self.outline_rgb, float)[None, :] * ol
        return np.clip(c, 0.0, 1.0)
