"""Perspective views of a height-field stock, drawn with numba (no VTK).

Data form. The simulated stock is ``heightmap : (ny, nx)`` (block-frame Z in mm at the cell
centres over ``[0, W] x [0, D]``, :mod:`woodcam.toolpath.simulate`) in the block
``size_mm = (W, D, H)``; its surface is the height field's vertex grid with four walls and a
bottom (:mod:`woodcam.toolpath.mesh`), and its colours are the baked atlas ``texture : (h, w, 3)
uint8`` whose six planar charts (``charts``: name -> ``(x0, y0, width, height, ...)`` px, as
:class:`woodcam.toolpath.mesh.HeightfieldCharts`) hold the top seen from +Z, the bottom and the
four walls.

What is drawn is what :func:`woodcam.view.preview` draws of the same stock, from the same
camera (:func:`woodcam.view.camera.frame_camera`, 30 degree perspective): the stock lit by
VTK's default light kit (Lambert + Phong, the preview's material), with a wood: the half toward
the camera cut away at the block's centre plane (:func:`woodcam.view.camera.default_cut_normal`)
and the wood on that plane, opaque inside the stock and translucent in the waste; the block as
translucent faces with dark edges; the toolpath over it (lines on the surface are hidden, as
VTK's depth test hides them). It is rendered at ``supersample`` times the size and averaged
down (anti-aliasing). On the 20,000-move raster this takes ~0.5 CPU-s where the VTK screenshot
took ~3 (imports, scene, render); the interactive window stays with VTK.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._types import ArrayLike, PathLike, WoodLike
from ..errors import WoodcamError
from ..frames import check_size
from .camera import UNCUT_CAMERAS, Camera, check_camera, default_cut_normal, frame_camera

#: VTK's default light kit (vtkLightKit, pyvista's default lighting) in camera coordinates:
#: (elevation deg, azimuth deg, intensity) of the key, fill, two back lights and the headlight
#: (key 0.75; key-to-fill 3, key-to-back 3.5, key-to-head 6).
_LIGHT_KIT = ((50.0, 10.0, 0.75), (-75.0, -10.0, 0.25), (0.0, 110.0, 0.75 / 3.5),
              (0.0, -110.0, 0.75 / 3.5), (0.0, 0.0, 0.125))
#: The stock's material as the preview sets it: ambient, diffuse, specular, specular power.
_MATERIAL = np.array([0.25, 0.8, 0.15, 20.0])
#: A toolpath line is drawn where it lies this far (mm) in front of the surface: lines on the
#: surface (a finishing pass's tip path) stay hidden, as VTK's depth test hides them (a line's
#: dots land up to a pixel, ~0.05 mm, beside it, where a slope is higher or lower).
_LINE_BIAS_MM = 0.15
#: The block's edges and the section outline are drawn where they lie up to this far (mm)
#: behind the surface: they run along the stock's own edges.
_EDGE_BIAS_MM = -0.2
_NEAR_MM = 1e-3


def _camera_array(camera, size, window_size, supersample):
    """The kernels' ``cam : (16,)`` (woodcam.view._zbuffer) for a named camera."""
    W, D, H = size
    position, focal, up = frame_camera(camera, (0.0, W, 0.0, D, 0.0, H), window_size)
    forward = focal - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    h_px = window_size[1] * supersample
    f = 0.5 * h_px / np.tan(np.radians(30.0) / 2)  # VTK's view angle: 30 degrees vertically
    return np.concatenate([position, right, up, forward,
                           [f, 0.5 * window_size[0] * supersample, 0.5 * h_px, _NEAR_MM]])


def _lights(cam):
    """The light kit in the block frame: ``(k, 4)`` unit direction towards the light and
    intensity."""
    right, up, back = cam[3:6], cam[6:9], -cam[9:12]
    out = []
    for el, az, intensity in _LIGHT_KIT:
        e, a = np.radians(el), np.radians(az)
        d = np.sin(a) * np.cos(e) * right + np.sin(e) * up + np.cos(a) * np.cos(e) * back
        out.append([*d / np.linalg.norm(d), intensity])
    return np.asarray(out)


def _walls(hm, size):
    """The four walls (quad strips from Z = 0 up to the border vertices) and the bottom as
    triangles ``(m, 3, 3)`` mm with their surface ids ``(m,)``."""
    from ._zbuffer import BACK, BOTTOM, FRONT, LEFT, RIGHT

    W, D, _ = size
    ny, nx = hm.shape

    def axis(n, L):
        return np.concatenate([[0.0], (np.arange(n) + 0.5) * L / n, [L]])

    xs, ys = axis(nx, W), axis(ny, D)
    ci = np.clip(np.arange(nx + 2) - 1, 0, nx - 1)
    cj = np.clip(np.arange(ny + 2) - 1, 0, ny - 1)
    tris, ids = [], []
    for sid, u, zt, fixed in ((FRONT, xs, hm[0, ci], (1, 0.0)), (BACK, xs, hm[-1, ci], (1, D)),
                              (LEFT, ys, hm[cj, 0], (0, 0.0)), (RIGHT, ys, hm[cj, -1], (0, W))):
        k = len(u) - 1
        corner = np.zeros((k, 4, 3))
        other = 1 - fixed[0]  # the coordinate running along the wall
        corner[:, :, fixed[0]] = fixed[1]
        corner[:, 0, other], corner[:, 1, other] = u[:-1], u[1:]
        corner[:, 2, other], corner[:, 3, other] = u[1:], u[:-1]
        corner[:, 2, 2], corner[:, 3, 2] = zt[1:], zt[:-1]
        tris += [corner[:, [0, 1, 2]], corner[:, [0, 2, 3]]]
        ids.append(np.full(2 * k, sid))
    tris.append(np.array([[[0, 0, 0], [W, 0, 0], [W, D, 0]], [[0, 0, 0], [W, D, 0], [0, D, 0]]],
                         float))
    ids.append(np.full(2, BOTTOM))
    tri, sid = np.vstack(tris), np.concatenate(ids).astype(np.int64)
    # counter-clockwise seen from outside (the rasteriser skips faces turned away)
    outward = np.array([[0, 0, 1], [0, 0, -1], [0, -1, 0], [0, 1, 0], [-1, 0, 0],
                        [1, 0, 0]], float)[sid]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.einsum("ij,ij->i", n, outward) < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return np.ascontiguousarray(tri), sid


def _section(wood, hm, size, normal, origin):
    """The wood on the cut plane: ``(axis, at_mm, colours (nv, nu, 3) float32 0..255, span
    (2,) mm, outline segments (k, 2, 3) mm)``."""
    from ..appearance.wood import wood_colors
    from ..toolpath.surface import surface_points
    from .scene import SECTION_MAX_SAMPLES_SCREENSHOT, SECTION_RESOLUTION_MM

    axis = int(np.argmax(np.abs(normal)))
    at = float(origin[axis])
    a, b = [i for i in range(3) if i != axis]
    span = np.array([size[a], size[b]], float)
    step = max(SECTION_RESOLUTION_MM, float(np.sqrt(span.prod() / SECTION_MAX_SAMPLES_SCREENSHOT)))
    nu, nv = (np.ceil(span / step).astype(int) + 1).clip(min=2)
    gu, gv = np.meshgrid(np.linspace(0, span[0], nu), np.linspace(0, span[1], nv))
    pts = np.empty((gu.size, 3))
    pts[:, axis], pts[:, a], pts[:, b] = at, gu.ravel(), gv.ravel()
    rgb = wood_colors(wood, pts, normal).reshape(nv, nu, 3) * np.float32(255)
    outline = np.empty((0, 2, 3))
    if axis != 2:  # a vertical plane cuts the stock along its top profile, walls and bottom
        W, D, _ = size
        n = max(2, int(np.ceil(4 * max(hm.shape) * span[0] / max(W, D))) + 1)
        u = np.linspace(0, span[0], n)
        xy = np.zeros((n, 2))
        xy[:, axis], xy[:, a] = at, u
        z, _ = surface_points(np.ascontiguousarray(hm, float), W, D, xy[:, 0], xy[:, 1])
        p = np.zeros((n, 3))
        p[:, :2], p[:, 2] = xy, z
        ends = [p[:-1], p[1:]]
        base = p.copy()
        base[:, 2] = 0.0
        segs = [np.stack(ends, axis=1), np.stack([base[[0, -1]], p[[0, -1]]], axis=1),
                np.stack([base[0], base[-1]])[None]]
        outline = np.vstack(segs)
    return axis, at, np.ascontiguousarray(rgb, np.float32), span, outline


def stock_view(heightmap: ArrayLike, size_mm: ArrayLike, texture: np.ndarray, charts: dict, *,
               wood: WoodLike | None = None, camera: Camera = "iso",
               overlay: list[tuple] | None = None, window_size: tuple[int, int] = (1280, 960),
               supersample: int = 2,
               background: object = (255, 255, 255)) -> np.ndarray:
    """The stock seen from ``camera``: an ``(h, w, 3) uint8`` image (module docstring).

    Parameters
    ----------
    heightmap : (ny, nx) float
        Block-frame Z (mm) at the cell centres.
    size_mm : (W, D, H)
    texture : (th, tw, 3) uint8
        The baked atlas.
    charts : dict
        ``name -> (x0, y0, width, height, ...)`` px of the atlas's "top", "bottom", "front",
        "back", "left" and "right" charts (:class:`woodcam.toolpath.mesh.HeightfieldCharts`).
    wood : object with ``color(points_mm (n, 3), normals (n, 3))``, optional
        Colours the cut plane; without it the stock is drawn whole.
    camera : "iso" | "top" | "front" | "back" | "left" | "right" | "bottom"
    overlay : list of (segments (k, 2, 3) mm, colour, width px), optional
        Block-frame segments (e.g. the toolpath), ``colour`` a name or hex string of
        matplotlib's table (e.g. "royalblue") or an RGB triple (whole numbers in 0..255 or
        floats in 0..1), as :func:`woodcam.view.preview` reads them
        (:func:`woodcam.view.scene.colour_rgb`); widths in pixels of the
        supersampled picture, as VTK's SSAA draws them (1 px there is half a pixel of the image).
    window_size : (width, height) px
    supersample : int
        Render at this many times the size and average down (1 = no anti-aliasing).
    background : colour
        Where no stock, block or section is seen; by the views' one colour rule
        (:func:`woodcam.view.scene.colour_rgb`, as preview's background): a name or hex string
        of matplotlib's table, whole numbers in 0..255 or floats in 0..1; default white.
    """
    from . import _zbuffer as zb
    from .scene import (BLOCK_COLOR, BLOCK_EDGE_COLOR, BLOCK_OPACITY, OUTLINE_COLOR, WASTE_OPACITY,
                        colour_rgb)

    hm = np.ascontiguousarray(heightmap, dtype=np.float64)
    size = check_size(size_mm)
    check_camera(camera)
    tex = np.ascontiguousarray(texture)
    if hm.ndim != 2 or min(hm.shape) < 1 or tex.ndim != 3 or tex.shape[2] != 3:
        raise WoodcamError(f"stock_view: heightmap must be (ny, nx) and texture (h, w, 3); got "
                           f"{hm.shape} and {tex.shape}")
    names = ("top", "bottom", "front", "back", "left", "right")
    missing = [n for n in names if n not in charts]
    if missing:
        raise WoodcamError(f"stock_view: charts lacks {missing}; pass HeightfieldCharts.charts")
    rect = np.array([[int(v) for v in charts[n][:4]] for n in names], np.int64)
    if (rect[:, 0] + rect[:, 2] > tex.shape[1]).any() or (rect[:, 1] + rect[:, 3]
                                                          > tex.shape[0]).any():
        raise WoodcamError(f"stock_view: a chart lies outside the {tex.shape[1]} x "
                           f"{tex.shape[0]} px texture; pass the atlas the charts belong to")
    ws = np.asarray(window_size)
    if ws.shape != (2,) or np.any(ws < 16) or np.any(ws % 1):
        raise WoodcamError(f"window_size must be two integers >= 16 (width, height) px; got "
                           f"{window_size!r}; e.g. (1280, 960)")
    if not (isinstance(supersample, (int, np.integer)) and 1 <= supersample <= 4):
        raise WoodcamError(f"supersample must be an integer 1..4; got {supersample!r}; e.g. 2")
    # read as 0..255 whatever it was: (1.0, 1.0, 1.0) drew nearly black, "white" was numpy's
    # bare ValueError, where preview drew both white
    bg = colour_rgb(background, "stock_view", "background")
    window = (int(ws[0]), int(ws[1]))
    s = int(supersample)
    w, h = window[0] * s, window[1] * s
    cam = _camera_array(camera, size, window, s)
    clip = np.array([0.0, 0.0, 0.0, 1.0])  # 0 > 1 never holds: nothing clipped
    section, axis, at, span, outline = np.zeros((2, 2, 3), np.float32), -1, 0.0, np.ones(2), None
    if wood is not None and camera not in UNCUT_CAMERAS:  # top/bottom: the outside, as preview's
        normal = default_cut_normal(camera, size)
        origin = size / 2
        clip = np.array([*normal, float(normal @ origin)])
        axis, at, section, span, outline = _section(wood, hm, size, normal, origin)

    depth = np.full(w * h, np.inf, np.float32)
    pos = np.empty((w * h, 3), np.float32)
    sid = np.full(w * h, -1, np.int8)
    zb.draw_heightfield(hm, size[0], size[1], cam, clip, w, h, depth, pos, sid)
    tri, ids = _walls(hm, size)
    zb.draw_triangles(tri, ids, cam, clip, w, h, depth, pos, sid)
    out = np.empty((w * h, 3), np.float32)
    block = np.array([*(255 * np.asarray(BLOCK_COLOR)), BLOCK_OPACITY])
    zb.shade(depth, pos, sid, w, h, cam, hm, size, tex, rect, _lights(cam), _MATERIAL, section,
             axis, at, span, block, WASTE_OPACITY, bg, out)
    del pos, sid
    bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
    corners = bits * size
    pairs = [(i, i | (1 << a)) for i in range(8) for a in range(3) if not i & (1 << a)]
    edges = np.stack([corners[[p for p, _ in pairs]], corners[[q for _, q in pairs]]], axis=1)
    lines = [(edges, 255 * np.asarray(BLOCK_EDGE_COLOR), 2, _EDGE_BIAS_MM)]
    if outline is not None and len(outline):
        lines.append((outline, 255 * np.asarray(OUTLINE_COLOR), 3, _EDGE_BIAS_MM))
    for segments, colour, width in overlay or ():
        lines.append((np.asarray(segments, float).reshape(-1, 2, 3), colour_rgb(colour, "stock_view"),
                      max(1, int(round(float(width)))), _LINE_BIAS_MM))
    for seg, rgb, width, bias in lines:
        if len(seg):
            zb.draw_lines(np.ascontiguousarray(seg, np.float64), np.asarray(rgb, float), 1.0,
                          int(width), float(bias), cam, w, h, depth, out)
    blocks = out.reshape(window[1], s, window[0], s, 3)
    img = np.zeros((window[1], window[0], 3), np.float32)
    for dy in range(s):  # the s x s block means, as strided sums (faster than .mean(axis))
        for dx in range(s):
            img += blocks[:, dy, :, dx]
    return np.clip(np.rint(img / (s * s)), 0, 255).astype(np.uint8)


def write_stock_view(path: PathLike, heightmap: ArrayLike, size_mm: ArrayLike,
                     texture: np.ndarray, charts: dict, **kwargs) -> Path:
    """:func:`stock_view` written as a PNG at ``path`` (atomically); returns the path."""
    import io

    from PIL import Image

    from .._atomic import write_bytes

    buf = io.BytesIO()
    Image.fromarray(stock_view(heightmap, size_mm, texture, charts, **kwargs)).save(
        buf, format="PNG", compress_level=1)
    return write_bytes(Path(path), buf.getvalue())
