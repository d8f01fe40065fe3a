"""Every compiled (numba) kernel against its numpy reference.

A fast kernel restates maths that has a plain home elsewhere; these tests tie each to that
home, so the two cannot drift apart (as the knot shading of the colour map and of the section
renderer once did):

- ``appearance.colormap._shade_kernel``: the species ramp (:meth:`ColorMapAppearance.ramp`),
  :class:`~woodcam.appearance.knots.KnotShading` and eq. 10 (:func:`blend_axis_colors`; both
  use ``orientation.eq10_weights``, whose numpy reference is in tests/appearance/test_colormap.py).
- ``appearance.noise`` (``noise_at``, ``_value_noise_kernel``): a numpy value noise below.
- ``appearance.volumes._detailed_kernel``: trilinear lookups (``_trilinear``) plus the slope.
- ``fields.radial._radial_kernel``: :meth:`RadialScalingField.radius_scale` (eq. 7-9).
- ``fields._knots_numba``: the numpy backend of :class:`KnottedLogField`.
"""

import numpy as np
import pytest

from woodcam.appearance.colormap import ColorMapAppearance, Species
from woodcam.appearance.knots import KnotShading
from woodcam.appearance.orientation import blend_axis_colors
from woodcam.fields.base import LogFrame, arf

RNG = np.random.default_rng(11)


class _KnottedStub:
    """A field with chosen years, grain and knot features (``evaluate(directions=True)``)."""

    def __init__(self, n):
        self.years = RNG.uniform(0, 30, n)
        g = RNG.normal(size=(n, 3))
        self.grain = g / np.linalg.norm(g, axis=1, keepdims=True)
        self.feats = {"knot": RNG.uniform(0, 1, n), "dead": RNG.uniform(0, 1, n) * (RNG.uniform(size=n) < 0.5),
                      "outline": RNG.uniform(0, 1, n) * (RNG.uniform(size=n) < 0.3)}

    def evaluate(self, points_mm, directions=False):
        return {"years": self.years, "direction": self.grain, **self.feats}


def test_colour_kernel_is_ramp_then_knot_shading_then_eq10():
    """With the texture switched off (no pores, streaks or end-grain terms), every per-axis
    colouring is the species ramp shaded by KnotShading, and the blended colour is eq. 10 of
    the three."""
    n = 4000
    flat = Species("flat", (0.9, 0.8, 0.6), (0.5, 0.35, 0.2), latewood_start=0.4, pore_contrast=0.0,
                   streak_contrast=0.0, endgrain_darkening=0.0, endgrain_roughness=0.0)
    shading = KnotShading(0.3, 0.5, (0.1, 0.05, 0.02))
    app = ColorMapAppearance(flat, knots=shading)
    field = _KnottedStub(n)
    p = RNG.uniform(0, 50, (n, 3))
    expected = shading.apply(app.ramp(arf(field.years)), field.feats)
    axes = app.axis_colors(field, p)
    for k in range(3):
        np.testing.assert_allclose(axes[k], expected, atol=2e-5)
    normals = RNG.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    np.testing.assert_allclose(app.color(field, p, normals), blend_axis_colors(*axes, normals), atol=2e-5)


def test_colour_kernel_blend_is_eq10_with_texture_on():
    """The one-pass blend equals eq. 10 of the kernel's own per-axis colourings (oak: pores,
    streaks, end grain all on)."""
    n = 3000
    app = ColorMapAppearance("oak")
    field = _KnottedStub(n)
    p = RNG.uniform(0, 50, (n, 3))
    normals = RNG.normal(size=(n, 3))
    np.testing.assert_allclose(app.color(field, p, normals / np.linalg.norm(normals, axis=1)[:, None]),
                               blend_axis_colors(*app.axis_colors(field, p), normals), atol=2e-5)


def _value_noise_numpy(q, table, seed):
    """The hashed lattice value noise of appearance/noise.py, vectorised in numpy."""
    from woodcam.appearance import noise

    f = np.floor(q)
    t = q - f
    w = t * t * (3 - 2 * t)
    fi = f.astype(np.int64)
    mask = len(table) - 1
    h0 = [fi[:, 0] * noise._PX + np.int64(seed) * 2654435761, fi[:, 1] * noise._PY, fi[:, 2] * noise._PZ]
    h1 = [h0[0] + noise._PX, h0[1] + noise._PY, h0[2] + noise._PZ]

    def c(a, b, d):
        return table[((h1[0] if a else h0[0]) ^ (h1[1] if b else h0[1]) ^ (h1[2] if d else h0[2])) & mask]

    x00 = c(0, 0, 0) + w[:, 0] * (c(1, 0, 0) - c(0, 0, 0))
    x10 = c(0, 1, 0) + w[:, 0] * (c(1, 1, 0) - c(0, 1, 0))
    x01 = c(0, 0, 1) + w[:, 0] * (c(1, 0, 1) - c(0, 0, 1))
    x11 = c(0, 1, 1) + w[:, 0] * (c(1, 1, 1) - c(0, 1, 1))
    y0 = x00 + w[:, 1] * (x10 - x00)
    y1 = x01 + w[:, 1] * (x11 - x01)
    return y0 + w[:, 2] * (y1 - y0)


@pytest.mark.parametrize("seed", [0, 7])
def test_value_noise_kernel_matches_numpy(seed):
    from woodcam.appearance.noise import TABLE, value_noise

    q = RNG.uniform(-40, 40, (5000, 3)).astype(np.float32)
    np.testing.assert_allclose(value_noise(q, seed), _value_noise_numpy(q.astype(np.float64), TABLE, seed),
                               atol=1e-5)


def test_detailed_volume_kernel_is_trilinear_plus_slope():
    from woodcam.appearance.volumes import _detailed_kernel, _trilinear

    shape = (5, 6, 7)
    m = int(np.prod(shape))
    vol = RNG.integers(0, 256, shape + (3,)).astype(np.uint8)
    guides = RNG.uniform(0, 1, shape).astype(np.float32)
    slopes = RNG.normal(0, 0.3, shape + (3,)).astype(np.float32)
    n = 2000
    # corners of random points inside the grid (as ColorVolumes._corners makes them)
    t = RNG.uniform(0, np.array(shape) - 1.0001, (n, 3))
    i0 = t.astype(np.int64)
    f = (t - i0).astype(np.float32)
    idx = np.empty((8, n), np.int64)
    w = np.empty((8, n), np.float32)
    k = 0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                idx[k] = ((i0[:, 0] + dx) * shape[1] + i0[:, 1] + dy) * shape[2] + i0[:, 2] + dz
                w[k] = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
                        * (f[:, 2] if dz else 1 - f[:, 2]))
                k += 1
    guide = RNG.uniform(0, 1, n).astype(np.float32)
    out = np.empty((n, 3), np.float32)
    _detailed_kernel(idx, w, vol.reshape(m, 3), guides.reshape(m), slopes.reshape(m, 3), guide, out)
    ref = (_trilinear(vol, (idx, w)) / 255.0
           + _trilinear(slopes, (idx, w)) * (guide - _trilinear(guides[..., None], (idx, w))[:, 0])[:, None])
    np.testing.assert_allclose(out, np.clip(ref, 0, 1), atol=2e-5)


def test_radial_kernel_is_eq_7_to_9():
    from woodcam.fields.radial import RadialScalingField, RadiusFunction

    frame = LogFrame((10.0, -60.0, 5.0), (0.1, 0.05, 1.0), (1.0, 0.2, 0.0))
    f = RadialScalingField(frame, 2.5, RadiusFunction.random(np.random.default_rng(1)),
                           RadiusFunction.random(np.random.default_rng(2)), 40.0, age_offset_years=3.0)
    p = RNG.uniform(0, 80, (5000, 3))
    loc = frame.to_log(p)
    phi = np.arctan2(loc[:, 0], loc[:, 1])                  # from (0, 1) to (x, y), eq. 7
    ref = 3.0 + np.hypot(loc[:, 0], loc[:, 1]) / (2.5 * f.radius_scale(phi, loc[:, 2] / 40.0))
    np.testing.assert_allclose(f(p), ref, rtol=1e-9, atol=1e-9)


def test_knot_field_numba_backend_matches_numpy():
    from woodcam.fields.knots import KnottedLogField, available_backends
    from woodcam.logs.generate import generate_log

    if "numba" not in available_backends():
        pytest.skip("numba backend not available")
    log = generate_log(3, length_mm=600.0).to_skeleton()
    a, b = KnottedLogField(log, backend="numpy"), KnottedLogField(log, backend="numba")
    r = RNG.uniform(20, 120, 6000)
    th = RNG.uniform(0, 2 * np.pi, 6000)
    p = np.stack([r * np.cos(th), r * np.sin(th), RNG.uniform(50, 550, 6000)], axis=1)
    ea, eb = a.evaluate(p), b.evaluate(p)
    for key in ("years", "knot", "dead", "outline"):
        np.testing.assert_allclose(eb[key], ea[key], atol=1e-6, err_msg=key)
    assert ea["knot"].max() > 0.5  # the points do meet knots
