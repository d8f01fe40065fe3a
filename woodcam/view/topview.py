"""Orthographic top view of a height-field stock drawn with numpy (no VTK).

Seen from +Z, a height-field stock is its top chart: the baked atlas's top chart
(:class:`woodcam.toolpath.mesh.HeightfieldCharts`) already holds the wood colour of every texel
of the surface at its XY, so the view is that image, shaded by the surface normal from the
height field's gradient (Lambert, light from the upper left, flat = the baked colour), with the
toolpath drawn over it. It costs ~0.1 s where an off-screen VTK render of the same stock costs
seconds (import, scene, render); the perspective views are :mod:`woodcam.view.stockview`'s.
"""

from __future__ import annotations

import numpy as np

from ..errors import WoodcamError

#: Direction towards the light (block frame), upper left and above; and the ambient share.
_LIGHT = np.array([-0.4, 0.4, 1.0]) / np.linalg.norm([-0.4, 0.4, 1.0])
_AMBIENT = 0.35
#: Overlay opacity (colours: :func:`woodcam.view.scene.colour_rgb`, as the VTK overlay).
_OVERLAY_ALPHA = 0.55
_OVERLAY_COVER = 0.08


def top_view(heightmap, size_mm, top_texels, *, overlay=None,
             window_size: tuple[int, int] = (1280, 960), margin_px: int = 24,
             background: object = (255, 255, 255)) -> np.ndarray:
    """The stock seen from +Z: an ``(h, w, 3) uint8`` image, +X right, +Y up.

    Parameters
    ----------
    heightmap : (ny, nx) float
        Block-frame Z (mm) at the cell centres over the stock's XY.
    size_mm : (W, D, H)
    top_texels : (th, tw, 3) uint8
        The atlas's top chart, row 0 at ``Y = D`` (the chart's own orientation).
    overlay : list of (segments (k, 2, 3) mm, colour, width px), optional
        Block-frame segments drawn over the stock (``colour`` a name or hex string of
        matplotlib's table, e.g. "royalblue", or an RGB triple: whole numbers in 0..255 or floats
        in 0..1, :func:`woodcam.view.scene.colour_rgb`), as :func:`woodcam.view.preview` takes
        them and in the same colour.
    window_size : (width, height) px
        The image size; the stock is fitted inside with ``margin_px``, the rest ``background``.
    background : colour
        Round the stock; by the views' one colour rule (:func:`woodcam.view.scene.colour_rgb`,
        as stock_view's and preview's background): a name or hex string of matplotlib's table,
        whole numbers in 0..255 or floats in 0..1; default white.
    """
    from .scene import colour_rgb

    hm = np.asarray(heightmap, float)
    tex = np.asarray(top_texels)
    if hm.ndim != 2 or tex.ndim != 3 or tex.shape[2] != 3:
        raise WoodcamError(f"top_view: heightmap must be (ny, nx) and top_texels (h, w, 3); "
                           f"got {hm.shape} and {tex.shape}")
    W, D, _ = (float(v) for v in size_mm)
    ww, wh = (int(v) for v in window_size)
    scale = min((ww - 2 * margin_px) / W, (wh - 2 * margin_px) / D)  # px per mm
    if scale <= 0:
        raise WoodcamError(f"top_view: window_size {window_size} leaves no room inside the "
                           f"{margin_px} px margin; give at least {2 * margin_px + 16} px a side")
    pw, ph = max(1, int(round(W * scale))), max(1, int(round(D * scale)))
    ox, oy = (ww - pw) // 2, (wh - ph) // 2
    # pixel centres -> block XY -> texel and cell (nearest)
    x = (np.arange(pw) + 0.5) / scale
    y = D - (np.arange(ph) + 0.5) / scale
    tx = np.clip((x / W * tex.shape[1]).astype(int), 0, tex.shape[1] - 1)
    ty = np.clip(((D - y) / D * tex.shape[0]).astype(int), 0, tex.shape[0] - 1)
    ny, nx = hm.shape
    cx = np.clip((x / W * nx).astype(int), 0, nx - 1)
    cy = np.clip((y / D * ny).astype(int), 0, ny - 1)
    gy, gx = np.gradient(hm, D / ny, W / nx)
    n = np.stack([-gx, -gy, np.ones_like(hm)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    lit = _AMBIENT + (1 - _AMBIENT) * np.clip(n @ _LIGHT, 0.0, None)
    shade = (lit / (_AMBIENT + (1 - _AMBIENT) * _LIGHT[2]))[np.ix_(cy, cx)]  # flat -> 1
    rgb = tex[np.ix_(ty, tx)].astype(np.float32) * shade[..., None].astype(np.float32)
    # stock_view's and preview's rule: top_view was always white, the others took a colour
    img = np.full((wh, ww, 3), colour_rgb(background, "top_view", "background"), np.float32)
    img[oy:oy + ph, ox:ox + pw] = np.clip(rgb, 0, 255)
    for segments, colour, width in overlay or ():
        _draw_segments(img, np.asarray(segments, float).reshape(-1, 2, 3), colour,
                       float(width), scale, D, ox, oy)
    return np.round(img).astype(np.uint8)


def _draw_segments(img, seg, colour, width, scale, D, ox, oy) -> None:
    """Blend XY segments (mm) into ``img`` as dots every half pixel, ``width`` px wide."""
    from .scene import colour_rgb

    rgb = colour_rgb(colour, "top_view").astype(np.float32)  # checked even with no segments
    if not len(seg):
        return
    p0 = np.column_stack([ox + seg[:, 0, 0] * scale, oy + (D - seg[:, 0, 1]) * scale])
    p1 = np.column_stack([ox + seg[:, 1, 0] * scale, oy + (D - seg[:, 1, 1]) * scale])
    steps = np.maximum(np.ceil(2 * np.linalg.norm(p1 - p0, axis=1)).astype(int), 1)
    k = np.repeat(np.arange(len(seg)), steps + 1)
    t = (np.arange(k.size) - np.repeat(np.cumsum(steps + 1) - (steps + 1), steps + 1)) \
        / np.repeat(steps, steps + 1)
    pts = p0[k] + t[:, None] * (p1[k] - p0[k])
    r = max(0, int(round(width)) - 1) // 2
    h, w = img.shape[:2]
    hit = np.zeros((h, w), bool)
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            px = np.floor(pts[:, 0]).astype(int) + dx
            py = np.floor(pts[:, 1]).astype(int) + dy
            ok = (px >= 0) & (px < w) & (py >= 0) & (py < h)
            hit[py[ok], px[ok]] = True
    # a dense raster (passes a few pixels apart) would hide the surface: fade it so the lines
    # cover about _OVERLAY_COVER of the picture's ink at most
    alpha = _OVERLAY_ALPHA * min(1.0, _OVERLAY_COVER / max(hit.mean(), 1e-9))
    img[hit] = (1 - alpha) * img[hit] + alpha * rgb


def write_top_view(path, heightmap, size_mm, top_texels, **kwargs):
    """:func:`top_view` written as a PNG at ``path`` (atomically); returns the path."""
    import io
    from pathlib import Path

    from PIL import Image

    from .._atomic import write_bytes

    buf = io.BytesIO()
    Image.fromarray(top_view(heightmap, size_mm, top_texels, **kwargs)).save(
        buf, format="PNG", compress_level=1)
    return write_bytes(Path(path), buf.getvalue())
