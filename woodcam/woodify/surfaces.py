"""Grown surfaces at any year, attributes carried back to the input, ring sections.

- :func:`surface_at`: the grown solid ``{T <= tau(t)}`` minus the obstacles (with a small
  clearance, tolerances.py) as a watertight triangle mesh (marching cubes, scikit-image),
  object frame, mm, outward normals.
- :func:`trace_back`: every grown point maps back to where it came from on the input surface
  (seed sec. 4.3.1, persistent texturing): it follows the characteristic of the front
  backwards, ``dx/dT = -(n + w) / (g (1 + w . n))`` with ``n = grad T / |grad T|`` (for the
  isotropic case the straight normal back to the closest point), until ``T <= 0``, then snaps to
  the closest input triangle. Texture coordinates and vertex attributes are interpolated there
  with barycentric weights, so an input texture stays put while the object grows (Fig. 4.6).
- :func:`section_image`: a plane cut through the field as an RGB image with the rings
  (integer years) drawn, the input in grey and obstacles black (seed Fig. 5.1);
  :func:`with_scale_bar` puts a scale bar of a round length (:func:`scale_bar_mm`) under it.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..errors import WoodcamError
from ..tolerances import WOODIFY_OBSTACLE_CLEARANCE_VOXELS
from ..units import MM_PER_UNIT, Units, fmt_length


def _solid_level(front, tau_mm: float) -> np.ndarray:
    """Level function (mm), negative inside the grown solid at pseudo-time ``tau_mm``."""
    T = np.where(np.isfinite(front.arrival_mm), front.arrival_mm, 1e9)
    phi = T - tau_mm
    if front.obstacle_sdf_mm is not None:
        eps = WOODIFY_OBSTACLE_CLEARANCE_VOXELS * front.grid.spacing_mm
        phi = np.maximum(phi, eps - front.obstacle_sdf_mm)
    return phi


def surface_at(front, tau_mm: float):
    """Watertight grown surface at pseudo-time ``tau_mm`` (object frame, mm) as a trimesh."""
    import trimesh
    from skimage import measure

    if not tau_mm >= 0:
        raise WoodcamError(f"tau_mm must be >= 0 (pseudo-time in mm); got {tau_mm!r}")
    phi = _solid_level(front, tau_mm)
    big = float(np.max(np.abs(phi[np.isfinite(phi)]))) + 1.0
    # pad with outside so a solid touching the grid border still closes
    phi = np.pad(np.minimum(phi, big), 1, constant_values=big).astype(np.float32)
    if phi.min() >= 0:
        raise WoodcamError(f"nothing is grown at pseudo-time {tau_mm:.3g} mm")
    verts, faces, _, _ = measure.marching_cubes(phi, level=0.0, spacing=(front.grid.spacing_mm,) * 3,
                                                allow_degenerate=False)
    verts = verts - front.grid.spacing_mm + np.asarray(front.grid.origin_mm)
    mesh = trimesh.Trimesh(verts, faces[:, ::-1], process=True)
    # skimage orients faces towards increasing values; reversed, normals point outwards
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def trace_grids(front):
    """The grids :func:`trace_back` interpolates, built once per front and kept on it.

    Returns ``(T, grads, t_max)``: ``T (nx, ny, nz) float32`` the arrival time with the nodes
    never reached set to ``t_max`` (mm, the largest finite arrival), and ``grads`` its three
    partial derivatives (float32 grids, central differences in float64 first). A crack run
    traces back twice per year; rebuilding these each call was most of its grid work. The
    cache (16 bytes a node) is tied to the ``front.arrival_mm`` array object (see
    :class:`~.front.Front`).
    """
    cache = front._trace_cache
    if cache is not None and cache[0] is front.arrival_mm:
        return cache[1:]
    A = front.arrival_mm
    finite = np.isfinite(A)
    t_max = float(np.max(A[finite])) if finite.any() else float("nan")
    Tf = np.where(finite, A, t_max)
    h = front.grid.spacing_mm
    # one axis at a time: the float64 differences of a 200^3 grid are 64 MB each
    grads = tuple(np.gradient(Tf, h, axis=d).astype(np.float32) for d in range(3))
    out = (Tf.astype(np.float32), grads, t_max)
    front._trace_cache = (A, *out)
    return out


def trace_back(front, points_mm, wind=None, step_voxels: float = 0.5, until_mm: float = 0.0):
    """Origins on the input surface of grown points (see module docstring).

    Parameters
    ----------
    front : Front
    points_mm : (n, 3) float
        Grown points, object frame, mm.
    wind : (3,) float, optional
        Constant direction part ``w`` of the speed (eccentricity).
    step_voxels : float
        Step of the backward integration in voxels.
    until_mm : float
        Stop on the front of this pseudo-time instead of the input (``T = 0``): where the
        points were at an earlier year.

    Returns
    -------
    origin_mm : (n, 3) float
        Points on the input surface.
    tri : (n,) int or None
        Input triangle of each origin (None when ``until_mm > 0``).
    """
    from ._voxel import sample_linear4

    h = front.grid.spacing_mm
    o = np.asarray(front.grid.origin_mm)
    Tfill, grads, t_max = trace_grids(front)
    w = np.zeros(3) if wind is None else np.asarray(wind, float)
    x = np.array(points_mm, dtype=float)
    active = np.ones(len(x), bool)
    step = step_voxels * h
    n_steps = int(t_max / step / (1 - np.linalg.norm(w) + 1e-9)) + 8
    for _ in range(n_steps):
        if not active.any():
            break
        xa = x[active]
        # the time and its gradient at once, bit for bit scipy's map_coordinates(order=1,
        # mode="nearest") of each grid (four such calls: a quarter of a crack run)
        tg = sample_linear4(Tfill, grads[0], grads[1], grads[2], (xa - o) / h)
        t = tg[0]
        done = t <= until_mm + 1e-9
        g = np.ascontiguousarray(tg[1:].T)
        n = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-12)
        v = n + w
        # do not step past the input surface: at most T / |v . n| along the characteristic
        s = np.minimum(step, np.maximum(t - until_mm, 0.0) / np.maximum(np.sum(v * n, 1), 1e-3))
        xa = xa - v * s[:, None]
        x[active] = xa
        ai = np.nonzero(active)[0]
        active[ai[done | (s < 1e-6 * h)]] = False
    if until_mm > 0:
        return x, None
    # snap to the closest input triangle known on the band nodes, then onto that triangle
    idx = np.clip(np.rint((x - o) / h).astype(int), 0, np.asarray(front.grid.shape) - 1)
    tri = front.input_tri[idx[:, 0], idx[:, 1], idx[:, 2]]
    miss = tri < 0
    if miss.any():  # beyond the band (should not happen): nearest band node
        band = front.input_tri >= 0
        _, near = ndimage.distance_transform_edt(~band, return_indices=True)
        j = idx[miss]
        k = tuple(near[d][j[:, 0], j[:, 1], j[:, 2]] for d in range(3))
        tri[miss] = front.input_tri[k]
    return x, tri


def barycentric_on(mesh, points_mm, tri) -> tuple[np.ndarray, np.ndarray]:
    """Closest points on triangles ``tri`` of ``mesh`` and their barycentric weights ``(n, 3)``."""
    import trimesh

    tris = mesh.triangles[tri]
    cp = trimesh.triangles.closest_point(tris, np.asarray(points_mm, float))
    bary = trimesh.triangles.points_to_barycentric(tris, cp)
    bary = np.clip(bary, 0.0, 1.0)
    bary /= bary.sum(1, keepdims=True)
    return cp, bary


def carry(mesh, values, tri, bary) -> np.ndarray:
    """Per-vertex ``values (n_in, k)`` of the input ``mesh`` carried to grown points."""
    v = np.asarray(values)
    f = mesh.faces[tri]
    return np.einsum("ij,ij...->i...", bary, v[f])


def section_image(field_years, no_wood, inside, plane_origin_mm, u_mm, v_mm, size_px,
                  ring_every: float = 1.0, years_final: float | None = None) -> np.ndarray:
    """RGB ``(rows, cols, 3) uint8`` cut of a grown object (seed Fig. 5.1).

    ``field_years``, ``no_wood``, ``inside`` are callables on ``(n, 3)`` object-frame points;
    pixel ``(r, c)`` sits at ``plane_origin_mm + (c + 0.5) / cols * u_mm + (1 - (r + 0.5) /
    rows) * v_mm`` (u to the right, v up). Wood within ``years_final`` gets an early/latewood
    ramp with dark ring boundaries every ``ring_every`` years; the input object is grey,
    obstacles black, air white.
    """
    rows, cols = size_px
    c = (np.arange(cols) + 0.5) / cols
    r = 1.0 - (np.arange(rows) + 0.5) / rows
    P = (np.asarray(plane_origin_mm, float)[None, None]
         + c[None, :, None] * np.asarray(u_mm, float)[None, None]
         + r[:, None, None] * np.asarray(v_mm, float)[None, None])
    pts = P.reshape(-1, 3)
    y = field_years(pts).reshape(rows, cols)
    phase = np.mod(y / ring_every, 1.0)
    early = np.array([222, 184, 135], float)
    late = np.array([150, 100, 55], float)
    t = np.clip((phase - 0.55) / 0.45, 0, 1)[..., None] ** 2
    img = early * (1 - t) + late * t
    # ring boundaries: one pixel-ish dark line where the year crosses a multiple of ring_every
    gy, gx = np.gradient(y / ring_every)
    width = np.hypot(gx, gy) * 0.9 + 1e-9
    near = np.minimum(phase, 1 - phase) < width
    img[near] = (70, 40, 20)
    if years_final is not None:
        img[y > years_final] = (255, 255, 255)
    img[inside(pts).reshape(rows, cols)] = (170, 170, 170)
    img[no_wood(pts).reshape(rows, cols)] = (20, 20, 20)
    return img.astype(np.uint8)


def scale_bar_mm(width_mm: float, units: Units = "mm") -> float:
    """Length (mm) of the scale bar of a picture ``width_mm`` wide: the longest round length in
    ``units`` (1, 2 or 5 times a power of ten: 10 mm, 20 mm, 0.5 in, 1 in) at most a fifth of
    the width, so the bar spans 8 % to 20 % of it."""
    if not (np.isfinite(width_mm) and width_mm > 0):
        raise WoodcamError(f"width_mm must be a length > 0 (the picture's width, mm); got {width_mm!r}")
    k = MM_PER_UNIT[units]
    most = width_mm / 5 / k
    power = 10.0 ** np.floor(np.log10(most))
    step = max(m for m in (1, 2, 5) if m * power <= most * (1 + 1e-9))
    return float(step * power * k)


def with_scale_bar(img, mm_per_px: float, units: Units = "mm") -> tuple[np.ndarray, float]:
    """``img`` (rows, cols, 3) uint8 with a white strip added below it holding a scale bar: a
    black bar :func:`scale_bar_mm` long (``mm_per_px`` mm a pixel along the rows) from column
    12, end ticks, its length written above it in ``units`` ("10 mm", "1 in"). The picture's
    own pixels are unchanged (the strip covers none of it). Returns (new image, bar length mm).
    """
    from PIL import Image, ImageDraw, ImageFont

    img = np.asarray(img, np.uint8)
    rows, cols = img.shape[:2]
    length_mm = scale_bar_mm(cols * mm_per_px, units)
    bar_px = int(round(length_mm / mm_per_px))
    label = fmt_length(length_mm, units)
    font = ImageFont.load_default()
    text_h = int(np.ceil(ImageDraw.Draw(Image.new("RGB", (1, 1))).textbbox((0, 0), label, font=font)[3]))
    pad, bar_h, tick = 6, 4, 4
    strip = Image.new("RGB", (cols, pad + text_h + 3 + tick + bar_h + pad), (255, 255, 255))
    draw = ImageDraw.Draw(strip)
    x0, y_bar = 12, pad + text_h + 3 + tick
    draw.text((x0, pad), label, fill=(0, 0, 0), font=font)
    draw.rectangle((x0, y_bar, x0 + bar_px - 1, y_bar + bar_h - 1), fill=(0, 0, 0))
    for x in (x0, x0 + bar_px - 1):  # end ticks, so the bar's two ends read exactly
        draw.line((x, y_bar - tick, x, y_bar + bar_h - 1), fill=(0, 0, 0))
    return np.concatenate([img, np.asarray(strip, np.uint8)], axis=0), length_mm
