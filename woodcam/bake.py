"""Texture baking: UV-unwrap a carved mesh and paint the wood's colour into a texture atlas.

Data form
---------
* Meshes are in the block frame, millimetres (``docs/conventions.md``).
* The wood is any object with ``color(points_mm: (n, 3) float, normals: (n, 3) float unit)
  -> (n, 3) float RGB in [0, 1]`` (seed 000, eq. 10 is one such appearance: a normal-weighted
  blend of three colour volumes). The baker never looks inside it.
* The atlas is an image ``(h, w, 3) uint8``; row 0 is the TOP row of the image file. Colours
  are stored as ``round(255 * rgb)``: ``wood.color`` is taken to return display (sRGB-encoded)
  values, which is how glTF and OBJ viewers read a base-colour texture.

Texel / UV convention (the "v flip")
------------------------------------
Texel ``(row r, col c)`` of an atlas of ``h x w`` texels covers ``[c, c + 1] x [r, r + 1]`` in
texel coordinates ``(x, y)``; its centre is ``(c + 0.5, r + 0.5)``.  The mesh carries trimesh /
OBJ texture coordinates, origin at the image's bottom-left::

    u = x / w,        v = 1 - y / h          (centre of texel (r, c): u = (c + .5) / w,
                                                                   v = 1 - (r + .5) / h)

trimesh's glTF exporter writes ``(u, 1 - v)``, i.e. glTF's top-left origin, so GLB viewers and
OBJ viewers both sample texel (r, c) at the same surface point.

Pipeline (each step timed in :attr:`BakeResult.timings`)
--------------------------------------------------------
1. ``unwrap``: charts made here (faces grouped by normal cone, projected flat, scaled so no
   face gets fewer texels per mm than asked; :func:`_projected_charts`), or xatlas' own charts
   where those fold or fragment; xatlas packs them at ``texels_per_unit = texels_per_mm`` (the
   mesh is in mm, so one xatlas "unit" is a millimetre), one atlas, charts ``padding_px``
   texels apart, in a worker process (a native crash never takes the caller down).
2. ``rasterise``: every triangle is rasterised conservatively in texel space by a numba kernel
   that walks the rows of its footprint (:mod:`woodcam._raster`). A texel is painted
   when its centre lies within L-infinity distance 1 (+ a 0.02 texel margin) of the triangle,
   which covers every texel bilinear sampling at any point of the triangle can read. A texel
   whose centre lies inside a triangle takes that triangle; a texel only in border rings takes the
   nearest triangle and the triangle's affine map is extrapolated to it (a point in the
   triangle's plane at most ~1.5 texels outside it).
3. ``color``: 3D point and normal of every painted texel -> ``wood.color`` in bounded batches.
4. ``dilate``: every unpainted texel takes the colour of a nearest painted texel (OpenCV's
   labelled chamfer distance transform), so no mip level ever averages in black.
"""

from __future__ import annotations

import math
import numbers
import os
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

import numpy as np

from woodcam._checks import check_bool, not_a_mesh
from woodcam._repr import summary_repr
from woodcam._types import Mesh, WoodLike
from woodcam.errors import WoodcamError, WoodcamWarning
from woodcam.limits import limit
from woodcam.units import say_area, say_length
from woodcam.tolerances import (
    ATLAS_PADDING_PX,
    DEFAULT_MAX_ATLAS_PX,
    MAX_BATCH_POINTS,
    MIN_NORMAL_LENGTH,
    MIN_UV_AREA_TEXELS2,
    RASTER_MARGIN_TEXELS,
)

NormalsMode = Literal["face", "smooth"]
UnwrapMode = Literal["auto", "xatlas"]

#: When projected charts (:func:`_projected_charts`) pack with a UV fill below this AND they
#: are fragmented (more than _MAX_SMALL_CHART_AREA of the surface in charts of fewer than
#: _SMALL_CHART_FACES faces), xatlas' own charts are made too and the fuller atlas kept: the
#: normals of a noisy or scanned mesh jump between cones (a noisy icosphere: 0.93 of its area in
#: such charts; the examples <= 0.1, the linuxcnc meshes 0.03-0.5). A low fill of large charts
#: is the padding's share at a low density, which xatlas' charts pay too (the 52k bowl at 2
#: texels/mm: 0.37 against 0.38, for 7 CPU-s more), so it does not call xatlas.
_MIN_PROJECTED_FILL = 0.4
_SMALL_CHART_FACES = 20
_MAX_SMALL_CHART_AREA = 0.2

#: Centroids each triangle tests for lying inside it in the fold check of projected charts
#: (its own and its ~3-12 neighbours come first; a second layer's centroid inside it is among
#: the nearest). 8 costs 0.05 CPU-s on the bowl, a radius query of all candidates 0.35.
_FOLD_NEIGHBOURS = 8

#: Fraction of the atlas xatlas fills with charts at 8 px padding (measured 0.5-0.85 on
#: spheres and carved boxes); used only to predict the atlas side before unwrapping.
_PACK_EFFICIENCY = 0.6

#: Upper bound on the area of one xatlas chart as a fraction of the surface area, via
#: ``ChartOptions.max_chart_area`` (0: no cap). Measured UV fill / xatlas CPU-s at 10 texels/mm
#: (bowl 32k triangles; lid 12k; 20k icosphere): uncapped 0.59 / 4.0, 0.57 / 0.9, 0.61 / 2.3;
#: cap 1/32 0.39 / 2.4, 0.50 / 1.2, 0.55 / 0.8; the earlier cap of 256 x the median face
#: made CAD parts (triangle areas vary by orders of magnitude) into ~1,100 sliver charts
#: filling 0.15. Fill is what the texel budget buys, so no cap; the triangle budget of
#: load_part bounds the unwrap time instead.
_CHART_AREA_FRACTION = 0.0

#: xatlas ``ChartOptions.max_iterations``: one pass of chart growing (see above).
_CHART_ITERATIONS = 0

#: Run xatlas in this process (no crash guard); for debugging only.
_XATLAS_IN_PROCESS = False

#: When xatlas' packed atlas overshoots ``max_atlas_px`` by a factor down to this, the layout is
#: scaled down instead of re-unwrapped: chart gaps shrink from ``padding_px`` to at worst
#: 0.85 x ``padding_px`` (never below _MIN_PADDING_PX), and xatlas' ~1 s is not repeated.
_MIN_RESCALE = 0.85

#: Smallest gap (texels) between charts: each chart needs its own 1-texel ring for bilinear
#: sampling, so two charts need 2 texels between them.
_MIN_PADDING_PX = 2

#: Atlas width and height are rounded up to a multiple of this, so mip levels 1..3 halve exactly.
_ATLAS_SIZE_MULTIPLE = 8


@dataclass
class BakeResult:
    """What :func:`bake` returns.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        The input surface with vertices split at UV seams (as xatlas returns them), mm, block
        frame, ``visual = TextureVisuals(uv (m, 2), material=PBRMaterial(baseColorTexture=PIL))``;
        faces in the input's order. With ``normals="smooth"`` its ``vertex_normals`` are the
        input's (seam-free shading).
    atlas : (h, w, 3) uint8
        The baked, dilated texture; row 0 is the image's top row.
    coverage_mask : (h, w) bool
        Texels painted from a triangle (before dilation); the rest are dilation fill.
    texels_per_mm : float
        Texel density actually used (lower than asked when the atlas would exceed
        ``max_atlas_px``; then ``warnings`` says so).
    timings : dict[str, float]
        Seconds per step: ``unwrap``, ``rasterise``, ``color``, ``dilate``, ``total``.
    warnings : list[str]
        Human-readable messages about anything the baker changed from what was asked.
    vertex_map : (m,) int
        Index of the input vertex each output vertex came from.
    uv_fill : float
        Share of the atlas covered by the triangles' texel-space area (packing efficiency).
    density_stretch : float
        Area-weighted mean density over ``texels_per_mm`` (>= 1): projected charts give tilted
        faces more texels than asked, never fewer; 1 for xatlas' own charts.
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    mesh: Any
    atlas: np.ndarray
    coverage_mask: np.ndarray
    texels_per_mm: float
    timings: dict[str, float]
    warnings: list[str] = field(default_factory=list)
    vertex_map: np.ndarray | None = None
    uv_fill: float = 0.0
    density_stretch: float = 1.0

    @property
    def gpu_bytes(self) -> int:
        """GPU memory of the texture as an RGBA8 image with its mip chain (x 4/3)."""
        h, w = self.atlas.shape[:2]
        return int(h * w * 4 * 4 / 3)

    def summary(self) -> str:
        """One line: atlas size, fill, texel density and GPU memory."""
        h, w = self.atlas.shape[:2]
        mean = (f" (mean {self.texels_per_mm * self.density_stretch:.3g})"
                if self.density_stretch > 1.01 else "")
        return (f"atlas {w}x{h}, UV fill {100 * self.uv_fill:.0f} %, "
                f"{self.texels_per_mm:.3g} texels/mm{mean}, "
                f"GPU {self.gpu_bytes / 2**20:.0f} MiB")


def bake(
    mesh: Mesh,
    wood: WoodLike,
    *,
    texels_per_mm: float = 10.0,
    max_atlas_px: int = DEFAULT_MAX_ATLAS_PX,
    padding_px: int = ATLAS_PADDING_PX,
    normals: NormalsMode = "face",
    progress: bool = False,
    unwrap: UnwrapMode = "auto",
) -> BakeResult:
    """Unwrap ``mesh`` and bake ``wood.color`` into a texture atlas.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Triangle surface in the block frame, mm (e.g. a carved part).
    wood : object with ``color(points_mm (n, 3), normals (n, 3)) -> (n, 3) RGB in [0, 1]``
    texels_per_mm : float
        Wanted texel density (texels per mm along the surface), > 0.
    max_atlas_px : int
        Largest allowed atlas side in texels; the density is lowered (with a warning) to fit.
    padding_px : int
        Texels between charts in the atlas, >= 2 (with 0 or 1 a texel between two charts would
        need two colours: measured errors reach the bound's limit). 8 keeps mip levels 1-2 inside
        one chart's dilation.
    normals : {"face", "smooth"}
        Normal passed to ``wood.color``: the flat triangle normal (right for CAD parts with sharp
        edges), or trimesh's vertex normal of the INPUT mesh (before the seam split) interpolated
        barycentrically and renormalised (for smooth organic surfaces).
    progress : bool
        Show a tqdm bar over the rasterisation groups.
    unwrap : {"auto", "xatlas"}
        ``"auto"``: woodcam's projected charts (faces grouped by normal cone, projected flat, no
        face below the asked density), packed by xatlas; xatlas' own charting when they fold or
        fragment. ``"xatlas"``: xatlas charts and packs (slower: 3.5 CPU-s on the 32k-triangle
        bowl against 0.6; exact density on every face).

    Returns
    -------
    BakeResult
    """
    from .appearance.wood import wood_colors  # the one check of the colour contract

    t_start = time.perf_counter()
    _check_args(mesh, wood, texels_per_mm, max_atlas_px, padding_px, normals)
    progress = check_bool(progress, "bake: progress")
    if unwrap not in get_args(UnwrapMode):
        raise WoodcamError(f"bake: unwrap must be one of {get_args(UnwrapMode)}; got {unwrap!r}")
    verts_in = np.asarray(mesh.vertices, dtype=np.float64)
    # "smooth": the input's vertex normals, read once; the colour lookup interpolates them and
    # the result mesh keeps them as its shading normals (_bake_atlas)
    vertex_normals = (np.asarray(mesh.vertex_normals, dtype=np.float64) if normals == "smooth"
                      else None)

    def colours(vmap, faces, xy):
        # xatlas keeps face order, so output face i is input face i.
        point_map = _affine_maps(xy, faces, verts_in[vmap])
        face_normals = _face_directions(mesh)
        if vertex_normals is not None:
            normal_map = _affine_maps(xy, faces, vertex_normals[vmap])

        def paint(t, cx, cy):
            points = _apply_affine(point_map, t, cx, cy)
            if vertex_normals is None:
                nrm = face_normals[t]
            else:
                nrm = _apply_affine(normal_map, t, cx, cy)
                length = np.linalg.norm(nrm, axis=1, keepdims=True)
                # vertex normals that cancel (a thin fin's two sides) interpolate to no
                # direction, which the wood refuses: the triangle's own normal there
                flat = length[:, 0] < MIN_NORMAL_LENGTH
                nrm /= np.maximum(length, 1e-12)
                nrm[flat] = face_normals[t[flat]]
            rgb = wood_colors(wood, points, nrm)
            return np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
        return paint

    return _bake_atlas(mesh, float(texels_per_mm), int(max_atlas_px), int(padding_px), unwrap,
                       colours, progress=progress, t_start=t_start, vertex_normals=vertex_normals)


def _bake_atlas(mesh, tpm: float, max_px: int, padding: int, unwrap: str, colours, *,
                progress: bool = False, t_start: float,
                vertex_normals: np.ndarray | None = None) -> BakeResult:
    """The pipeline :func:`bake` and :func:`rebake_texture` share: unwrap, rasterise, colour
    every covered texel, dilate, and the textured mesh. Only the colour source differs:
    ``colours(vmap (m,), faces (f, 3), xy (m, 2) texel coordinates) -> paint``, and
    ``paint(tri (k,), cx (k, 1), cy (k, 1)) -> (k, 3) uint8`` colours the texels whose centres
    ``(cx, cy)`` (texels) lie in output faces ``tri``, called in batches of MAX_BATCH_POINTS.
    ``vertex_normals`` (optional, (n, 3) unit, the INPUT mesh's) become the result mesh's
    shading normals, split with its vertices: no shading seam where the unwrap split vertices
    (normals recomputed on the split mesh differ on each side of a seam; ``export_glb(...,
    normals="mesh")`` writes them as they are). ``timings["total"]`` runs from ``t_start``.
    Arguments are checked by the callers; warnings are raised at their callers."""
    import trimesh

    messages: list[str] = []
    timings: dict[str, float] = {}

    # ---- 1. unwrap -------------------------------------------------------------------------
    t0 = time.perf_counter()
    vmap, faces, xy, width, height, tpm, stretch = _unwrap(mesh, tpm, max_px, padding, messages, unwrap)
    timings["unwrap"] = time.perf_counter() - t0
    img_w = _round_up(width, _ATLAS_SIZE_MULTIPLE)
    img_h = _round_up(height, _ATLAS_SIZE_MULTIPLE)

    # ---- 2. rasterise ----------------------------------------------------------------------
    t0 = time.perf_counter()
    tri_of_texel = _rasterise(xy, faces, img_w, img_h, progress=progress)
    painted = np.flatnonzero(tri_of_texel >= 0)
    tri = tri_of_texel[painted]
    timings["rasterise"] = time.perf_counter() - t0

    # ---- 3. colour -------------------------------------------------------------------------
    t0 = time.perf_counter()
    paint = colours(vmap, faces, xy)
    atlas = np.zeros((img_h * img_w, 3), dtype=np.uint8)
    # Batches of MAX_BATCH_POINTS texels: bounded memory, arrays that stay in cache.
    for s in range(0, len(painted), MAX_BATCH_POINTS):
        idx = painted[s:s + MAX_BATCH_POINTS]
        atlas[idx] = paint(tri[s:s + MAX_BATCH_POINTS], (idx % img_w + 0.5)[:, None],
                           (idx // img_w + 0.5)[:, None])
    atlas = atlas.reshape(img_h, img_w, 3)
    coverage = (tri_of_texel >= 0).reshape(img_h, img_w)
    timings["color"] = time.perf_counter() - t0

    # ---- 4. dilate -------------------------------------------------------------------------
    t0 = time.perf_counter()
    atlas = _dilate(atlas, coverage)
    timings["dilate"] = time.perf_counter() - t0

    uv = np.column_stack([xy[:, 0] / img_w, 1.0 - xy[:, 1] / img_h])
    out = _textured_mesh(trimesh, np.asarray(mesh.vertices, dtype=np.float64)[vmap], faces, uv, atlas,
                         None if vertex_normals is None else vertex_normals[vmap])
    timings["total"] = time.perf_counter() - t_start
    for msg in messages:
        warnings.warn(msg, WoodcamWarning, stacklevel=3)  # at the caller of bake / rebake_texture
    return BakeResult(
        mesh=out,
        atlas=atlas,
        coverage_mask=coverage,
        texels_per_mm=tpm,
        timings=timings,
        warnings=messages,
        vertex_map=vmap,
        uv_fill=_uv_fill(xy, faces, img_w, img_h),
        density_stretch=stretch,
    )


def bake_charts(mesh, uv_px, size_px, texels, wood, *, texels_per_mm: float,
                vertex_normals=None, messages=(), fill_gutters=None) -> BakeResult:
    """Bake ``wood.color`` into an atlas whose charts the caller already knows (no unwrap, no
    rasterisation): ``mesh`` with per-vertex texel coordinates ``uv_px : (n, 2)`` (x right, y
    down, pixel corners at integers) in an atlas of ``size_px = (width, height)``, and
    ``texels``, an iterable of ``(flat texel indices (k,), points_mm (k, 3), normals (k, 3))``
    giving every chart texel's point and normal. Used for the height-field stock of a G-code
    preview (:class:`woodcam.toolpath.mesh.HeightfieldCharts`), whose top is textured by its own
    planar parameterisation. ``vertex_normals`` (optional, (n, 3)) are kept on the result mesh
    for export; ``fill_gutters(atlas, coverage) -> atlas`` (optional) paints the texels outside
    the charts when the caller knows a cheaper way than the nearest-texel transform (the
    height field's rectangles); the rest as :func:`bake`."""
    import trimesh

    from .appearance.wood import wood_colors  # the one check of the colour contract

    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    w, h = (int(v) for v in size_px)
    atlas = np.zeros((h * w, 3), np.uint8)
    coverage = np.zeros(h * w, bool)
    for idx, pts, nrm in texels:
        for s in range(0, len(idx), MAX_BATCH_POINTS):
            sl = slice(s, s + MAX_BATCH_POINTS)
            rgb = wood_colors(wood, pts[sl], nrm[sl])
            atlas[idx[sl]] = np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
        coverage[idx] = True
    atlas = atlas.reshape(h, w, 3)
    coverage = coverage.reshape(h, w)
    timings["color"] = time.perf_counter() - t_start
    t0 = time.perf_counter()
    atlas = fill_gutters(atlas, coverage) if fill_gutters is not None else _dilate(atlas, coverage)
    timings["dilate"] = time.perf_counter() - t0
    uv_px = np.asarray(uv_px, float)
    uv = np.column_stack([uv_px[:, 0] / w, 1.0 - uv_px[:, 1] / h])
    # vertex_normals exported as they are (export normals="mesh")
    out = _textured_mesh(trimesh, np.asarray(mesh.vertices), np.asarray(mesh.faces), uv, atlas,
                         vertex_normals)
    timings["total"] = time.perf_counter() - t_start
    messages = list(messages)
    for msg in messages:
        warnings.warn(msg, WoodcamWarning, stacklevel=2)
    return BakeResult(mesh=out, atlas=atlas, coverage_mask=coverage,
                      texels_per_mm=float(texels_per_mm), timings=timings, warnings=messages,
                      uv_fill=float(coverage.mean()))


def rebake_texture(mesh, corner_uv, image, *, texels_per_mm: float, max_atlas_px: int = DEFAULT_MAX_ATLAS_PX,
                   padding_px: int = ATLAS_PADDING_PX) -> BakeResult:
    """Move a picture laid on ``mesh`` by any texture coordinates into an atlas of even texel
    density (:func:`bake`'s unwrap): every face gets ``texels_per_mm`` along the surface, also
    where the given coordinates squeeze it to a line (a cylindrical projection of a flat face).
    What is drawn into the result per mm of surface (cracks) then no longer depends on how the
    picture was laid on.

    Parameters
    ----------
    mesh : trimesh.Trimesh, mm
    corner_uv : (f, 3, 2) float
        Texture coordinates of every face's corners (u right, v up from the image's bottom row;
        outside [0, 1] the picture repeats).
    image : (h, w, 3) uint8
    texels_per_mm, max_atlas_px, padding_px : as :func:`bake`

    Returns
    -------
    BakeResult ; ``mesh.faces`` keep the input's order, ``vertex_map`` names each vertex's input
    vertex, the atlas is the picture sampled bilinearly (repeating) at every texel.
    """
    t_start = time.perf_counter()
    corner_uv = np.asarray(corner_uv, np.float64)
    faces_in = np.asarray(mesh.faces)
    if corner_uv.shape != (len(faces_in), 3, 2):
        raise WoodcamError(f"rebake_texture: corner_uv must be (faces, 3, 2) = ({len(faces_in)}, 3, 2); "
                           f"got {corner_uv.shape}")
    shape = np.shape(image)
    if len(shape) != 3 or shape[2] != 3 or not shape[0] or not shape[1]:
        # a grey (h, w) picture was read as h rows of w-wide "colours": a 2^18 x 2^18 atlas
        raise WoodcamError(f"rebake_texture: image must be an (h, w, 3) RGB array; got shape {shape}; "
                           "repeat a grey picture into three channels (np.dstack([grey] * 3))")
    _check_args(mesh, None, texels_per_mm, max_atlas_px, padding_px, "face", picture=True)
    pic = np.asarray(image, np.float32)
    ph, pw = pic.shape[:2]

    def colours(vmap, faces, xy):
        # per corner: a face's own uv (a seam's two sides differ), interpolated over its triangle
        corners = np.arange(3 * len(faces)).reshape(-1, 3)
        uv_map = _affine_maps(xy[faces].reshape(-1, 2), corners, corner_uv.reshape(-1, 2))

        def paint(t, cx, cy):
            uv = _apply_affine(uv_map, t, cx, cy)
            x, y = uv[:, 0] * pw - 0.5, (1.0 - uv[:, 1]) * ph - 0.5
            x0, y0 = np.floor(x), np.floor(y)
            fx, fy = (x - x0)[:, None], (y - y0)[:, None]
            c0, r0 = x0.astype(np.int64) % pw, y0.astype(np.int64) % ph
            c1, r1 = (c0 + 1) % pw, (r0 + 1) % ph
            rgb = ((pic[r0, c0] * (1 - fx) + pic[r0, c1] * fx) * (1 - fy)
                   + (pic[r1, c0] * (1 - fx) + pic[r1, c1] * fx) * fy)
            return np.round(np.clip(rgb, 0, 255)).astype(np.uint8)
        return paint

    return _bake_atlas(mesh, float(texels_per_mm), int(max_atlas_px), int(padding_px), "auto", colours,
                       t_start=t_start)


# ------------------------------------------------------------------------------------------------
# helpers


def _face_directions(mesh) -> np.ndarray:
    """A direction per triangle ``(f, 3)`` float64 for the colour lookup, which refuses a zero
    normal: trimesh's face normal, or for a degenerate triangle (zero area: its normal is zero,
    yet the atlas gives it texels, e.g. the slivers of woodify's crack insertion) the mean of its
    corners' normals (:func:`~woodcam.appearance.wood.vertex_color_normals`), or +Z where even
    those cancel. Such a triangle covers no surface, so its colour is only seen by filtering."""
    from .appearance.wood import vertex_color_normals

    normals = np.array(mesh.face_normals, dtype=np.float64).reshape(-1, 3)
    length = np.linalg.norm(normals, axis=1)
    bad = ~(np.isfinite(length) & (length >= MIN_NORMAL_LENGTH))
    if bad.any():
        corners = vertex_color_normals(mesh)[np.asarray(mesh.faces)[bad]].sum(axis=1)
        size = np.linalg.norm(corners, axis=1, keepdims=True)
        normals[bad] = np.where(size >= MIN_NORMAL_LENGTH, corners / np.maximum(size, 1e-300),
                                (0.0, 0.0, 1.0))
    return normals


def _check_args(mesh, wood, texels_per_mm, max_atlas_px, padding_px, normals, *,
                picture: bool = False) -> None:
    """The arguments of :func:`bake` checked at the door (``picture``: a picture is baked, no
    wood, as :func:`rebake_texture`)."""
    if isinstance(mesh, (str, os.PathLike)):  # was "got str with 0 faces"
        raise not_a_mesh("bake: mesh", mesh, "")
    faces = getattr(mesh, "faces", None)
    if faces is None or len(faces) == 0:
        raise WoodcamError(
            f"bake: mesh must be a trimesh.Trimesh with at least one triangle; got "
            f"{type(mesh).__name__} with {0 if faces is None else len(faces)} faces; pass the "
            "carved part's surface mesh"
        )
    verts = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
    span = float(np.ptp(verts, axis=0).max()) if len(verts) else 0.0  # NaN with a NaN vertex
    cap = limit("MAX_BLOCK_SIZE_MM")
    if not span <= cap:
        raise WoodcamError(
            f"bake: the mesh's vertices must be finite and span at most {say_length(cap, 'g')} (the "
            f"largest block); got a span of {say_length(span, '.4g')} or NaN/inf; check the part's units and "
            "coordinates (one far vertex made a 7 GB atlas), or raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N"
        )
    if not picture and not callable(getattr(wood, "color", None)):
        raise WoodcamError(
            f"bake: wood must have a method color(points_mm, normals) -> rgb; got "
            f"{type(wood).__name__}; pass a woodcam.appearance.Wood or any object with .color"
        )
    if not (isinstance(texels_per_mm, numbers.Real) and math.isfinite(texels_per_mm)
            and texels_per_mm > 0):
        raise WoodcamError(
            f"bake: texels_per_mm must be a finite number > 0; got {texels_per_mm!r}; "
            "use e.g. 10 (0.1 mm texels)"
        )
    if not isinstance(max_atlas_px, (int, np.integer)) or not 64 <= max_atlas_px <= 65_536:
        raise WoodcamError(
            f"bake: max_atlas_px must be an integer in [64, 65536] (the --max-atlas range); got "
            f"{max_atlas_px!r}; use e.g. {DEFAULT_MAX_ATLAS_PX}"
        )
    if not isinstance(padding_px, (int, np.integer)) or padding_px < _MIN_PADDING_PX:
        raise WoodcamError(
            f"bake: padding_px must be an integer >= 2 (each chart needs its own 1-texel ring "
            f"for bilinear sampling, so charts must be 2 texels apart); got {padding_px!r}; use "
            f"e.g. {ATLAS_PADDING_PX}"
        )
    if normals not in get_args(NormalsMode):
        raise WoodcamError(
            f"bake: normals must be one of {get_args(NormalsMode)}; got {normals!r}"
        )


def _round_up(n: int, k: int) -> int:
    return int(-(-int(n) // k) * k)


def _unwrap(mesh, tpm: float, max_px: int, padding: int, messages: list[str],
            unwrap: str = "auto"):
    """Charts (:func:`_projected_charts`, or xatlas' own when ``unwrap == "xatlas"`` or the
    projection is not trusted) packed by xatlas into ONE atlas whose sides are <= ``max_px``.

    Returns ``vmap (m,) int``, ``faces (f, 3) int``, ``xy (m, 2) float64`` texel coordinates,
    atlas ``width``, ``height`` (texels), the density used (texels / mm, the least any face
    gets) and the mean density over it (area-weighted, >= 1).
    """
    # The image side is later rounded up to a multiple of _ATLAS_SIZE_MULTIPLE: stay below.
    max_px = max_px // _ATLAS_SIZE_MULTIPLE * _ATLAS_SIZE_MULTIPLE
    verts = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    faces_in = np.ascontiguousarray(mesh.faces, dtype=np.uint32)
    area = float(mesh.area)
    asked = tpm
    # Predict the side from surface area and density; lower the density before unwrapping so a
    # huge request never makes xatlas allocate a huge packing bitmap.
    predicted = math.sqrt(area * tpm * tpm / _PACK_EFFICIENCY) + 2 * padding
    if predicted > max_px:
        tpm = tpm * (max_px - 2 * padding) / (predicted - 2 * padding) * 0.97
    chart_cap = _chart_area_cap(mesh)
    pieces = [np.arange(len(faces_in))]
    charts = _projected_charts(mesh) if unwrap == "auto" else None
    stretch = 1.0 if charts is None else charts[3]

    for _attempt in range(4):
        if charts is not None:
            packed = _pack_guarded(charts, tpm, padding, messages)
            if packed is None:  # xatlas died packing: chart with xatlas instead
                charts, stretch = None, 1.0
        if charts is not None:
            vmap, faces, uv, width, height = packed
            fill = _uv_fill(uv * [width, height], faces, width, height)
            if fill < _MIN_PROJECTED_FILL and charts[4] > _MAX_SMALL_CHART_AREA:  # noisy normals
                other = _layout_guarded(verts, faces_in, pieces, chart_cap, tpm, padding,
                                        messages)
                if _uv_fill(other[2] * other[3:5], other[1], *other[3:5]) > fill:
                    charts, stretch = None, 1.0
                    vmap, faces, uv, width, height, pieces = other
        else:
            vmap, faces, uv, width, height, pieces = _layout_guarded(
                verts, faces_in, pieces, chart_cap, tpm, padding, messages)
        scale = max_px / max(width, height)
        if scale >= _MIN_RESCALE and scale * padding >= _MIN_PADDING_PX:
            break
        tpm *= (max_px - 2 * padding) / (max(width, height) - 2 * padding) * 0.97
    else:  # pragma: no cover - xatlas overshooting four times in a row
        raise WoodcamError(
            f"bake: could not fit the atlas into max_atlas_px={max_px} (last {width}x{height} at "
            f"{tpm:.3g} texels/mm); raise max_atlas_px (--max-atlas) or lower texels_per_mm"
        )
    # xatlas-python normalises by the atlas size; back to texel coordinates (float64).
    xy = np.asarray(uv, dtype=np.float64) * np.array([width, height], dtype=np.float64)
    if scale < 1.0:
        # A slight overshoot: shrink the packed layout instead of re-running xatlas (~1 s).
        xy *= scale
        width = min(max_px, math.ceil(width * scale))
        height = min(max_px, math.ceil(height * scale))
        tpm *= scale
    if tpm < asked:
        messages.append(
            f"bake: texels_per_mm lowered from {asked:g} to {tpm:.4g} (texel {say_length(1 / tpm, '.3g')}) "
            f"so the {say_area(area, '.0f')} surface fits a {width}x{height} atlas within "
            f"max_atlas_px={max_px}; raise max_atlas_px (--max-atlas) for finer texels"
        )
    return (vmap.astype(np.int64), faces.astype(np.int64), xy, width, height, float(tpm),
            float(stretch))


def _pack_guarded(charts, tpm: float, padding: int, messages: list[str]):
    """:func:`woodcam._xatlas_worker.pack` of :func:`_projected_charts` in a worker process
    (:func:`_run_guarded`); vmap mapped back to input vertices. None, with a message saying
    so, if xatlas crashed (the caller then charts with xatlas)."""
    uv_mm, chart_faces, corner_vertex = charts[:3]
    try:
        out = _run_guarded("pack", uv_mm, chart_faces, texels_per_mm=float(tpm),
                           padding=int(padding))
    except _WorkerCrashed:
        messages.append("bake: xatlas crashed packing the projected UV charts; unwrapped with "
                        "xatlas' own charts instead (exact density, slower)")
        return None
    except RuntimeError as err:
        raise WoodcamError(f"bake: packing the UV charts failed ({err})") from err
    vmap, faces, uv, width, height = out
    return corner_vertex[vmap], faces, uv, width, height


def _uv_fill(xy: np.ndarray, faces: np.ndarray, width: int, height: int) -> float:
    """Texel-space triangle area over the atlas area."""
    p = xy[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return float(0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / (width * height))


def _chart_area_cap(mesh) -> float:
    """xatlas ``max_chart_area`` (mm^2, 0: none) for ``mesh``: :data:`_CHART_AREA_FRACTION`."""
    return float(_CHART_AREA_FRACTION * float(mesh.area))


def _cone_directions() -> np.ndarray:
    """The 26 chart directions (cube faces, edges and corners), unit (26, 3): every unit vector
    lies within 27.6 degrees of one of them."""
    import itertools

    d = np.array([p for p in itertools.product((-1.0, 0.0, 1.0), repeat=3) if any(p)])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _projected_charts(mesh):
    """Charts made by woodcam (no xatlas charting): the faces whose normals lie in the same one of
    :func:`_cone_directions`' cones and that are edge-connected form a chart, projected
    orthogonally on the plane normal to its area-weighted mean normal and scaled by
    ``1 / min cos`` (the face tilted most against that normal), so no face gets fewer texels per
    mm than asked (the others up to ``1 / min cos`` more; measured 1.03-1.12 x on the example
    parts in mean density).

    Written here because xatlas' own charting (chart growing + LSCM) took 3.5 of the bowl's 5.6
    CPU-s while this takes 0.05 s and xatlas still packs; the cones keep every chart's stretch
    below 1 / cos(55 deg) and in practice 1 / 0.82.

    Returns ``(uv_mm (k, 2) float32, chart_faces (f, 3) int, corner_vertex (k,) int,
    mean_stretch float, fragmented float)`` with one uv vertex per chart corner (fragmented: the
    area share in charts of fewer than _SMALL_CHART_FACES faces), or None when a chart folds
    over itself (e.g. a helical ramp), left to xatlas.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    verts = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    tri = verts[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    valid = double_area > 1e-12 * max(1.0, float(double_area.max(initial=0.0)))
    normal = cross / np.where(valid, double_area, 1.0)[:, None]
    cone = np.argmax(normal @ _cone_directions().T, axis=1)
    adj = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
    adj = adj[cone[adj[:, 0]] == cone[adj[:, 1]]]
    n_faces = len(faces)
    graph = coo_matrix((np.ones(len(adj)), (adj[:, 0], adj[:, 1])), shape=(n_faces, n_faces))
    n_charts, chart = connected_components(graph, directed=False)
    mean = np.zeros((n_charts, 3))
    np.add.at(mean, chart, cross)  # area-weighted (|cross| = 2 x area)
    length = np.linalg.norm(mean, axis=1, keepdims=True)
    axis = np.zeros((n_charts, 3))
    axis[chart] = _cone_directions()[cone]  # a chart of zero-area faces only: its cone's axis
    mean = np.where(length > 0, mean / np.where(length > 0, length, 1.0), axis)
    cos = np.einsum("ij,ij->i", normal, mean[chart])
    min_cos = np.ones(n_charts)
    np.minimum.at(min_cos, chart[valid], cos[valid])
    if np.any(min_cos <= 0.1):  # cannot happen for cones < 90 deg; a guard against NaN meshes
        return None
    ref = np.where(np.abs(mean[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(mean, ref)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(mean, e1)  # (e1, e2, mean) right-handed: faces keep their winding in uv
    key = np.repeat(chart, 3) * len(verts) + faces.reshape(-1)
    corners, chart_faces = np.unique(key, return_inverse=True)
    c_chart = corners // len(verts)
    c_vertex = corners % len(verts)
    scale = 1.0 / min_cos[c_chart]
    p = verts[c_vertex]
    uv = np.column_stack([np.einsum("ij,ij->i", p, e1[c_chart]) * scale,
                          np.einsum("ij,ij->i", p, e2[c_chart]) * scale])
    chart_faces = chart_faces.reshape(-1, 3)
    if _charts_fold(uv, chart_faces, chart):
        return None
    # Lay the charts apart on a grid: xatlas joins uv-mesh corners that coincide, which would
    # merge charts whose projections overlap into one folded chart.
    lo = np.full((n_charts, 2), np.inf)
    hi = np.full((n_charts, 2), -np.inf)
    np.minimum.at(lo, c_chart, uv)
    np.maximum.at(hi, c_chart, uv)
    cell = float((hi - lo).max()) + 1.0
    cols = math.ceil(math.sqrt(n_charts))
    origin = np.column_stack([np.arange(n_charts) % cols, np.arange(n_charts) // cols]) * cell
    uv = uv - lo[c_chart] + origin[c_chart]
    total = max(float(double_area.sum()), 1e-300)
    stretch = float(np.sum(double_area / min_cos[chart] ** 2 * cos) / total)
    small = np.bincount(chart, minlength=n_charts)[chart] < _SMALL_CHART_FACES
    fragmented = float(double_area[small].sum() / total)
    return (uv.astype(np.float32), chart_faces, c_vertex.astype(np.int64), math.sqrt(stretch),
            fragmented)


def _charts_fold(uv: np.ndarray, faces: np.ndarray, chart: np.ndarray) -> bool:
    """True when some chart's projection covers a point twice: the centroid of one of its
    triangles lies strictly inside another of its triangles (k-d tree over the centroids, each
    triangle testing its :data:`_FOLD_NEIGHBOURS` nearest within its corner radius). Every
    triangle of a chart keeps its orientation, so two layers overlapping over more than a few
    triangles are caught; a sliver overlap at a chart's rim can be missed and costs at most a
    few texels."""
    from scipy.spatial import cKDTree

    p = uv[faces]  # (f, 3, 2)
    centre = p.mean(axis=1)
    radius = np.linalg.norm(p - centre[:, None], axis=2).max(axis=1)
    span = float(np.ptp(uv, axis=0).max()) * 4.0 + 1.0
    points = np.column_stack([centre, chart * span])
    k = min(len(faces), _FOLD_NEIGHBOURS)
    dist, other = cKDTree(points).query(points, k=k)
    tri = np.repeat(np.arange(len(faces)), k)
    other = other.reshape(-1)
    keep = (other != tri) & (other < len(faces)) & (dist.reshape(-1) <= np.repeat(radius, k))
    tri, other = tri[keep], other[keep]
    a, b, c = p[tri, 0], p[tri, 1], p[tri, 2]
    q = centre[other]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    det = np.where(np.abs(det) > 1e-12, det, np.inf)  # degenerate: l1 = l2 = 0, never inside
    l1 = ((q[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (q[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / det
    l2 = ((b[:, 0] - a[:, 0]) * (q[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (q[:, 0] - a[:, 0])) / det
    eps = 1e-6
    inside = (l1 > eps) & (l2 > eps) & (1.0 - l1 - l2 > eps)
    return bool(inside.any())


def _split_pieces(verts: np.ndarray, faces: np.ndarray, n: int) -> list[np.ndarray]:
    """``n`` pieces of about equal face count, cut across the longest axis of the surface."""
    centres = verts[faces].mean(axis=1)
    axis = int(np.argmax(np.ptp(centres, axis=0)))
    return [np.sort(p) for p in np.array_split(np.argsort(centres[:, axis], kind="stable"), n)]


class _WorkerCrashed(Exception):
    """The xatlas worker process died natively (segfault): :func:`_run_guarded`."""


def _run_guarded(name: str, *args, **kwargs):
    """``woodcam._xatlas_worker.<name>(*args, **kwargs)`` (``name``: ``"layout"`` or
    ``"pack"``) in a worker process, so a native crash in xatlas never takes the caller down:
    its result, :class:`_WorkerCrashed` when the worker died, and a ``RuntimeError`` of the
    worker (e.g. xatlas made several atlases) raised as is."""
    import concurrent.futures as cf
    import multiprocessing as mp

    import woodcam._xatlas_worker as _xatlas_worker

    if _XATLAS_IN_PROCESS:  # pragma: no cover - debugging aid
        return getattr(_xatlas_worker, name)(*args, **kwargs)
    # fork: the worker needs no fresh interpreter (spawn/forkserver re-import the caller's
    # __main__, which re-runs a user's script that has no ``if __name__ == "__main__"`` guard),
    # and it runs only xatlas' own threads and numpy, none of the parent's thread pools.
    # ``run_<name>`` looks ``<name>`` up when called, so a test's crashing stand-in is what the
    # forked worker runs.
    pool = cf.ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context("fork"),
                                  initializer=_xatlas_worker.die_with_parent)
    try:
        job = pool.submit(getattr(_xatlas_worker, f"run_{name}"), *args, **kwargs)
        try:
            return job.result()
        except cf.process.BrokenProcessPool as err:
            raise _WorkerCrashed(name) from err
    except BaseException:
        # Ctrl-C (or any error) while it works: the worker must not outlive the call (leaving
        # the with-block waited for it to finish, minutes on a huge atlas)
        from ._parallel import kill_workers

        kill_workers(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _layout_guarded(verts, faces, pieces, chart_cap, tpm, padding, messages):
    """:func:`woodcam._xatlas_worker.layout` in a worker process (:func:`_run_guarded`). When
    xatlas dies natively (segfault), retry with the surface cut into 2, 4, 8 pieces (seams are
    invisible after the conservative rasterisation and dilation); if every try dies, one clear
    error."""
    tries = [pieces] + [_split_pieces(verts, faces, n) for n in (2, 4, 8) if n > len(pieces)]
    for attempt in tries:
        try:
            return (*_run_guarded("layout", verts, faces, attempt, max_chart_area=chart_cap,
                                  max_iterations=_CHART_ITERATIONS, texels_per_mm=float(tpm),
                                  padding=int(padding)), attempt)
        except _WorkerCrashed:
            messages.append(
                f"bake: xatlas crashed unwrapping the surface in {len(attempt)} piece(s); "
                f"retried in {2 * len(attempt)} pieces")
        except RuntimeError as err:
            raise WoodcamError(f"bake: the UV unwrap failed ({err})") from err
    raise WoodcamError(
        f"bake: xatlas crashed (native fault) unwrapping this {len(faces)}-triangle surface, "
        f"also when cut into up to {len(tries[-1])} pieces; simplify or re-mesh the part "
        "(e.g. trimesh simplify_quadric_decimation, or a coarser --tolerance)"
    )


def _triangle_frames(xy: np.ndarray, faces: np.ndarray):
    """Per-triangle texel-space data: origin p0 (f, 2), inverse edge matrix (f, 2, 2), double
    signed area (f,), and validity (f,) bool (non-degenerate in UV)."""
    p = xy[faces]  # (f, 3, 2)
    e1 = p[:, 1] - p[:, 0]
    e2 = p[:, 2] - p[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    valid = np.abs(det) > 2.0 * MIN_UV_AREA_TEXELS2
    inv_det = np.where(valid, 1.0 / np.where(valid, det, 1.0), 0.0)
    # (l1, l2) = inv([e1 e2]) @ (x - p0)
    minv = np.empty((len(faces), 2, 2))
    minv[:, 0, 0] = e2[:, 1] * inv_det
    minv[:, 0, 1] = -e2[:, 0] * inv_det
    minv[:, 1, 0] = -e1[:, 1] * inv_det
    minv[:, 1, 1] = e1[:, 0] * inv_det
    return p, minv, det, valid


def _rasterise(xy: np.ndarray, faces: np.ndarray, width: int, height: int, *,
               progress: bool = False) -> np.ndarray:
    """Conservative rasterisation of all triangles in texel space.

    Parameters
    ----------
    xy : (m, 2) float64
        Vertex texel coordinates (x right, y down; texel (r, c) centre at (c + .5, r + .5)).
    faces : (f, 3) int
    width, height : int
        Atlas size in texels.

    Returns
    -------
    (height * width,) int64
        Triangle painting each texel (row-major), -1 where none. A texel whose centre is inside
        (or on the edge of) a triangle takes that triangle; otherwise, if its centre is within
        L-infinity distance 1 of some triangles (the bilinear footprint: the Minkowski sum of the
        triangle and the square [-1, 1]^2, i.e. each edge pushed out by |n_x| + |n_y| plus the
        bounding box grown by 1), the one with the smallest outward edge distance.

    Notes
    -----
    :func:`woodcam._raster.rasterise_kernel` (numba) walks each triangle's rows, testing only
    the columns where the footprint can hold, in float64: O(painted texels + rows), whatever
    the triangle's shape (CAD slivers cost no more than compact triangles).
    """
    from woodcam._raster import rasterise_kernel

    p, _, _, valid = _triangle_frames(xy, faces)
    n = height * width
    owner = np.full(n, -1, dtype=np.int64)
    best_out = np.full(n, np.inf)
    best_tri = np.full(n, -1, dtype=np.int64)
    reach = 1.0 + RASTER_MARGIN_TEXELS  # footprint half-width, texels
    p = np.ascontiguousarray(p, dtype=np.float64)
    chunks = np.linspace(0, len(faces), min(len(faces), 16) + 1).astype(np.int64)
    steps = list(zip(chunks[:-1], chunks[1:]))
    if progress:
        from ._progress import progress_bar

        steps = progress_bar(steps, desc="rasterise", unit="chunk")
    for first, last in steps:
        rasterise_kernel(p, valid, int(width), int(height), float(reach), int(first), int(last),
                         owner, best_out, best_tri)
    return np.where(owner >= 0, owner, best_tri)


def _affine_maps(xy, faces, values):
    """Per-triangle affine maps from texel coordinates to per-vertex ``values (m, d)``:
    ``value(x, y) = origin + jac_x * x + jac_y * y`` (barycentric interpolation inside the
    triangle, linear extrapolation of the same map outside it). Returns three (f, d) arrays, so
    each texel later costs three gathers instead of a (k, 3, d) corner array."""
    p, minv, _, _ = _triangle_frames(xy, faces)
    v = values[faces]  # (f, 3, d)
    e1 = v[:, 1] - v[:, 0]
    e2 = v[:, 2] - v[:, 0]
    jac_x = e1 * minv[:, 0, 0, None] + e2 * minv[:, 1, 0, None]
    jac_y = e1 * minv[:, 0, 1, None] + e2 * minv[:, 1, 1, None]
    origin = v[:, 0] - jac_x * p[:, 0, 0, None] - jac_y * p[:, 0, 1, None]
    return origin, jac_x, jac_y


def _apply_affine(maps, tri, cx, cy) -> np.ndarray:
    """Evaluate :func:`_affine_maps` of triangles ``tri (k,)`` at texel centres
    ``cx, cy (k, 1)``; (k, d) float64."""
    origin, jac_x, jac_y = maps
    return origin[tri] + jac_x[tri] * cx + jac_y[tri] * cy


def _dilate(atlas: np.ndarray, coverage: np.ndarray) -> np.ndarray:
    """Fill every unpainted texel with the colour of a nearest painted texel.

    Filling the whole atlas (not just ``padding_px`` rings) costs the same with a distance
    transform and guarantees that no mip level averages in black. OpenCV's labelled distance
    transform (5x5 chamfer mask, 0.07 CPU-s on a 2k^2 atlas against 0.25 for scipy's exact
    one) may pick a painted texel a little farther than the nearest (measured up to 7.5 texels
    farther, 200 texels out); no surface point samples these texels, only coarse mip levels.
    """
    if coverage.all() or not coverage.any():
        return atlas
    import cv2

    h, w = coverage.shape
    # DIST_LABEL_PIXEL numbers the zero pixels (here: painted texels) 1, 2, ... in row-major
    # order and gives every pixel the label of its nearest zero pixel.
    _, labels = cv2.distanceTransformWithLabels((~coverage).astype(np.uint8), cv2.DIST_L2,
                                                cv2.DIST_MASK_5,
                                                labelType=cv2.DIST_LABEL_PIXEL)
    source = np.flatnonzero(coverage.ravel())[labels.ravel() - 1]
    return atlas.reshape(h * w, -1)[source].reshape(atlas.shape)


def _textured_mesh(trimesh, verts, faces, uv, atlas, vertex_normals=None):
    """The baked mesh: ``verts (m, 3)`` mm, ``faces (f, 3)``, ``uv (m, 2)`` (origin bottom-left),
    the atlas as its PBR base colour, and ``vertex_normals (m, 3)`` (optional) as its shading
    normals (none: trimesh computes them from the faces on demand)."""
    from PIL import Image

    material = trimesh.visual.material.PBRMaterial(
        name="wood",
        baseColorTexture=Image.fromarray(atlas),
        metallicFactor=0.0,  # wood is a dielectric
        roughnessFactor=0.8,  # unfinished / satin wood; a viewer-side choice, not measured
    )
    visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    return trimesh.Trimesh(vertices=verts, faces=faces, visual=visual, vertex_normals=vertex_normals,
                           process=False)
